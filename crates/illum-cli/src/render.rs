//! The `render` command (`cargo run --example render`): its flags ([`RenderArgs`]) and
//! [`render`], which picks the renderer and runs its path: [`crate::raster`],
//! [`crate::whitted`] or [`crate::pathtrace`]. `--renderer auto` measures first (its pilot is a
//! measuring tool, in illum-lab): the example checks its flags with [`RenderArgs::auto_goal`],
//! and renders the plan with [`RenderArgs::follow`] and [`render`].
//!
//! With no arguments it renders `scenes/cornell.toml` to `out/cornell.png` and `out/cornell.exr`.
//! `--renderer pathtrace|raster|whitted|auto` picks the renderer; the default is the scene
//! file's `renderer` (`scenes/whitted.toml` says `raster`). A renderer given a scene it cannot
//! render, or a flag of another renderer, says what it lacks.
//!
//! Ctrl-C or SIGTERM stops a render early, exiting with status 130 (SIGINT) or 143 (SIGTERM).
//! Copies of the signal within a second of the first (`timeout`, Slurm and systemd signal the
//! whole process group) are the same request; a signal after that ends the process at once
//! ([`crate::interrupt`]). What each renderer writes when stopped is in its module. Every output
//! is checked before rendering.
//!
//! Progress: a bar on a terminal; when standard error is not one (a job log), a line starting
//! with `progress: ` every `--progress-seconds` (default 10) and at every tenth of the way.

use std::path::PathBuf;
use std::time::Duration;

use clap::Parser;
use illum_image::Encoding;
use illum_pathtrace::Sequence;
use illum_scene::{RendererKind, Scene};

use crate::auto::RendererChoice;
use crate::interrupt::Interrupt;
use crate::raster::{RasterArgs, RasterRequest, render_raster};
use crate::whitted::{WhittedArgs, WhittedRequest, render_whitted};
use crate::{DEFAULT_SCENE, LongRender, SceneArgs};

#[derive(Parser, Clone, Debug)]
#[command(
    name = "render",
    about = "Render a scene file to PNG and/or EXR with the path tracer, the rasterizer or the Whitted ray tracer",
    after_help = "Stopping: Ctrl-C or SIGTERM stops a render and exits with status 130 or 143. The path tracer \
writes what has accumulated (a checkpoint that --resume continues), or, before its first complete pass, \
nothing, and says so. The Whitted ray tracer and a raster frame above 4 Mpixels render in parts and stop \
between them; their images are deterministic, so an interrupted one writes nothing and says so (a complete \
one is written). Copies of the signal within a second of the first (timeout, Slurm and systemd signal the \
whole process group) are the same request; a signal after that ends the process at once.\n\n\
Progress: a bar on a terminal; in a job log (standard error not a terminal), lines starting with \
\"progress: \" every --progress-seconds and at every tenth of the way."
)]
pub struct RenderArgs {
    /// Scene file (TOML).
    #[arg(default_value = DEFAULT_SCENE)]
    pub scene: PathBuf,
    /// Renderer: `pathtrace`, `raster`, `whitted`, or `auto`: the fastest renderer and settings
    /// predicted to reach --target-error, or the most accurate predicted to finish within
    /// --time-budget, from a pilot of this scene on this machine (docs/auto.md). Default: the
    /// scene file's `renderer`.
    #[arg(long)]
    pub renderer: Option<RendererChoice>,
    #[command(flatten)]
    pub settings: SceneArgs,
    #[command(flatten)]
    pub raster: RasterArgs,
    #[command(flatten)]
    pub whitted: WhittedArgs,
    /// Output file(s); the extension (.png or .exr) picks the format. Default: out/NAME.png and
    /// out/NAME.exr.
    #[arg(short = 'o', long = "output")]
    pub outputs: Vec<PathBuf>,
    /// Stop once the estimated relative standard error falls to this value (e.g. 0.01). Lifts
    /// the scene's spp; with --spp too, the first rule that holds wins.
    #[arg(long, allow_negative_numbers = true, value_parser = crate::target_error_arg)]
    pub target_error: Option<f64>,
    /// Stop after this many seconds of wall-clock time (after one complete pass at least).
    /// Lifts the scene's spp; with --spp too, the first rule that holds wins.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true, value_parser = crate::time_budget_arg)]
    pub time_budget: Option<Duration>,
    /// With --target-error: stop when this percentile of the pixels' estimated errors reaches
    /// the target (95: 95% of pixels at or under it), instead of the whole image's error.
    #[arg(long, value_name = "PERCENT", allow_negative_numbers = true, value_parser = crate::pathtrace::error_percentile_arg)]
    pub error_percentile: Option<f64>,
    /// With --target-error: measure the error over one region only: an object's name in the
    /// scene file (e.g. "glass sphere") or one of the ladder's regions (e.g. "floor, lit"),
    /// found through the Whitted tracer's object-ID image. An unknown name lists the valid ones.
    #[arg(long, value_name = "NAME")]
    pub region: Option<String>,
    /// Rasterizer and Whitted ray tracer: a converged EXR of the same scene (by illum.scene_hash)
    /// and size; the EXR outputs get the layer illum.difference, image minus reference, and the
    /// summary its relMSE.
    #[arg(long, value_name = "FILE.exr")]
    pub reference: Option<PathBuf>,
    /// PNG encoding: gamma2.2, srgb or linear. Default: gamma2.2 (the assignment's) for
    /// path-traced scenes, linear for rasterizer scenes (the assignment's figure 1 is linear).
    #[arg(long)]
    pub encoding: Option<Encoding>,
    /// Path-tracer scenes: `independent` (default) or `low-discrepancy` sample values (lower
    /// error for the same spp; its error is estimated from 4 independently randomised
    /// replicates: see docs/accuracy.md).
    #[arg(long)]
    pub sequence: Option<Sequence>,
    /// Path-tracer scenes: the caustic's light tracer `on` or `off` (default: the file's
    /// `[pathtrace] caustics`). It runs only on a scene with a directional light and a mirror
    /// or glass object (docs/caustics.md).
    #[arg(long, value_name = "on|off", value_parser = crate::on_off_arg)]
    pub caustics: Option<bool>,
    /// PNG exposure in stops, e.g. -1 or 2, at most 64 either way, or `auto`: the stops that
    /// bring the median luminance to mid-grey (0.18), for scenes of any brightness. EXR output
    /// is never scaled. Default 0.
    #[arg(long, allow_hyphen_values = true, value_parser = crate::exposure_arg)]
    pub exposure: Option<illum_image::Exposure>,
    /// Continue the path-traced render saved in this EXR (a checkpoint) to --spp N samples per
    /// pixel (or to the end of --sample-range). Give the same scene file; the settings that
    /// change the image (size, bounces, seed, sampling, sequence, caustics) default to the
    /// file's, and one given that differs is refused. Default output: the same file.
    #[arg(long, value_name = "FILE.exr")]
    pub resume: Option<PathBuf>,
    /// Render only sample indices A to B-1 of every pixel (B - A spp), for the merge example
    /// to combine with other ranges. A must be a multiple of 16 (the chunk the GPU sums in), so
    /// that merged ranges give the image of one render.
    #[arg(long, value_name = "A..B", value_parser = crate::sample_range_arg)]
    pub sample_range: Option<std::ops::Range<u32>>,
    /// Path-tracer scenes: denoise the image (`atrous`: the edge-avoiding à-trous filter on the
    /// GPU; `oidn`: Intel Open Image Denoise's RT filter on the CPU, only in builds with
    /// `--features illum-denoise/oidn`, docs/denoising.md). The render is kept as two
    /// independent halves, and the denoised image's error is estimated from them
    /// (docs/denoising.md): it is the `illum.estimated_relative_error` written and the one
    /// --target-error stops at. The EXR holds the denoised image, and layers `noisy`, `albedo`
    /// and `normal`. --spp is rounded up to an even number. Not with --resume, --sample-range,
    /// --adaptive or --checkpoint-seconds.
    #[arg(long, value_name = "atrous|oidn", value_parser = crate::denoise::denoiser_arg)]
    pub denoise: Option<crate::denoise::DenoiserKind>,
    /// Path-tracer scenes: adaptive sampling. A pilot of 16 spp (another seed, then discarded)
    /// measures the noise of every 8 x 8 block of pixels, and the --spp budget is spread over
    /// the blocks in proportion to it: the spp is then the mean over the image (docs/accuracy.md, "Adaptive sampling").
    /// Needs --spp; not with --resume, --sample-range or the caustic's light tracer.
    #[arg(long)]
    pub adaptive: bool,
    /// Write the EXR outputs (checkpoints, see --resume) every this many seconds while
    /// rendering. Default 60.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true, value_parser = crate::checkpoint_seconds_arg)]
    pub checkpoint_seconds: Option<Duration>,
    /// When standard error is not a terminal (a job log, `> log 2>&1`): print a line starting
    /// with `progress: ` this often (0.1 to 86400 seconds; default 10), and at every tenth of the
    /// way, with every renderer. On a terminal a progress bar shows the same.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true, value_parser = crate::progress::period_arg)]
    pub progress_seconds: Option<Duration>,
}

impl RenderArgs {
    /// The PNG-only flags given (`--encoding`, `--exposure`).
    pub fn png_flags(&self) -> Vec<&'static str> {
        crate::given_flags(&[
            (self.encoding.is_some(), "--encoding"),
            (self.exposure.is_some(), "--exposure"),
        ])
    }

    /// The flags only the path tracer takes that were given.
    fn path_tracer_only_flags(&self) -> Vec<&'static str> {
        crate::given_flags(&[
            (self.target_error.is_some(), "--target-error"),
            (self.time_budget.is_some(), "--time-budget"),
            (self.error_percentile.is_some(), "--error-percentile"),
            (self.region.is_some(), "--region"),
            (self.sequence.is_some(), "--sequence"),
            (self.caustics.is_some(), "--caustics"),
            (self.resume.is_some(), "--resume"),
            (self.sample_range.is_some(), "--sample-range"),
            (self.checkpoint_seconds.is_some(), "--checkpoint-seconds"),
            (self.adaptive, "--adaptive"),
            (self.denoise.is_some(), "--denoise"),
        ])
    }
}

/// Renders with the renderer and settings the flags name; for the path tracer, returns its
/// estimated relative error from noise.
pub fn render(args: &RenderArgs) -> anyhow::Result<Option<f64>> {
    // First, so that a stop during the (slow on lavapipe) setup is handled like one during the
    // render: a message and the signal's status, never the default silent death.
    let interrupt = Interrupt::install()?;
    interrupt
        .set_note(&crate::interrupt::note("nothing (no file was written yet)", "the render and its setup"));
    let long = LongRender {
        interrupt: Some(&interrupt),
        progress_period: args.progress_seconds.unwrap_or(crate::progress::DEFAULT_PERIOD),
    };
    let renderer = match args.renderer {
        Some(RendererChoice::Kind(renderer)) => renderer,
        Some(RendererChoice::Auto) | None => Scene::load(&crate::resolve_scene_path(&args.scene))?.renderer,
    };
    let path_tracer_only = args.path_tracer_only_flags();
    if renderer == RendererKind::Whitted {
        let mut other_flags = path_tracer_only;
        other_flags.extend(args.raster.given());
        return render_whitted(&WhittedRequest {
            scene: &args.scene,
            settings: &args.settings,
            args: &args.whitted,
            outputs: &args.outputs,
            encoding: args.encoding,
            exposure: args.exposure,
            other_flags,
            long,
            reference: args.reference.as_deref(),
        })
        .map(|()| None);
    }
    let whitted_flags = args.whitted.given();
    if !whitted_flags.is_empty() {
        anyhow::bail!(
            "{}: {} {} only to the Whitted ray tracer (--renderer whitted)",
            args.scene.display(),
            whitted_flags.join(", "),
            crate::verb(whitted_flags.len())
        );
    }
    if renderer == RendererKind::Raster {
        return render_raster(&RasterRequest {
            scene: &args.scene,
            settings: &args.settings,
            args: &args.raster,
            outputs: &args.outputs,
            encoding: args.encoding,
            exposure: args.exposure,
            other_flags: path_tracer_only,
            long,
            reference: args.reference.as_deref(),
        })
        .map(|()| None);
    }
    crate::pathtrace::render_pathtrace(args, &interrupt, long)
}
