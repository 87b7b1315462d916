//! illum-scene: the TOML scene format, its validation, and camera math.
//!
//! A scene file is parsed into the raw structs of `file.rs` (which mirror the TOML
//! one to one and reject unknown keys), then checked and converted by `validate` into the
//! [`Scene`] the renderers consume. Every error names the file, the field, the offending value
//! and what would have been allowed (see [`SceneError`]).
//!
//! ```
//! let text = r#"
//! [camera]
//! eye = [0.0, 0.0, -5.0]
//! target = [0.0, 0.0, 0.0]
//! up = [0.0, 1.0, 0.0]
//! vfov = 45.0
//! width = 64
//! height = 48
//! [materials.grey]
//! albedo = [0.5, 0.5, 0.5]
//! [[objects]]
//! material = "grey"
//! sphere = { center = [0.0, 0.0, 0.0], radius = 1.0 }
//! "#;
//! let scene = illum_scene::Scene::from_toml_str(text, "example.toml").unwrap();
//! assert_eq!(scene.name, "example");
//! assert_eq!(scene.render.spp, 16);
//! ```
//!
//! The same folder holds scenes for the Whitted look-alike rasterizer, marked with a top-level
//! `renderer = "raster"`: [`scene_kind`] tells the two formats apart, and [`WhittedScene`] loads
//! the rasterizer's (format in `whitted_file.rs`).

mod camera;
mod error;
mod file;
mod kind;
mod load;
mod settings;
mod types;
mod validate;
mod whitted;
mod whitted_file;
mod whitted_validate;

pub use error::{ParseValueError, SceneError};
pub use kind::{SceneKind, scene_kind};
pub use types::*;
pub use whitted::{
    AmbientLight, CheckerFloor, ClipPlanes, DirectionalLight, Effects, GlassSphere, Look, MetalSphere,
    RasterLimits, RasterQuality, WhittedScene,
};
