#define_import_path illum::rtcore::material

// The one material record of both compute ray tracers (mirrored by illum-rtcore's material.rs,
// whose MaterialCode gives the MATERIAL_* kinds of illum::rtcore::codes).
// a: the albedo (Lambertian), the even tiles' albedo (checker) or the reflectance (mirror) in
//    xyz; the tile size (checker) or the index of refraction (dielectric) in w.
// b: the odd tiles' albedo (checker) or the emitted radiance (emitter) in xyz.
struct Material {
    kind: u32,
    a: vec4<f32>,
    b: vec4<f32>,
}
