//! The path tracer's test helpers: scenes, renders and their statistics, beside the device,
//! paths and failure images every crate's GPU tests share (`illum_gpu::testing`).
#![allow(dead_code)] // each test binary uses a different subset

use std::path::PathBuf;

use illum_image::RgbImage32;
use illum_pathtrace::PathTracer;
use illum_scene::{Bounces, Overrides, Sampling, Scene};

pub mod edit;

pub use illum_gpu::testing::{failure_dir, gpu, run_compute, workspace_path};

/// `relative` under this crate (its tests' data: `tests/reference/...`).
pub fn crate_path(relative: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(relative)
}

/// Loads `scenes/NAME.toml` with overrides.
pub fn scene(name: &str, overrides: Overrides) -> Scene {
    let mut scene = Scene::load(&workspace_path(&format!("scenes/{name}.toml"))).expect("scene loads");
    scene.apply_overrides(&overrides, "test").expect("valid overrides");
    scene
}

/// The Cornell box at `size` x `size` with these render settings.
pub fn cornell(size: u32, spp: u32, bounces: Bounces, sampling: Sampling, seed: u32) -> Scene {
    scene(
        "cornell",
        Overrides {
            width: Some(size),
            height: Some(size),
            spp: Some(spp),
            bounces: Some(bounces),
            seed: Some(seed),
            sampling: Some(sampling),
            sequence: None,
        },
    )
}

pub fn small(width: u32, height: u32, spp: u32) -> Overrides {
    Overrides { width: Some(width), height: Some(height), spp: Some(spp), ..Default::default() }
}

/// Renders `scene` to its own spp and returns the tracer (for the accumulator's statistics).
pub fn render(scene: &Scene) -> PathTracer {
    let mut tracer = PathTracer::new(gpu(), scene).expect("path tracer builds");
    // One pass of all the samples: `render` would size its passes by measured speed, which
    // tests running in parallel change, and the grouping of samples into f32 chunk sums with
    // it; a test comparing two renders bit for bit needs the same grouping every time.
    tracer.add_samples_in_one_pass(scene.pathtrace.spp).expect("render succeeds");
    tracer
}

/// Mean over all pixels of the per-pixel means, and the variance of that mean (the pixels are
/// independent, so the variances of their means add, divided by N^2).
pub fn image_mean_and_variance(tracer: &PathTracer, channel: usize) -> (f64, f64) {
    let acc = tracer.accumulator();
    let n = (acc.width * acc.height) as usize;
    let mut mean = 0.0;
    let mut variance = 0.0;
    for p in 0..n {
        mean += acc.pixel_mean(p)[channel];
        variance += acc.pixel_variance_of_mean(p)[channel];
    }
    (mean / n as f64, variance / (n * n) as f64)
}

pub fn assert_all_finite(image: &RgbImage32, what: &str) {
    assert!(!image.has_non_finite(), "{what}: the image contains NaN or Inf");
}
