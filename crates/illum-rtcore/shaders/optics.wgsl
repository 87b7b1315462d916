#define_import_path illum::rtcore::optics

// The optical rules both compute ray tracers apply at a surface, each written once: the
// checkerboard's albedo, and refraction with its Fresnel reflectance at a smooth dielectric.
// (Mirror reflection is WGSL's built-in reflect.) The oracle's f64 copy is illum-oracle's
// optics.rs.

#import illum::rtcore::geometry::Object
#import illum::rtcore::material::Material

// The checker's albedo at p on the quad obj: tile (i, j) counted from its corner along its edges,
// of side m.a.w; even tiles m.a.rgb, odd ones m.b.rgb.
fn checker_albedo(obj: Object, m: Material, p: vec3<f32>) -> vec3<f32> {
    let q = p - obj.a.xyz;
    let i = floor(dot(q, obj.b.xyz) / length(obj.b.xyz) / m.a.w);
    let j = floor(dot(q, obj.c.xyz) / length(obj.c.xyz) / m.a.w);
    return select(m.a.rgb, m.b.rgb, (i32(i) + i32(j)) % 2 != 0);
}

// cos^2 of the transmitted direction's angle for a cosine of incidence cos_i and
// eta = n_from / n_to (Snell's law); negative under total internal reflection.
fn transmitted_cos2(cos_i: f32, eta: f32) -> f32 {
    return 1.0 - eta * eta * (1.0 - cos_i * cos_i);
}

// The refracted direction of unit d through the surface of unit normal n (facing d, so that
// cos_i = -d.n > 0), with cos_t = sqrt(transmitted_cos2(cos_i, eta)).
fn refracted(d: vec3<f32>, n: vec3<f32>, eta: f32, cos_i: f32, cos_t: f32) -> vec3<f32> {
    return normalize(eta * d + (eta * cos_i - cos_t) * n);
}

// Exact unpolarised Fresnel reflectance for cosines of incidence and transmission and
// eta = n_from / n_to.
fn fresnel(cos_i: f32, cos_t: f32, eta: f32) -> f32 {
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5 * (rs * rs + rp * rp);
}
