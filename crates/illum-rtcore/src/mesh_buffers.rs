//! The BVH's storage buffers (bvh.rs), bound as group 1 of a pipeline whose traversal has a
//! BVH; a pipeline for a scene without a mesh has no group 1.

use illum_gpu::wgpu;
use illum_scene::{Scene, SceneError};

use crate::bvh::Bvh;

/// Group 1: the nodes at binding 0, the triangles at binding 1 (bvh.wgsl).
pub struct MeshBindGroup {
    bind_group: wgpu::BindGroup,
}

impl MeshBindGroup {
    /// The bind group index the BVH's buffers take.
    pub const GROUP: u32 = 1;
    /// The variables of group 1 in bvh.wgsl and their bindings.
    pub const BINDINGS: [(&'static str, u32); 2] = [("bvh_nodes", 0), ("mesh_triangles", 1)];

    /// Uploads `bvh` and binds it to `pipeline`'s group 1 (which its shader must declare).
    pub fn new(device: &wgpu::Device, pipeline: &wgpu::ComputePipeline, bvh: &Bvh) -> Self {
        let nodes = illum_gpu::buffers::storage_buffer(device, "bvh nodes", bytemuck::cast_slice(&bvh.nodes));
        let triangles = illum_gpu::buffers::storage_buffer(
            device,
            "mesh triangles",
            bytemuck::cast_slice(&bvh.triangles),
        );
        let bind_group = illum_gpu::buffers::buffer_bind_group(
            device,
            "bvh",
            &pipeline.get_bind_group_layout(Self::GROUP),
            &[(Self::BINDINGS[0].1, &nodes), (Self::BINDINGS[1].1, &triangles)],
        );
        MeshBindGroup { bind_group }
    }

    /// The bytes the BVH takes on the device: nodes and triangles.
    pub fn bytes(bvh: &Bvh) -> u64 {
        (std::mem::size_of_val(bvh.nodes.as_slice()) + std::mem::size_of_val(bvh.triangles.as_slice())) as u64
    }

    /// Refuses a BVH one of whose buffers exceeds `limit` bytes, the device's
    /// max_storage_buffer_binding_size, with the bytes it needs.
    pub fn check_size(scene: &Scene, bvh: &Bvh, limit: u64) -> Result<(), SceneError> {
        let nodes = std::mem::size_of_val(bvh.nodes.as_slice()) as u64;
        let triangles = std::mem::size_of_val(bvh.triangles.as_slice()) as u64;
        if nodes.max(triangles) <= limit {
            return Ok(());
        }
        Err(SceneError::invalid(
            &scene.source,
            "objects (meshes)",
            format!(
                "{} triangles ({triangles} bytes of triangles, {nodes} bytes of BVH nodes)",
                bvh.triangles.len()
            ),
            format!("each buffer must fit in {limit} bytes, the device's max_storage_buffer_binding_size"),
        ))
    }

    /// Binds the buffers in `pass`.
    pub fn set(&self, pass: &mut wgpu::ComputePass<'_>) {
        pass.set_bind_group(Self::GROUP, &self.bind_group, &[]);
    }
}
