#define_import_path illum::pathtrace::materials

// Generic material lookup: reads the path tracer's material buffer, so one pipeline serves every
// scene. (A specialised pipeline replaces this module with the scene's materials as literals:
// specialise.rs, materials_module.)

#import illum::pathtrace::scene::{Material, materials}

// The material at `index`.
fn material_at(index: u32) -> Material {
    return materials[index];
}
