#define_import_path illum::rtcore::bvh

#import illum::rtcore::geometry::{Hit, Object, Surface, FAR, triangle_barycentrics}
#import illum::rtcore::spawn::{spawn_error, max_abs}

// The records of the bounding volume hierarchies (built and flattened by illum-rtcore's bvh.rs,
// which states the layout and why) and the tests their walk makes; the walk itself is generated
// into the traversal with the leaf tests of the primitives it holds (bvh_traversal.rs). Imported
// only by the traversal of a scene with a mesh or with more small analytic objects than the
// literal limit (analytic_bvh.rs); only a scene with a hierarchy binds group 1, and only the
// buffers its traversal reads: a mesh's nodes and triangles, the analytic objects' nodes and
// records.

struct BvhNode {
    lo: vec3<f32>,
    a: u32,
    hi: vec3<f32>,
    b: u32,
}

struct MeshTriangle {
    a: vec3<f32>,
    material: u32,
    b: vec3<f32>,
    object: u32,
    c: vec3<f32>,
    // Its index among the scene's triangles in scene order (bvh.rs): where its shading normals
    // are (mesh_shading.wgsl).
    order: u32,
}

@group(1) @binding(0) var<storage, read> bvh_nodes: array<BvhNode>;
@group(1) @binding(1) var<storage, read> mesh_triangles: array<MeshTriangle>;
// An object under the analytic objects' hierarchy (analytic_bvh.rs): its Object record's a, b, c
// and d.xyz (geometry.wgsl), and `tag`, its kind in the low 4 bits and its material above them.
// The hierarchy's nodes and these are read from uniform buffers (group 1, bindings 2 and 3),
// sized per scene and so declared in the generated traversal (analytic_bvh.rs gives the reason).
struct BvhObject {
    a: vec4<f32>,
    b: vec4<f32>,
    c: vec4<f32>,
    d: vec3<f32>,
    tag: u32,
}

// Reads for the generated walk (the buffers are this module's).
fn mesh_node(i: u32) -> BvhNode {
    return bvh_nodes[i];
}

fn mesh_triangle(i: u32) -> MeshTriangle {
    return mesh_triangles[i];
}

// bvh.rs's MAX_DEPTH: at most one entry per level is pushed.
const BVH_STACK: u32 = 32u;

// A ray prepared for the watertight ray-triangle test (Woop, Benthin and Wald 2013): the axes
// permuted so that z is the largest component of d (x and y swapped when that component is
// negative, which keeps the triangles' winding), and the shear that makes the ray (0, 0, 1).
struct ShearedRay {
    o: vec3<f32>,
    k: vec3<u32>,
    shear: vec3<f32>,
}

fn sheared_ray(o: vec3<f32>, d: vec3<f32>) -> ShearedRay {
    let a = abs(d);
    var kz = 2u;
    if (a.x >= a.y && a.x >= a.z) {
        kz = 0u;
    } else if (a.y >= a.z) {
        kz = 1u;
    }
    var kx = (kz + 1u) % 3u;
    var ky = (kx + 1u) % 3u;
    if (d[kz] < 0.0) {
        let swap = kx;
        kx = ky;
        ky = swap;
    }
    let dz = d[kz];
    return ShearedRay(o, vec3<u32>(kx, ky, kz), vec3<f32>(d[kx] / dz, d[ky] / dz, 1.0 / dz));
}

fn permuted(v: vec3<f32>, k: vec3<u32>) -> vec3<f32> {
    return vec3<f32>(v[k.x], v[k.y], v[k.z]);
}

// The distance along the ray to the triangle (corner_a, corner_b, corner_c) if it lies in (0, t_max), else FAR.
// In the sheared frame the ray is the z axis through the origin, and the edge functions U, V, W
// are 2D cross products of the translated corners: the ray meets the triangle when they share a
// sign. Each is computed from the same two corners in the same order wherever the edge is
// shared, so a ray through a shared edge or vertex gets the same value (0 included) for that
// edge from both triangles, and is found by at least one: no ray passes between them. Both
// sides count (the caller decides what the back side means).
fn hit_triangle(r: ShearedRay, corner_a: vec3<f32>, corner_b: vec3<f32>, corner_c: vec3<f32>, t_max: f32) -> f32 {
    let a = permuted(corner_a - r.o, r.k);
    let b = permuted(corner_b - r.o, r.k);
    let c = permuted(corner_c - r.o, r.k);
    let ax = a.x - r.shear.x * a.z;
    let ay = a.y - r.shear.y * a.z;
    let bx = b.x - r.shear.x * b.z;
    let by = b.y - r.shear.y * b.z;
    let cx = c.x - r.shear.x * c.z;
    let cy = c.y - r.shear.y * c.z;
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    if ((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0)) {
        return FAR;
    }
    let det = u + v + w;
    if (det == 0.0) {
        return FAR;
    }
    // t det = u az + v bz + w cz, with the z coordinates scaled by the shear's 1 / d_z; compared
    // with 0 and t_max det after taking det's sign, so no division decides a miss.
    let t_scaled = r.shear.z * (u * a.z + v * b.z + w * c.z);
    let s = sign(det);
    if (t_scaled * s <= 0.0 || t_scaled * s >= t_max * abs(det)) {
        return FAR;
    }
    return t_scaled / det;
}

// Whether the ray enters the box [lo, hi] before t_max (and exits after 0). The exit distance is
// widened by 2 gamma_3 = 6u / (1 - 3u) (Ize 2013) so that rounding never culls a box the ray
// grazes, whose triangles the watertight test would find.
fn enters_box(o: vec3<f32>, inv_d: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>, t_max: f32) -> bool {
    let t0 = (lo - o) * inv_d;
    let t1 = (hi - o) * inv_d;
    let near = min(t0, t1);
    let far = max(t0, t1);
    let t_enter = max(max(max(near.x, near.y), near.z), 0.0);
    let t_exit = min(min(far.x, far.y), far.z) * 1.0000004;
    return t_enter <= min(t_exit, t_max);
}

// Triangle `i` as an object record of kind `kind` (the traversal's KIND_TRIANGLE): a, b, c hold
// its corners, `padding` its order (mesh_shading.wgsl reads it).
fn triangle_object(i: u32, kind: u32) -> Object {
    let tri = mesh_triangles[i];
    let zero = vec4<f32>(0.0);
    return Object(kind, tri.material, 0u, tri.order, vec4<f32>(tri.a, 0.0), vec4<f32>(tri.b, 0.0), vec4<f32>(tri.c, 0.0), zero);
}

// The surface of a triangle (a, b, c) at a hit point, rebuilt as a + beta (b - a) + gamma (c - a)
// from its barycentric coordinates, as surface_quad rebuilds a parallelogram's (geometry.wgsl):
// the same operations on the same kind of numbers, so the same bound, spawn_error of
// M = |a| + |b - a| + |c - a|. The normal is the front normal (b - a) x (c - a) (flat shading).
fn surface_triangle(obj: Object, p: vec3<f32>) -> Surface {
    let corner = obj.a.xyz;
    let edge_b = obj.b.xyz - corner;
    let edge_c = obj.c.xyz - corner;
    let n = cross(edge_b, edge_c);
    let barycentric = triangle_barycentrics(obj, p);
    let q = corner + barycentric.x * edge_b + barycentric.y * edge_c;
    let magnitude = max_abs(corner) + max_abs(edge_b) + max_abs(edge_c);
    return Surface(q, normalize(n), spawn_error(magnitude));
}
