//! The scene's triangle meshes as one vertex buffer: three vertices per triangle (no index
//! buffer: each corner carries its triangle's own geometric normal), drawn by `shaders/mesh.wgsl`
//! in the cube maps and the main pass and by `shaders/shadow.wgsl`'s `vs_mesh` into the shadow
//! map.

use bytemuck::{Pod, Zeroable};
use illum_gpu::wgpu;
use illum_scene::SceneError;

use crate::scene::RasterScene;

/// One corner of a triangle, as `VertexIn` in mesh.wgsl reads it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct MeshVertex {
    pub position: [f32; 3],
    /// The unit shading normal at the corner: the file's vertex normal for a smooth mesh, the
    /// triangle's own normal for a flat one.
    pub normal: [f32; 3],
    /// The triangle's unit front normal, (b - a) x (c - a) normalised: it decides which side is
    /// seen and lit (illum-rtcore's mesh_shading.wgsl states the rules).
    pub face_normal: [f32; 3],
    /// The mesh's Lambertian albedo.
    pub albedo: [f32; 3],
}

impl MeshVertex {
    /// The fields at attribute locations 0..4, in order.
    const ATTRIBUTES: [wgpu::VertexAttribute; 4] =
        wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x3, 3 => Float32x3];

    /// The layout of the vertex buffer.
    pub const LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<MeshVertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &Self::ATTRIBUTES,
    };
}

/// The corners of every triangle of `scene`'s meshes, three per triangle, in file order.
pub fn mesh_vertices(scene: &RasterScene) -> Vec<MeshVertex> {
    let mut out = Vec::new();
    for raster_mesh in &scene.meshes {
        let mesh = &raster_mesh.mesh;
        for (i, corners) in mesh.triangles.iter().enumerate() {
            let [a, b, c] = mesh.triangle(i);
            // Validation keeps only triangles with a normal in f32.
            let face = (b - a).cross(c - a).normalize();
            for &v in corners {
                let normal = mesh.normals.as_ref().map_or(face, |normals| normals[v as usize]);
                out.push(MeshVertex {
                    position: mesh.positions[v as usize].to_array(),
                    normal: normal.to_array(),
                    face_normal: face.to_array(),
                    albedo: raster_mesh.albedo.to_array(),
                });
            }
        }
    }
    out
}

/// The vertex buffer's bytes for `scene`.
pub fn vertex_bytes(scene: &RasterScene) -> u64 {
    let triangles: usize = scene.meshes.iter().map(|m| m.mesh.triangles.len()).sum();
    3 * triangles as u64 * std::mem::size_of::<MeshVertex>() as u64
}

/// Refuses meshes whose vertex buffer exceeds `max_buffer_size`, with their files and the bytes
/// it needs.
pub fn check_size(scene: &RasterScene, max_buffer_size: u64) -> Result<(), SceneError> {
    let bytes = vertex_bytes(scene);
    if bytes <= max_buffer_size {
        return Ok(());
    }
    let triangles: usize = scene.meshes.iter().map(|m| m.mesh.triangles.len()).sum();
    let files: Vec<String> = scene.meshes.iter().map(|m| format!("{:?}", m.mesh.file)).collect();
    Err(SceneError::invalid(
        &format!("scene {:?}", scene.name),
        "objects (meshes)",
        format!("{triangles} triangles of {} ({bytes} bytes of vertices)", files.join(", ")),
        format!("must fit in {max_buffer_size} bytes, the device's max_buffer_size"),
    ))
}

/// The meshes' vertex buffer on the device.
pub struct MeshBuffer {
    pub buffer: wgpu::Buffer,
    pub vertices: u32,
}

impl MeshBuffer {
    /// Uploads `scene`'s meshes; `None` for a scene without one.
    pub fn new(device: &wgpu::Device, scene: &RasterScene) -> Option<MeshBuffer> {
        use wgpu::util::DeviceExt;
        let vertices = mesh_vertices(scene);
        if vertices.is_empty() {
            return None;
        }
        let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("raster mesh vertices"),
            contents: bytemuck::cast_slice(&vertices),
            usage: wgpu::BufferUsages::VERTEX,
        });
        Some(MeshBuffer { buffer, vertices: vertices.len() as u32 })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_vertex_layout_is_the_struct() {
        assert_eq!(std::mem::size_of::<MeshVertex>(), 48);
        let offsets: Vec<u64> = MeshVertex::LAYOUT.attributes.iter().map(|a| a.offset).collect();
        assert_eq!(offsets, [0, 12, 24, 36]);
    }
}
