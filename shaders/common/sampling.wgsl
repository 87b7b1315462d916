#define_import_path illum::sampling

#import illum::constants::{PI, TWO_PI, INV_PI}

// Hemisphere sampling around +Z (local frame). Both return a unit vector; the caller maps it to
// the surface's frame with `to_world`.

// Cosine-weighted (Malley's method): a uniform point on the unit disk lifted to the hemisphere.
// pdf(w) = cos(theta) / pi.
fn sample_cosine_hemisphere(u1: f32, u2: f32) -> vec3<f32> {
    let r = sqrt(u1);
    let phi = TWO_PI * u2;
    return vec3<f32>(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - u1)));
}

fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    return max(cos_theta, 0.0) * INV_PI;
}

// Uniform over solid angle: cos(theta) is uniform in [0, 1] (Archimedes' hat-box theorem).
// pdf(w) = 1 / (2 pi).
fn sample_uniform_hemisphere(u1: f32, u2: f32) -> vec3<f32> {
    let z = u1;
    let r = sqrt(max(0.0, 1.0 - z * z));
    let phi = TWO_PI * u2;
    return vec3<f32>(r * cos(phi), r * sin(phi), z);
}

// A direction uniform over the cone of half-angle a around +z (a sun disc seen from the scene),
// given one_minus_cos_max = 1 - cos(a): solid angle is linear in cos(theta), so 1 - cos(theta) =
// u1 (1 - cos a); pdf = 1 / (2 pi (1 - cos a)). The cone is given by 1 - cos a, not cos a: for a
// disc below about 0.02 degrees cos a rounds to 1 in f32 (the pdf's denominator would be 0), while
// 1 - cos a = 2 sin^2(a / 2) keeps its precision; sin(theta) is computed from it for the same
// reason, as sqrt((1 - cos) (1 + cos)). Local frame, like the hemispheres above.
fn sample_uniform_cone(one_minus_cos_max: f32, u1: f32, u2: f32) -> vec3<f32> {
    let one_minus_cos = u1 * one_minus_cos_max;
    let cos_t = 1.0 - one_minus_cos;
    let sin_t = sqrt(max(one_minus_cos * (2.0 - one_minus_cos), 0.0));
    let phi = TWO_PI * u2;
    return vec3<f32>(sin_t * cos(phi), sin_t * sin(phi), cos_t);
}

fn uniform_hemisphere_pdf() -> f32 {
    return 0.5 * INV_PI;
}

// Orthonormal basis around unit n without a branch on n's direction: Duff et al., "Building an
// Orthonormal Basis, Revisited" (JCGT 2017). Maps local (x, y, z) to x t + y b + z n.
fn to_world(n: vec3<f32>, local: vec3<f32>) -> vec3<f32> {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    let t = vec3<f32>(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    let bt = vec3<f32>(b, s + n.y * n.y * a, -n.y);
    return local.x * t + local.y * bt + local.z * n;
}

// A uniform point on the disc of radius `radius` about `centre`, perpendicular to the unit
// vector `axis` (where the caustic's particles cross the light's plane): the radius
// r = radius sqrt(u1) makes the area inside r, pi r^2, uniform in u1; phi = 2 pi u2.
// pdf = 1 / (pi radius^2) with respect to area.
fn sample_disc(centre: vec3<f32>, axis: vec3<f32>, radius: f32, u1: f32, u2: f32) -> vec3<f32> {
    let r = radius * sqrt(u1);
    let phi = TWO_PI * u2;
    return centre + to_world(axis, vec3<f32>(r * cos(phi), r * sin(phi), 0.0));
}

// A uniform point on the parallelogram corner + s u + t v: pdf = 1 / area with respect to area.
fn sample_parallelogram(corner: vec3<f32>, edge_u: vec3<f32>, edge_v: vec3<f32>, u1: f32, u2: f32) -> vec3<f32> {
    return corner + u1 * edge_u + u2 * edge_v;
}
