//! The scene's resolution against what the device allows. A scene is data and validates
//! without a device; the limits of the real `wgpu::Limits` are checked here, by the crate that
//! allocates on the device.

use illum_gpu::wgpu;
use illum_scene::{Scene, SceneError};

/// Each side of the image within `max_texture_dimension_2d` (a viewer shows it as a texture).
/// Errors are labelled `scene "NAME"`, since the resolution may come from the file or from
/// overrides.
pub fn check_texture_size(scene: &Scene, limits: &wgpu::Limits) -> Result<(), SceneError> {
    let label = format!("scene {:?}", scene.name);
    for (field, side) in [("camera.width", scene.camera.width), ("camera.height", scene.camera.height)] {
        if side > limits.max_texture_dimension_2d {
            return Err(SceneError::invalid(
                &label,
                field,
                side.to_string(),
                format!(
                    "must be at most {}, the device's max_texture_dimension_2d",
                    limits.max_texture_dimension_2d
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use illum_scene::testing::check_invalid;

    use super::*;

    fn limits() -> wgpu::Limits {
        wgpu::Limits {
            max_texture_dimension_2d: 8192,
            max_storage_buffer_binding_size: 128 << 20,
            ..wgpu::Limits::default()
        }
    }

    /// The Cornell box, named "test", at `w` x `h`.
    fn with_size(w: u32, h: u32) -> Scene {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/cornell.toml");
        let mut s = Scene::load(std::path::Path::new(path)).unwrap();
        s.name = "test".to_owned();
        s.camera.width = w;
        s.camera.height = h;
        s
    }

    /// Why a `w` x `h` image is refused.
    fn refused(w: u32, h: u32) -> SceneError {
        check_texture_size(&with_size(w, h), &limits()).unwrap_err()
    }

    #[test]
    fn resolution_within_limits_passes() {
        check_texture_size(&with_size(8192, 1024), &limits()).unwrap();
        check_texture_size(&with_size(1, 8192), &limits()).unwrap();
    }

    #[test]
    fn resolution_beyond_the_texture_limit_names_it() {
        let label = "scene \"test\"";
        let err = refused(8193, 16);
        check_invalid(
            &err,
            label,
            "camera.width",
            "8193",
            "must be at most 8192, the device's max_texture_dimension_2d",
        );
        let err = refused(16, 10000);
        check_invalid(&err, label, "camera.height", "10000", "max_texture_dimension_2d");
    }
}
