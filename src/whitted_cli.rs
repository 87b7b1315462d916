//! The `render` example's path for the Whitted ray tracer (`--renderer whitted`): its flags, and
//! rendering to PNG / EXR with the same error quality as the other renderers' paths.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::bail;
use clap::Args;
use illum_image::ExrMetadata;
use illum_scene::{MAX_WHITTED_AA, MAX_WHITTED_DEPTH, Overrides, Scene};
use illum_whitted::WhittedTracer;

use crate::cli::{self, RenderRequest, given_flags};

/// Flags that apply to the Whitted ray tracer only; each overrides the scene's `[whitted]`.
#[derive(Args, Clone, Debug, Default)]
pub struct WhittedArgs {
    /// Whitted ray tracer: recursion depth, 0..=64 (reflected and refracted rays followed this
    /// many times). Default: the scene file's `[whitted] depth`.
    #[arg(long)]
    pub depth: Option<u32>,
    /// Whitted ray tracer: n for an n x n grid of rays per pixel, 1..=16. Default: the scene
    /// file's `[whitted] aa`.
    #[arg(long)]
    pub aa: Option<u32>,
}

impl WhittedArgs {
    /// The flags given, as typed.
    pub fn given(&self) -> Vec<&'static str> {
        given_flags(&[(self.depth.is_some(), "--depth"), (self.aa.is_some(), "--aa")])
    }
}

/// Everything the `render` example passes for the Whitted ray tracer.
pub type WhittedRequest<'a> = RenderRequest<'a, WhittedArgs>;

/// Checks a flag's value against `min..=max`, in the words of the scene file's errors.
fn in_range(flag: &str, value: Option<u32>, min: u32, max: u32) -> anyhow::Result<Option<u32>> {
    match value {
        Some(v) if !(min..=max).contains(&v) => {
            bail!("command line: {flag} = {v}: must be an integer in {min}..={max}")
        }
        v => Ok(v),
    }
}

/// Loads the scene with the flags applied and checks every output, before any GPU work.
fn prepare(request: &WhittedRequest) -> anyhow::Result<(Scene, Vec<PathBuf>)> {
    let flags = request.refused_flags();
    if !flags.is_empty() {
        bail!(
            "{}: {} {} to the other renderers; this render uses the Whitted ray tracer \
             (--renderer whitted), whose flags are --depth, --aa, --width, --height, --encoding, \
             --exposure, -o",
            request.scene.display(),
            flags.join(", "),
            cli::verb(flags.len())
        );
    }
    let depth = in_range("--depth", request.args.depth, 0, MAX_WHITTED_DEPTH)?;
    let aa = in_range("--aa", request.args.aa, 1, MAX_WHITTED_AA)?;
    let mut scene = Scene::load(&cli::resolve_scene_path(request.scene))?;
    let sizes =
        Overrides { width: request.settings.width, height: request.settings.height, ..Default::default() };
    scene.apply_overrides(&sizes, "command line")?;
    scene.whitted.depth = depth.unwrap_or(scene.whitted.depth);
    scene.whitted.aa = aa.unwrap_or(scene.whitted.aa);
    let outputs = request.checked_outputs(&scene.name, "whitted")?;
    Ok((scene, outputs))
}

/// Renders the scene with the Whitted ray tracer as `request` says.
pub fn render_whitted(request: &WhittedRequest) -> anyhow::Result<()> {
    let (scene, outputs) = prepare(request)?;
    let gpu = cli::gpu()?;
    let started = Instant::now();
    let image = WhittedTracer::new(&gpu, &scene)?.render()?;
    let seconds = started.elapsed().as_secs_f64();
    let metadata = ExrMetadata {
        renderer: "whitted".to_owned(),
        scene: scene.name.clone(),
        render_seconds: seconds,
        fields: vec![
            ("depth".into(), scene.whitted.depth.to_string()),
            ("aa".into(), scene.whitted.aa.to_string()),
            ("adapter".into(), gpu.adapter_info.name.clone()),
        ],
    };
    let (w, h) = (scene.camera.width, scene.camera.height);
    let summary = format!(
        "{}: {w}x{h}, Whitted ray tracer, depth {}, {} x {} rays per pixel, {seconds:.2} s including setup",
        scene.name, scene.whitted.depth, scene.whitted.aa, scene.whitted.aa
    );
    request.write(&outputs, &image, &metadata, &summary)
}
