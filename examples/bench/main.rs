//! Throughput benchmark of the path tracer (and, where built, the raster scene).
//!
//! ```text
//! cargo run --release --example bench -- [--runs N] [--quick | --large [--compare-readback] | --viewer | --sequences
//!     | --glint SCENE... | --parts SCENE | --first-image SCENE... | --largest-mesh [SCENE]
//!     | --against OLD_RENDER --truth TRUTH.exr SCENE]
//! ```
//! For `scenes/cornell.toml` at each size and bounce count it renders a fixed number of samples
//! per pixel `runs` times and prints the median of:
//! - samples/s: width x height x spp / wall time of the GPU submissions (readback and f64 fold
//!   included, as a user experiences it);
//! - GPU samples/s: the same over the compute passes' timestamp-query time;
//! - rays/s: rays traced (camera, bounce and shadow rays) per second of wall time; the count
//!   comes from the bounce structure (see `rays_per_sample`);
//! - wall / GPU: the first rate over the second (1: the host adds nothing to the GPU's time).
//!
//! `--quick` and the default also time the low-discrepancy sequence against independent numbers
//! (256 x 256, 256 spp, bounces 2): the two tracers' runs alternate, A B A B, and the ratio of
//! their samples/s is taken pair by pair, so that the sequence's price per sample is measured
//! side by side whatever the machine's drift. `--sequences` measures only that.
//!
//! `--large` measures only the 1024 x 1024 rows, where the host's share (readback and fold) is
//! largest; `--compare-readback` adds each of them read through a staging copy, as on a discrete
//! GPU, beside the default mapped readback of a device that shares the host's memory.
//!
//! `--viewer` measures the viewer's path tracer as a user meets it: the real window under
//! `xvfb-run` with the view still (`illum-viewer --mode pathtrace --screenshot`, which prints its
//! statistics on exit), and `render`'s loop on the same scene at the viewer's resolution for the
//! same wall time, run after it, side by side, `runs` times.
//!
//! `--parts` gives each part of a render with the caustic's estimators on its own row beside the
//! camera paths alone (`parts.rs`).
//!
//! `--first-image` times the first image of each scene given, the whole `render` process with
//! Mesa's shader cache cold and warm, beside the path tracer's throughput (`first_image.rs`).
//!
//! `--glint` times the host's solve of the sun's glint (`illum::pathtrace::glint::solve`, part of
//! a render's set-up before its first sample) for each scene given, on all the host's threads,
//! and the whole set-up (the path tracer's construction with the scene's estimators on):
//! `scripts/many-spheres.py` writes scenes with many specular spheres for it.
//!
//! `--largest-mesh` grows a grid mesh on the scene's floor until the device's limit on one
//! storage binding refuses it, and prints the largest accepted size's triangles, bytes on the
//! device per triangle, hierarchy build time and one frame's throughput (`largest_mesh.rs`).
//!
//! `--against` compares the efficiency of this build's caustic estimators and sequences with
//! another build's `render`, side by side against one truth (`against.rs`).
//!
//! Timings are never asserted in tests; the figures go to docs/performance.md.

use std::path::PathBuf;

use clap::Parser;
use illum::image::median;
use illum::pathtrace::{PathTracer, Readback, TracerOptions, Traversal};
use illum::raster::RasterScene;
use illum::raster::{Look, Motion, Options, bench_frames};
use illum::scene::Sequence;
use illum::scene::{Bounces, Scene};
use illum_cli::SceneArgs;
use illum_lab::report::load_average;

mod against;
mod first_image;
mod largest_mesh;
mod parts;
mod viewer;

#[derive(Parser, Debug)]
#[command(about = "Measure path-tracer throughput (samples/s, rays/s, GPU time per submission; generic \
             against specialised pipelines) and the rasterizer's frame time")]
struct Args {
    /// Scene to benchmark.
    #[arg(default_value = illum_cli::DEFAULT_SCENE)]
    scene: PathBuf,
    /// Repetitions per configuration (the median is reported), 1 to 1000.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000))]
    runs: u32,
    /// Only the headline configuration (256 x 256, 64 spp, bounces 2 and 8).
    #[arg(long, conflicts_with = "large")]
    quick: bool,
    /// Only the 1024 x 1024 rows (the wall-against-GPU-clock figures), without the rasterizer.
    #[arg(long)]
    large: bool,
    /// With --large: each row also read back through a staging copy (see `PathTracer::set_readback`).
    #[arg(long, requires = "large")]
    compare_readback: bool,
    /// Only the low-discrepancy sequence against independent numbers (runs alternated).
    #[arg(long, conflicts_with_all = ["quick", "large"])]
    sequences: bool,
    /// Only the viewer's row: its path tracer's samples/s in a real window under xvfb-run,
    /// beside `render`'s at the same size (needs `cargo build --release -p illum-viewer`).
    #[arg(long, conflicts_with_all = ["quick", "large"])]
    viewer: bool,
    /// With --viewer: frames the window draws before it closes, 10 to 100000.
    #[arg(long, default_value_t = 150, requires = "viewer", value_parser = clap::value_parser!(u32).range(10..=100_000))]
    frames: u32,
    /// Only the glint's solve on the host and the set-up before the first sample, for each of these scenes (see `scripts/many-spheres.py`).
    #[arg(long, num_args = 1.., conflicts_with_all = ["quick", "large", "viewer"])]
    glint: Vec<PathBuf>,
    /// Only the time to the first image of each of these scenes, cold and warm (see
    /// `scripts/many-spheres.py`; needs `cargo build --release --example render`).
    #[arg(long, num_args = 1.., conflicts_with_all = ["quick", "large", "viewer", "sequences", "parts"])]
    first_image: Vec<PathBuf>,
    /// Only the parts of a render with the caustic's estimators on, each beside the camera paths
    /// alone (the scene should have a caustic: scenes/whitted.toml).
    #[arg(long, conflicts_with_all = ["quick", "large", "viewer", "sequences"])]
    parts: bool,
    /// Only the largest mesh the device holds: a grid on the scene's floor, grown until the
    /// device's storage-binding limit refuses it.
    #[arg(long, conflicts_with_all = ["quick", "large", "viewer", "sequences", "parts", "glint", "first_image"])]
    largest_mesh: bool,
    /// Only this build's caustic estimators and sequences against another build's `render`
    /// binary (its scene's caustic estimator), side by side: time, relMSE against --truth,
    /// efficiency (the scene should have a caustic: scenes/whitted.toml).
    #[arg(long, requires = "truth", conflicts_with_all = ["quick", "large", "viewer", "sequences", "parts", "glint", "first_image", "largest_mesh"])]
    against: Option<PathBuf>,
    /// With --against: the truth every row is compared with (320 x 180, of the same scene).
    #[arg(long, requires = "against")]
    truth: Option<PathBuf>,
}

struct Config {
    size: u32,
    spp: u32,
    bounces: u32,
    traversal: Traversal,
    /// Read back through a staging copy even where the batch buffers can be mapped.
    staging_copy: bool,
}

fn main() {
    illum_cli::main_with(run);
}

/// Upper bound on rays per path for a fixed bounce count: one camera ray, then at each of the
/// `bounces + 1` surface hits one shadow ray, plus one bounce ray per bounce. Paths that escape
/// or reach the light early trace fewer, so rays/s computed from this is an upper estimate.
fn rays_per_sample(bounces: u32) -> u64 {
    1 + (bounces as u64 + 1) + bounces as u64
}

fn run(args: Args) -> anyhow::Result<()> {
    if let (Some(other), Some(truth)) = (&args.against, &args.truth) {
        return against::bench_against(other, truth, &illum_cli::resolve_scene_path(&args.scene), args.runs);
    }
    if !args.glint.is_empty() {
        return bench_glint(&args.glint, args.runs);
    }
    let gpu = illum_cli::gpu()?;
    if !args.first_image.is_empty() {
        let load = load_average().map_or(String::new(), |l| format!(", load average {l} at the start"));
        return first_image::bench_first_image(&gpu, &args.first_image, args.runs, &load);
    }
    if args.largest_mesh {
        let load = load_average().map_or(String::new(), |l| format!(", load average {l} at the start"));
        return largest_mesh::bench_largest_mesh(&gpu, &Scene::load(&args.scene)?, &load);
    }
    if args.parts {
        let load = load_average().map_or(String::new(), |l| format!(", load average {l} at the start"));
        return parts::bench_parts(&gpu, &Scene::load(&args.scene)?, args.runs, &load);
    }
    if args.viewer {
        return viewer::bench_viewer(&gpu, &args);
    }
    if args.sequences {
        return bench_sequences(&gpu, &args);
    }
    println!(
        "adapter: {} ({:?}, driver {})",
        gpu.adapter_info.name, gpu.adapter_info.backend, gpu.adapter_info.driver_info
    );
    // The headline configurations, each with the specialised (default) and generic traversal.
    let mut configs = Vec::new();
    if !args.large {
        for bounces in [2, 8] {
            for traversal in [Traversal::Specialised, Traversal::Generic] {
                configs.push(Config { size: 256, spp: 64, bounces, traversal, staging_copy: false });
            }
        }
    }
    if !args.quick {
        for (size, spp) in [(256, 64), (1024, 4)] {
            for bounces in [0, 1, 2, 8] {
                let headline = size == 256 && (bounces == 2 || bounces == 8);
                if headline || (args.large && size != 1024) {
                    continue;
                }
                let traversal = Traversal::Specialised;
                configs.push(Config { size, spp, bounces, traversal, staging_copy: false });
                if args.compare_readback {
                    configs.push(Config { size, spp, bounces, traversal, staging_copy: true });
                }
            }
        }
    }
    println!(
        "| size | spp | bounces | traversal | readback | Msamples/s (wall) | Msamples/s (GPU) | wall / GPU | Mrays/s (wall, upper) | GPU ms per submission |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for config in configs {
        let settings = SceneArgs {
            spp: Some(config.spp),
            bounces: Some(Bounces::Fixed(config.bounces)),
            width: Some(config.size),
            height: Some(config.size),
            ..Default::default()
        };
        let scene: Scene = illum_cli::load_scene(&args.scene, &settings)?;
        let options = TracerOptions { traversal: config.traversal, ..Default::default() };
        let mut tracer = PathTracer::with_options(&gpu, &scene, options)?;
        tracer.set_readback(if config.staging_copy { Readback::Staging } else { Readback::Mapped });
        let readback = if tracer.readback() == Readback::Mapped { "mapped" } else { "staging copy" };
        // Warm-up, an untimed run of the row up to 16 spp: compiles the pipeline on the driver,
        // teaches the planner the cost, and grows the batch buffers to the bands the timed runs
        // use (a first band into freshly allocated buffers pays their page faults). 16 spp do
        // all three (a band's size follows the time per submission, not the spp) and keep the
        // generic rows' warm-up short: a whole 64-spp run of the generic pipeline at 8 bounces
        // took longer than everything else in `--quick`.
        tracer.render_to_spp(config.spp.min(16))?;
        let (mut wall, mut gpu_rate, mut per_submission) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..args.runs {
            tracer.reset();
            let mut submissions = 0u32;
            while tracer.spp_done() < config.spp {
                tracer.render_step(Some(config.spp))?;
                submissions += 1;
            }
            let samples = (config.size as f64).powi(2) * config.spp as f64;
            wall.push(samples / tracer.wall_seconds());
            gpu_rate.push(samples / tracer.gpu_seconds());
            per_submission.push(tracer.gpu_seconds() * 1e3 / submissions as f64);
        }
        let wall = median(&mut wall);
        let gpu_rate = median(&mut gpu_rate);
        println!(
            "| {0}x{0} | {1} | {2} | {3:?} | {readback} | {4:.2} | {5:.2} | {6:.2} | {7:.1} | {8:.0} |",
            config.size,
            config.spp,
            config.bounces,
            config.traversal,
            wall * 1e-6,
            gpu_rate * 1e-6,
            wall / gpu_rate,
            wall * rays_per_sample(config.bounces) as f64 * 1e-6,
            median(&mut per_submission),
        );
    }
    if args.large {
        return Ok(());
    }
    bench_sequences(&gpu, &args)?;
    bench_raster(&gpu, args.runs)
}

/// Samples/s of the low-discrepancy sequence, with its replicates and without
/// (`TracerOptions::replicates`), against independent numbers, the runs alternated (see the
/// module documentation). Prints each one's median rates and, for each low-discrepancy row, the
/// median, lowest and highest of its per-run ratios to independent numbers.
fn bench_sequences(gpu: &illum::gpu::GpuContext, args: &Args) -> anyhow::Result<()> {
    const SIZE: u32 = 256;
    const SPP: u32 = 256;
    const BOUNCES: u32 = 2;
    let settings = SceneArgs {
        spp: Some(SPP),
        bounces: Some(Bounces::Fixed(BOUNCES)),
        width: Some(SIZE),
        height: Some(SIZE),
        ..Default::default()
    };
    let scene: Scene = illum_cli::load_scene(&args.scene, &settings)?;
    let mut tracers = Vec::new();
    for (sequence, replicates) in
        [(Sequence::Independent, true), (Sequence::LowDiscrepancy, true), (Sequence::LowDiscrepancy, false)]
    {
        let options = TracerOptions { sequence, replicates, ..Default::default() };
        let mut tracer = PathTracer::with_options(gpu, &scene, options)?;
        // Warm-up, as for the rows above.
        tracer.render_to_spp(16)?;
        tracers.push((options, tracer, Vec::new(), Vec::new(), Vec::new()));
    }
    let samples = f64::from(SIZE).powi(2) * f64::from(SPP);
    for _ in 0..args.runs {
        let mut independent_rate = 0.0;
        for (options, tracer, wall, gpu_rate, ratios) in tracers.iter_mut() {
            tracer.reset();
            tracer.render_to_spp(SPP)?;
            let rate = samples / tracer.wall_seconds();
            wall.push(rate);
            gpu_rate.push(samples / tracer.gpu_seconds());
            if options.sequence == Sequence::Independent {
                independent_rate = rate;
            } else {
                ratios.push(rate / independent_rate);
            }
        }
    }
    println!();
    println!(
        "| sequence ({SIZE}x{SIZE}, {SPP} spp, bounces {BOUNCES}, runs alternated) | Msamples/s (wall) | Msamples/s (GPU) |"
    );
    println!("|---|---|---|");
    for (options, _, wall, gpu_rate, _) in &mut tracers {
        println!(
            "| {} | {:.2} | {:.2} |",
            options.sequence_label(),
            median(wall) * 1e-6,
            median(gpu_rate) * 1e-6
        );
    }
    for (options, _, _, _, ratios) in tracers.iter_mut().filter(|t| !t.4.is_empty()) {
        let (lowest, highest) =
            ratios.iter().fold((f64::INFINITY, 0f64), |(lo, hi), &r| (lo.min(r), hi.max(r)));
        let ratio = median(ratios);
        println!(
            "\n{} / independent samples/s (wall), {} pairs: median {ratio:.3} ({lowest:.3} to {highest:.3}); \
             time per sample {:.3}x",
            options.sequence_label(),
            ratios.len(),
            1.0 / ratio
        );
    }
    Ok(())
}

/// The rasterizer on the Whitted scene at 1280 x 720, enhanced look, every effect on: frames per second and
/// the GPU time of each pass (more options: `--example raster_bench`).
fn bench_raster(gpu: &illum::gpu::GpuContext, runs: u32) -> anyhow::Result<()> {
    let path = illum_cli::resolve_scene_path(std::path::Path::new("scenes/whitted.toml"));
    let scene = RasterScene::load(&path)?;
    let options = Options::all_on(Look::Enhanced);
    println!();
    println!(
        "| Rasterizer, Whitted scene, 1280x720, enhanced, every effect on | median frame (ms) | fps | shadow (ms) | cube maps (ms) | main (ms) |"
    );
    println!("|---|---|---|---|---|---|");
    for motion in [Motion::CameraOrbit, Motion::SceneChange, Motion::SceneChangeReducedCubes] {
        let report = bench_frames(gpu, &scene, 1280, 720, &options, motion, 5, 12 * runs)?;
        let passes = report.median_pass_ms();
        let pass = |f: fn(&illum::raster::PassTimes) -> f64| {
            passes.as_ref().map_or("n/a".to_owned(), |p| format!("{:.2}", f(p)))
        };
        println!(
            "| {} | {:.2} | {:.1} | {} | {} | {} |",
            motion.describe(),
            report.median_frame_ms(),
            report.fps(),
            pass(|p| p.shadow_ms),
            pass(|p| p.cube_ms),
            pass(|p| p.main_ms),
        );
    }
    Ok(())
}

/// The glint's host solve per scene, and the set-up before the first sample it is part of: their
/// median times over `runs`, on every host thread.
fn bench_glint(scenes: &[PathBuf], runs: u32) -> anyhow::Result<()> {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let load = load_average().map_or(String::new(), |l| format!(", load average {l} at the start"));
    println!("glint solve on the host, {threads} threads, median of {runs} runs{load}\n");
    println!(
        "set-up: the path tracer's construction with the scene's estimators on (the glint's solve started on a \
         thread of its own, which the first samples do not wait for; the light tracer's buffers; the pipelines \
         from Mesa's warm shader cache), each run on a new device\n"
    );
    println!("| scene | objects | specular objects | glints | solve s | set-up before the first sample s |");
    println!("|---|---|---|---|---|---|");
    for path in scenes {
        let scene = Scene::load(path)?;
        let specular = scene
            .objects
            .iter()
            .filter(|o| {
                matches!(
                    scene.material_of(o).kind,
                    illum::scene::MaterialKind::Mirror { .. } | illum::scene::MaterialKind::Dielectric { .. }
                )
            })
            .count();
        let mut seconds = Vec::new();
        let mut glints = 0;
        for _ in 0..runs {
            let start = std::time::Instant::now();
            glints = illum::pathtrace::glint::solve(&scene).len();
            seconds.push(start.elapsed().as_secs_f64());
        }
        // A new device each time, so that no pipeline comes from the last run's context; the
        // first, untimed, fills Mesa's shader cache as any earlier render of the scene would.
        let mut setup = Vec::new();
        for run in 0..=runs {
            let gpu = illum_cli::gpu()?;
            let start = std::time::Instant::now();
            let tracer = PathTracer::new(&gpu, &scene)?;
            let elapsed = start.elapsed().as_secs_f64();
            drop(tracer);
            if run > 0 {
                setup.push(elapsed);
            }
        }
        println!(
            "| {} | {} | {specular} | {glints} | {:.3} | {:.3} |",
            path.display(),
            scene.objects.len(),
            median(&mut seconds),
            median(&mut setup)
        );
    }
    Ok(())
}
