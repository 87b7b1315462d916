//! The hierarchies' buffers (bvh.rs), and the smooth meshes' shading normals (mesh_shading.rs),
//! bound as group 1 of a pipeline whose traversal walks a hierarchy or whose shading reads the
//! normals; a pipeline for a scene with neither has no group 1.

use illum_gpu::wgpu;
use illum_scene::{Scene, SceneError, Shape};
use wgpu::util::DeviceExt;

use crate::traversal::Geometry;

/// Group 1: a mesh's nodes (binding 0) and triangles (1) in storage buffers (bvh.wgsl); the
/// spheres' nodes (2) and spheres (3) in uniform buffers (sphere_bvh.rs says why); the smooth
/// meshes' shading normals (4) in a storage buffer (mesh_shading.wgsl). Each buffer is bound
/// only when the scene has it, as the shader reads only those (and a pipeline's automatic layout
/// holds only what it reads).
pub struct BvhBindGroup {
    bind_group: wgpu::BindGroup,
}

/// How a buffer is bound.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Storage,
    Uniform,
}

/// The buffers of `scene`, whose traversal is generated from `geometry`: (binding, label, kind,
/// bytes).
fn contents(scene: &Scene, geometry: &Geometry) -> Vec<(u32, &'static str, Kind, Vec<u8>)> {
    let mut out = Vec::new();
    if let Some(bvh) = geometry.mesh_bvh() {
        out.push((0, "bvh nodes", Kind::Storage, bytemuck::cast_slice(&bvh.nodes).to_vec()));
        out.push((1, "mesh triangles", Kind::Storage, bytemuck::cast_slice(&bvh.triangles).to_vec()));
    }
    if let Some(spheres) = &geometry.spheres {
        out.push((2, "sphere bvh nodes", Kind::Uniform, bytemuck::cast_slice(&spheres.nodes).to_vec()));
        out.push((3, "bvh spheres", Kind::Uniform, bytemuck::cast_slice(&spheres.spheres()).to_vec()));
    }
    if let Some(normals) = crate::mesh_shading::shading_normals(scene) {
        out.push((4, "mesh shading normals", Kind::Storage, bytemuck::cast_slice(&normals).to_vec()));
    }
    out
}

impl BvhBindGroup {
    /// The bind group index the hierarchies' buffers take.
    pub const GROUP: u32 = 1;
    /// The variables of group 1 (bvh.wgsl's, the spheres' uniform buffers that the generated
    /// traversal declares with the scene's sizes, and mesh_shading.wgsl's) and their bindings.
    pub const BINDINGS: [(&'static str, u32); 5] =
        [("bvh_nodes", 0), ("mesh_triangles", 1), ("sphere_nodes", 2), ("spheres", 3), ("mesh_normals", 4)];

    /// Uploads `scene`'s hierarchies (from `geometry`) and shading normals and binds them to
    /// `pipeline`'s group 1 (which its shader, specialised for this scene, declares); `None`
    /// when it has none.
    pub fn new(
        device: &wgpu::Device,
        pipeline: &wgpu::ComputePipeline,
        scene: &Scene,
        geometry: &Geometry,
    ) -> Option<Self> {
        let contents = contents(scene, geometry);
        if contents.is_empty() {
            return None;
        }
        let buffers: Vec<(u32, wgpu::Buffer)> = contents
            .into_iter()
            .map(|(binding, label, kind, bytes)| {
                let buffer = match kind {
                    Kind::Storage => illum_gpu::buffers::storage_buffer(device, label, &bytes),
                    Kind::Uniform => device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some(label),
                        contents: &bytes,
                        usage: wgpu::BufferUsages::UNIFORM,
                    }),
                };
                (binding, buffer)
            })
            .collect();
        let entries: Vec<(u32, &wgpu::Buffer)> =
            buffers.iter().map(|(binding, buffer)| (*binding, buffer)).collect();
        let bind_group = illum_gpu::buffers::buffer_bind_group(
            device,
            "bvh",
            &pipeline.get_bind_group_layout(Self::GROUP),
            &entries,
        );
        Some(BvhBindGroup { bind_group })
    }

    /// The bytes the group's buffers take on the device.
    pub fn bytes(scene: &Scene, geometry: &Geometry) -> u64 {
        contents(scene, geometry).iter().map(|(_, _, _, bytes)| bytes.len() as u64).sum()
    }

    /// Refuses hierarchies one of whose buffers exceeds the device's limit for its binding
    /// (`storage`: max_storage_buffer_binding_size, `uniform`: max_uniform_buffer_binding_size),
    /// with the bytes it needs.
    pub fn check_size(
        scene: &Scene,
        geometry: &Geometry,
        storage: u64,
        uniform: u64,
    ) -> Result<(), SceneError> {
        for (_, label, kind, bytes) in contents(scene, geometry) {
            let (limit, name) = match kind {
                Kind::Storage => (storage, "max_storage_buffer_binding_size"),
                Kind::Uniform => (uniform, "max_uniform_buffer_binding_size"),
            };
            let needed = bytes.len() as u64;
            if needed <= limit {
                continue;
            }
            let (field, value) = match (geometry.mesh_bvh(), &geometry.spheres) {
                (_, Some(spheres)) if label.contains("sphere") => (
                    "objects (spheres)",
                    format!("{} spheres ({needed} bytes of {label})", spheres.records.len()),
                ),
                (Some(bvh), _) if !label.contains("normals") => (
                    "objects (meshes)",
                    format!("{} triangles ({needed} bytes of {label})", bvh.triangles.len()),
                ),
                _ if label.contains("normals") => {
                    let triangles: usize = scene
                        .objects
                        .iter()
                        .map(|o| match &o.shape {
                            Shape::Mesh(m) => m.triangles.len(),
                            _ => 0,
                        })
                        .sum();
                    ("objects (meshes)", format!("{triangles} triangles ({needed} bytes of {label})"))
                }
                _ => ("objects", format!("{needed} bytes of {label}")),
            };
            return Err(SceneError::invalid(
                &scene.source,
                field,
                value,
                format!("each buffer must fit in {limit} bytes, the device's {name}"),
            ));
        }
        Ok(())
    }

    /// Binds the buffers in `pass`.
    pub fn set(&self, pass: &mut wgpu::ComputePass<'_>) {
        pass.set_bind_group(Self::GROUP, &self.bind_group, &[]);
    }
}
