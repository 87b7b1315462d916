//! The traversal generated for scenes with meshes or many spheres composes and validates (naga),
//! in each form and arrangement: triangles as literals or under a BVH, spheres as literals or
//! under a BVH, each alone, together, or after other analytic objects and before an emitter.

use illum_gpu::shader::{self, ShaderFile};
use illum_rtcore::Geometry;
use illum_rtcore::mesh_traversal::LITERAL_TRIANGLES;
use illum_rtcore::sphere_bvh::LITERAL_SPHERES;
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

/// Scene text of `n` unit spheres in a row.
fn spheres(n: usize) -> String {
    (0..n)
        .map(|i| {
            format!(
                "[[objects]]\nmaterial = \"grey\"\nsphere = {{ center = [{}.0, 0.0, 9.0], radius = 0.4 }}\n",
                i
            )
        })
        .collect()
}

/// `triangles` mesh triangles (none: no mesh), `spheres` spheres, then `objects`.
fn compose(objects: &str, triangles: usize, sphere_count: usize) {
    let mesh =
        if triangles > 0 { "[[objects]]\nmaterial = \"grey\"\nmesh = { file = \"m.obj\" }\n" } else { "" };
    let scene = format!(
        "[camera]\neye = [0.0, 0.0, -5.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\nvfov = 45.0\nwidth = 8\nheight = 8\n\
         [environment]\nradiance = [1.0, 1.0, 1.0]\n[materials.grey]\nalbedo = [0.5, 0.5, 0.5]\n[materials.lamp]\nemission = [1.0, 1.0, 1.0]\n\
         {mesh}{}{objects}",
        spheres(sphere_count)
    );
    let obj = strip(triangles.max(1));
    let scene = scene_with_files(&scene, "t.toml", &[("m.obj", &obj)]).unwrap_or_else(|e| panic!("{e}"));
    let geometry = Geometry::new(&scene);
    assert_eq!(geometry.mesh_bvh().is_some(), triangles > LITERAL_TRIANGLES);
    assert_eq!(geometry.spheres.is_some(), sphere_count > LITERAL_SPHERES);
    let mut modules = illum_rtcore::shaders::core_modules();
    modules.push(generate(&geometry).module("t"));
    let entry = ShaderFile::generated("entry".to_owned(), ENTRY.to_owned());
    let what = format!("{triangles} triangles, {sphere_count} spheres, {objects:?}");
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
    for sphere_count in [LITERAL_SPHERES, LITERAL_SPHERES + 1, 200] {
        for objects in ["", lamp, &format!("{floor}{lamp}")] {
            for triangles in [0, 1, LITERAL_TRIANGLES + 1] {
                compose(objects, triangles, sphere_count);
            }
        }
    }
}
