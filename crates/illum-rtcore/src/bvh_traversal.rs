//! The walk of a bounding volume hierarchy (bvh.rs), generated into the traversal module with
//! the leaf test of the primitives its tree holds: one walk, written once here, for the tree
//! over a mesh's triangles and the tree over the spheres (sphere_bvh.rs), so that a scene's
//! shader holds only the primitive tests it needs.
//!
//! The walk visits one node per step, the near child first by the ray's sign on the node's
//! split axis, with a stack of at most `BVH_STACK` entries (bvh.rs, `MAX_DEPTH`).

/// A tree of the scene's hierarchy: which buffers it reads and what its leaves hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Tree {
    /// Mesh triangles; triangle i is object `base + i` (after the analytic objects).
    Triangles { base: usize },
    /// Spheres; sphere i is object i of the scene's order (sphere_bvh.rs puts them first).
    Spheres,
}

impl Tree {
    /// The generated functions' prefix: `{prefix}_closest` and `{prefix}_occluded`.
    pub(crate) fn prefix(self) -> &'static str {
        match self {
            Tree::Triangles { .. } => "mesh_bvh",
            Tree::Spheres => "sphere_bvh",
        }
    }

    /// The bvh.wgsl functions the generated walk calls.
    pub(crate) fn imports(self) -> &'static [&'static str] {
        match self {
            Tree::Triangles { .. } => {
                &["BVH_STACK", "enters_box", "mesh_node", "mesh_triangle", "sheared_ray", "hit_triangle"]
            }
            Tree::Spheres => &["BVH_STACK", "enters_box", "BvhNode"],
        }
    }

    fn node_read(self) -> &'static str {
        match self {
            Tree::Triangles { .. } => "mesh_node",
            Tree::Spheres => "sphere_node",
        }
    }

    /// Set-up before the walk (the sheared ray of the watertight triangle test).
    fn setup(self) -> &'static str {
        match self {
            Tree::Triangles { .. } => "    let ray = sheared_ray(o, d);\n",
            Tree::Spheres => "",
        }
    }

    /// The test of primitive `i` in a leaf of closest_hit's walk, which lowers `best`.
    fn closest_leaf(self) -> String {
        match self {
            Tree::Triangles { base } => format!(
                "                let tri = mesh_triangle(i);
                let t = hit_triangle(ray, tri.a, tri.b, tri.c, best.t);
                if (t < best.t && i + {base}u != own) {{
                    best = Hit(t, i + {base}u);
                }}
"
            ),
            // hit_sphere never takes the own sphere's root at the ray's origin (geometry.wgsl).
            Tree::Spheres => "                let s = sphere_at(i);
                let t = hit_sphere(o, d, s.xyz, s.w, own == i);
                if (t < best.t) {
                    best = Hit(t, i);
                }
"
            .to_owned(),
        }
    }

    /// The test of primitive `i` in a leaf of occluded's walk.
    fn occluded_leaf(self) -> String {
        match self {
            Tree::Triangles { base } => format!(
                "                let tri = mesh_triangle(i);
                if (i + {base}u != own && hit_triangle(ray, tri.a, tri.b, tri.c, t_max) < t_max) {{
                    return true;
                }}
"
            ),
            Tree::Spheres => "                let s = sphere_at(i);
                if (hit_sphere(o, d, s.xyz, s.w, own == i) < t_max) {
                    return true;
                }
"
            .to_owned(),
        }
    }
}

/// The walk's loop: `bound` is the distance a node must be entered before (`best.t` or
/// `t_max`), `ordered` whether inner nodes push the far child (closest_hit) or either (occluded,
/// which stops at the first hit), `leaf` the test of primitive `i`.
fn walk(tree: Tree, bound: &str, ordered: bool, leaf: &str) -> String {
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
pub(crate) fn functions(tree: Tree) -> String {
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
