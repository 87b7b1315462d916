//! Renders a scene file to PNG and/or EXR.
//!
//! ```text
//! cargo run --release --example render -- [SCENE] [--spp N] [--bounces B|unbounded] [--seed S]
//!     [--width W --height H] [--sampling cosine|uniform] [-o FILE.png|FILE.exr]...
//!     [--target-error X] [--time-budget SECONDS] [--encoding gamma2.2|srgb] [--exposure STOPS]
//! ```
//! With no arguments it renders `scenes/cornell.toml` to `out/cornell.png` and `out/cornell.exr`.
//! `--renderer raster|pathtrace` picks the renderer; the default is the scene file's `renderer`
//! (`scenes/whitted.toml` says `raster`). The rasterizer takes `[--look figure|enhanced]
//! [--no-shadows] [--no-pcf] [--no-refraction] [--no-reflection] [--no-fresnel] [--no-msaa]`
//! (see `illum::raster_cli`). A renderer given a scene it cannot render says what it lacks.
//! Ctrl-C stops the render early and still writes what has accumulated; the EXR's metadata
//! records the samples per pixel actually reached.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Context, bail};
use clap::Parser;
use illum::cli::{self, DEFAULT_SCENE, OutputFormat, SceneArgs, output_format};
use illum::image::{Encoding, ExrMetadata, save_exr, save_png};
use illum::pathtrace::{PathTracer, Sequence, StopReason, StopRules, TracerOptions, render_progressive};
use illum::raster_cli::{RasterArgs, RasterRequest, render_raster};
use illum::scene::{RendererKind, Scene};
use indicatif::{ProgressBar, ProgressStyle};

#[derive(Parser, Debug)]
#[command(about = "Render a scene file to PNG and/or EXR with the path tracer or the rasterizer")]
struct Args {
    /// Scene file (TOML).
    #[arg(default_value = DEFAULT_SCENE)]
    scene: PathBuf,
    /// Renderer: `pathtrace` or `raster`. Default: the scene file's `renderer`.
    #[arg(long)]
    renderer: Option<RendererKind>,
    #[command(flatten)]
    settings: SceneArgs,
    #[command(flatten)]
    raster: RasterArgs,
    /// Output file(s); the extension (.png or .exr) picks the format. Default: out/NAME.png and
    /// out/NAME.exr.
    #[arg(short = 'o', long = "output")]
    outputs: Vec<PathBuf>,
    /// Stop early once the estimated relative standard error falls to this value (e.g. 0.01).
    #[arg(long)]
    target_error: Option<f64>,
    /// Stop early after this many seconds.
    #[arg(long)]
    time_budget: Option<f64>,
    /// PNG encoding: gamma2.2, srgb or linear. Default: gamma2.2 (the assignment's) for
    /// path-traced scenes, linear for rasterizer scenes (the assignment's figure 1 is linear).
    #[arg(long)]
    encoding: Option<Encoding>,
    /// Sample values: `independent` or `low-discrepancy` (lower error for the same spp; see
    /// docs/accuracy.md). Default: the scene file's `[pathtrace] sequence`.
    #[arg(long)]
    sequence: Option<Sequence>,
    /// PNG exposure in stops (EXR output is never scaled).
    #[arg(long, default_value_t = 0.0)]
    exposure: f32,
}

fn main() {
    illum::cli::main_with(run);
}

fn run(args: Args) -> anyhow::Result<()> {
    let renderer = match args.renderer {
        Some(renderer) => renderer,
        None => Scene::load(&cli::resolve_scene_path(&args.scene))?.renderer,
    };
    if renderer == RendererKind::Raster {
        let given = [
            (args.target_error.is_some(), "--target-error"),
            (args.time_budget.is_some(), "--time-budget"),
            (args.sequence.is_some(), "--sequence"),
        ];
        return render_raster(&RasterRequest {
            scene: &args.scene,
            settings: &args.settings,
            raster: &args.raster,
            outputs: &args.outputs,
            encoding: args.encoding,
            exposure: args.exposure,
            path_tracer_flags: given.into_iter().filter_map(|(on, flag)| on.then_some(flag)).collect(),
        });
    }
    args.raster.reject_for_path_tracer(&args.scene)?;
    let mut scene = cli::load_scene(&args.scene, &args.settings)?;
    if let Some(sequence) = args.sequence {
        scene.pathtrace.sequence = sequence;
    }
    let outputs = if args.outputs.is_empty() {
        vec![
            PathBuf::from(format!("out/{}.png", scene.name)),
            PathBuf::from(format!("out/{}.exr", scene.name)),
        ]
    } else {
        args.outputs.clone()
    };
    for output in &outputs {
        output_format(output)?;
    }
    if let Some(target) = args.target_error
        && !(target > 0.0 && target.is_finite())
    {
        bail!("--target-error = {target}: must be a finite number above 0 (for example 0.01 for 1%)");
    }
    let time_budget = match args.time_budget {
        Some(s) if s > 0.0 && s.is_finite() => Some(Duration::from_secs_f64(s)),
        Some(s) => bail!("--time-budget = {s}: must be a finite number of seconds above 0"),
        None => None,
    };

    let gpu = cli::gpu()?;
    let mut tracer = PathTracer::with_options(
        &gpu,
        &scene,
        TracerOptions { sequence: scene.pathtrace.sequence, ..Default::default() },
    )?;
    let cancel = Arc::new(AtomicBool::new(false));
    {
        let cancel = cancel.clone();
        ctrlc::set_handler(move || {
            if cancel.swap(true, Ordering::SeqCst) {
                // A second Ctrl-C while the first is being honoured: leave at once.
                std::process::exit(130);
            }
        })
        .context("installing the Ctrl-C handler")?;
    }

    let spp = scene.pathtrace.spp;
    let progress = ProgressBar::new(spp as u64);
    progress.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} spp  {msg}  [{elapsed_precise}, ETA {eta}]")
            .expect("valid template"),
    );
    let started = Instant::now();
    let rules = StopRules { spp: Some(spp), target_error: args.target_error, time_budget };
    let reason = render_progressive(&mut tracer, &rules, &cancel, |t| {
        progress.set_position(t.spp_done() as u64);
        let rate = t.accumulator().total_samples() as f64 / t.wall_seconds().max(1e-9);
        progress.set_message(format!("{:.2} Msamples/s", rate * 1e-6));
    })?;
    progress.finish_and_clear();
    let seconds = started.elapsed().as_secs_f64();

    let accumulator = tracer.accumulator();
    let image = accumulator.mean_image();
    let spp_reached = accumulator.min_samples();
    let metadata = ExrMetadata {
        scene: scene.name.clone(),
        spp: spp_reached,
        bounces: scene.pathtrace.bounces.to_string(),
        seed: scene.pathtrace.seed,
        sampling: scene.pathtrace.sampling.to_string(),
        render_seconds: seconds,
        extra: vec![
            ("stopped_by".into(), format!("{reason:?}")),
            ("sequence".into(), scene.pathtrace.sequence.to_string()),
            ("dropped_samples".into(), accumulator.dropped_samples().to_string()),
            ("estimated_relative_error".into(), format!("{:.6}", accumulator.estimated_relative_error())),
            ("adapter".into(), gpu.adapter_info.name.clone()),
        ],
    };
    for output in &outputs {
        match output_format(output)? {
            OutputFormat::Png => save_png(output, &image, args.exposure, args.encoding.unwrap_or_default())?,
            OutputFormat::Exr => save_exr(output, &image, &metadata)?,
        }
    }
    let samples = accumulator.total_samples() as f64;
    println!(
        "{}: {}x{}, {} spp ({}), bounces {}, {} sampling, {:.2} s, {:.2} Msamples/s, estimated relative error {:.4}, dropped samples {}",
        scene.name,
        scene.camera.width,
        scene.camera.height,
        spp_reached,
        match reason {
            StopReason::SppReached => "target reached",
            StopReason::ErrorReached => "stopped at the error target",
            StopReason::TimeBudget => "stopped by the time budget",
            StopReason::Cancelled => "interrupted; kept what had accumulated",
        },
        scene.pathtrace.bounces,
        scene.pathtrace.sampling,
        seconds,
        samples / tracer.wall_seconds().max(1e-9) * 1e-6,
        accumulator.estimated_relative_error(),
        accumulator.dropped_samples(),
    );
    for output in &outputs {
        println!("wrote {}", output.display());
    }
    Ok(())
}
