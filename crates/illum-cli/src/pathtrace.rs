//! The `render` command's path for the path tracer (`--renderer pathtrace`, the default for a
//! scene whose file says so): its stop rules, checkpoints, split renders, adaptive sampling and
//! denoising, from the checked flags to the written files.
//!
//! Stop rules: without `--target-error` or `--time-budget` the render stops at `--spp` (or the
//! scene's spp). A target error or a time budget lifts the scene's spp: the render runs until
//! that rule fires, or until `--spp` if that is given too (the first rule that holds wins). The
//! time budget is wall-clock time and, like the error target, waits for one complete pass. With
//! no stop-rule flag at all (`--spp`, `--target-error`, `--time-budget`, `--sample-range`,
//! `--resume`) it renders until a 2% estimated error or for 5 s, whichever comes first, and
//! says so: a clean image in a few seconds rather than the scene's 16-spp preview.
//!
//! Ctrl-C or SIGTERM writes what has accumulated (the EXR's metadata records the spp reached
//! and `illum.stopped_by = cancelled`); interrupted before the first complete pass, it writes
//! nothing and says so.
//!
//! Long renders (README, "Long renders"): every EXR it writes is a checkpoint
//! (`illum_pathtrace::checkpoint`), written every `--checkpoint-seconds` (default 60) while
//! rendering and on Ctrl-C/SIGTERM. `--resume FILE.exr --spp N` continues one to N spp, bit for
//! bit the render N spp would have made straight away; `--sample-range A..B` renders sample
//! indices A to B-1 only, for the `merge` example to combine.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::bail;
use illum_image::save_png;
use illum_pathtrace::checkpoint::{Checkpoint, load_checkpoint, save_checkpoint};
use illum_pathtrace::error_map::ErrorScope;
use illum_pathtrace::{PathTracer, SampleAllocation, StopRules, TracerOptions, render_progressive_over};
use illum_scene::Scene;

use crate::interrupt::Interrupt;
use crate::progress::RenderProgress;
use crate::render_args::RenderArgs;
pub use crate::render_args::error_percentile_arg;
use crate::summary::{budget_overrun, summary};
use crate::{LongRender, OutputFormat, output_format};

/// The default stop rules of a render given no stop-rule flag: a clean image in a few seconds
/// on a 2-core machine without a GPU (the README's headline has what it reaches there).
const DEFAULT_TARGET_ERROR: f64 = 0.02;
const DEFAULT_TIME_BUDGET: Duration = Duration::from_secs(5);
const DEFAULT_CHECKPOINT: Duration = Duration::from_secs(60);

/// What `--target-error` is measured over: `--error-percentile`, `--region` (its pixels from
/// the Whitted tracer's object-ID image of `scene`), or the whole image.
fn error_scope(args: &RenderArgs, gpu: &illum_gpu::GpuContext, scene: &Scene) -> anyhow::Result<ErrorScope> {
    Ok(match (args.error_percentile, &args.region) {
        (Some(p), _) => ErrorScope::Percentile(p),
        (None, Some(name)) => {
            let ids = illum_whitted::WhittedTracer::new(gpu, scene)?.object_ids()?;
            let mask = illum_auto::regions::region_mask(scene, &ids, name)
                .map_err(|e| anyhow::anyhow!("--region {name:?}: {e}"))?;
            ErrorScope::Region { name: name.clone(), mask }
        }
        (None, None) => ErrorScope::Image,
    })
}

/// A path-traced render checked and ready, before any GPU work.
struct Prepared {
    scene: Scene,
    options: TracerOptions,
    rules: StopRules,
    /// The `--resume` file's checkpoint, checked against the scene and the flags.
    resumed: Option<Checkpoint>,
    /// The outputs, each checked.
    outputs: Vec<PathBuf>,
}

/// Checks the flags, reads the `--resume` checkpoint and the scene, and checks every output:
/// everything a path-traced render can refuse without a GPU, refused before anything is
/// announced, rendered or written. `Ok(None)`: a resume with nothing to render and no other
/// output to write (said so).
fn prepare(args: &RenderArgs) -> anyhow::Result<Option<Prepared>> {
    args.raster.reject_for_path_tracer(&args.scene)?;
    if let Some(reference) = &args.reference {
        bail!(
            "--reference {}: the path tracer is the truth and writes its own error layer (illum.error); \
             --reference applies to --renderer raster and --renderer whitted",
            reference.display()
        );
    }
    if (args.error_percentile.is_some() || args.region.is_some()) && args.target_error.is_none() {
        bail!(
            "--error-percentile and --region say what --target-error is measured over: give --target-error too"
        );
    }
    if args.error_percentile.is_some() && args.region.is_some() {
        bail!("give --error-percentile or --region, not both");
    }
    // Read the checkpoint first: a bad file is refused before anything is rendered or written,
    // and the settings not given on the command line are the file's.
    let checkpoint = match &args.resume {
        Some(path) => Some(load_checkpoint(path).map_err(anyhow::Error::msg)?),
        None => None,
    };
    let mut settings = args.settings.clone();
    let (mut sequence, mut replicates, mut caustics, mut caustic_method) =
        (args.sequence, args.replicates, args.caustics, args.caustic_method);
    if let Some(checkpoint) = &checkpoint {
        crate::resume::fill_from_checkpoint(
            checkpoint,
            &mut settings,
            (&mut sequence, &mut replicates),
            &mut caustics,
        );
        caustic_method = caustic_method.or_else(|| crate::resume::caustic_method_of(checkpoint));
    }
    let mut scene = crate::load_scene(&args.scene, &settings)?;
    if let Some(sequence) = sequence {
        scene.pathtrace.sequence = sequence;
    }
    if let Some(caustics) = caustics {
        scene.pathtrace.caustics = caustics;
    }
    if let Some(method) = caustic_method {
        scene.pathtrace.caustic_method = method;
    }
    if let Some(why) = illum_pathtrace::Estimators::manifold_falls_back(&scene) {
        eprintln!("{}: {why}", args.scene.display());
    }
    if let Some(why) = illum_pathtrace::Estimators::mesh_stops_caustics(&scene) {
        if args.caustics == Some(true) {
            bail!("{}: --caustics on: {why}", args.scene.display());
        }
        eprintln!("{}: {why}", args.scene.display());
    } else if args.caustics == Some(true) && !illum_pathtrace::Estimators::of(&scene).caustics() {
        bail!(
            "{}: --caustics on: this scene has no caustic to light-trace (the light tracer follows a \
             directional light through mirror or glass objects, and the scene lacks one or the other)",
            args.scene.display()
        );
    }
    check_combinations(args)?;
    let options = TracerOptions {
        sequence: scene.pathtrace.sequence,
        replicates: replicates.unwrap_or(true),
        ..Default::default()
    };
    let rules = stop_rules(args, &scene);
    check_replicates(args, options, &rules)?;
    let resumed = match (&args.resume, checkpoint) {
        (Some(path), Some(checkpoint)) => {
            Some(crate::resume::check_resume(args, path, checkpoint, &scene, options, &rules)?)
        }
        _ => None,
    };
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
        match &args.resume {
            Some(path) => vec![path.clone()],
            None => vec![
                PathBuf::from(format!("out/{}.png", scene.name)),
                PathBuf::from(format!("out/{}.exr", scene.name)),
            ],
        }
    } else if nothing_to_render {
        args.outputs.iter().filter(|o| Some(*o) != args.resume.as_ref()).cloned().collect()
    } else {
        args.outputs.clone()
    };
    crate::check_outputs(&outputs, &args.png_flags())?;
    let any_exr = outputs.iter().any(|o| matches!(output_format(o), Ok(OutputFormat::Exr)));
    if let Some(range) = &args.sample_range
        && !any_exr
    {
        bail!(
            "--sample-range {}..{}: -o {}: a part of a split render must be written to an EXR (.exr), the \
             only file `merge` can combine; add -o PART.exr",
            range.start,
            range.end,
            crate::describe_outputs(&outputs)
        );
    }
    if args.checkpoint_seconds.is_some() && !any_exr {
        bail!("--checkpoint-seconds writes the EXR outputs, and no -o file is a .exr");
    }
    Ok(Some(Prepared { scene, options, rules, resumed, outputs }))
}

/// Refuses flags that cannot go together (checked before the stop rules are announced: a
/// refused render announces nothing).
fn check_combinations(args: &RenderArgs) -> anyhow::Result<()> {
    if args.denoise.is_some() {
        let conflicting = crate::given_flags(&[
            (args.resume.is_some(), "--resume"),
            (args.sample_range.is_some(), "--sample-range"),
            (args.adaptive, "--adaptive"),
            (args.checkpoint_seconds.is_some(), "--checkpoint-seconds"),
        ]);
        if !conflicting.is_empty() {
            bail!(
                "--denoise renders two independent halves of the samples and writes a denoised image, not a \
                 checkpoint, so it cannot be combined with {}",
                conflicting.join(" or ")
            );
        }
    }
    if args.adaptive {
        let conflicting = crate::given_flags(&[
            (args.resume.is_some(), "--resume"),
            (args.sample_range.is_some(), "--sample-range"),
        ]);
        if !conflicting.is_empty() {
            bail!(
                "--adaptive spreads one render's samples unevenly over the image, so it cannot be combined with {}: \
                 a resumed or merged render needs the same samples in every pixel",
                conflicting.join(" or ")
            );
        }
        if args.settings.spp.is_none() {
            bail!("--adaptive needs --spp N: the mean samples per pixel it spreads over the image");
        }
    }
    if args.sample_range.is_some() && args.settings.spp.is_some() {
        bail!("--sample-range A..B renders B - A spp; give it or --spp, not both");
    }
    if args.sample_range.is_some() && (args.target_error.is_some() || args.time_budget.is_some()) {
        bail!(
            "--sample-range A..B renders exactly samples A to B-1 so that the parts merge into one render; \
             --target-error and --time-budget would stop it short (a part stopped short cannot be merged)"
        );
    }
    Ok(())
}

/// Refuses `--replicates off` where it cannot go: with independent numbers (which have no
/// replicates), and, for any render without replicates (the flag's, or a resumed file's), with
/// every rule or output that reads the error estimate it leaves out.
fn check_replicates(args: &RenderArgs, options: TracerOptions, rules: &StopRules) -> anyhow::Result<()> {
    if args.replicates == Some(false) && options.sequence != illum_pathtrace::Sequence::LowDiscrepancy {
        bail!(
            "--replicates off: the {} sequence has no replicates (they randomise the low-discrepancy one); \
             give --sequence low-discrepancy, or leave --replicates out",
            options.sequence
        );
    }
    if options.estimates_error() {
        return Ok(());
    }
    let (source, hint) = match (&args.resume, args.replicates) {
        (Some(path), None) => (
            format!("{} was rendered with --replicates off, so it", path.display()),
            "continue it with a fixed --spp, or render it again with replicates",
        ),
        _ => ("--replicates off".to_owned(), "leave --replicates out"),
    };
    let conflicting = crate::given_flags(&[
        (args.target_error.is_some(), "--target-error"),
        (args.error_percentile.is_some(), "--error-percentile"),
        (args.region.is_some(), "--region"),
        (args.adaptive, "--adaptive"),
        (args.denoise.is_some(), "--denoise"),
    ]);
    if !conflicting.is_empty() {
        bail!(
            "{source} renders without an error estimate, and {} needs one; {hint}",
            conflicting.join(" and ")
        );
    }
    if rules.target_error.is_some() {
        bail!(
            "{source} renders without an error estimate, and the default stop rule stops at an \
             estimated error: give --spp N (or --sample-range A..B, or --time-budget S)"
        );
    }
    Ok(())
}

/// The stop rules the flags give; with no stop-rule flag at all, the default rules (said so).
fn stop_rules(args: &RenderArgs, scene: &Scene) -> StopRules {
    let no_stop_flag = args.settings.spp.is_none()
        && args.target_error.is_none()
        && args.time_budget.is_none()
        && args.sample_range.is_none()
        && args.resume.is_none();
    if no_stop_flag {
        println!(
            "no stop rule given: rendering until the estimated error is {}% or for {} s, whichever comes first \
             (--spp N, --target-error X or --time-budget S choose another)",
            DEFAULT_TARGET_ERROR * 100.0,
            DEFAULT_TIME_BUDGET.as_secs()
        );
        return StopRules {
            spp: None,
            target_error: Some(DEFAULT_TARGET_ERROR),
            time_budget: Some(DEFAULT_TIME_BUDGET),
        };
    }
    let spp = args.sample_range.as_ref().map(|r| r.end - r.start).or(args.settings.spp);
    StopRules::from_command_line(scene.pathtrace.spp, spp, args.target_error, args.time_budget)
}

/// Renders with the path tracer as the flags say and writes the outputs; returns the estimated
/// relative error from noise (`None`: nothing was rendered).
pub fn render_pathtrace(
    args: &RenderArgs,
    interrupt: &Interrupt,
    long: LongRender,
) -> anyhow::Result<Option<f64>> {
    let Some(Prepared { scene, options, rules, resumed, outputs }) = prepare(args)? else {
        return Ok(None);
    };
    long.exit_if_requested("before the render started");
    let gpu = crate::gpu()?;
    if let Some(denoiser) = args.denoise {
        interrupt.set_note(&crate::interrupt::note(
            "nothing (a denoised render writes its image once, at the end)",
            "every sample rendered so far",
        ));
        let outcome = crate::denoise::render_denoised(&crate::denoise::DenoiseRequest {
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
            bail!("the denoised render stopped before its first round");
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
    let mut earlier_seconds = 0.0;
    let mut rules = rules;
    if args.adaptive {
        let budget = rules.spp.expect("--adaptive needs --spp (checked in prepare)");
        let pilot = Instant::now();
        let allocation = illum_pathtrace::allocation::plan_adaptive(&mut tracer, budget)?;
        // The pilot is part of the render's time.
        earlier_seconds = pilot.elapsed().as_secs_f64();
        println!("adaptive sampling: {} ({:.2} s)", allocation.describe(), earlier_seconds);
        // Done when every block is: at the largest count.
        rules.spp = Some(allocation.max());
    }
    if let Some(checkpoint) = resumed {
        let path = args.resume.as_ref().expect("resumed");
        earlier_seconds = checkpoint.metadata.render_seconds;
        crate::resume::restore(&mut tracer, path, checkpoint, &rules)?;
    } else if let Some(range) = &args.sample_range {
        tracer.set_sample_offset(range.start);
    }
    let exr_outputs: Vec<PathBuf> =
        outputs.iter().filter(|o| matches!(output_format(o), Ok(OutputFormat::Exr))).cloned().collect();
    let every = args.checkpoint_seconds.unwrap_or(DEFAULT_CHECKPOINT);
    // A part of a split render records where its range ends, so that a part stopped early can
    // be finished with the exact command (`merge` and the resume message name it).
    let range_end: Option<(String, String)> = args
        .sample_range
        .as_ref()
        .map(|r| (illum_pathtrace::metadata::SAMPLE_END.to_owned(), r.end.to_string()));
    let mut last_checkpoint = Instant::now();
    let mut checkpoint_error: Option<illum_pathtrace::checkpoint::CheckpointError> = None;
    let scope = error_scope(args, &gpu, tracer.scene())?;
    let progress = RenderProgress::with_period(long.progress_period);
    let outputs_named = crate::describe_outputs(&exr_outputs);
    interrupt.set_note(&crate::interrupt::note(
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
                    illum_pathtrace::metadata::exr_metadata(t, seconds, None, "render example (checkpoint)");
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
                    interrupt.set_note(&crate::interrupt::note(&kept, "the samples rendered after it"));
                }
                last_checkpoint = Instant::now();
            }
        })?;
    progress.finish();
    interrupt.set_note(&crate::interrupt::note(
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
            "error: {signal} before the first complete pass ({seconds:.1} s in): no pixel had all its samples yet, \
             so nothing was written"
        );
        std::process::exit(code);
    }
    let accumulator = tracer.accumulator();
    let estimated_error = accumulator.estimated_relative_error();
    let image = accumulator.mean_image();
    let mut metadata =
        illum_pathtrace::metadata::exr_metadata(&tracer, seconds, Some(reason), "render example");
    metadata.fields.extend(range_end);
    for output in &outputs {
        match output_format(output)? {
            OutputFormat::Png => {
                let stops = args.exposure.unwrap_or_default().stops_for(&image);
                if args.exposure == Some(illum_image::Exposure::Auto) {
                    println!("--exposure auto: {stops:.2} stops");
                }
                save_png(output, &image, stops, args.encoding.unwrap_or_default())?
            }
            OutputFormat::Exr => save_checkpoint(output, &tracer, &metadata).map_err(anyhow::Error::msg)?,
        }
    }
    println!("{}", summary(&tracer, reason, seconds, status.samples_per_second()));
    if let Some(over) = budget_overrun(reason, rules.time_budget, seconds) {
        println!("{over}");
    }
    let scope = progressive.error_scope();
    if *scope != ErrorScope::Image
        && let Some(error) = status.relative_error
    {
        println!(
            "estimated relative error over {}: {}",
            scope.describe(),
            illum_pathtrace::progressive::error_text(Some(error), 0)
        );
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
