#define_import_path illum::rtcore::mesh_shading

// Smooth shading of mesh triangles. illum-rtcore's mesh_shading.rs uploads the normals; the
// oracle states the same rules in f64, written apart (illum-oracle's geometry.rs and optics.rs).
//
// A triangle of a smooth mesh has a unit normal at each corner (from its file, rotated with the
// mesh). Its shading normal at a point is those three interpolated by the point's barycentric
// coordinates and normalised. The rules every renderer that shades a mesh smoothly follows:
// - Sides: the geometric normal (the winding's, (b - a) x (c - a)) alone decides which side a
//   ray arrives from, hence which side of a glass mesh is inside and which side a new ray starts
//   on. A shading normal on the other side of the surface from the geometric one (a file whose
//   normals disagree with its winding) is flipped onto the geometric side: a file's normals
//   never change what is inside.
// - Shading: the cosines (Lambert, the highlight, next-event estimation), the lobe a diffuse
//   bounce is drawn from and the specular directions use the shading normal.
// - No light leaks: light counts only from the geometric side a ray arrives on. A light behind
//   the geometric surface lights nothing, and a diffuse bounce drawn below it ends the path,
//   even where the shading normal faces them.
// - Specular: a mirror or a dielectric uses the shading normal when every direction it makes
//   lies on its own geometric side (the arriving ray in front of the shading normal, the
//   reflection in front of the surface, the refraction behind it); otherwise the geometric
//   normal, so that no reflection goes into the surface and no refraction stays out of it.

#import illum::rtcore::geometry::{Object, triangle_barycentrics}
#import illum::rtcore::optics::{transmitted_cos2, refracted}

// Per triangle, in scene order (the `padding` of its object record, set to its order by
// mesh_traversal.rs and bvh.wgsl): nine floats, the unit normals at its corners a, b, c; zeros
// for a triangle of a flat mesh.
@group(1) @binding(4) var<storage, read> mesh_normals: array<f32>;

fn corner_normal(first: u32) -> vec3<f32> {
    return vec3<f32>(mesh_normals[first], mesh_normals[first + 1u], mesh_normals[first + 2u]);
}

// The shading normal of the triangle `obj` at p (a point on it), n its unit geometric normal
// facing the arriving ray: the corners' normals interpolated and flipped onto n's side. n itself
// on a flat mesh's triangle (zero normals), or where opposing corner normals cancel.
fn triangle_shading_normal(obj: Object, p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let first = 9u * obj.padding;
    let na = corner_normal(first);
    let nb = corner_normal(first + 3u);
    let nc = corner_normal(first + 6u);
    let barycentric = triangle_barycentrics(obj, p);
    let beta = barycentric.x;
    let gamma = barycentric.y;
    let ns = (1.0 - beta - gamma) * na + beta * nb + gamma * nc;
    let length2 = dot(ns, ns);
    // Unit corner normals interpolate to a length of at least 1e-3 unless they nearly oppose.
    if (!(length2 > 1.0e-6)) {
        return n;
    }
    let unit = ns * inverseSqrt(length2);
    return select(unit, -unit, dot(unit, n) < 0.0);
}

// The normal a mirror reflects the unit direction d about, at a surface of geometric normal n
// and shading normal ns, both facing d: ns unless d arrives from behind it or the reflection
// about it goes into the surface; then n.
fn mirror_normal(d: vec3<f32>, n: vec3<f32>, ns: vec3<f32>) -> vec3<f32> {
    let r = reflect(d, ns);
    return select(n, ns, dot(d, ns) < 0.0 && dot(r, n) > 0.0);
}

// The normal a dielectric's reflection and refraction of d use (relative index eta =
// n_from / n_to), n and ns as for mirror_normal: ns unless d arrives from behind it, the
// reflection about it goes into the surface, or the refraction through it stays out; then n.
fn dielectric_normal(d: vec3<f32>, n: vec3<f32>, ns: vec3<f32>, eta: f32) -> vec3<f32> {
    let cos_i = -dot(d, ns);
    var keeps_sides = cos_i > 0.0 && dot(reflect(d, ns), n) > 0.0;
    let k = transmitted_cos2(cos_i, eta);
    if (k >= 0.0) {
        keeps_sides = keeps_sides && dot(refracted(d, ns, eta, cos_i, sqrt(k)), n) < 0.0;
    }
    return select(n, ns, keeps_sides);
}
