//! illum-whitted: Whitted's 1980 ray tracer as a WGSL compute pipeline.
//!
//! At each hit point, with the scene's `[shading]` parameters (the rasterizer's enhanced look
//! uses the same local model): ambient x colour; colour x N.L and a Blinn-Phong highlight where
//! a hard shadow ray reaches a light (every object blocks it, glass and mirror included); for a
//! mirror, the reflected ray weighted by the mirror weight and tinted by its reflectance; for a
//! dielectric, the reflected and refracted rays weighted by the exact unpolarised Fresnel
//! factor, everything reflected under total internal reflection; escaped rays see the
//! environment's radiance. Reflected and refracted rays are followed `[whitted] depth` times
//! (0 to 64); an n x n grid of rays per pixel (`[whitted] aa`) anti-aliases, so the image is
//! deterministic. An area light (the Cornell box's) is treated as a point light at its centre
//! with the quad's power pattern (radiance x area x cos theta); a sun of finite size is refused.
//!
//! The ray tree is walked with an explicit stack of as many entries as its depth
//! (`shaders/whitted.wgsl`).
//! The objects, materials, camera, optics and traversal are illum-rtcore's, shared with the
//! path tracer: one copy.
//! `illum_oracle::whitted` is the independent f64 copy of the algorithm the tests compare with.
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let gpu = illum_gpu::GpuContext::new()?;
//! let scene = illum_scene::Scene::load("scenes/whitted.toml".as_ref())?;
//! let image = illum_whitted::WhittedTracer::new(&gpu, &scene)?.render()?;
//! # Ok(()) }
//! ```

mod encode;
pub mod metadata;
mod tracer;

pub use encode::{Specialisation, implements};
pub use tracer::{
    ObjectIds, PendingImage, PendingObjectIds, Shadow, WHITTED_SHADER, WhittedError, WhittedTracer,
    shader_defs, shader_modules,
};
