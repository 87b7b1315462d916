#define_import_path illum::pathtrace::light_choice

// Generic light choice: reads the path tracer's light buffer, so one pipeline serves every scene.
// (A specialised pipeline replaces this module with the scene's light areas as literals:
// specialise.rs.)

#import illum::pathtrace::scene::{params, lights}

// The light whose share of the total light area contains `pick` (in [0, total area)): lights
// are chosen with probability proportional to their area.
fn choose_light(pick: f32) -> u32 {
    var li = 0u;
    for (; li + 1u < params.num_lights; li++) {
        if (pick < lights[li].corner.w) {
            break;
        }
    }
    return li;
}
