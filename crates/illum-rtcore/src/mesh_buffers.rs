//! The mesh's storage buffers, bound as group 1: the BVH's (bvh.rs, bvh.wgsl), for a scene with
//! more mesh triangles than its traversal writes as literals, and the shading normals
//! (mesh_shading.rs, mesh_shading.wgsl), for a scene with a smooth mesh. A pipeline for a scene
//! with neither has no group 1.

use illum_gpu::wgpu;
use illum_scene::{Scene, SceneError};

use crate::bvh::Bvh;
use crate::traversal::Geometry;

/// What group 1 holds for one scene.
pub struct MeshBuffers<'a> {
    pub bvh: Option<&'a Bvh>,
    /// [`crate::mesh_shading::shading_normals`].
    pub normals: Option<Vec<f32>>,
}

impl<'a> MeshBuffers<'a> {
    /// The buffers of `scene`, whose traversal is generated from `geometry`.
    pub fn of(scene: &Scene, geometry: &'a Geometry) -> Self {
        MeshBuffers { bvh: geometry.bvh(), normals: crate::mesh_shading::shading_normals(scene) }
    }

    /// Each buffer's name and its bytes.
    fn sizes(&self) -> Vec<(&'static str, u64)> {
        let mut sizes = Vec::new();
        if let Some(bvh) = self.bvh {
            sizes.push(("BVH nodes", std::mem::size_of_val(bvh.nodes.as_slice()) as u64));
            sizes.push(("triangles", std::mem::size_of_val(bvh.triangles.as_slice()) as u64));
        }
        if let Some(normals) = &self.normals {
            sizes.push(("shading normals", std::mem::size_of_val(normals.as_slice()) as u64));
        }
        sizes
    }

    /// The bytes the buffers take on the device.
    pub fn bytes(&self) -> u64 {
        self.sizes().iter().map(|(_, b)| b).sum()
    }

    /// Refuses buffers one of which exceeds `limit` bytes, the device's
    /// max_storage_buffer_binding_size, with the bytes each needs.
    pub fn check_size(&self, scene: &Scene, limit: u64) -> Result<(), SceneError> {
        let sizes = self.sizes();
        if sizes.iter().all(|&(_, bytes)| bytes <= limit) {
            return Ok(());
        }
        let triangles: usize = scene
            .objects
            .iter()
            .map(|o| match &o.shape {
                illum_scene::Shape::Mesh(m) => m.triangles.len(),
                _ => 0,
            })
            .sum();
        let each: Vec<String> =
            sizes.iter().map(|(name, bytes)| format!("{bytes} bytes of {name}")).collect();
        Err(SceneError::invalid(
            &scene.source,
            "objects (meshes)",
            format!("{triangles} triangles ({})", each.join(", ")),
            format!("each buffer must fit in {limit} bytes, the device's max_storage_buffer_binding_size"),
        ))
    }
}

/// Group 1 of one pipeline: the BVH's nodes at binding 0 and triangles at binding 1 (bvh.wgsl),
/// the shading normals at binding 2 (mesh_shading.wgsl).
pub struct MeshBindGroup {
    bind_group: wgpu::BindGroup,
}

impl MeshBindGroup {
    /// The bind group index the mesh's buffers take.
    pub const GROUP: u32 = 1;
    /// The variables of group 1 in bvh.wgsl and mesh_shading.wgsl, and their bindings.
    pub const BINDINGS: [(&'static str, u32); 3] =
        [("bvh_nodes", 0), ("mesh_triangles", 1), ("mesh_normals", 2)];

    /// Uploads `buffers` and binds them to `pipeline`'s group 1, whose shader must read each of
    /// them (an automatic layout holds only what the shader reads); `None` when there are none.
    pub fn new(
        device: &wgpu::Device,
        pipeline: &wgpu::ComputePipeline,
        buffers: &MeshBuffers<'_>,
    ) -> Option<Self> {
        let storage = |label: &str, bytes: &[u8]| illum_gpu::buffers::storage_buffer(device, label, bytes);
        let mut bound = Vec::new();
        if let Some(bvh) = buffers.bvh {
            bound.push((Self::BINDINGS[0].1, storage("bvh nodes", bytemuck::cast_slice(&bvh.nodes))));
            bound
                .push((Self::BINDINGS[1].1, storage("mesh triangles", bytemuck::cast_slice(&bvh.triangles))));
        }
        if let Some(normals) = &buffers.normals {
            bound.push((Self::BINDINGS[2].1, storage("mesh shading normals", bytemuck::cast_slice(normals))));
        }
        if bound.is_empty() {
            return None;
        }
        let entries: Vec<(u32, &wgpu::Buffer)> =
            bound.iter().map(|(binding, buffer)| (*binding, buffer)).collect();
        let bind_group = illum_gpu::buffers::buffer_bind_group(
            device,
            "mesh",
            &pipeline.get_bind_group_layout(Self::GROUP),
            &entries,
        );
        Some(MeshBindGroup { bind_group })
    }

    /// Binds the buffers in `pass`.
    pub fn set(&self, pass: &mut wgpu::ComputePass<'_>) {
        pass.set_bind_group(Self::GROUP, &self.bind_group, &[]);
    }
}
