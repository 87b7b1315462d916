//! illum: a Rust + wgpu renderer for the two scenes of an illumination assignment.
//!
//! This facade re-exports the workspace's renderer crates under one name, for `examples/`, the
//! cross-renderer tests in `tests/` and anyone who links illum. The command-line front end the
//! examples share is `illum-cli`, the measuring tools' code `illum-lab`: neither is linked by
//! this crate.

pub use illum_gpu as gpu;
pub use illum_image as image;
pub use illum_pathtrace as pathtrace;
pub use illum_raster as raster;
pub use illum_rtcore as rtcore;
pub use illum_scene as scene;
pub use illum_whitted as whitted;
