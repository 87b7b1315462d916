#define_import_path illum::pathtrace::surfaces

// What the path tracer's two estimators (pathtrace.wgsl from the camera, caustic.wgsl from the
// sun) both need to know about surfaces and the sun: the material kinds, the functions that
// read them, and the sun's sampled direction.

#import illum::sampling::{sample_uniform_cone, to_world}
#import illum::pathtrace::scene::{Material, params, objects}

#ifdef SUN
// A direction toward the directional light and its weight, radiance / pdf. A delta light: its
// direction and irradiance (u1, u2 unused). A disc of half-angle a: a direction uniform in its
// cone (pdf 1 / (2 pi (1 - cos a))) of radiance L = irradiance / (pi sin^2 a), so L / pdf =
// irradiance x 2 / (1 + cos a), finite however small the disc; params.sun.w holds 1 - cos a
// (see sample_uniform_cone). Next-event estimation weighs a surface's cos by it; the caustic's
// light tracer uses it as the flux density crossing the plane across the sun's direction.
struct SunSample {
    w: vec3<f32>,
    weight: vec3<f32>,
}

fn sample_sun(u1: f32, u2: f32) -> SunSample {
#ifdef SUN_DISC
    let one_minus_cos_max = params.sun.w;
    let w = normalize(to_world(params.sun.xyz, sample_uniform_cone(one_minus_cos_max, u1, u2)));
    return SunSample(w, params.sun_irradiance.xyz * (2.0 / (2.0 - one_minus_cos_max)));
#else
    return SunSample(params.sun.xyz, params.sun_irradiance.xyz);
#endif
}
#endif

const MATERIAL_CHECKER: u32 = 1u;
const MATERIAL_DIELECTRIC: u32 = 2u;
const MATERIAL_MIRROR: u32 = 3u;

#ifdef CHECKER
// The checker's albedo at p on quad obj: tile (i, j) counted from its corner along its edges.
fn checker_albedo(obj_index: u32, m: Material, p: vec3<f32>) -> vec3<f32> {
    let obj = objects[obj_index];
    let q = p - obj.a.xyz;
    let i = floor(dot(q, obj.b.xyz) / length(obj.b.xyz) / m.emission.w);
    let j = floor(dot(q, obj.c.xyz) / length(obj.c.xyz) / m.emission.w);
    return select(m.albedo.rgb, m.emission.rgb, (i32(i) + i32(j)) % 2 != 0);
}
#endif

#ifdef SPECULAR
// Exact unpolarised Fresnel reflectance for cosines of incidence and transmission and
// eta = n_from / n_to.
fn fresnel(cos_i: f32, cos_t: f32, eta: f32) -> f32 {
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5 * (rs * rs + rp * rp);
}
#endif
