//! Frame-rate benchmark of the rasterizer (which fakes Whitted's look).
//!
//! ```text
//! cargo run --release --example raster_bench -- [SCENE] [--width 1280 --height 720]
//!     [--frames 60] [--warmup 5] [--look figure|enhanced] [--cube-size N] [--no-antialiasing] ...
//! ```
//! Renders `frames` frames (after `warmup` untimed ones) without reading them back and prints the
//! median frame time, frames per second, and the median GPU time of each pass (shadow map, the
//! cube-map faces together, the main pass) from timestamp queries, twice: with the
//! camera orbiting an unchanged scene (a viewer's steady state: the shadow and cube maps are
//! reused) and with the scene changing every frame (every map made again). With no
//! flags: `scenes/whitted.toml` at 1280 x 720, enhanced look, every effect on. Timings are never
//! asserted in tests; the figures are in docs/performance-raster.md.

use std::path::PathBuf;

use anyhow::Context;
use clap::Parser;

use illum::raster::RasterScene;
use illum::raster::{Look, Motion, bench_frames};
use illum_cli::raster::RasterArgs;

#[derive(Parser, Debug)]
#[command(about = "Measure the rasterizer's frame rate and the GPU time of each pass (shadow, \
             cube capture, main)")]
struct Args {
    /// Rasterizer scene file.
    #[arg(default_value = "scenes/whitted.toml")]
    scene: PathBuf,
    /// Frame width in pixels.
    #[arg(long, default_value_t = 1280)]
    width: u32,
    /// Frame height in pixels.
    #[arg(long, default_value_t = 720)]
    height: u32,
    /// Timed frames (the median is reported), 1 to 100000.
    #[arg(long, default_value_t = 60, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    frames: u32,
    /// Untimed frames first (pipeline compilation, allocation), 0 to 10000.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(0..=10_000))]
    warmup: u32,
    /// Overrides the scene's cube-map face size.
    #[arg(long)]
    cube_size: Option<u32>,
    #[command(flatten)]
    raster: RasterArgs,
}

fn main() {
    illum_cli::main_with(run);
}

fn run(args: Args) -> anyhow::Result<()> {
    let path = illum_cli::resolve_scene_path(&args.scene);
    let mut scene = RasterScene::load(&path)?;
    if let Some(size) = args.cube_size {
        anyhow::ensure!(size >= 1, "--cube-size = 0: must be at least 1");
        scene.quality.cube_size = size;
    }
    let mut options = args.raster.options(&scene);
    if args.raster.look.is_none() {
        options.look = Look::Enhanced;
    }
    let gpu = illum_cli::gpu()?;
    for motion in [Motion::CameraOrbit, Motion::SceneChange, Motion::SceneChangeReducedCubes] {
        bench_one(&gpu, &scene, &args, &options, motion)?;
    }
    let (mean, p99, max) = illum::raster::reduced_cube_error(&gpu, &scene, args.width, args.height, &options)
        .context("measuring the reduced cube maps' error")?;
    println!(
        "reduced cube maps while the scene changes, against full size, the frame after a moved sphere: \
         mean {mean:.3} levels, 99th percentile {p99:.1}, largest {max:.0} (8-bit, largest channel)"
    );
    Ok(())
}

fn bench_one(
    gpu: &illum::gpu::GpuContext,
    scene: &RasterScene,
    args: &Args,
    options: &illum::raster::Options,
    motion: Motion,
) -> anyhow::Result<()> {
    let report = bench_frames(gpu, scene, args.width, args.height, options, motion, args.warmup, args.frames)
        .context("benchmarking the rasterizer")?;
    println!(
        "{} {}x{} look {}, {} (shadow map {}^2, cube faces {}^2, {} frames): median frame {:.2} ms = {:.1} fps (min {:.2}, max {:.2})",
        scene.name,
        args.width,
        args.height,
        options.look,
        motion.describe(),
        report.shadow_map_size,
        report.cube_size,
        report.frame_ms.len(),
        report.median_frame_ms(),
        report.fps(),
        report.frame_ms.iter().copied().fold(f64::INFINITY, f64::min),
        report.frame_ms.iter().copied().fold(0.0, f64::max),
    );
    match report.median_pass_ms() {
        Some(t) => println!(
            "  median GPU ms per pass: shadow {:.2}, cube {:.2}, main {:.2} (sum {:.2})",
            t.shadow_ms,
            t.cube_ms,
            t.main_ms,
            t.total_ms()
        ),
        None => println!("  (no timestamp queries on {}: no per-pass GPU times)", gpu.adapter_info.name),
    }
    Ok(())
}
