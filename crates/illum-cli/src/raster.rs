//! The `render` example's path for the rasterizer (`--renderer raster`, the default for a scene
//! whose file says `renderer = "raster"`): its flags, and rendering to PNG / EXR with the same
//! error quality as the path tracer's path.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::bail;
use clap::Args;
use illum_gpu::GpuContext;
use illum_image::RgbImage32;

use illum_raster::{Frame, Look, Options, PassTimes, RasterRenderer, RasterScene};

use crate::RenderRequest;
use crate::progress::{Reporter, describe_parts};

/// Flags that apply to rasterizer scenes only. Each effect is on unless the scene file or one of
/// these flags turns it off.
#[derive(Args, Clone, Debug, Default)]
pub struct RasterArgs {
    /// Rasterizer: `figure` (the assignment's figure 1) or `enhanced` (mirror reflections,
    /// Fresnel, refraction through both faces). Default: the scene file's `[raster] look`.
    #[arg(long)]
    pub look: Option<Look>,
    /// Rasterizer scenes: no shadow map.
    #[arg(long)]
    pub no_shadows: bool,
    /// Rasterizer scenes: hard shadow edges (one depth comparison instead of PCF).
    #[arg(long)]
    pub no_pcf: bool,
    /// Rasterizer scenes: the glass shows what is straight behind it, unbent.
    #[arg(long)]
    pub no_refraction: bool,
    /// Rasterizer scenes (enhanced look): no mirror reflections.
    #[arg(long)]
    pub no_reflection: bool,
    /// Rasterizer scenes (enhanced look): the glass reflects its normal-incidence fraction everywhere.
    #[arg(long)]
    pub no_fresnel: bool,
    /// Rasterizer scenes: jagged edges (each pixel shows what the ray through its centre meets)
    /// instead of edges blended by their coverage. `--no-msaa`, its former name, still works.
    #[arg(long, alias = "no-msaa")]
    pub no_antialiasing: bool,
}

impl RasterArgs {
    /// The flags given, as typed.
    pub fn given(&self) -> Vec<&'static str> {
        crate::given_flags(&[
            (self.look.is_some(), "--look"),
            (self.no_shadows, "--no-shadows"),
            (self.no_pcf, "--no-pcf"),
            (self.no_refraction, "--no-refraction"),
            (self.no_reflection, "--no-reflection"),
            (self.no_fresnel, "--no-fresnel"),
            (self.no_antialiasing, "--no-antialiasing"),
        ])
    }

    /// The scene file's look and effects, changed by the flags.
    pub fn options(&self, scene: &RasterScene) -> Options {
        let mut options = Options::from_scene(scene);
        if let Some(look) = self.look {
            options.look = look;
        }
        let e = &mut options.effects;
        e.shadows &= !self.no_shadows;
        e.pcf &= !self.no_pcf;
        e.refraction &= !self.no_refraction;
        e.reflection &= !self.no_reflection;
        e.fresnel &= !self.no_fresnel;
        e.antialiasing &= !self.no_antialiasing;
        options
    }

    /// An error when rasterizer flags are given for a path-tracer scene.
    pub fn reject_for_path_tracer(&self, scene: &Path) -> anyhow::Result<()> {
        let given = self.given();
        if !given.is_empty() {
            bail!(
                "{}: {} {} only to the rasterizer (--renderer raster, the default for scenes such as \
                 scenes/whitted.toml); this render uses the path tracer",
                scene.display(),
                given.join(", "),
                crate::verb(given.len())
            );
        }
        Ok(())
    }
}

/// Everything the `render` example passes for a rasterizer scene.
pub type RasterRequest<'a> = RenderRequest<'a, RasterArgs>;

/// Loads the scene, applies `--width` / `--height`, and checks every flag and output name,
/// before any GPU work.
fn prepare(request: &RasterRequest) -> anyhow::Result<Prepared> {
    let path = crate::resolve_scene_path(request.scene);
    let flags = request.refused_flags();
    if !flags.is_empty() {
        bail!(
            "{}: {} {} only to the path tracer; this render uses the rasterizer (--renderer raster), \
             whose flags are --look, --no-shadows, --no-pcf, --no-refraction, --no-reflection, \
             --no-fresnel, --no-antialiasing, --width, --height, --encoding, --exposure, --reference, -o",
            request.scene.display(),
            flags.join(", "),
            crate::verb(flags.len())
        );
    }
    let mut scene = RasterScene::load(&path)?;
    scene.set_resolution(request.settings.width, request.settings.height, "command line")?;
    let options = request.args.options(&scene);
    let outputs = request.checked_outputs(&scene.name, options.look.as_str())?;
    let reference = request.reference_image()?;
    Ok(Prepared { scene, options, outputs, reference })
}

/// A rasterizer render checked and ready: its scene, options, outputs and `--reference` image.
struct Prepared {
    scene: RasterScene,
    options: Options,
    outputs: Vec<PathBuf>,
    reference: Option<RgbImage32>,
}

/// Renders a rasterizer scene as `request` says, creating the GPU context.
pub fn render_raster(request: &RasterRequest) -> anyhow::Result<()> {
    let prepared = prepare(request)?;
    let gpu = crate::gpu()?;
    render_prepared(&gpu, &prepared, request)
}

/// [`render_raster`] on an existing GPU context (tests share one device).
pub fn render_raster_with(gpu: &GpuContext, request: &RasterRequest) -> anyhow::Result<()> {
    let prepared = prepare(request)?;
    render_prepared(gpu, &prepared, request)
}

/// Pixels of the main pass per submission of a large frame: a fraction of a second on lavapipe,
/// so that progress and Ctrl-C are seen that often. A frame of at most this many pixels (the
/// default 1280 x 720 among them) is one submission, with its pass times.
const PIXELS_PER_BAND: u64 = 1 << 22;

/// Rows per band of a `width`-wide frame: about [`PIXELS_PER_BAND`] pixels.
fn rows_per_band(width: u32) -> u32 {
    (PIXELS_PER_BAND / u64::from(width.max(1))).clamp(1, u64::from(u32::MAX)) as u32
}

fn render_prepared(gpu: &GpuContext, prepared: &Prepared, request: &RasterRequest) -> anyhow::Result<()> {
    let Prepared { scene, options, outputs, reference } = prepared;
    let (width, height) = (scene.camera.width, scene.camera.height);
    let long = request.long;
    long.exit_if_requested("before the render started");
    let started = Instant::now();
    let mut renderer = RasterRenderer::new(gpu, scene, width, height)?;
    long.exit_if_requested("while the rasterizer's pipelines were compiled");
    let rows = rows_per_band(width);
    let (frame, progress) = if rows >= height {
        (renderer.render_timed(options)?, None)
    } else {
        // A large frame: in bands, with progress, stopping between bands.
        let progress = Reporter::new(long.progress_period);
        let drawing = Instant::now();
        let mut rows_done = 0;
        let image = renderer.render_in_bands(options, rows, |done| {
            rows_done = done;
            let elapsed = drawing.elapsed();
            let rate = f64::from(done) * f64::from(width) / elapsed.as_secs_f64().max(1e-9);
            progress.update(Some(f64::from(done) / f64::from(height)), || {
                describe_parts(u64::from(done), u64::from(height), "rows", Some((rate, "Mpixels/s")), elapsed)
            });
            if done == height {
                progress.note("reading the frame back");
            }
            if long.stop_requested() { ControlFlow::Break(()) } else { ControlFlow::Continue(()) }
        })?;
        let Some(image) = image else {
            long.exit_if_requested(&format!(
                "after {rows_done} of {height} rows of the raster frame ({:.1} s in; a partial frame is not an \
                 image, and a rerun draws the same frame)",
                started.elapsed().as_secs_f64()
            ));
            bail!("the raster render stopped after {rows_done} of {height} rows without a stop request");
        };
        (Frame { image, pass_times: None }, Some(progress))
    };
    let seconds = started.elapsed().as_secs_f64();
    let times = frame.pass_times.map(|t: PassTimes| {
        format!(
            "GPU ms of this first (cold) frame: shadow {:.2}, cube {:.2}, main {:.2} (warm figures: raster_bench)",
            t.shadow_ms, t.cube_ms, t.main_ms
        )
    });
    let metadata = illum_raster::metadata::exr_metadata(scene, options, &gpu.adapter_info.name, seconds);
    let summary = format!(
        "{}: {width}x{height}, {}, {:.2} s including setup{}",
        scene.name,
        illum_raster::metadata::describe(options),
        seconds,
        times.map(|t| format!(", {t}")).unwrap_or_default()
    );
    if let Some(progress) = progress {
        progress.note(&format!("writing {}", crate::describe_outputs(outputs)));
        progress.finish();
    }
    request.write(outputs, &frame.image, &metadata, &summary, reference.as_ref())?;
    long.exit_after_complete_image();
    Ok(())
}
