//! What a mesh file's parser (`mesh_obj.rs`, `mesh_ply.rs`) gives `mesh_load.rs`.

/// A mesh as its file gives it, in the file's own coordinates: every index in range, every
/// position and normal finite, at least one triangle.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct FileMesh {
    pub positions: Vec<[f32; 3]>,
    /// One normal per position, when the file gives every vertex one.
    pub normals: Option<Vec<[f32; 3]>>,
    pub triangles: Vec<[u32; 3]>,
}
