//! The shading normals of a scene's smooth meshes, as `shaders/mesh_shading.wgsl` reads them
//! (that file states how they are interpolated and the rules a shading normal follows).

use illum_scene::{Scene, Shape};

/// The floats each triangle takes in the buffer: the unit normals at its corners a, b, c.
pub const FLOATS_PER_TRIANGLE: usize = 9;

/// The shading normals of every mesh triangle of `scene`, in scene order (object by object,
/// each mesh's triangles in its own order: the triangles' `order`, set by
/// [`MeshForm::of`](crate::mesh_traversal::MeshForm::of)), [`FLOATS_PER_TRIANGLE`] each;
/// zeros for a triangle of a flat mesh, which is shaded with its geometric normal. `None` when
/// no mesh of the scene is smooth: its pipelines read no shading normals.
pub fn shading_normals(scene: &Scene) -> Option<Vec<f32>> {
    let meshes: Vec<_> = scene
        .objects
        .iter()
        .filter_map(|o| match &o.shape {
            Shape::Mesh(mesh) => Some(mesh),
            _ => None,
        })
        .collect();
    if !meshes.iter().any(|m| m.smooth()) {
        return None;
    }
    let count: usize = meshes.iter().map(|m| m.triangles.len()).sum();
    let mut out = Vec::with_capacity(FLOATS_PER_TRIANGLE * count);
    for mesh in meshes {
        match &mesh.normals {
            Some(normals) => {
                for corners in &mesh.triangles {
                    for &v in corners {
                        out.extend(normals[v as usize].to_array());
                    }
                }
            }
            None => out.resize(out.len() + FLOATS_PER_TRIANGLE * mesh.triangles.len(), 0.0),
        }
    }
    Some(out)
}
