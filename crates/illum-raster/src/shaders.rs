//! The rasterizer's WGSL: three composable modules and four entry files in `shaders/`.
//!
//! Every entry file is composed with [`MODULES`] (see [`compose`]), and imports nothing else;
//! the naga validation test below walks [`SHADERS`] the same way.

use illum_gpu::GpuError;
use illum_gpu::shader::{self, ShaderFile};

/// Uniform layout and helpers shared by every raster pass (`illum::raster::scene`).
pub const SCENE_MODULE: ShaderFile = illum_gpu::shader_file!("shaders/scene.wgsl");
/// Sphere impostors: billboards, ray-sphere tests, silhouette coverage (`illum::raster::sphere`).
pub const SPHERE_MODULE: ShaderFile = illum_gpu::shader_file!("shaders/sphere.wgsl");
/// Shadows, the filtered checker, cube-map lookups and the two looks (`illum::raster::lighting`).
pub const LIGHTING_MODULE: ShaderFile = illum_gpu::shader_file!("shaders/lighting.wgsl");

/// The raster modules, in dependency order (each imports only those before it).
pub const MODULES: &[ShaderFile] = &[SCENE_MODULE, SPHERE_MODULE, LIGHTING_MODULE];

/// The modules every entry file is composed with: [`MODULES`].
pub fn modules() -> Vec<ShaderFile> {
    MODULES.to_vec()
}

/// The shadow pass: sphere depth from the light (`vs_main`, `fs_main`).
pub const SHADOW_SHADER: ShaderFile = illum_gpu::shader_file!("shaders/shadow.wgsl");
/// The checkerboard floor (`vs_main`, `fs_main`).
pub const FLOOR_SHADER: ShaderFile = illum_gpu::shader_file!("shaders/floor.wgsl");
/// The glass and metal spheres (`vs_main`, `fs_main`).
pub const SPHERES_SHADER: ShaderFile = illum_gpu::shader_file!("shaders/spheres.wgsl");
/// The triangle meshes (`vs_main`, `fs_main`).
pub const MESH_SHADER: ShaderFile = illum_gpu::shader_file!("shaders/mesh.wgsl");

/// The entry files, each composed with [`MODULES`].
pub const SHADERS: &[ShaderFile] = &[SHADOW_SHADER, FLOOR_SHADER, SPHERES_SHADER, MESH_SHADER];

/// Composes one of [`SHADERS`] into a naga module (validated by naga_oil's composer).
pub fn compose(entry: &ShaderFile) -> Result<naga::Module, GpuError> {
    shader::compose(&modules(), entry, &[])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_entry_composes_and_validates() {
        for entry in SHADERS {
            let module = compose(entry).unwrap_or_else(|e| panic!("{e}"));
            shader::validate(&module, &entry.path).unwrap_or_else(|e| panic!("{e}"));
            for stage in ["vs_main", "fs_main"] {
                assert!(module.entry_points.iter().any(|e| e.name == stage), "{}: no {stage}", entry.path);
            }
        }
    }
}
