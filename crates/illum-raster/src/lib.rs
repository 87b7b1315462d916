//! illum-raster: the rasterizer, which fakes the look of Whitted's scene (the assignment's task
//! 1), drawn with wgpu render pipelines only.
//!
//! Each frame ([`frame`] has the order and why):
//! - a **shadow map** from the directional light, fitted to the spheres ([`shadow_fit`]), read
//!   with percentage-closer filtering for soft edges;
//! - a **cube map** captured at the glass sphere's centre (six faces, without the glass), which
//!   the glass refracts; in the enhanced look a second one at the metal sphere's centre, which
//!   the metal mirrors ([`views`] has the face conventions);
//! - only the passes the scene needs: no shadow map for a light that casts no shadows, no cube
//!   map for a sphere the scene lacks or that mirrors nothing ([`plan`]);
//! - the **main pass** at one sample per pixel: the procedural checkerboard floor, anti-aliased
//!   by an exact filter over each pixel's footprint, then the triangle meshes from a vertex
//!   buffer ([`mesh`]; Lambertian, smooth or flat, casting and receiving shadows and seen in the
//!   cube maps; their edges are not anti-aliased), then the spheres back to front as analytic
//!   impostors that write their true depth, so silhouettes are round at any size. With
//!   anti-aliasing on, the floor's outline and each silhouette are blended over what is behind by
//!   the exact fraction of the pixel they cover (docs/performance-raster.md has the measured
//!   difference from 4x MSAA and from 16x supersampling).
//!
//! Two looks ([`Look`]): `Figure` reproduces the assignment's figure 1, `Enhanced` adds what a
//! rasterizer can of a Whitted ray tracer's image. Every effect is a toggle ([`Effects`]).
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use illum_raster::{Options, RasterRenderer};
//! let gpu = illum_gpu::GpuContext::new()?;
//! let scene = illum_raster::RasterScene::load("scenes/whitted.toml".as_ref())?;
//! let mut renderer = RasterRenderer::new(&gpu, &scene, 640, 360)?;
//! let image = renderer.render(&Options::from_scene(&scene))?;
//! illum_image::save_png("whitted.png", &image, 0.0, illum_image::Encoding::Linear)?;
//! # Ok(()) }
//! ```
//!
//! The WGSL lives in the crate's `shaders/` ([`shaders`]).

// Times frames until the GPU has finished them, which only a native program can wait for.
#[cfg(not(target_arch = "wasm32"))]
mod bench;
mod bindings;
mod error;
pub mod frame;
pub mod limits;
pub mod mesh;
pub mod metadata;
mod options;
mod pass_times;
mod pipelines;
pub mod plan;
mod renderer;
pub mod scene;
pub mod shaders;
pub mod shadow_fit;
mod targets;
pub mod uniforms;
pub mod variants;
pub mod views;

#[cfg(not(target_arch = "wasm32"))]
pub use bench::{BenchReport, Motion, bench_frames, reduced_cube_error};
pub use error::RasterError;
pub use illum_scene::{Effects, Look};
pub use limits::check_device_limits;
pub use options::Options;
pub use pass_times::{Frame, PassTimes};
pub use plan::FramePlan;
pub use renderer::{MIN_MOVING_CUBE_SIZE, PendingFrame, RasterRenderer, moving_cube_size};
pub use scene::{
    CheckerFloor, GlassSphere, MetalSphere, RasterLight, RasterMesh, RasterQuality, RasterScene,
};
pub use shaders::{MODULES, SHADERS};
