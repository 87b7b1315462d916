#define_import_path illum::rtcore::geometry

#import illum::rtcore::spawn::{spawn_error, max_abs}

// The objects as every compute ray tracer stores them (mirrored by illum-rtcore's object.rs;
// their KIND_* codes are generated from it into illum::rtcore::codes), the ray-shape tests, and
// the surface at a hit point made precise for spawning the next ray. No bindings. The traversal
// over a scene's objects (closest_hit, occluded, surface_at) is the module
// illum::rtcore::traversal, generated per scene by illum-rtcore's traversal.rs.

const NO_HIT: u32 = 0xffffffffu;
const FAR: f32 = 3.0e38;

// A ray that hits an emitter within this relative distance of a coplanar surface sees the
// emitter: the light's face lies exactly in the ceiling's plane and must win that tie. The two
// distances come from different tests of the same plane (slab and quad), each within about 10
// units of roundoff (u = 2^-24) of the exact distance, so they agree to ~20 u = 1.2e-6 relative;
// 1e-5 (~170 u) leaves a wide margin and is still far below any gap between distinct surfaces
// that the image could resolve.
const EMITTER_TIE: f32 = 1.0e-5;

// Box: a = (local min, cos), b = (local max, sin), c = (offset, err): world = R_y local + offset,
// err the error bound of its rebuilt surface points (see surface_box).
// Axis-aligned box: a = (world min, 1), b = (world max, 0), c = 0: also valid as a box rotated by
// zero whose rebuilt points are exact (err 0), so surface_box can serve both kinds.
// Quad: a = corner, b = edge_u, c = edge_v, d = (edge_u x edge_v, 0).
// Sphere: a = (centre, radius).
struct Object {
    kind: u32,
    material: u32,
    emitter: u32,
    padding: u32,
    a: vec4<f32>,
    b: vec4<f32>,
    c: vec4<f32>,
    d: vec4<f32>,
}

// The barycentric coordinates (beta, gamma) of a point p in the plane of the triangle (a, b, c)
// that `obj` holds, p = a + beta (b - a) + gamma (c - a): what both the hit's rebuilt point
// (surface_triangle, bvh.wgsl) and a smooth mesh's shading normal (mesh_shading.wgsl) are made of.
fn triangle_barycentrics(obj: Object, p: vec3<f32>) -> vec2<f32> {
    let corner = obj.a.xyz;
    let edge_b = obj.b.xyz - corner;
    let edge_c = obj.c.xyz - corner;
    let n = cross(edge_b, edge_c);
    let w = n / dot(n, n);
    let h = p - corner;
    return vec2<f32>(dot(w, cross(h, edge_c)), dot(w, cross(edge_b, h)));
}

struct Hit {
    t: f32,
    index: u32,
}

// Ray direction with zero components replaced by a tiny value of the same slab behaviour, so the
// slab test divides by it without producing 0 * inf = NaN. Directions are unit vectors, so
// 1e-30 is far below their resolution (6e-8); (lo - o) * 1e30 stays finite while coordinates
// differ by less than 3e8, beyond any scene f32 can hold with useful precision.
fn safe_inverse(d: vec3<f32>) -> vec3<f32> {
    let tiny = vec3<f32>(1.0e-30);
    return 1.0 / select(d, tiny, abs(d) < tiny);
}

// Inverse of R_y(angle): world-to-local for a direction. R_y maps (x, y, z) to
// (c x + s z, y, -s x + c z), so its transpose maps (x, y, z) to (c x - s z, y, s x + c z).
fn rotate_y_inverse(v: vec3<f32>, c: f32, s: f32) -> vec3<f32> {
    return vec3<f32>(c * v.x - s * v.z, v.y, s * v.x + c * v.z);
}

fn rotate_y(v: vec3<f32>, c: f32, s: f32) -> vec3<f32> {
    return vec3<f32>(c * v.x + s * v.z, v.y, -s * v.x + c * v.z);
}

// Nearest t > 0 at which the ray o + t d meets the surface of the box [lo, hi], or FAR, given
// inv = 1 / d. Slab method (Kay and Kajiya): the ray is inside the box between the largest
// entering and the smallest leaving slab distance.
fn hit_slabs(o: vec3<f32>, inv: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>) -> f32 {
    let t0 = (lo - o) * inv;
    let t1 = (hi - o) * inv;
    let near = min(t0, t1);
    let far = max(t0, t1);
    let t_enter = max(max(near.x, near.y), near.z);
    let t_exit = min(min(far.x, far.y), far.z);
    if (t_exit < t_enter || t_exit <= 0.0) {
        return FAR;
    }
    return select(t_exit, t_enter, t_enter > 0.0);
}

// A box [lo, hi] rotated by R_y (cos c, sin s) and moved by offset: the slab test in its frame.
fn hit_box(o: vec3<f32>, d: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>, c: f32, s: f32, offset: vec3<f32>) -> f32 {
    let ol = rotate_y_inverse(o - offset, c, s);
    let inv = safe_inverse(rotate_y_inverse(d, c, s));
    return hit_slabs(ol, inv, lo, hi);
}

// The parallelogram corner + s u + t v, s, t in [0, 1]; n = u x v (not normalised).
fn hit_quad(o: vec3<f32>, d: vec3<f32>, corner: vec3<f32>, u: vec3<f32>, v: vec3<f32>, n: vec3<f32>) -> f32 {
    let denom = dot(n, d);
    if (denom == 0.0) {
        return FAR;
    }
    let t = dot(corner - o, n) / denom;
    if (!(t > 0.0)) {
        return FAR;
    }
    // Barycentric-like coordinates of the hit in the (edge_u, edge_v) basis: with w = n / |n|^2,
    // alpha = w . (h x v) and beta = w . (u x h) (h = hit - corner).
    let w = n / dot(n, n);
    let h = o + t * d - corner;
    let alpha = dot(w, cross(h, v));
    let beta = dot(w, cross(u, h));
    if (alpha < 0.0 || alpha > 1.0 || beta < 0.0 || beta > 1.0) {
        return FAR;
    }
    return t;
}

// d must be unit length (the quadratic's leading coefficient is taken as 1). `own`: the ray
// starts on this sphere's surface, where the last hit put it (see surface_sphere). A sphere is
// convex: a ray leaving its surface toward the outside never meets it again, and one heading
// inside meets it only at the far root. So the own sphere's near root, which is the ray's own
// origin up to rounding, is never taken, and the origin needs no offset off this sphere.
fn hit_sphere(o: vec3<f32>, d: vec3<f32>, centre: vec3<f32>, radius: f32, own: bool) -> f32 {
    let oc = o - centre;
    let b = dot(oc, d);
    let c = dot(oc, oc) - radius * radius;
    let disc = b * b - c;
    if (own) {
        // The origin lies on the surface to within rounding, so c is about 0 and disc about b^2:
        // a grazing ray's disc may round below 0, where its chord, 2 |b|, is about 0 too.
        return select(FAR, -b + sqrt(max(disc, 0.0)), b < 0.0);
    }
    if (disc < 0.0) {
        return FAR;
    }
    let s = sqrt(disc);
    let t_near = -b - s;
    let t_far = -b + s;
    if (t_near > 0.0) {
        return t_near;
    }
    return select(FAR, t_far, t_far > 0.0);
}

// Outward normal of the face of the cube [-1, 1]^3 nearest to q (q on the cube's surface): the
// axis on which q sits farthest out.
fn box_face_normal(q: vec3<f32>) -> vec3<f32> {
    let aq = abs(q);
    if (aq.x >= aq.y && aq.x >= aq.z) {
        return vec3<f32>(sign(q.x), 0.0, 0.0);
    } else if (aq.y >= aq.z) {
        return vec3<f32>(0.0, sign(q.y), 0.0);
    }
    return vec3<f32>(0.0, 0.0, sign(q.z));
}

// A hit point made precise: the point moved onto the surface it belongs to, the unit geometric
// normal there (not yet oriented toward the ray), and `err`, a bound on the point's remaining
// distance from the surface along that normal, for spawn_point (spawn.wgsl).
struct Surface {
    p: vec3<f32>,
    n: vec3<f32>,
    err: f32,
}

// q with its coordinate on the axis of the unit axis vector n replaced by the box face's: hi on
// a + face, lo on a - face. Those are the slab planes the intersection test uses, as exact floats.
fn snap_to_face(q: vec3<f32>, n: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>) -> vec3<f32> {
    return select(q, select(lo, hi, n > vec3<f32>(0.0)), n != vec3<f32>(0.0));
}

// The surface of `obj` at the computed hit point p = o + t d.
//
// p itself carries the rounding of o + t d, which grows with |o| and t (a camera 1e5 units from
// the origin puts errors of ~0.01 in it), not with the surface. Each shape therefore rebuilds the
// point from its own numbers, so that the error left depends only on the shape's magnitude M.
// The bounds below are in units of u = 2^-24 (the unit roundoff) and cover both the rebuilt
// point and the same shape's intersection test run again from the spawned origin, whose answer
// decides whether the new ray "hits its own surface":
// - axis-aligned box: the coordinate across the face is set to the face's plane (lo or hi), the
//   very float the slab test subtracts from; the test's (plane - origin) then has the exact sign,
//   so err = 0 and the one-float step of spawn_point is enough.
// - rotated box: the local point is snapped to the local face and rotated back: <= 5.3 u M for
//   the rotation, the added offset and R^T R != I in floats, <= 3 u M for the test's own
//   world-to-local transform; M = |offset| + 2 |local corner| bounds every intermediate.
// - quad: the point is rebuilt as corner + alpha u + beta v: <= 7.2 u M, including the tilt of
//   the rounded normal u x v; the test's dot(corner - o, n) <= 8.7 u M. M = |corner|+|u|+|v|.
// - sphere: the point is projected back onto the sphere (pbrt's reprojection); the ray it
//   spawns skips the sphere's root at its origin instead of being offset (hit_sphere's `own`).
// All are under 17 u = 8.5 epsilons of M; spawn_error allows 32 epsilons (SPAWN_REL_ERROR).
// (The traversal module's surface_at dispatches to these on the kinds its scene contains.)
fn surface_aabb(obj: Object, p: vec3<f32>) -> Surface {
    let lo = obj.a.xyz;
    let hi = obj.b.xyz;
    let n = box_face_normal((p - 0.5 * (lo + hi)) / (0.5 * (hi - lo)));
    return Surface(snap_to_face(p, n, lo, hi), n, 0.0);
}

// Also an axis-aligned box's record (cos 1, sin 0, offset 0, err 0): the rotations by zero and
// the added zero offset are exact in floats (x * 1 = x, x * 0 + y = y), so the point, normal and
// bound are surface_aabb's.
fn surface_box(obj: Object, p: vec3<f32>) -> Surface {
    // Local frame: the face is the axis on which p sits farthest out, relative to the
    // half-extent.
    let lo = obj.a.xyz;
    let hi = obj.b.xyz;
    let c = obj.a.w;
    let s = obj.b.w;
    let pl = rotate_y_inverse(p - obj.c.xyz, c, s);
    let nl = box_face_normal((pl - 0.5 * (lo + hi)) / (0.5 * (hi - lo)));
    let q = rotate_y(snap_to_face(pl, nl, lo, hi), c, s) + obj.c.xyz;
    // err = spawn_error(|offset| + 2 max(|lo|, |hi|)), stored in the record (object.rs).
    return Surface(q, rotate_y(nl, c, s), obj.c.w);
}

fn surface_quad(obj: Object, p: vec3<f32>) -> Surface {
    let corner = obj.a.xyz;
    let u = obj.b.xyz;
    let v = obj.c.xyz;
    let w = obj.d.xyz / dot(obj.d.xyz, obj.d.xyz);
    let h = p - corner;
    let q = corner + dot(w, cross(h, v)) * u + dot(w, cross(u, h)) * v;
    let magnitude = max_abs(corner) + max_abs(u) + max_abs(v);
    return Surface(q, normalize(obj.d.xyz), spawn_error(magnitude));
}

// The bound is 0: a ray leaving a sphere is traced with the sphere as its own (hit_sphere), which
// never takes the root at its origin, so no offset off this sphere is needed. An offset of the
// sphere's error bound, 2^-18 (|centre| + radius), would move the origin of every reflected and
// refracted ray by that much: 0.076 units on a sphere of radius 10^4, a visible shift of what the
// sphere reflects (docs/extremes.md, "Every renderer at the scene's extremes").
fn surface_sphere(obj: Object, p: vec3<f32>) -> Surface {
    let centre = obj.a.xyz;
    let radius = obj.a.w;
    let n = normalize(p - centre);
    return Surface(centre + radius * n, n, 0.0);
}
