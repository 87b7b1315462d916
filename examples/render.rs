//! Renders a scene file to PNG and/or EXR.
//!
//! Over 450 lines: the one command a user runs, from its flags to its files, for all three renderers.
//!
//! ```text
//! cargo run --release --example render -- [SCENE] [--spp N] [--bounces B|unbounded] [--seed S]
//!     [--width W --height H] [--sampling cosine|uniform] [-o FILE.png|FILE.exr]...
//!     [--target-error X] [--time-budget SECONDS] [--encoding gamma2.2|srgb] [--exposure STOPS]
//!     [--caustics on|off] [--denoise atrous|oidn]
//! ```
//! With no arguments it renders `scenes/cornell.toml` to `out/cornell.png` and `out/cornell.exr`.
//! `--renderer raster|pathtrace` picks the renderer; the default is the scene file's `renderer`
//! (`scenes/whitted.toml` says `raster`). The rasterizer takes `[--look figure|enhanced]
//! [--no-shadows] [--no-pcf] [--no-refraction] [--no-reflection] [--no-fresnel] [--no-antialiasing]`
//! (see `illum_cli::raster`). A renderer given a scene it cannot render says what it lacks.
//!
//! Stop rules: without `--target-error` or `--time-budget` the render stops at `--spp` (or the
//! scene's spp). A target error or a time budget lifts the scene's spp: the render runs until
//! that rule fires, or until `--spp` if that is given too (the first rule that holds wins). The
//! time budget is wall-clock time and, like the error target, waits for one complete pass.
//!
//! Ctrl-C or SIGTERM stops the render early and still writes what has accumulated (the EXR's
//! metadata records the spp reached and `illum.stopped_by = cancelled`), then exits with status
//! 130 (SIGINT) or 143 (SIGTERM). Interrupted before the first complete pass, it writes nothing
//! and says so. Copies of the signal within a second of the first (`timeout`, Slurm and
//! systemd signal the whole process group) are the same request; a signal after that ends the
//! process at once. The Whitted ray tracer and the rasterizer (a frame above 4 Mpixels) render in
//! parts (bands of rows, tiles) and stop between them; their images are deterministic, so an
//! interrupted one writes nothing and says so, and one whose image was complete writes it. Every output is checked
//! before rendering.
//!
//! Progress: a bar on a terminal; when standard error is not one (a job log), a line starting
//! with `progress: ` every `--progress-seconds` (default 10) and at every tenth of the way.
//!
//! With no stop-rule flag at all (`--spp`, `--target-error`, `--time-budget`, `--sample-range`)
//! the path tracer renders until a 2% estimated error or for 5 s, whichever comes first, and
//! says so: a clean image in a few seconds rather than the scene's 16-spp preview.
//!
//! Long renders (see README, "Long renders"): every EXR the path tracer writes is a checkpoint
//! (`illum_pathtrace::checkpoint`), written every `--checkpoint-seconds` (default 60) while
//! rendering and on Ctrl-C/SIGTERM. `--resume FILE.exr --spp N` continues one to N spp, bit for
//! bit the render N spp would have made straight away; `--sample-range A..B` renders sample
//! indices A to B-1 only, for the `merge` example to combine.
//!
//! Over 450 lines: the command a user runs, from its flags to its written files; each renderer's
//! flags and loops are library modules (`illum_cli`, `illum_cli::raster`, `illum_cli::whitted`,
//! `illum_pathtrace::progressive`).

use std::path::PathBuf;
use std::time::Duration;

use clap::Parser;
use illum::image::{Encoding, save_png};
use illum::pathtrace::checkpoint::{Checkpoint, load_checkpoint, save_checkpoint};
use illum::pathtrace::{
    PathTracer, SampleAllocation, Sequence, StopReason, StopRules, TracerOptions, render_progressive_over,
};
use illum::scene::{RendererKind, Scene};
use illum_cli::auto::RendererChoice;
use illum_cli::interrupt::Interrupt;
use illum_cli::progress::RenderProgress;
use illum_cli::raster::{RasterArgs, RasterRequest, render_raster};
use illum_cli::whitted::{WhittedArgs, WhittedRequest, render_whitted};
use illum_cli::{DEFAULT_SCENE, LongRender, OutputFormat, SceneArgs, output_format};
use illum_lab::auto::pilot::PilotOptions;
use illum_lab::auto::plan::{Goal, Setting};

#[derive(Parser, Debug)]
#[command(
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
struct Args {
    /// Scene file (TOML).
    #[arg(default_value = DEFAULT_SCENE)]
    scene: PathBuf,
    /// Renderer: `pathtrace`, `raster`, `whitted`, or `auto`: the fastest renderer and settings
    /// predicted to reach --target-error, or the most accurate predicted to finish within
    /// --time-budget, from a pilot of this scene on this machine (docs/auto.md). Default: the
    /// scene file's `renderer`.
    #[arg(long)]
    renderer: Option<RendererChoice>,
    #[command(flatten)]
    settings: SceneArgs,
    #[command(flatten)]
    raster: RasterArgs,
    #[command(flatten)]
    whitted: WhittedArgs,
    /// Output file(s); the extension (.png or .exr) picks the format. Default: out/NAME.png and
    /// out/NAME.exr.
    #[arg(short = 'o', long = "output")]
    outputs: Vec<PathBuf>,
    /// Stop once the estimated relative standard error falls to this value (e.g. 0.01). Lifts
    /// the scene's spp; with --spp too, the first rule that holds wins.
    #[arg(long, allow_negative_numbers = true, value_parser = illum_cli::target_error_arg)]
    target_error: Option<f64>,
    /// Stop after this many seconds of wall-clock time (after one complete pass at least).
    /// Lifts the scene's spp; with --spp too, the first rule that holds wins.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true, value_parser = illum_cli::time_budget_arg)]
    time_budget: Option<Duration>,
    /// With --target-error: stop when this percentile of the pixels' estimated errors reaches
    /// the target (95: 95% of pixels at or under it), instead of the whole image's error.
    #[arg(long, value_name = "PERCENT", allow_negative_numbers = true, value_parser = error_percentile_arg)]
    error_percentile: Option<f64>,
    /// With --target-error: measure the error over one region only: an object's name in the
    /// scene file (e.g. "glass sphere") or one of the ladder's regions (e.g. "floor, lit"),
    /// found through the Whitted tracer's object-ID image. An unknown name lists the valid ones.
    #[arg(long, value_name = "NAME")]
    region: Option<String>,
    /// Rasterizer and Whitted ray tracer: a converged EXR of the same scene (by illum.scene_hash)
    /// and size; the EXR outputs get the layer illum.difference, image minus reference, and the
    /// summary its relMSE.
    #[arg(long, value_name = "FILE.exr")]
    reference: Option<PathBuf>,
    /// PNG encoding: gamma2.2, srgb or linear. Default: gamma2.2 (the assignment's) for
    /// path-traced scenes, linear for rasterizer scenes (the assignment's figure 1 is linear).
    #[arg(long)]
    encoding: Option<Encoding>,
    /// Path-tracer scenes: `independent` (default) or `low-discrepancy` sample values (lower
    /// error for the same spp; its error is estimated from 4 independently randomised
    /// replicates: see docs/accuracy.md).
    #[arg(long)]
    sequence: Option<Sequence>,
    /// Path-tracer scenes: the caustic's light tracer `on` or `off` (default: the file's
    /// `[pathtrace] caustics`). It runs only on a scene with a directional light and a mirror
    /// or glass object (docs/caustics.md).
    #[arg(long, value_name = "on|off", value_parser = illum_cli::on_off_arg)]
    caustics: Option<bool>,
    /// PNG exposure in stops, e.g. -1 or 2, at most 64 either way, or `auto`: the stops that
    /// bring the median luminance to mid-grey (0.18), for scenes of any brightness. EXR output
    /// is never scaled. Default 0.
    #[arg(long, allow_hyphen_values = true, value_parser = illum_cli::exposure_arg)]
    exposure: Option<illum::image::Exposure>,
    /// Continue the path-traced render saved in this EXR (a checkpoint) to --spp N samples per
    /// pixel (or to the end of --sample-range). Give the same scene file; the settings that
    /// change the image (size, bounces, seed, sampling, sequence, caustics) default to the
    /// file's, and one given that differs is refused. Default output: the same file.
    #[arg(long, value_name = "FILE.exr")]
    resume: Option<PathBuf>,
    /// Render only sample indices A to B-1 of every pixel (B - A spp), for the merge example
    /// to combine with other ranges. A must be a multiple of 16 (the chunk the GPU sums in), so
    /// that merged ranges give the image of one render.
    #[arg(long, value_name = "A..B", value_parser = illum_cli::sample_range_arg)]
    sample_range: Option<std::ops::Range<u32>>,
    /// Path-tracer scenes: denoise the image (`atrous`: the edge-avoiding à-trous filter on the
    /// GPU; `oidn`: Intel Open Image Denoise's RT filter on the CPU, only in builds with
    /// `--features illum-denoise/oidn`, docs/denoising.md). The render is kept as two
    /// independent halves, and the denoised image's error is estimated from them
    /// (docs/denoising.md): it is the `illum.estimated_relative_error` written and the one
    /// --target-error stops at. The EXR holds the denoised image, and layers `noisy`, `albedo`
    /// and `normal`. --spp is rounded up to an even number. Not with --resume, --sample-range,
    /// --adaptive or --checkpoint-seconds.
    #[arg(long, value_name = "atrous|oidn", value_parser = denoiser_arg)]
    denoise: Option<illum_cli::denoise::DenoiserKind>,
    /// Path-tracer scenes: adaptive sampling. A pilot of 16 spp (another seed, then discarded)
    /// measures the noise of every 8 x 8 block of pixels, and the --spp budget is spread over
    /// the blocks in proportion to it: the spp is then the mean over the image (docs/accuracy.md, "Adaptive sampling").
    /// Needs --spp; not with --resume, --sample-range or the caustic's light tracer.
    #[arg(long)]
    adaptive: bool,
    /// Write the EXR outputs (checkpoints, see --resume) every this many seconds while
    /// rendering. Default 60.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true, value_parser = illum_cli::checkpoint_seconds_arg)]
    checkpoint_seconds: Option<Duration>,
    /// When standard error is not a terminal (a job log, `> log 2>&1`): print a line starting
    /// with `progress: ` this often (0.1 to 86400 seconds; default 10), and at every tenth of the
    /// way, with every renderer. On a terminal a progress bar shows the same.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true, value_parser = illum_cli::progress::period_arg)]
    progress_seconds: Option<Duration>,
}

/// The default stop rules of a render given no stop-rule flag: a clean image in a few seconds
/// on a 2-core machine without a GPU (the README's headline has what it reaches there).
const DEFAULT_TARGET_ERROR: f64 = 0.02;
const DEFAULT_TIME_BUDGET: Duration = Duration::from_secs(5);
const DEFAULT_CHECKPOINT: Duration = Duration::from_secs(60);

fn main() {
    illum_cli::main_with(run);
}

fn denoiser_arg(text: &str) -> Result<illum_cli::denoise::DenoiserKind, String> {
    text.parse()
}

/// Fills the image-changing settings not given on the command line from a checkpoint's
/// metadata, so that `--resume FILE` needs only the scene file and the new target.
fn fill_from_checkpoint(
    checkpoint: &Checkpoint,
    settings: &mut illum_cli::SceneArgs,
    sequence: &mut Option<Sequence>,
    caustics: &mut Option<bool>,
) {
    let get = |key: &str| checkpoint.metadata.get(key);
    settings.width = settings.width.or(Some(checkpoint.accumulator.width));
    settings.height = settings.height.or(Some(checkpoint.accumulator.height));
    settings.bounces = settings.bounces.or_else(|| get("bounces")?.parse().ok());
    settings.seed = settings.seed.or_else(|| get("seed")?.parse().ok());
    settings.sampling = settings.sampling.or_else(|| get("sampling")?.parse().ok());
    *sequence = sequence.or_else(|| get("sequence")?.parse().ok());
    *caustics = caustics.or_else(|| illum_cli::on_off_arg(get("caustics")?).ok());
}

/// Parses `--error-percentile` (see [`illum::pathtrace::error_map::parse_error_percentile`]).
fn error_percentile_arg(text: &str) -> Result<f64, String> {
    illum::pathtrace::error_map::parse_error_percentile("--error-percentile", text)
}

/// What `--target-error` is measured over: `--error-percentile`, `--region` (its pixels from
/// the Whitted tracer's object-ID image of `scene`), or the whole image.
fn error_scope(
    args: &Args,
    gpu: &illum::gpu::GpuContext,
    scene: &Scene,
) -> anyhow::Result<illum::pathtrace::error_map::ErrorScope> {
    use illum::pathtrace::error_map::ErrorScope;
    if (args.error_percentile.is_some() || args.region.is_some()) && args.target_error.is_none() {
        anyhow::bail!(
            "--error-percentile and --region say what --target-error is measured over: give --target-error too"
        );
    }
    Ok(match (args.error_percentile, &args.region) {
        (Some(_), Some(_)) => anyhow::bail!("give --error-percentile or --region, not both"),
        (Some(p), None) => ErrorScope::Percentile(p),
        (None, Some(name)) => {
            let ids = illum::whitted::WhittedTracer::new(gpu, scene)?.object_ids()?;
            let mask = illum_lab::regions::region_mask(scene, &ids, name)
                .map_err(|e| anyhow::anyhow!("--region {name:?}: {e}"))?;
            ErrorScope::Region { name: name.clone(), mask }
        }
        (None, None) => ErrorScope::Image,
    })
}

fn run(args: Args) -> anyhow::Result<()> {
    if args.renderer == Some(RendererChoice::Auto) {
        return run_auto(args);
    }
    render(args).map(|_| ())
}

/// `--renderer auto`: checks the flags, runs the pilot, prints the plan, then renders it as
/// the flags naming its renderer and settings would, and compares what it reached with what
/// was predicted.
fn run_auto(mut args: Args) -> anyhow::Result<()> {
    let mut chosen = illum_cli::given_flags(&[
        (args.settings.spp.is_some(), "--spp"),
        (args.settings.bounces.is_some(), "--bounces"),
        (args.sequence.is_some(), "--sequence"),
        (args.caustics.is_some(), "--caustics"),
        (args.adaptive, "--adaptive"),
        (args.resume.is_some(), "--resume"),
        (args.sample_range.is_some(), "--sample-range"),
        (args.checkpoint_seconds.is_some(), "--checkpoint-seconds"),
        (args.denoise.is_some(), "--denoise"),
    ]);
    chosen.extend(args.raster.given());
    chosen.extend(args.whitted.given());
    illum_cli::auto::check_auto_flags(args.target_error, args.time_budget, &chosen)
        .map_err(anyhow::Error::msg)?;
    let goal = match (args.target_error, args.time_budget) {
        (Some(error), _) => Goal::Error(error),
        (None, budget) => Goal::Seconds(budget.expect("one goal (checked)").as_secs_f64()),
    };
    illum_lab::auto::plan::check_goal(goal).map_err(anyhow::Error::msg)?;
    let scene = illum_cli::load_scene(&args.scene, &args.settings)?;
    let png_flags = illum_cli::given_flags(&[
        (args.encoding.is_some(), "--encoding"),
        (args.exposure.is_some(), "--exposure"),
    ]);
    illum_cli::check_outputs(&args.outputs, &png_flags)?;
    let started = std::time::Instant::now();
    let gpu = illum_cli::gpu()?;
    let device_seconds = started.elapsed().as_secs_f64();
    let options = PilotOptions::default();
    let pilot = illum_lab::auto::pilot::measure(&gpu, &scene, device_seconds, &options)?;
    drop(gpu);
    let plan = illum_lab::auto::plan::plan(&pilot.candidates, goal)
        .map_err(|why| anyhow::anyhow!("{}: {why}", args.scene.display()))?;
    print!("{}", illum_lab::auto::describe(&scene, &pilot, goal, &plan));
    let choice = plan.choice;
    args.target_error = None;
    args.time_budget = None;
    match &choice.candidate.setting {
        Setting::Raster { look, effects } => {
            args.renderer = Some(RendererChoice::Kind(RendererKind::Raster));
            args.raster.look = Some(*look);
            args.raster.no_shadows = !effects.shadows;
            args.raster.no_pcf = !effects.pcf;
            args.raster.no_refraction = !effects.refraction;
            args.raster.no_reflection = !effects.reflection;
            args.raster.no_fresnel = !effects.fresnel;
            args.raster.no_antialiasing = !effects.antialiasing;
        }
        Setting::Whitted { depth, aa } => {
            args.renderer = Some(RendererChoice::Kind(RendererKind::Whitted));
            args.whitted.depth = Some(*depth);
            args.whitted.aa = Some(*aa);
        }
        Setting::PathTrace { bounces, caustics, sequence, adaptive, denoise } => {
            args.renderer = Some(RendererChoice::Kind(RendererKind::PathTrace));
            args.settings.spp = choice.spp;
            args.settings.bounces = Some(*bounces);
            args.sequence = Some(*sequence);
            args.adaptive = *adaptive;
            args.denoise = *denoise;
            // Named only where the scene has a caustic: elsewhere `--caustics` is refused.
            args.caustics = illum_lab::auto::pilot::has_caustic(&scene).then_some(*caustics);
        }
    }
    let started = std::time::Instant::now();
    let noise = render(args)?;
    let seconds = started.elapsed().as_secs_f64();
    println!("{}", illum_lab::auto::reached(&choice, noise, seconds));
    Ok(())
}

/// Renders with the renderer and settings the flags name; for the path tracer, returns its
/// estimated relative error from noise.
fn render(args: Args) -> anyhow::Result<Option<f64>> {
    // First, so that a stop during the (slow on lavapipe) setup is handled like one during the
    // render: a message and the signal's status, never the default silent death.
    let interrupt = Interrupt::install()?;
    interrupt.set_note(&illum_cli::interrupt::note(
        "nothing (no file was written yet)",
        "the render and its setup",
    ));
    let long = LongRender {
        interrupt: Some(&interrupt),
        progress_period: args.progress_seconds.unwrap_or(illum_cli::progress::DEFAULT_PERIOD),
    };
    let renderer = match args.renderer {
        Some(RendererChoice::Kind(renderer)) => renderer,
        Some(RendererChoice::Auto) | None => {
            Scene::load(&illum_cli::resolve_scene_path(&args.scene))?.renderer
        }
    };
    let path_tracer_only = illum_cli::given_flags(&[
        (args.target_error.is_some(), "--target-error"),
        (args.time_budget.is_some(), "--time-budget"),
        (args.error_percentile.is_some(), "--error-percentile"),
        (args.region.is_some(), "--region"),
        (args.sequence.is_some(), "--sequence"),
        (args.caustics.is_some(), "--caustics"),
        (args.resume.is_some(), "--resume"),
        (args.sample_range.is_some(), "--sample-range"),
        (args.checkpoint_seconds.is_some(), "--checkpoint-seconds"),
        (args.adaptive, "--adaptive"),
        (args.denoise.is_some(), "--denoise"),
    ]);
    if renderer == RendererKind::Whitted {
        let mut other_flags = path_tracer_only.clone();
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
            illum_cli::verb(whitted_flags.len())
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
    args.raster.reject_for_path_tracer(&args.scene)?;
    if let Some(reference) = &args.reference {
        anyhow::bail!(
            "--reference {}: the path tracer is the truth and writes its own error layer (illum.error); \
             --reference applies to --renderer raster and --renderer whitted",
            reference.display()
        );
    }
    // Read the checkpoint first: a bad file is refused before anything is rendered or written,
    // and the settings not given on the command line are the file's.
    let checkpoint = match &args.resume {
        Some(path) => Some(load_checkpoint(path).map_err(anyhow::Error::msg)?),
        None => None,
    };
    let mut settings = args.settings.clone();
    let (mut sequence, mut caustics) = (args.sequence, args.caustics);
    if let Some(checkpoint) = &checkpoint {
        fill_from_checkpoint(checkpoint, &mut settings, &mut sequence, &mut caustics);
    }
    let mut scene = illum_cli::load_scene(&args.scene, &settings)?;
    if let Some(sequence) = sequence {
        scene.pathtrace.sequence = sequence;
    }
    if let Some(caustics) = caustics {
        scene.pathtrace.caustics = caustics;
    }
    if args.caustics == Some(true) && !illum::pathtrace::Estimators::of(&scene).caustics() {
        anyhow::bail!(
            "{}: --caustics on: this scene has no caustic to light-trace (the light tracer follows a \
             directional light through mirror or glass objects, and the scene lacks one or the other)",
            args.scene.display()
        );
    }
    // Checked before the stop rules are announced: a refused render announces nothing.
    if args.denoise.is_some() {
        let conflicting = illum_cli::given_flags(&[
            (args.resume.is_some(), "--resume"),
            (args.sample_range.is_some(), "--sample-range"),
            (args.adaptive, "--adaptive"),
            (args.checkpoint_seconds.is_some(), "--checkpoint-seconds"),
        ]);
        if !conflicting.is_empty() {
            anyhow::bail!(
                "--denoise renders two independent halves of the samples and writes a denoised image, not a \
                 checkpoint, so it cannot be combined with {}",
                conflicting.join(" or ")
            );
        }
    }
    if args.adaptive {
        let conflicting = illum_cli::given_flags(&[
            (args.resume.is_some(), "--resume"),
            (args.sample_range.is_some(), "--sample-range"),
        ]);
        if !conflicting.is_empty() {
            anyhow::bail!(
                "--adaptive spreads one render's samples unevenly over the image, so it cannot be combined with {}: \
                 a resumed or merged render needs the same samples in every pixel",
                conflicting.join(" or ")
            );
        }
        if args.settings.spp.is_none() {
            anyhow::bail!("--adaptive needs --spp N: the mean samples per pixel it spreads over the image");
        }
    }
    let no_stop_flag = args.settings.spp.is_none()
        && args.target_error.is_none()
        && args.time_budget.is_none()
        && args.sample_range.is_none()
        && args.resume.is_none();
    let rules = if no_stop_flag {
        println!(
            "no stop rule given: rendering until the estimated error is {}% or for {} s, whichever comes first \
             (--spp N, --target-error X or --time-budget S choose another)",
            DEFAULT_TARGET_ERROR * 100.0,
            DEFAULT_TIME_BUDGET.as_secs()
        );
        StopRules {
            spp: None,
            target_error: Some(DEFAULT_TARGET_ERROR),
            time_budget: Some(DEFAULT_TIME_BUDGET),
        }
    } else {
        let spp = args.sample_range.as_ref().map(|r| r.end - r.start).or(args.settings.spp);
        StopRules::from_command_line(scene.pathtrace.spp, spp, args.target_error, args.time_budget)
    };
    let resumed: Option<Checkpoint> = match (&args.resume, checkpoint) {
        (Some(path), Some(checkpoint)) => {
            let options = TracerOptions { sequence: scene.pathtrace.sequence, ..Default::default() };
            checkpoint.check_matches(path, &scene, options).map_err(anyhow::Error::msg)?;
            if let Some(range) = &args.sample_range
                && range.start != checkpoint.sample_start
            {
                anyhow::bail!(
                    "--sample-range {}..{}: {} holds samples from index {}, so a continued range must start there",
                    range.start,
                    range.end,
                    path.display(),
                    checkpoint.sample_start
                );
            }
            if let Some(target) = rules.spp
                && target < checkpoint.spp_done
            {
                let asked = if args.sample_range.is_some() || args.settings.spp.is_some() {
                    "asked for"
                } else {
                    "of the scene file's [pathtrace] spp"
                };
                anyhow::bail!(
                    "{} already holds {} spp, more than the {target} {asked}: nothing to continue (give a larger \
                     --spp{})",
                    path.display(),
                    checkpoint.spp_done,
                    if args.sample_range.is_some() { " or a longer --sample-range" } else { "" }
                );
            }
            if checkpoint.sample_start != 0 && args.sample_range.is_none() {
                anyhow::bail!(
                    "{} is a part of a split render (samples from index {}): continue it with --sample-range {}..END",
                    path.display(),
                    checkpoint.sample_start,
                    checkpoint.sample_start
                );
            }
            Some(checkpoint)
        }
        _ => None,
    };
    if args.sample_range.is_some() && args.settings.spp.is_some() {
        anyhow::bail!("--sample-range A..B renders B - A spp; give it or --spp, not both");
    }
    if args.sample_range.is_some() && (args.target_error.is_some() || args.time_budget.is_some()) {
        anyhow::bail!(
            "--sample-range A..B renders exactly samples A to B-1 so that the parts merge into one render; \
             --target-error and --time-budget would stop it short (a part stopped short cannot be merged)"
        );
    }
    // A resume whose file already holds the spp asked for has nothing to render: the file is
    // left as it is (rewriting it would only change its render time), and other outputs, if
    // any, are written from its samples.
    let nothing_to_render =
        resumed.as_ref().is_some_and(|c| c.partial_pass.is_none() && rules.spp == Some(c.spp_done));
    if nothing_to_render {
        let path = args.resume.as_ref().expect("resumed");
        println!(
            "{} already holds the {} spp asked for: nothing to render; the file is left as it is",
            path.display(),
            resumed.as_ref().map_or(0, |c| c.spp_done)
        );
        if args.outputs.iter().all(|o| o == path) {
            return Ok(None);
        }
    }
    let outputs = if args.outputs.is_empty() {
        if let Some(path) = &args.resume {
            vec![path.clone()]
        } else {
            vec![
                PathBuf::from(format!("out/{}.png", scene.name)),
                PathBuf::from(format!("out/{}.exr", scene.name)),
            ]
        }
    } else if nothing_to_render {
        args.outputs.iter().filter(|o| Some(*o) != args.resume.as_ref()).cloned().collect()
    } else {
        args.outputs.clone()
    };
    let png_flags = illum_cli::given_flags(&[
        (args.encoding.is_some(), "--encoding"),
        (args.exposure.is_some(), "--exposure"),
    ]);
    illum_cli::check_outputs(&outputs, &png_flags)?;
    let sequence = scene.pathtrace.sequence;

    long.exit_if_requested("before the render started");
    let gpu = illum_cli::gpu()?;
    let options = TracerOptions { sequence, ..Default::default() };
    if let Some(denoiser) = args.denoise {
        interrupt.set_note(&illum_cli::interrupt::note(
            "nothing (a denoised render writes its image once, at the end)",
            "every sample rendered so far",
        ));
        let outcome = illum_cli::denoise::render_denoised(&illum_cli::denoise::DenoiseRequest {
            gpu: &gpu,
            scene: &scene,
            options,
            rules,
            denoiser,
            cancel: interrupt.flag(),
            outputs: &outputs,
            encoding: args.encoding,
            exposure: args.exposure,
        })?;
        if let Some((signal, code)) = interrupt.exit_status() {
            eprintln!("stopped by {signal}: exiting with status {code}");
            std::process::exit(code);
        }
        let Some((_, error)) = outcome else {
            anyhow::bail!("the denoised render stopped before its first round");
        };
        return Ok(Some(error));
    }
    let mut tracer = if args.adaptive {
        // Built with the adaptive pipeline, which plan_adaptive's pilot runs (every block
        // unlimited until it sets the allocation): one compilation instead of two.
        let camera = scene.camera;
        let unlimited = SampleAllocation::uniform(camera.width, camera.height, u32::MAX);
        PathTracer::with_sample_allocation(&gpu, &scene, options, unlimited)?
    } else {
        PathTracer::with_options(&gpu, &scene, options)?
    };
    // Passes end on chunk boundaries, so that this render, a resumed one and a straight one
    // fold the very same f32 chunk sums: see illum_pathtrace::checkpoint.
    tracer.set_chunk_aligned_passes(true);
    let range_start = args.sample_range.as_ref().map(|r| r.start);
    let mut earlier_seconds = 0.0;
    let mut rules = rules;
    if args.adaptive {
        let budget = rules.spp.expect("--adaptive needs --spp (checked above)");
        let pilot = std::time::Instant::now();
        let allocation = illum::pathtrace::allocation::plan_adaptive(&mut tracer, budget)?;
        // The pilot is part of the render's time.
        earlier_seconds = pilot.elapsed().as_secs_f64();
        println!("adaptive sampling: {} ({:.2} s)", allocation.describe(), earlier_seconds);
        // Done when every block is: at the largest count.
        rules.spp = Some(allocation.max());
    }
    if let Some(checkpoint) = resumed {
        tracer.set_sample_offset(checkpoint.sample_start);
        earlier_seconds = checkpoint.metadata.render_seconds;
        println!(
            "resuming {}: {} spp done{}",
            args.resume.as_ref().expect("resumed").display(),
            checkpoint.spp_done,
            checkpoint
                .partial_pass
                .map_or(String::new(), |(spp, rows)| format!(", and {rows} rows of a pass of {spp} spp"))
        );
        // Going on past the file's spp, to an spp target.
        let continues = rules.spp.is_some_and(|target| target > checkpoint.spp_done);
        match checkpoint.aligned_prefix {
            // The samples end inside a chunk: start again from the last chunk boundary, so that
            // the chunk is summed whole, as a straight render sums it (illum_pathtrace::checkpoint).
            // Only when the render goes on to more spp: otherwise nothing may be taken away.
            Some((prefix, spp)) if checkpoint.partial_pass.is_none() && continues => {
                println!(
                    "  (going on from {spp} spp, the last chunk boundary, so that the result equals a straight render)"
                );
                tracer.restore(prefix, spp, None, None)?
            }
            prefix => {
                let chunk = illum::pathtrace::CHUNK_SAMPLES;
                if continues
                    && prefix.is_none()
                    && !(checkpoint.sample_start + checkpoint.spp_done).is_multiple_of(chunk)
                {
                    println!(
                        "  (the file ends inside a chunk of {chunk} samples and has no copy of its statistics at the \
                         chunk boundary: the result will differ from a straight render by f32 rounding, about 1e-7)"
                    );
                }
                tracer.restore(
                    checkpoint.accumulator,
                    checkpoint.spp_done,
                    checkpoint.partial_pass,
                    prefix,
                )?
            }
        }
    } else if let Some(start) = range_start {
        tracer.set_sample_offset(start);
    }
    let exr_outputs: Vec<PathBuf> =
        outputs.iter().filter(|o| matches!(output_format(o), Ok(OutputFormat::Exr))).cloned().collect();
    let every = args.checkpoint_seconds.unwrap_or(DEFAULT_CHECKPOINT);
    if args.checkpoint_seconds.is_some() && exr_outputs.is_empty() {
        anyhow::bail!("--checkpoint-seconds writes the EXR outputs, and no -o file is a .exr");
    }
    // A part of a split render records where its range ends, so that a part stopped early can
    // be finished with the exact command (`merge` and the resume message name it).
    let range_end: Option<(String, String)> = args
        .sample_range
        .as_ref()
        .map(|r| (illum::pathtrace::metadata::SAMPLE_END.to_owned(), r.end.to_string()));
    let mut last_checkpoint = std::time::Instant::now();
    let mut checkpoint_error: Option<illum::pathtrace::checkpoint::CheckpointError> = None;
    let scope = error_scope(&args, &gpu, tracer.scene())?;
    let progress = RenderProgress::with_period(long.progress_period);
    let outputs_named = illum_cli::describe_outputs(&exr_outputs);
    interrupt.set_note(&illum_cli::interrupt::note(
        "nothing (no checkpoint was written yet)",
        "every sample rendered so far, and the image, which was not written",
    ));
    let mut kept = String::from("nothing (no checkpoint was written)");
    let (reason, progressive) =
        render_progressive_over(&mut tracer, &rules, scope, interrupt.flag(), |t, p| {
            progress.update(t, p);
            if last_checkpoint.elapsed() >= every && t.spp_done() > 0 && checkpoint_error.is_none() {
                let seconds = earlier_seconds + p.clock().elapsed().as_secs_f64();
                let mut metadata =
                    illum::pathtrace::metadata::exr_metadata(t, seconds, None, "render example (checkpoint)");
                metadata.fields.extend(range_end.clone());
                for output in &exr_outputs {
                    if let Err(error) = save_checkpoint(output, t, &metadata) {
                        checkpoint_error = Some(error);
                    }
                }
                log::info!("checkpoint written at {} spp", t.spp_done());
                if checkpoint_error.is_none() && !exr_outputs.is_empty() {
                    kept = format!(
                        "the checkpoint {outputs_named} ({} spp, {seconds:.1} s of rendering)",
                        t.spp_done()
                    );
                    interrupt.set_note(&illum_cli::interrupt::note(&kept, "the samples rendered after it"));
                }
                last_checkpoint = std::time::Instant::now();
            }
        })?;
    progress.finish();
    interrupt.set_note(&illum_cli::interrupt::note(
        &kept,
        &format!(
            "the final image of {} spp, which was being written (a file being written is replaced only \
             when complete, so each output holds what is named as kept, or its earlier content)",
            tracer.spp_done()
        ),
    ));
    if let Some(error) = checkpoint_error {
        eprintln!("warning: a checkpoint could not be written: {error}");
    }
    let seconds = earlier_seconds + progressive.clock().elapsed().as_secs_f64();
    let status = progressive.status(&tracer);

    if let Some((signal, code)) = interrupt.exit_status()
        && status.spp_done == 0
    {
        eprintln!(
            "error: {signal} before the first complete pass ({:.1} s in): no pixel had all its samples yet, \
             so nothing was written",
            seconds
        );
        std::process::exit(code);
    }
    let accumulator = tracer.accumulator();
    let estimated_error = accumulator.estimated_relative_error();
    let image = accumulator.mean_image();
    let mut metadata =
        illum::pathtrace::metadata::exr_metadata(&tracer, seconds, Some(reason), "render example");
    metadata.fields.extend(range_end);
    for output in &outputs {
        match output_format(output)? {
            OutputFormat::Png => {
                let stops = args.exposure.unwrap_or_default().stops_for(&image);
                if args.exposure == Some(illum::image::Exposure::Auto) {
                    println!("--exposure auto: {stops:.2} stops");
                }
                save_png(output, &image, stops, args.encoding.unwrap_or_default())?
            }
            OutputFormat::Exr => save_checkpoint(output, &tracer, &metadata).map_err(anyhow::Error::msg)?,
        }
    }
    let spp = match tracer.sample_allocation() {
        // Mean over the image of what each pixel holds (the blocks' counts, or fewer if stopped early).
        Some(_) => format!(
            "{:.1} spp on average (adaptive)",
            accumulator.total_samples() as f64
                / (f64::from(scene.camera.width) * f64::from(scene.camera.height))
        ),
        None => format!("{} spp", status.spp_done),
    };
    println!(
        "{}: {}x{}, {} ({}), bounces {}, {} sampling, caustics {}, {:.2} s, {:.2} Msamples/s (wall clock), estimated relative error {:.4}, dropped samples {}",
        scene.name,
        scene.camera.width,
        scene.camera.height,
        spp,
        match reason {
            StopReason::SppReached => "spp target reached",
            StopReason::ErrorReached => "stopped at the error target",
            StopReason::TimeBudget => "stopped by the time budget",
            StopReason::Cancelled => "interrupted; kept what had accumulated",
        },
        scene.pathtrace.bounces,
        scene.pathtrace.sampling,
        illum::pathtrace::Estimators::of(&scene).caustics_label(),
        seconds,
        status.samples_per_second() * 1e-6,
        accumulator.estimated_relative_error(),
        accumulator.dropped_samples(),
    );
    let scope = progressive.error_scope();
    if *scope != illum::pathtrace::error_map::ErrorScope::Image
        && let Some(error) = status.relative_error
    {
        println!("estimated relative error over {}: {error:.4}", scope.describe());
    }
    for output in &outputs {
        println!("wrote {}", output.display());
    }
    if let Some((signal, code)) = interrupt.exit_status() {
        eprintln!("stopped by {signal}: exiting with status {code}");
        std::process::exit(code);
    }
    Ok(Some(estimated_error))
}
