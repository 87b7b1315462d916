//! Throughput benchmark of the path tracer (and, where built, the raster scene).
//!
//! ```text
//! cargo run --release --example bench -- [--runs N] [--quick | --large [--compare-readback]]
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
//! `--large` measures only the 1024 x 1024 rows, where the host's share (readback and fold) is
//! largest; `--compare-readback` adds each of them read through a staging copy, as on a discrete
//! GPU, beside the default mapped readback of a device that shares the host's memory.
//!
//! Timings are never asserted in tests; the figures go to docs/performance.md.

use std::path::PathBuf;

use clap::Parser;
use illum::cli::{self, SceneArgs};
use illum::image::median;
use illum::pathtrace::{PathTracer, TracerOptions, Traversal};
use illum::raster::RasterScene;
use illum::raster::{Look, Motion, Options, bench_frames};
use illum::scene::{Bounces, Scene};

#[derive(Parser, Debug)]
#[command(about = "Measure path-tracer throughput (samples/s, rays/s, GPU time per submission; generic \
             against specialised pipelines) and the rasterizer's frame time")]
struct Args {
    /// Scene to benchmark.
    #[arg(default_value = cli::DEFAULT_SCENE)]
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
    /// With --large: each row also read back through a staging copy (see `PathTracer::set_mapped_readback`).
    #[arg(long, requires = "large")]
    compare_readback: bool,
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
    illum::cli::main_with(run);
}

/// Upper bound on rays per path for a fixed bounce count: one camera ray, then at each of the
/// `bounces + 1` surface hits one shadow ray, plus one bounce ray per bounce. Paths that escape
/// or reach the light early trace fewer, so rays/s computed from this is an upper estimate.
fn rays_per_sample(bounces: u32) -> u64 {
    1 + (bounces as u64 + 1) + bounces as u64
}

fn run(args: Args) -> anyhow::Result<()> {
    let gpu = cli::gpu()?;
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
        let scene: Scene = cli::load_scene(&args.scene, &settings)?;
        let options = TracerOptions { traversal: config.traversal, ..Default::default() };
        let mut tracer = PathTracer::with_options(&gpu, &scene, options)?;
        tracer.set_mapped_readback(!config.staging_copy);
        let readback = if tracer.mapped_readback() { "mapped" } else { "staging copy" };
        // Warm-up, one untimed run of the row: compiles the pipeline on the driver, teaches the
        // planner the cost, and grows the batch buffers to the bands the timed runs use (a first
        // band into freshly allocated buffers pays their page faults, 20 to 30 ms at 1024 x 1024).
        tracer.render_to_spp(config.spp)?;
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
    bench_raster(&gpu, args.runs)
}

/// The rasterizer on the Whitted scene at 1280 x 720, enhanced look, every effect on: frames per second and
/// the GPU time of each pass (more options: `--example raster_bench`).
fn bench_raster(gpu: &illum::gpu::GpuContext, runs: u32) -> anyhow::Result<()> {
    let path = cli::resolve_scene_path(std::path::Path::new("scenes/whitted.toml"));
    let scene = RasterScene::load(&path)?;
    let options = Options::all_on(Look::Enhanced);
    println!();
    println!(
        "| Rasterizer, Whitted scene, 1280x720, enhanced, every effect on | median frame (ms) | fps | shadow (ms) | cube maps (ms) | main (ms) |"
    );
    println!("|---|---|---|---|---|---|");
    for motion in [Motion::CameraOrbit, Motion::SceneChange] {
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
