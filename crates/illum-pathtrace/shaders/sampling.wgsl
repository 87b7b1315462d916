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

// x in [0, 1] with density proportional to (1 - x) a + x b (a, b >= 0), by inverting its CDF in
// the form that needs no division by a - b: x = u (a + b) / (a + sqrt((1 - u) a^2 + u b^2)).
// a + b = 0 (or not a number) gives u.
fn sample_linear(u: f32, a: f32, b: f32) -> f32 {
    let sum = a + b;
    if (!(sum > 0.0)) {
        return u;
    }
    return clamp(u * sum / (a + sqrt(mix(a * a, b * b, u))), 0.0, 1.0);
}

// A point on the parallelogram light corner + s u + t v for next-event estimation at the
// surface point p (unit normal n), drawn with a density over (s, t) proportional to the bilinear
// interpolation of the integrand's geometric term g = cos(theta_x) cos(theta_y) / r^2 at the
// four corners (light_normal: the unit normal of the emitting side). Returns (s, t) and the
// inverse of that density, 1 / pdf(s, t); the caller multiplies the area estimator's weight by
// it (uniform sampling has pdf 1). Where the light is near and the geometric term varies over it
// (the upper walls next to the Cornell box's light), the samples follow it, as solid-angle
// sampling would, with square roots only.
//
// Unbiased: a half-space that meets the light contains one of its corners, so wherever the
// integrand is positive inside the light some corner weight is too, and the bilinear density,
// whose four basis functions are positive inside, is positive there. A sixteenth of the mean
// weight is added to every corner (defensive sampling): the density never falls below 1/17 of
// uniform, so a sample's weight is at most 17 times uniform sampling's. Corner weights that are
// not finite (a point on a corner, or a scene at f32's limits) give uniform sampling.
fn sample_light_bilinear(p: vec3<f32>, n: vec3<f32>, corner: vec3<f32>, edge_u: vec3<f32>, edge_v: vec3<f32>, light_normal: vec3<f32>, u1: f32, u2: f32) -> vec3<f32> {
    let g00 = corner_weight(corner - p, n, light_normal);
    let g10 = corner_weight(corner + edge_u - p, n, light_normal);
    let g01 = corner_weight(corner + edge_v - p, n, light_normal);
    let g11 = corner_weight(corner + edge_u + edge_v - p, n, light_normal);
    let mean = 0.25 * (g00 + g10 + g01 + g11);
    // Written so that a NaN or an infinite mean takes the uniform branch.
    if (!(mean > 0.0 && mean <= 3.0e38)) {
        return vec3<f32>(u1, u2, 1.0);
    }
    let floor = 0.0625 * mean;
    let w = vec4<f32>(g00, g10, g01, g11) + floor;
    let s = sample_linear(u1, w.x + w.z, w.y + w.w);
    let a = mix(w.x, w.y, s);
    let b = mix(w.z, w.w, s);
    let t = sample_linear(u2, a, b);
    // pdf(s, t) = bilinear(s, t) / its mean over the square (the mean of the four weights).
    let f = mix(a, b, t);
    return vec3<f32>(s, t, (mean + floor) / f);
}

// cos(theta_x) cos(theta_y) / r^2 toward a light point at offset w from the shading point, as two
// factors of magnitude 1 / r (no overflow of r^4); zero where either cosine is not positive.
fn corner_weight(w: vec3<f32>, n: vec3<f32>, light_normal: vec3<f32>) -> f32 {
    let inv_d2 = 1.0 / dot(w, w);
    return max(dot(n, w) * inv_d2, 0.0) * max(-dot(light_normal, w) * inv_d2, 0.0);
}
