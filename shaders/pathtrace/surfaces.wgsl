#define_import_path illum::pathtrace::surfaces

// What the path tracer's two estimators (pathtrace.wgsl from the camera, caustic.wgsl from the
// sun) both need to know about surfaces: the material kinds and the functions that read them.

#import illum::pathtrace::scene::{Material, objects}

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
