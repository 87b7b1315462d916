//! The hierarchies' buffers (bvh.rs), and the smooth meshes' shading normals (mesh_shading.rs),
//! bound as group 1 of a pipeline whose traversal walks a hierarchy or whose shading reads the
//! normals; a pipeline for a scene with neither has no group 1.

use illum_gpu::wgpu;
use illum_scene::{Scene, SceneError, Shape};
use wgpu::util::DeviceExt;

use crate::analytic_bvh;
use crate::traversal::Geometry;

/// Group 1: a mesh's nodes (binding 0) and triangles (1) in storage buffers (bvh.wgsl); the
/// analytic objects' nodes (2) and records (3) in uniform buffers (analytic_bvh.rs says why); the smooth
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
    if let Some(analytic) = &geometry.analytic {
        out.push((2, "analytic bvh nodes", Kind::Uniform, bytemuck::cast_slice(&analytic.nodes).to_vec()));
        out.push((
            3,
            "analytic bvh records",
            Kind::Uniform,
            bytemuck::cast_slice(&analytic.records()).to_vec(),
        ));
    }
    if let Some(normals) = crate::mesh_shading::shading_normals(scene) {
        out.push((4, "mesh shading normals", Kind::Storage, bytemuck::cast_slice(&normals).to_vec()));
    }
    out
}

impl BvhBindGroup {
    /// The bind group index the hierarchies' buffers take.
    pub const GROUP: u32 = 1;
    /// The variables of group 1 (bvh.wgsl's, the analytic objects' uniform buffers that the generated
    /// traversal declares with the scene's sizes, and mesh_shading.wgsl's) and their bindings.
    pub const BINDINGS: [(&'static str, u32); 5] = [
        ("bvh_nodes", 0),
        ("mesh_triangles", 1),
        ("analytic_nodes", 2),
        ("analytic_records", 3),
        ("mesh_normals", 4),
    ];

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

    /// Refuses a scene whose group 1 the device cannot hold: more objects than the analytic
    /// objects' hierarchy takes ([`analytic_bvh::check_count`]), or a buffer beyond the device's
    /// limit for its binding (`storage`: max_storage_buffer_binding_size, `uniform`:
    /// max_uniform_buffer_binding_size), with the bytes it needs and, for a mesh's buffers, the
    /// mesh files. Every GPU ray tracer calls it before compiling the scene's traversal.
    pub fn check_size(
        scene: &Scene,
        geometry: &Geometry,
        storage: u64,
        uniform: u64,
    ) -> Result<(), SceneError> {
        analytic_bvh::check_count(scene, &geometry.objects)?;
        for (_, label, kind, bytes) in contents(scene, geometry) {
            let (limit, name) = match kind {
                Kind::Storage => (storage, "max_storage_buffer_binding_size"),
                Kind::Uniform => (uniform, "max_uniform_buffer_binding_size"),
            };
            let needed = bytes.len() as u64;
            if needed <= limit {
                continue;
            }
            let meshes = || {
                scene
                    .objects
                    .iter()
                    .filter_map(|o| match &o.shape {
                        Shape::Mesh(m) => Some(m),
                        _ => None,
                    })
                    .collect::<Vec<_>>()
            };
            let mesh_value = || {
                let meshes = meshes();
                let triangles: usize = meshes.iter().map(|m| m.triangles.len()).sum();
                let files: Vec<String> = meshes.iter().map(|m| format!("{:?}", m.file)).collect();
                format!("{triangles} triangles of {} ({needed} bytes of {label})", files.join(", "))
            };
            let (field, value) = match &geometry.analytic {
                Some(analytic) if label.contains("analytic") => (
                    "objects",
                    format!("{} objects under a BVH ({needed} bytes of {label})", analytic.objects.len()),
                ),
                _ => ("objects (meshes)", mesh_value()),
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

    /// The bind group, for a pass its owner records (tests' compute runs).
    pub fn bind_group(&self) -> &wgpu::BindGroup {
        &self.bind_group
    }

    /// Binds the buffers in `pass`.
    pub fn set(&self, pass: &mut wgpu::ComputePass<'_>) {
        pass.set_bind_group(Self::GROUP, &self.bind_group, &[]);
    }
}

#[cfg(test)]
mod tests {
    use std::mem::size_of;

    use illum_scene::testing::obj::{icosphere_obj, scene_with_files};

    use super::*;
    use crate::analytic_bvh::{BvhObject, MAX_BVH_OBJECTS};
    use crate::bvh::{BvhNode, MeshTriangle};

    const HEADER: &str = "[camera]\neye = [0.0, 0.0, -5.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\n\
                          vfov = 45.0\nwidth = 8\nheight = 8\n[environment]\nradiance = [1.0, 1.0, 1.0]\n\
                          [materials.grey]\nalbedo = [0.5, 0.5, 0.5]\n";

    /// A scene "big.toml" of one icosphere of subdivision `k` read from "models/ball.obj".
    fn icosphere_scene(k: u32, smooth: bool) -> Scene {
        let text =
            format!("{HEADER}[[objects]]\nmaterial = \"grey\"\nmesh = {{ file = \"models/ball.obj\" }}\n");
        scene_with_files(&text, "big.toml", &[("models/ball.obj", &icosphere_obj(k, smooth))])
            .unwrap_or_else(|e| panic!("{e}"))
    }

    /// A scene "many.toml" of `n` small grey objects in rows of 64, every other one a sphere
    /// and a quad.
    fn small_objects_scene(n: usize) -> Scene {
        let object = |i: usize| {
            let (x, y) = (i % 64, i / 64);
            let shape = if i.is_multiple_of(2) {
                format!("sphere = {{ center = [{x}.0, {y}.0, 9.0], radius = 0.25 }}")
            } else {
                format!(
                    "quad = {{ corner = [{x}.0, {y}.0, 9.0], edge_u = [0.5, 0.0, 0.0], edge_v = [0.0, 0.5, 0.1] }}"
                )
            };
            format!("[[objects]]\nmaterial = \"grey\"\n{shape}\n")
        };
        let mut text = HEADER.to_owned();
        text.extend((0..n).map(object));
        Scene::from_toml_str(&text, "many.toml").unwrap_or_else(|e| panic!("{e}"))
    }

    /// `scene`'s buffers bound as `kind`, the largest of which needs `needed` bytes, pass a limit
    /// of `needed` and are refused at a byte less, by a message that names each of `names`, the
    /// bytes needed, the limit and the binding's limit.
    fn check_just_fits(scene: &Scene, kind: Kind, needed: u64, names: &[&str]) {
        let geometry = Geometry::new(scene);
        let limits = |limit: u64| match kind {
            Kind::Storage => (limit, u64::MAX),
            Kind::Uniform => (u64::MAX, limit),
        };
        let (storage, uniform) = limits(needed);
        BvhBindGroup::check_size(scene, &geometry, storage, uniform)
            .unwrap_or_else(|e| panic!("{needed} bytes fit a limit of {needed}: {e}"));
        let (storage, uniform) = limits(needed - 1);
        let message = BvhBindGroup::check_size(scene, &geometry, storage, uniform)
            .expect_err("a byte over the limit")
            .to_string();
        let binding = match kind {
            Kind::Storage => "max_storage_buffer_binding_size",
            Kind::Uniform => "max_uniform_buffer_binding_size",
        };
        let needed_text = format!("{needed} bytes");
        let limit_text = format!("{} bytes", needed - 1);
        for part in names.iter().copied().chain([needed_text.as_str(), limit_text.as_str(), binding]) {
            assert!(message.contains(part), "{part:?} is not in {message:?}");
        }
    }

    /// A mesh under a BVH (320 triangles): its largest storage buffer, counted from the
    /// hierarchy's own lengths and the records' sizes, fits a limit of its size and not a byte
    /// less; the message names the scene, the mesh file and the triangles.
    #[test]
    fn a_mesh_just_over_the_storage_binding_is_refused_by_file_and_bytes() {
        let scene = icosphere_scene(2, false);
        let geometry = Geometry::new(&scene);
        let bvh = geometry.mesh_bvh().expect("320 triangles are under a BVH");
        assert_eq!(bvh.triangles.len(), 320);
        let nodes = (bvh.nodes.len() * size_of::<BvhNode>()) as u64;
        let triangles = (320 * size_of::<MeshTriangle>()) as u64;
        assert_ne!(nodes, triangles, "one buffer is the largest");
        check_just_fits(
            &scene,
            Kind::Storage,
            nodes.max(triangles),
            &["big.toml", "\"models/ball.obj\"", "320 triangles"],
        );
    }

    /// A mesh of literal triangles (20) binds no buffer, so no storage limit refuses it.
    #[test]
    fn literal_triangles_bind_no_buffer() {
        let scene = icosphere_scene(0, false);
        let geometry = Geometry::new(&scene);
        assert!(geometry.mesh_bvh().is_none());
        BvhBindGroup::check_size(&scene, &geometry, 0, 0).expect("nothing to bind");
    }

    /// The analytic objects' hierarchy is held to the uniform binding: its records' buffer (64
    /// bytes an object) is the larger at 100 objects.
    #[test]
    fn objects_just_over_the_uniform_binding_are_refused_by_count_and_bytes() {
        let scene = small_objects_scene(100);
        let geometry = Geometry::new(&scene);
        let bvh = geometry.analytic.as_ref().expect("100 objects are under a BVH");
        let records = (100 * size_of::<BvhObject>()) as u64;
        let nodes = (bvh.nodes.len() * size_of::<BvhNode>()) as u64;
        check_just_fits(&scene, Kind::Uniform, records.max(nodes), &["many.toml", "100 objects"]);
    }

    /// MAX_BVH_OBJECTS objects are taken within WebGPU's default uniform binding (64 KiB); one
    /// more is refused by count and limit, whatever the device's limits.
    #[test]
    fn more_objects_than_the_hierarchy_holds_are_refused_by_count() {
        let most = small_objects_scene(MAX_BVH_OBJECTS);
        BvhBindGroup::check_size(&most, &Geometry::new(&most), u64::MAX, 64 << 10)
            .unwrap_or_else(|e| panic!("{MAX_BVH_OBJECTS} objects fit WebGPU's default 64 KiB: {e}"));
        let over = small_objects_scene(MAX_BVH_OBJECTS + 1);
        let message = BvhBindGroup::check_size(&over, &Geometry::new(&over), u64::MAX, u64::MAX)
            .expect_err("one object too many")
            .to_string();
        let count = format!("{} non-emitting spheres, quads and boxes", MAX_BVH_OBJECTS + 1);
        let limit = format!("at most {MAX_BVH_OBJECTS}");
        for part in ["many.toml", count.as_str(), limit.as_str(), "remove some"] {
            assert!(message.contains(part), "{part:?} is not in {message:?}");
        }
    }
}
