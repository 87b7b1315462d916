#define_import_path illum::rtcore::materials

// Generic material lookup: reads the path tracer's material buffer, so one pipeline serves every
// scene. (A specialised pipeline replaces this module with the scene's materials as literals:
// illum-rtcore's material.rs, materials_module.)

#import illum::rtcore::material::Material
#import illum::pathtrace::scene::materials

// The material at `index`.
fn material_at(index: u32) -> Material {
    return materials[index];
}
