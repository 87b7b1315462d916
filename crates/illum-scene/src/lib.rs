//! illum-scene: one physical scene description for every renderer, its TOML file format,
//! validation, and camera math.
//!
//! A scene file is parsed into the raw structs of `file.rs` (which mirror the TOML one to one
//! and reject unknown keys), then checked and converted by `validate` into the [`Scene`] the
//! renderers consume. Every error names the file, the field, the offending value and what would
//! have been allowed (see [`SceneError`]).
//!
//! Positions are read in f64 and, for a scene farther than its own size from the world origin,
//! measured from the camera's eye before they are rounded to the f32 the renderers use
//! ([`Scene::origin`], `frame.rs`): the image does not depend on where the scene sits.
//!
//! The modules follow the scene's concepts: [`Camera`] (`camera.rs`), shapes (`shapes.rs`),
//! triangle meshes (`mesh.rs`, read from OBJ files by `mesh_obj.rs`, checked by `validate_mesh.rs`),
//! materials (`materials.rs`), lights (`lights.rs`; area lights are emitting quads), the
//! per-renderer sections (`renderers.rs`), what a renderer must implement to render a scene
//! (`features.rs`), and the scene's identity, a hash of its content over versioned canonical
//! bytes ([`Scene::content_hash`], `content_hash.rs`).
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
//! assert_eq!(scene.pathtrace.spp, 16);
//! ```

mod camera;
mod content_hash;
mod error;
mod features;
mod file;
mod frame;
mod lights;
mod load;
mod materials;
mod mesh;
mod mesh_file;
mod mesh_load;
mod mesh_obj;
mod mesh_ply;
mod paths;
mod renderers;
mod scene;
mod settings;
mod shapes;
pub mod specular_spheres;
mod spelling;
#[cfg(any(test, feature = "testing"))]
pub mod testing;
mod validate;
mod validate_materials;
mod validate_mesh;
mod validate_objects;
mod validate_sections;

pub use camera::{Camera, CameraBasis, ClipPlanes};
pub use content_hash::{CONTENT_TAG, CONTENT_VERSION, fnv1a_64};
pub use error::{ParseValueError, SceneError};
pub use features::{Feature, FeatureSet};
pub use lights::{DirectionalLight, Environment};
pub use materials::{Checker, Material, MaterialKind};
pub use mesh::{MeshPlacement, MeshRef, TriangleMesh};
pub use mesh_load::ReadFile;
pub use paths::resolve_scene_path;
pub use renderers::{
    Bounces, CausticMethod, DenoiserKind, DielectricShading, Effects, Look, MAX_BOUNCES, MAX_WHITTED_AA,
    MAX_WHITTED_DEPTH, MirrorShading, PathTraceSettings, RasterSettings, RendererKind, Sampling, Sequence,
    Shading, WhittedSettings,
};
pub use scene::{Object, Overrides, Scene};
pub use shapes::{BoxShape, Quad, Shape, Sphere};
pub use spelling::{fmt_f32, toml_key};
