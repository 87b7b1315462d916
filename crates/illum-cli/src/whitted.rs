//! The `render` example's path for the Whitted ray tracer (`--renderer whitted`): its flags, and
//! rendering to PNG / EXR with the same error quality as the other renderers' paths.

use std::ops::ControlFlow;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::bail;
use clap::Args;
use illum_scene::{MAX_WHITTED_AA, MAX_WHITTED_DEPTH, Overrides, Scene};
use illum_whitted::WhittedTracer;

use crate::progress::{Reporter, describe_parts};
use crate::{RenderRequest, given_flags};

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
             --exposure, --reference, -o",
            request.scene.display(),
            flags.join(", "),
            crate::verb(flags.len())
        );
    }
    let depth = in_range("--depth", request.args.depth, 0, MAX_WHITTED_DEPTH)?;
    let aa = in_range("--aa", request.args.aa, 1, MAX_WHITTED_AA)?;
    let mut scene = Scene::load(&crate::resolve_scene_path(request.scene))?;
    for note in scene.notes() {
        eprintln!("{note}");
    }
    let sizes =
        Overrides { width: request.settings.width, height: request.settings.height, ..Default::default() };
    scene.apply_overrides(&sizes, "command line")?;
    scene.whitted.depth = depth.unwrap_or(scene.whitted.depth);
    scene.whitted.aa = aa.unwrap_or(scene.whitted.aa);
    let outputs = request.checked_outputs(&scene.name, "whitted")?;
    Ok((scene, outputs))
}

/// Camera rays per part of a long render: well under a second on lavapipe even with deep glass
/// recursion (depth 64, 16 x 16 rays per pixel: about 0.1 M camera rays/s), so that progress
/// and Ctrl-C are seen that often.
const RAYS_PER_PART: u64 = 1 << 16;

/// Pixels per part with `aa` x `aa` rays per pixel: about [`RAYS_PER_PART`] camera rays.
fn pixels_per_part(aa: u32) -> u64 {
    RAYS_PER_PART / (u64::from(aa) * u64::from(aa)).max(1)
}

/// Renders the scene with the Whitted ray tracer as `request` says: in parts, showing progress
/// after each and stopping after the part during which Ctrl-C or SIGTERM came. The image is
/// deterministic, so an interrupted render writes nothing (a rerun makes the same image from
/// the start) and exits with the signal's status.
pub fn render_whitted(request: &WhittedRequest) -> anyhow::Result<()> {
    let (scene, outputs) = prepare(request)?;
    let reference = request.reference_image()?;
    let long = request.long;
    long.exit_if_requested("before the render started");
    let gpu = crate::gpu()?;
    let started = Instant::now();
    let tracer = WhittedTracer::new(&gpu, &scene)?;
    long.exit_if_requested("while the Whitted ray tracer's pipeline was compiled");
    let (w, h) = (scene.camera.width, scene.camera.height);
    let aa = u64::from(scene.whitted.aa);
    let pixels = u64::from(w) * u64::from(h);
    let progress = Reporter::new(long.progress_period);
    let tracing = Instant::now();
    let mut pixels_done = 0;
    let image = tracer.render_in_parts(pixels_per_part(scene.whitted.aa), |done| {
        pixels_done = done;
        let elapsed = tracing.elapsed();
        let rate = (done * aa * aa) as f64 / elapsed.as_secs_f64().max(1e-9);
        progress.update(Some(done as f64 / pixels as f64), || {
            describe_parts(done, pixels, "pixels", Some((rate, "M camera rays/s")), elapsed)
        });
        if long.stop_requested() { ControlFlow::Break(()) } else { ControlFlow::Continue(()) }
    })?;
    let Some(image) = image else {
        long.exit_if_requested(&format!(
            "after {pixels_done} of {pixels} pixels of the Whitted image ({:.1} s in; the image is \
             deterministic, so a rerun makes it again from the start)",
            started.elapsed().as_secs_f64()
        ));
        anyhow::bail!(
            "the Whitted render stopped after {pixels_done} of {pixels} pixels without a stop request"
        );
    };
    let seconds = started.elapsed().as_secs_f64();
    let metadata = illum_whitted::metadata::exr_metadata(&scene, &gpu.adapter_info.name, seconds);
    let summary = format!(
        "{}: {w}x{h}, Whitted ray tracer, depth {}, {} x {} rays per pixel, {seconds:.2} s including setup",
        scene.name, scene.whitted.depth, scene.whitted.aa, scene.whitted.aa
    );
    progress.note(&format!("writing {}", crate::describe_outputs(&outputs)));
    progress.finish();
    request.write(&outputs, &image, &metadata, &summary, reference.as_ref())?;
    long.exit_after_complete_image();
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_hold_about_65536_camera_rays() {
        assert_eq!(pixels_per_part(16), 256, "deep anti-aliasing: 256 pixels of 256 rays");
        assert_eq!(pixels_per_part(1), 65_536);
        assert_eq!(pixels_per_part(0), 65_536, "aa 0 is refused earlier; no division by zero");
    }
}
