//! The traversal generated for scenes with meshes or many small objects composes and validates
//! (naga), in each form and arrangement: triangles as literals or under a BVH, spheres (alone or
//! with quads and boxes) as literals or under a BVH, each alone, together, or after other
//! analytic objects and before an emitter;
//! and, run on the GPU, it finds a closed mesh for every ray aimed at a shared edge or vertex.

use illum_gpu::shader::{self, ShaderFile};
use illum_rtcore::Geometry;
use illum_rtcore::analytic_bvh::LITERAL_OBJECTS;
use illum_rtcore::mesh_traversal::LITERAL_TRIANGLES;
use illum_rtcore::traversal::generate;
use illum_scene::testing::obj::scene_with_files;

/// OBJ text of a strip of `n` triangles.
fn strip(n: usize) -> String {
    let mut text = String::new();
    for i in 0..n + 2 {
        text.push_str(&format!("v {} {} 5\n", i / 2, i % 2));
    }
    for i in 0..n {
        text.push_str(&format!("f {} {} {}\n", i + 1, i + 2, i + 3));
    }
    text
}

const ENTRY: &str =
    "#import illum::rtcore::traversal::{closest_hit, occluded, object_at, surface_at, scattering_surface_at}
@group(0) @binding(0) var<storage, read_write> out: array<vec4<f32>>;
@compute @workgroup_size(1)
fn main() {
    let d = vec3<f32>(0.0, 0.0, 1.0);
    let hit = closest_hit(vec3<f32>(0.2, 0.3, 0.0), d, 0xffffffffu);
    let obj = object_at(hit.index);
    let s = surface_at(obj, d * hit.t);
    let r = scattering_surface_at(obj, d * hit.t);
    out[0] = vec4<f32>(s.p + r.n, select(0.0, 1.0, occluded(s.p, d, 1.0, hit.index)));
}
";

/// Scene text of `n` small objects in a row: object i a sphere, a quad, a rotated box or an
/// axis-aligned box by `i % kinds`.
fn small_objects(n: usize, kinds: usize) -> String {
    (0..n)
        .map(|i| {
            let shape = match i % kinds {
                0 => format!("sphere = {{ center = [{i}.0, 0.0, 9.0], radius = 0.4 }}"),
                1 => format!("quad = {{ corner = [{i}.0, 0.0, 9.0], edge_u = [0.5, 0.0, 0.0], edge_v = [0.0, 0.5, 0.2] }}"),
                2 => format!("box = {{ min = [{i}.0, 0.0, 9.0], max = [{i}.5, 0.5, 9.5], rotate_y = 30.0 }}"),
                _ => format!("box = {{ min = [{i}.0, 0.0, 9.0], max = [{i}.5, 0.5, 9.5] }}"),
            };
            format!("[[objects]]\nmaterial = \"grey\"\n{shape}\n")
        })
        .collect()
}

/// `triangles` mesh triangles (none: no mesh), `sphere_count` small objects of `kinds` kinds
/// ([`small_objects`]), then `objects`.
fn compose(objects: &str, triangles: usize, sphere_count: usize) {
    compose_kinds(objects, triangles, sphere_count, 1);
}

fn compose_kinds(objects: &str, triangles: usize, sphere_count: usize, kinds: usize) {
    let mesh =
        if triangles > 0 { "[[objects]]\nmaterial = \"grey\"\nmesh = { file = \"m.obj\" }\n" } else { "" };
    let scene = format!(
        "[camera]\neye = [0.0, 0.0, -5.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\nvfov = 45.0\nwidth = 8\nheight = 8\n\
         [environment]\nradiance = [1.0, 1.0, 1.0]\n[materials.grey]\nalbedo = [0.5, 0.5, 0.5]\n[materials.lamp]\nemission = [1.0, 1.0, 1.0]\n\
         {mesh}{}{objects}",
        small_objects(sphere_count, kinds)
    );
    let obj = strip(triangles.max(1));
    let scene = scene_with_files(&scene, "t.toml", &[("m.obj", &obj)]).unwrap_or_else(|e| panic!("{e}"));
    let geometry = Geometry::new(&scene);
    assert_eq!(geometry.mesh_bvh().is_some(), triangles > LITERAL_TRIANGLES);
    assert_eq!(geometry.analytic.is_some(), sphere_count > LITERAL_OBJECTS);
    let mut modules = illum_rtcore::shaders::core_modules();
    modules.push(generate(&geometry).module("t"));
    let entry = ShaderFile::generated("entry".to_owned(), ENTRY.to_owned());
    let what = format!("{triangles} triangles, {sphere_count} objects of {kinds} kinds, {objects:?}");
    let module = shader::compose(&modules, &entry, &[]).unwrap_or_else(|e| panic!("{what}: {e}"));
    shader::validate(&module, "entry").unwrap_or_else(|e| panic!("{what}: {e}"));
}

#[test]
fn mesh_traversals_compose_and_validate() {
    let others = "[[objects]]\nmaterial = \"grey\"\nsphere = { center = [0.0, 0.0, 9.0], radius = 1.0 }\n\
                  [[objects]]\nmaterial = \"lamp\"\nquad = { corner = [0.0, 3.0, 0.0], edge_u = [1.0, 0.0, 0.0], edge_v = [0.0, 0.0, 1.0] }\n";
    for triangles in [1, LITERAL_TRIANGLES, LITERAL_TRIANGLES + 1, 500] {
        compose("", triangles, 0);
        compose(others, triangles, 0);
    }
}

#[test]
fn sphere_traversals_compose_and_validate() {
    let lamp = "[[objects]]\nmaterial = \"lamp\"\nquad = { corner = [0.0, 3.0, 0.0], edge_u = [1.0, 0.0, 0.0], edge_v = [0.0, 0.0, 1.0] }\n";
    let floor = "[[objects]]\nmaterial = \"grey\"\nquad = { corner = [-9.0, -1.0, 0.0], edge_u = [18.0, 0.0, 0.0], edge_v = [0.0, 0.0, 18.0] }\n";
    for sphere_count in [LITERAL_OBJECTS, LITERAL_OBJECTS + 1, 200] {
        for objects in ["", lamp, &format!("{floor}{lamp}")] {
            for triangles in [0, 1, LITERAL_TRIANGLES + 1] {
                compose(objects, triangles, sphere_count);
            }
        }
    }
}

/// The hierarchy's leaf test dispatches on the kinds it holds: two (a switch with a default),
/// all four (boxes of both kinds share hit_box's case).
#[test]
fn mixed_object_traversals_compose_and_validate() {
    let lamp = "[[objects]]\nmaterial = \"lamp\"\nquad = { corner = [0.0, 3.0, 0.0], edge_u = [1.0, 0.0, 0.0], edge_v = [0.0, 0.0, 1.0] }\n";
    for count in [LITERAL_OBJECTS, LITERAL_OBJECTS + 1, 200] {
        for kinds in [2, 3, 4] {
            for triangles in [0, LITERAL_TRIANGLES + 1] {
                compose_kinds(lamp, triangles, count, kinds);
            }
        }
    }
}

/// The shading normals' buffer follows the triangles' order (mesh_shading.rs): triangle g of the
/// traversal, wherever the BVH put it, finds the normals of the scene's triangle g, a flat
/// mesh's triangles zeros; and a scene without a smooth mesh has no buffer.
#[test]
fn shading_normals_follow_the_triangles_order() {
    use illum_rtcore::mesh_shading::{FLOATS_PER_TRIANGLE, shading_normals};
    use illum_scene::testing::obj::{icosphere_obj, scene_with_files};
    let text = "[camera]\neye = [0.0, 0.0, -5.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\nvfov = 45.0\nwidth = 8\nheight = 8\n\
                [environment]\nradiance = [1.0, 1.0, 1.0]\n[materials.grey]\nalbedo = [0.5, 0.5, 0.5]\n\
                [[objects]]\nmaterial = \"grey\"\nmesh = { file = \"flat.obj\", translate = [3.0, 0.0, 0.0] }\n\
                [[objects]]\nmaterial = \"grey\"\nmesh = { file = \"smooth.obj\", translate = [-3.0, 0.0, 0.0] }\n";
    let (flat, smooth) = (icosphere_obj(1, false), icosphere_obj(1, true));
    let scene = scene_with_files(text, "t.toml", &[("flat.obj", &flat), ("smooth.obj", &smooth)]).unwrap();
    let geometry = Geometry::new(&scene);
    let form = geometry.meshes.as_ref().unwrap();
    assert!(geometry.mesh_bvh().is_some());
    let normals = shading_normals(&scene).expect("a smooth mesh");
    assert_eq!(normals.len(), FLOATS_PER_TRIANGLE * 160);
    for t in form.triangles() {
        let g = t.order as usize;
        let corners = [t.a, t.b, t.c].map(glam::Vec3::from_array);
        let n: Vec<glam::Vec3> =
            (0..3).map(|k| glam::Vec3::from_slice(&normals[9 * g + 3 * k..9 * g + 3 * k + 3])).collect();
        if g < 80 {
            assert!(n.iter().all(|n| *n == glam::Vec3::ZERO), "flat triangle {g}");
            assert!(corners.iter().all(|c| c.x > 1.0), "triangle {g} is the flat mesh's");
        } else {
            // The smooth icosphere's normals point from its centre (-3, 0, 0) to its corners.
            for (c, n) in corners.iter().zip(&n) {
                let radial = (*c - glam::Vec3::new(-3.0, 0.0, 0.0)).normalize();
                assert!(radial.dot(*n) > 0.9999, "triangle {g}: normal {n} at corner {c}");
            }
        }
    }
    let only_flat =
        scene_with_files(&text.replace("smooth.obj", "flat.obj"), "t.toml", &[("flat.obj", &flat)]).unwrap();
    assert!(shading_normals(&only_flat).is_none());
}

/// The shading normal's module composes and validates with the traversal of a smooth mesh, as
/// literals and under a BVH.
#[test]
fn smooth_shading_composes_with_each_form() {
    use illum_scene::testing::obj::{icosphere_obj, scene_with_files};
    let entry = ShaderFile::generated(
        "entry".to_owned(),
        "#import illum::rtcore::traversal::{closest_hit, object_at, surface_at, KIND_TRIANGLE}
#import illum::rtcore::mesh_shading::{triangle_shading_normal, mirror_normal, dielectric_normal}
@group(0) @binding(0) var<storage, read_write> out: array<vec4<f32>>;
@compute @workgroup_size(1)
fn main() {
    let d = vec3<f32>(0.0, 0.0, 1.0);
    let hit = closest_hit(vec3<f32>(0.1, 0.2, -5.0), d, 0xffffffffu);
    let obj = object_at(hit.index);
    let s = surface_at(obj, d * hit.t);
    var ns = s.n;
    if (obj.kind == KIND_TRIANGLE) {
        ns = triangle_shading_normal(obj, s.p, s.n);
    }
    out[0] = vec4<f32>(mirror_normal(d, s.n, ns) + dielectric_normal(d, s.n, ns, 1.5), 0.0);
}
"
        .to_owned(),
    );
    for k in [0, 1] {
        let text = "[camera]\neye = [0.0, 0.0, -5.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\nvfov = 45.0\nwidth = 8\nheight = 8\n\
                    [environment]\nradiance = [1.0, 1.0, 1.0]\n[materials.grey]\nalbedo = [0.5, 0.5, 0.5]\n\
                    [[objects]]\nmaterial = \"grey\"\nmesh = { file = \"m.obj\" }\n";
        let scene = scene_with_files(text, "t.toml", &[("m.obj", &icosphere_obj(k, true))]).unwrap();
        let geometry = Geometry::new(&scene);
        assert_eq!(geometry.mesh_bvh().is_some(), k > 0);
        let mut modules = illum_rtcore::shaders::core_modules();
        modules.push(generate(&geometry).module("t"));
        let module =
            shader::compose(&modules, &entry, &[]).unwrap_or_else(|e| panic!("subdivision {k}: {e}"));
        shader::validate(&module, "entry").unwrap_or_else(|e| panic!("subdivision {k}: {e}"));
    }
}

/// Casts each ray (origin, expected distance; direction, 0) through the traversal on the GPU:
/// per ray (t, 1 if it hit, 1 if occluded within 1.5 t, 1 if occluded within 0.5 t).
const CAST: &str = "#import illum::rtcore::traversal::{closest_hit, occluded}
#import illum::rtcore::geometry::NO_HIT
struct Ray {
    o: vec4<f32>,
    d: vec4<f32>,
}
@group(0) @binding(0) var<storage, read> rays: array<Ray>;
@group(0) @binding(1) var<storage, read_write> out: array<vec4<f32>>;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= arrayLength(&rays)) {
        return;
    }
    let o = rays[i].o.xyz;
    let d = rays[i].d.xyz;
    let t = rays[i].o.w;
    let hit = closest_hit(o, d, NO_HIT);
    out[i] = vec4<f32>(
        hit.t,
        select(0.0, 1.0, hit.index != NO_HIT),
        select(0.0, 1.0, occluded(o, d, 1.5 * t, NO_HIT)),
        select(0.0, 1.0, occluded(o, d, 0.5 * t, NO_HIT)),
    );
}
";

/// Watertightness on the GPU: rays aimed exactly at every shared vertex and edge (its f32
/// midpoint) of a closed cube and icosphere, from inside, from outside at several angles, and
/// along an axis where f32 holds the ray and the point exactly
/// ([`rays_at_edges_and_vertices`](illum_scene::testing::obj::rays_at_edges_and_vertices)),
/// each hit the mesh where aimed (within 1e-3 of the distance) and are occluded by it, never
/// before: as literals (a cube of 12 triangles and an icosahedron of 20) and under the BVH (48
/// and 80), whose boxes rounding must not cull.
#[test]
fn rays_at_shared_edges_and_vertices_never_pass_between_triangles() {
    use illum_rtcore::BvhBindGroup;
    use illum_scene::testing::obj::closed_meshes;
    let gpu = illum_gpu::testing::gpu();
    for (n, k) in [(1, 0), (2, 1)] {
        let (scene, rays) = closed_meshes(n, k);
        let geometry = Geometry::new(&scene);
        let triangles = 12 * n * n + 20 * 4u32.pow(k);
        assert_eq!(geometry.mesh_bvh().is_some(), triangles as usize > LITERAL_TRIANGLES);
        let mut modules = illum_rtcore::shaders::core_modules();
        modules.push(generate(&geometry).module("t"));
        let input: Vec<f32> = rays
            .iter()
            .flat_map(|r| {
                let (o, d) = (r.origin, r.direction);
                [o.x, o.y, o.z, r.t, d.x, d.y, d.z, 0.0]
            })
            .collect();
        let bytes = illum_gpu::testing::run_compute_with(
            "watertight",
            &modules,
            CAST.to_owned(),
            &[bytemuck::cast_slice(&input)],
            16 * rays.len() as u64,
            ((rays.len() as u32).div_ceil(64), 1, 1),
            |pipeline| {
                BvhBindGroup::new(&gpu.device, pipeline, &scene, &geometry)
                    .map(|group| (BvhBindGroup::GROUP, group.bind_group().clone()))
                    .into_iter()
                    .collect()
            },
        );
        let out: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
        let axis = rays.iter().filter(|r| r.direction.abs().max_element() == 1.0).count();
        println!("{triangles} triangles: {} rays ({axis} along an axis)", rays.len());
        for (ray, [t, hit, far, near]) in rays.iter().zip(out) {
            assert!(*hit == 1.0, "{triangles} triangles: {ray:?} passed between them");
            assert!((t - ray.t).abs() <= 1e-3, "{triangles} triangles: {ray:?} hit at {t}");
            assert!(*far == 1.0 && *near == 0.0, "{triangles} triangles: {ray:?} occluded: {far} {near}");
        }
    }
}
