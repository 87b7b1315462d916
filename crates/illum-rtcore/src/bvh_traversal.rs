//! The walk of a bounding volume hierarchy (bvh.rs), generated into the traversal module with
//! the leaf test of the primitives its tree holds: one walk, written once here, for the tree
//! over a mesh's triangles and the tree over the analytic objects (analytic_bvh.rs), so that a
//! scene's shader holds only the primitive tests it needs: the analytic tree's leaf test
//! dispatches on the kinds it holds, and only on those.
//!
//! The walk visits one node per step, the near child first by the ray's sign on the node's
//! split axis, with a stack of at most `BVH_STACK` entries (bvh.rs, `MAX_DEPTH`).

use std::collections::BTreeSet;

use crate::object::ShapeKind;

/// A tree of the scene's hierarchy: which buffers it reads and what its leaves hold.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum Tree {
    /// Mesh triangles; triangle i is object `base + i` (after the analytic objects).
    Triangles { base: usize },
    /// Analytic objects of these kinds; object i of the tree is object i of the scene's order
    /// (analytic_bvh.rs puts them first).
    Analytic { kinds: BTreeSet<ShapeKind> },
}

/// The hit distance of the analytic tree's record `r` (bvh.wgsl's BvhObject, object `i`) of
/// `kind`: the literal's test (traversal.rs) with the record's numbers.
fn record_hit(kind: ShapeKind) -> &'static str {
    match kind {
        ShapeKind::Aabb => "hit_slabs(o, inv_d, r.a.xyz, r.b.xyz)",
        ShapeKind::Box => "hit_box(o, d, r.a.xyz, r.b.xyz, r.a.w, r.b.w, r.c.xyz)",
        ShapeKind::Quad => "hit_quad(o, d, r.a.xyz, r.b.xyz, r.c.xyz, r.d)",
        // hit_sphere never takes the own sphere's root at the ray's origin (geometry.wgsl).
        ShapeKind::Sphere => "hit_sphere(o, d, r.a.xyz, r.a.w, own == i)",
        ShapeKind::Triangle => unreachable!("triangles are the mesh tree's"),
    }
}

/// `let t` = the hit distance of record `r`, dispatched on its kind among `kinds` (the last
/// one is the switch's default). An axis-aligned box's record is also a box rotated by zero,
/// whose test in its frame is exact (x * 1 - z * 0 = x), so where both kinds occur hit_box
/// serves both, as surface_box does (traversal.rs, surface_cases).
fn analytic_hit(kinds: &BTreeSet<ShapeKind>) -> String {
    let tests: Vec<ShapeKind> = kinds
        .iter()
        .copied()
        .filter(|&k| !(k == ShapeKind::Aabb && kinds.contains(&ShapeKind::Box)))
        .collect();
    let mut out = "                let r = analytic_record(i);\n".to_owned();
    if let [kind] = tests[..] {
        out.push_str(&format!("                let t = {};\n", record_hit(kind)));
        return out;
    }
    out.push_str("                var t: f32;\n                switch r.tag & 15u {\n");
    for (k, &kind) in tests.iter().enumerate() {
        let selector = if k + 1 == tests.len() {
            "default".to_owned()
        } else if kind == ShapeKind::Box && kinds.contains(&ShapeKind::Aabb) {
            "case KIND_AABB, KIND_BOX".to_owned()
        } else {
            format!("case {}", kind.wgsl_constant())
        };
        out.push_str(&format!("                    {selector}: {{ t = {}; }}\n", record_hit(kind)));
    }
    out.push_str("                }\n");
    out
}

impl Tree {
    /// The generated functions' prefix: `{prefix}_closest` and `{prefix}_occluded`.
    pub(crate) fn prefix(&self) -> &'static str {
        match self {
            Tree::Triangles { .. } => "mesh_bvh",
            Tree::Analytic { .. } => "analytic_bvh",
        }
    }

    /// The bvh.wgsl functions and structs the generated walk calls.
    pub(crate) fn imports(&self) -> &'static [&'static str] {
        match self {
            Tree::Triangles { .. } => {
                &["BVH_STACK", "enters_box", "mesh_node", "mesh_triangle", "sheared_ray", "hit_triangle"]
            }
            Tree::Analytic { .. } => &["BVH_STACK", "enters_box", "BvhNode", "BvhObject"],
        }
    }

    fn node_read(&self) -> &'static str {
        match self {
            Tree::Triangles { .. } => "mesh_node",
            Tree::Analytic { .. } => "analytic_node",
        }
    }

    /// Set-up before the walk (the sheared ray of the watertight triangle test).
    fn setup(&self) -> &'static str {
        match self {
            Tree::Triangles { .. } => "    let ray = sheared_ray(o, d);\n",
            Tree::Analytic { .. } => "",
        }
    }

    /// The test of primitive `i` in a leaf of closest_hit's walk, which lowers `best`.
    fn closest_leaf(&self) -> String {
        match self {
            Tree::Triangles { base } => format!(
                "                let tri = mesh_triangle(i);
                let t = hit_triangle(ray, tri.a, tri.b, tri.c, best.t);
                if (t < best.t && i + {base}u != own) {{
                    best = Hit(t, i + {base}u);
                }}
"
            ),
            Tree::Analytic { kinds } => format!(
                "{}                if (t < best.t) {{
                    best = Hit(t, i);
                }}
",
                analytic_hit(kinds)
            ),
        }
    }

    /// The test of primitive `i` in a leaf of occluded's walk.
    fn occluded_leaf(&self) -> String {
        match self {
            Tree::Triangles { base } => format!(
                "                let tri = mesh_triangle(i);
                if (i + {base}u != own && hit_triangle(ray, tri.a, tri.b, tri.c, t_max) < t_max) {{
                    return true;
                }}
"
            ),
            Tree::Analytic { kinds } => format!(
                "{}                if (t < t_max) {{
                    return true;
                }}
",
                analytic_hit(kinds)
            ),
        }
    }
}

/// The walk's loop: `bound` is the distance a node must be entered before (`best.t` or
/// `t_max`), `ordered` whether inner nodes push the far child (closest_hit) or either (occluded,
/// which stops at the first hit), `leaf` the test of primitive `i`.
fn walk(tree: &Tree, bound: &str, ordered: bool, leaf: &str) -> String {
    let node = tree.node_read();
    let descend = if ordered {
        "                let axis = n.b & 3u;
                let second_first = d[axis] < 0.0;
                stack[top] = select(n.a, node + 1u, second_first);
                top += 1u;
                node = select(node + 1u, n.a, second_first);
"
    } else {
        "                stack[top] = n.a;
                top += 1u;
                node += 1u;
"
    };
    format!(
        "    var stack: array<u32, BVH_STACK>;
    var top = 0u;
    var node = 0u;
    loop {{
        let n = {node}(node);
        if (enters_box(o, inv_d, n.lo, n.hi, {bound})) {{
            let count = n.b >> 2u;
            if (count == 0u) {{
{descend}                continue;
            }}
            for (var i = n.a; i < n.a + count; i += 1u) {{
{leaf}            }}
        }}
        if (top == 0u) {{
            break;
        }}
        top -= 1u;
        node = stack[top];
    }}
"
    )
}

/// `{prefix}_closest(o, d, inv_d, own, best)`: the nearest primitive of `tree` nearer than
/// `best`, and `{prefix}_occluded(o, d, inv_d, t_max, own)`: whether one lies strictly between 0
/// and t_max. `own` is the object the ray leaves, as for closest_hit.
pub(crate) fn functions(tree: &Tree) -> String {
    let prefix = tree.prefix();
    let setup = tree.setup();
    format!(
        "// The walk of the {prefix} hierarchy (bvh_traversal.rs).
fn {prefix}_closest(o: vec3<f32>, d: vec3<f32>, inv_d: vec3<f32>, own: u32, best_in: Hit) -> Hit {{
{setup}    var best = best_in;
{closest}    return best;
}}

fn {prefix}_occluded(o: vec3<f32>, d: vec3<f32>, inv_d: vec3<f32>, t_max: f32, own: u32) -> bool {{
{setup}{occluded}    return false;
}}

",
        closest = walk(tree, "best.t", true, &tree.closest_leaf()),
        occluded = walk(tree, "t_max", false, &tree.occluded_leaf()),
    )
}
