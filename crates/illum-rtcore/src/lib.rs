//! illum-rtcore: what illum's two compute ray tracers, the path tracer and the Whitted ray
//! tracer, share and neither owns.
//!
//! - [`object`]: the objects as the shaders store them (one record layout for every kind of
//!   shape), in the order both use (emitters last);
//! - [`bvh`]: the hierarchy's builder, over a scene's mesh triangles or its small analytic
//!   objects (only a scene with a mesh, or with more of those than
//!   [`analytic_bvh::LITERAL_OBJECTS`], has one);
//! - [`mesh_shading`]: the shading normals of smooth meshes (`shaders/mesh_shading.wgsl` holds
//!   the rules they follow);
//! - [`material`]: the one material record and its kind codes;
//! - [`camera`]: the pinhole camera's record;
//! - [`spawn`]: where a ray leaving a surface starts, with its error bound (the CPU mirror of
//!   `shaders/spawn.wgsl`);
//! - [`traversal`]: `closest_hit`, `occluded` and `surface_at` generated per scene, with the
//!   scene's numbers as literals;
//! - [`shaders`]: the WGSL modules (`shaders/`): geometry, optics (Fresnel, refraction, the
//!   checkerboard), the camera, and the kind codes generated from the Rust enums.
//!
//! Each renderer keeps its own lights, parameters, errors and entry shader.

pub mod analytic_bvh;
pub mod bvh;
pub mod bvh_buffers;
mod bvh_traversal;
pub mod camera;
pub mod literal;
pub mod material;
pub mod mesh_shading;
pub mod mesh_traversal;
pub mod object;
pub mod scene_geometry;
pub mod shaders;
pub mod spawn;
pub mod traversal;

pub use bvh_buffers::BvhBindGroup;
pub use camera::CameraRecord;
pub use material::{MaterialCode, MaterialRecord, materials_module};
pub use object::{GpuObject, GpuShape, ObjectRecord, ShapeKind, gpu_shape, ordered_objects};
pub use traversal::{Geometry, Traversal};
