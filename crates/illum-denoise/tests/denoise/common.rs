//! Scenes, renders and the checked-in converged Cornell box.

use illum_gpu::testing::workspace_path;
use illum_image::{RgbImage32, load_exr};
use illum_pathtrace::PathTracer;
use illum_scene::{Bounces, Overrides, Scene};

pub use illum_gpu::testing::gpu;

/// Size and bounces of illum-pathtrace's checked-in reference (16384 spp, seed 1000).
pub const SIZE: u32 = 64;
pub const BOUNCES: u32 = 2;

/// The Cornell box at SIZE x SIZE, BOUNCES bounces, `spp`, `seed`.
pub fn cornell(spp: u32, seed: u32) -> Scene {
    cornell_sized(SIZE, spp, seed)
}

/// The Cornell box at `size` x `size`, BOUNCES bounces, `spp`, `seed`.
pub fn cornell_sized(size: u32, spp: u32, seed: u32) -> Scene {
    let mut scene = Scene::load(&workspace_path("scenes/cornell.toml")).expect("scene loads");
    let overrides = Overrides {
        width: Some(size),
        height: Some(size),
        spp: Some(spp),
        seed: Some(seed),
        bounces: Some(Bounces::Fixed(BOUNCES)),
        ..Default::default()
    };
    scene.apply_overrides(&overrides, "test").expect("valid overrides");
    scene
}

/// The converged Cornell box (mean, variance of the mean) of illum-pathtrace's reference test.
pub fn reference() -> (RgbImage32, RgbImage32) {
    let dir = "crates/illum-pathtrace/tests/reference";
    let load = |what: &str| {
        load_exr(workspace_path(&format!("{dir}/cornell-{SIZE}-b{BOUNCES}-{what}.exr")))
            .expect("illum-pathtrace's reference exists")
            .0
    };
    (load("mean"), load("variance"))
}

/// `scene` rendered to its spp in one pass.
pub fn render(scene: &Scene) -> PathTracer {
    let mut tracer = PathTracer::new(gpu(), scene).expect("path tracer builds");
    tracer.add_samples_in_one_pass(scene.pathtrace.spp).expect("render succeeds");
    tracer
}

/// relMSE of `image` against the reference, less the reference's own contribution
/// (E (x - R)^2 = (x - I)^2 + Var R for R unbiased and independent of x).
pub fn true_rel_mse(image: &RgbImage32, reference: &RgbImage32, reference_variance: &RgbImage32) -> f64 {
    let mut total = 0.0;
    for ((x, r), v) in image.pixels.iter().zip(&reference.pixels).zip(&reference_variance.pixels) {
        for c in 0..3 {
            let (x, r, v) = (f64::from(x[c]), f64::from(r[c]), f64::from(v[c]));
            total += ((x - r).powi(2) - v) / (r * r + illum_image::metrics::REL_MSE_EPSILON);
        }
    }
    total / (3 * image.pixels.len()) as f64
}

/// The Whitted scene at `width` x `height` with every caustic estimator, `spp`, `seed`.
pub fn whitted(width: u32, height: u32, spp: u32, seed: u32) -> Scene {
    let mut scene = Scene::load(&workspace_path("scenes/whitted.toml")).expect("scene loads");
    let overrides = Overrides {
        width: Some(width),
        height: Some(height),
        spp: Some(spp),
        seed: Some(seed),
        ..Default::default()
    };
    scene.apply_overrides(&overrides, "test").expect("valid overrides");
    scene
}

/// The Whitted scene's truth at `width` x `height` (mean, variance of the mean): `spp` samples
/// from index 0 with a seed of its own.
pub fn whitted_truth(width: u32, height: u32, spp: u32) -> (RgbImage32, RgbImage32) {
    let tracer = render(&whitted(width, height, spp, 9001));
    assert!(tracer.caustics(), "the light tracer and the gather run");
    (tracer.accumulator().mean_image(), tracer.accumulator().variance_image())
}
