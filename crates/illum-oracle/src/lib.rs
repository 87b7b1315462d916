//! illum-oracle: an independent, scalar CPU reference for illum's renderers, in f64.
//!
//! It estimates the same per-pixel quantity as the GPU path tracer (`crates/illum-pathtrace/shaders/`) —
//! equal in expectation, not sample for sample — from its own mathematics and its own random
//! numbers, so that tests and the convergence tool can compare the two statistically. It is
//! slow and simple on purpose: no acceleration structure, no SIMD, one ray at a time.
//!
//! It also holds [`whitted`], Whitted's deterministic 1980 algorithm in f64, the reference a GPU
//! Whitted ray tracer is to match pixel by pixel (its module documentation states the model).
//!
//! What is estimated (see `integrator.rs` for the derivation):
//! - pinhole camera, rays jittered uniformly inside each pixel (`camera.rs`);
//! - boxes (rotated about +Y), parallelograms and spheres; Lambertian (constant or checker,
//!   two-sided), smooth mirrors (weight = reflectance) and smooth dielectrics (reflect with the
//!   exact Fresnel probability, else refract; no eta^2 scaling, as every light and diffuse
//!   surface is outside);
//! - emitting parallelograms, one-sided (front = edge_u x edge_v), seen directly only by camera
//!   and specular rays, winning ties against a coplanar surface;
//! - a directional light: delta (next-event estimation along its direction) or a sun disc
//!   (next-event estimation uniform in its cone, and seen directly by camera and specular rays
//!   only); a constant environment seen by every escaping ray (no next-event estimation, so no
//!   double counting). Light that a delta light sends through glass onto a diffuse surface
//!   (the caustic, paths L S+ D E) is found by a second estimator with `caustics = true`:
//!   light tracing from the sun, paired sample by sample with the camera paths (`caustic.rs`),
//!   or instead, with `Oracle::with_manifold`, by manifold next-event estimation through one
//!   sphere, exact and without random numbers (`manifold.rs`; docs/caustics-manifold.md);
//! - next-event estimation at every diffuse hit with a point uniform on the union of the lights
//!   by area; `Bounces::Fixed(n)` continuation rays (specular ones count) or unbounded with
//!   Russian roulette; cosine or uniform hemisphere sampling (`Sampling`).
//!
//! Random numbers: SplitMix64 (`rng.rs`) keyed by (seed, pixel, sample), so results do not
//! depend on threading or on how samples are grouped.
//!
//! ```
//! let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/cornell.toml");
//! let mut scene = illum_scene::Scene::load(std::path::Path::new(path)).unwrap();
//! scene.camera.width = 4;
//! scene.camera.height = 4;
//! let image = illum_oracle::render(&scene, 2, 0).unwrap();
//! assert_eq!(image.mean.len(), 16);
//! ```
//!
//! Beside the oracle, the statistical tools every test uses, as library code: Pearson's
//! chi-square test ([`chi_square`]) and direct light in closed form ([`closed_form`]: Lambert's
//! polygon formula and an empty room lit through its ceiling).

mod camera;
pub mod caustic;
pub mod chi_square;
pub mod closed_form;
pub mod gather;
pub mod geometry;
pub mod glint;
mod integrator;
pub mod manifold;
pub mod manifold_chain;
#[cfg(test)]
mod manifold_flux;
mod manifold_oracle;
#[cfg(test)]
mod manifold_roots;
pub mod optics;
mod parallel;
mod particle_source;
mod render;
mod rng;
mod sampling;
pub mod scene;
pub mod whitted;
pub mod whitted_agreement;

pub use camera::PinholeCamera;
pub use integrator::Oracle;
pub use manifold::{ManifoldPath, ManifoldSettings};
pub use manifold_chain::Chain;
pub use render::{OracleImage, PixelEstimate};
pub use rng::Rng;
pub use whitted::WhittedOracle;

use illum_scene::{Scene, SceneError};

/// Renders `scene` at its camera's resolution with `spp` samples per pixel under `seed`, using
/// `scene.pathtrace.bounces` and `scene.pathtrace.sampling`, on all available cores. Errors
/// name the feature of the scene the oracle does not implement.
///
/// # Panics
/// If `spp` is 0.
pub fn render(scene: &Scene, spp: u32, seed: u64) -> Result<OracleImage, SceneError> {
    Ok(Oracle::new(scene)?.render(spp, seed, default_threads()))
}

/// The estimate of one pixel: exactly the value [`render`] produces for it with the same
/// `spp` and `seed`.
///
/// # Panics
/// If `spp` is 0.
pub fn radiance_at_pixel(
    scene: &Scene,
    x: u32,
    y: u32,
    spp: u32,
    seed: u64,
) -> Result<PixelEstimate, SceneError> {
    Ok(Oracle::new(scene)?.pixel(x, y, spp, seed))
}

/// The number of threads [`render`] uses: `std::thread::available_parallelism`, or 1.
pub fn default_threads() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}
