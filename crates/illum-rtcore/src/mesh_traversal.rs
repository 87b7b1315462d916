//! The part of the generated traversal (traversal.rs) that covers a scene's mesh triangles, in
//! one of two forms:
//! - a few triangles (at most [`LITERAL_TRIANGLES`]) as literals, one straight-line test each,
//!   like the analytic objects: no buffer is read, no loop runs;
//! - more under the BVH (bvh.rs, bvh.wgsl), read from bind group 1.
//!
//! Either way triangle i is object `base + i` (after the analytic objects) and is tested with
//! the same watertight test (bvh.wgsl's `hit_triangle`).

use crate::bvh::{Bvh, MeshTriangle};
use crate::bvh_traversal::{self, Tree};
use crate::literal::{vec3, vec4};
use crate::object::ShapeKind;

/// Up to this many triangles a scene's meshes are literals; past it, a BVH: the crossover
/// measured on lavapipe lies between 20 and 80 triangles (docs/performance-geometry.md, "Meshes", has
/// the figures), and a literal list's shader compile grows with its length.
pub const LITERAL_TRIANGLES: usize = 32;

/// The scene's triangles in the form the traversal uses.
#[derive(Clone, Debug, PartialEq)]
pub enum MeshForm {
    Literals(Vec<MeshTriangle>),
    Bvh(std::sync::Arc<Bvh>),
}

impl MeshForm {
    /// The form for `triangles` (at least one), in scene order: object by object, each mesh's
    /// triangles in its own order. Each triangle's `order` is set to its index in that order,
    /// which the shading normals' buffer follows (mesh_shading.rs).
    pub fn of(mut triangles: Vec<MeshTriangle>) -> MeshForm {
        for (i, t) in triangles.iter_mut().enumerate() {
            t.order = i as u32;
        }
        if triangles.len() <= LITERAL_TRIANGLES {
            MeshForm::Literals(triangles)
        } else {
            MeshForm::Bvh(std::sync::Arc::new(Bvh::build(triangles)))
        }
    }

    /// The triangles, in the order the traversal numbers them.
    pub fn triangles(&self) -> &[MeshTriangle] {
        match self {
            MeshForm::Literals(triangles) => triangles,
            MeshForm::Bvh(bvh) => &bvh.triangles,
        }
    }
}

/// The generated code for the triangles: what closest_hit runs before the emitters, what
/// occluded runs last, the object records of literal triangles (after the analytic objects'),
/// for a BVH's the expression of the record of object `index` (>= `base`), the names it imports
/// from illum::rtcore::bvh, and its module-level definitions.
pub(crate) struct MeshCode {
    pub closest: String,
    pub occluded: String,
    pub object_literals: Vec<String>,
    pub object_range: Option<String>,
    pub bvh_imports: Vec<&'static str>,
    pub definitions: String,
}

/// A triangle's object record: its corners in a, b, c and its order in `padding`, as bvh.wgsl's
/// triangle_object makes it (mesh_shading.wgsl reads the order).
fn triangle_object_literal(t: &MeshTriangle) -> String {
    let v = |p: [f32; 3]| vec4([p[0], p[1], p[2], 0.0]);
    format!(
        "Object({}, {}u, 0u, {}u, {}, {}, {}, vec4<f32>(0.0))",
        ShapeKind::Triangle.wgsl_constant(),
        t.material,
        t.order,
        v(t.a),
        v(t.b),
        v(t.c)
    )
}

/// The code for `form`, its triangles numbered from `base`.
pub(crate) fn mesh_code(form: &MeshForm, base: usize) -> MeshCode {
    let constant =
        format!("const {}: u32 = {}u;\n", ShapeKind::Triangle.wgsl_constant(), ShapeKind::Triangle.code());
    match form {
        MeshForm::Literals(triangles) => {
            let mut closest = format!(
                "    // The meshes' {} triangles, numbered from {base}, as literals (mesh_traversal.rs).\n    let ray = sheared_ray(o, d);\n",
                triangles.len()
            );
            let mut occluded = "    // The meshes' triangles\n    let ray = sheared_ray(o, d);\n".to_owned();
            for (i, t) in triangles.iter().enumerate() {
                let index = base + i;
                let corners = |p: [f32; 3]| vec3(glam::Vec3::from_array(p));
                let (a, b, c) = (corners(t.a), corners(t.b), corners(t.c));
                closest.push_str(&format!(
                    "    t = hit_triangle(ray, {a}, {b}, {c}, best.t);\n    if (t < best.t && own != {index}u) {{\n        best = Hit(t, {index}u);\n    }}\n"
                ));
                occluded.push_str(&format!(
                    "    if (own != {index}u && hit_triangle(ray, {a}, {b}, {c}, t_max) < t_max) {{\n        return true;\n    }}\n"
                ));
            }
            MeshCode {
                closest,
                occluded,
                object_literals: triangles.iter().map(triangle_object_literal).collect(),
                object_range: None,
                bvh_imports: vec!["sheared_ray", "hit_triangle", "surface_triangle"],
                definitions: constant,
            }
        }
        MeshForm::Bvh(bvh) => {
            let tree = Tree::Triangles { base };
            let prefix = tree.prefix();
            let mut bvh_imports = tree.imports().to_vec();
            bvh_imports.extend(["triangle_object", "surface_triangle"]);
            MeshCode {
                closest: format!(
                    "    // The meshes' {} triangles under one BVH (bvh.rs), numbered from {base}.\n    best = {prefix}_closest(o, d, inv_d, own, best);\n",
                    bvh.triangles.len()
                ),
                occluded: format!(
                    "    // The meshes' triangles\n    if ({prefix}_occluded(o, d, inv_d, t_max, own)) {{\n        return true;\n    }}\n"
                ),
                object_literals: Vec::new(),
                object_range: Some(if base == 0 {
                    "triangle_object(index, KIND_TRIANGLE)".to_owned()
                } else {
                    format!("triangle_object(index - {base}u, KIND_TRIANGLE)")
                }),
                bvh_imports,
                definitions: format!("{constant}\n{}", bvh_traversal::functions(&tree)),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    #[test]
    fn a_few_triangles_are_literals_and_more_a_bvh() {
        let triangles = |n: usize| {
            (0..n)
                .map(|i| MeshTriangle::new([Vec3::ZERO, Vec3::X, Vec3::Y + i as f32 * Vec3::Z], 0, 0))
                .collect()
        };
        assert!(
            matches!(MeshForm::of(triangles(LITERAL_TRIANGLES)), MeshForm::Literals(t) if t.len() == LITERAL_TRIANGLES)
        );
        let bvh = MeshForm::of(triangles(LITERAL_TRIANGLES + 1));
        assert!(matches!(&bvh, MeshForm::Bvh(_)));
        assert_eq!(bvh.triangles().len(), LITERAL_TRIANGLES + 1);
        // Each triangle keeps its index in the input as its order, wherever the BVH puts it.
        for t in bvh.triangles() {
            assert_eq!(t.c[2], t.order as f32);
        }
    }
}
