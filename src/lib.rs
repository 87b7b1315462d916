//! illum: a Rust + wgpu renderer for the two scenes of an illumination assignment.
//!
//! This facade re-exports the workspace crates so that `examples/` and `tests/` can use one name,
//! and holds the command-line pieces the examples share ([`cli`], [`interrupt`], [`progress`], and
//! each renderer's path of the render example: [`raster_cli`], [`whitted_cli`]), and what the
//! measuring tools share: the cached [`reference`](mod@reference), [`plot`]s, [`report`] tables and the
//! ladder's [`regions`] and errors.
pub mod cli;
pub mod interrupt;
pub mod plot;
pub mod progress;
pub mod raster_cli;
pub mod reference;
pub mod regions;
pub mod report;
pub mod whitted_cli;

pub use illum_gpu as gpu;
pub use illum_image as image;
pub use illum_pathtrace as pathtrace;
pub use illum_raster as raster;
pub use illum_rtcore as rtcore;
pub use illum_scene as scene;
pub use illum_whitted as whitted;
