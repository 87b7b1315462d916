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

/// [`check_texture_size`], and width x height x `bytes_per_pixel` (a buffer that holds the whole
/// image at once) within one storage binding, `max_storage_buffer_binding_size`.
pub fn check_resolution(
    scene: &Scene,
    limits: &wgpu::Limits,
    bytes_per_pixel: u64,
) -> Result<(), SceneError> {
    check_texture_size(scene, limits)?;
    let (w, h) = (scene.camera.width, scene.camera.height);
    // u64 holds 2^32 * 2^32 pixels only without the factor; saturate rather than wrap.
    let bytes = u64::from(w).saturating_mul(u64::from(h)).saturating_mul(bytes_per_pixel);
    if bytes > limits.max_storage_buffer_binding_size {
        return Err(SceneError::invalid(
            &format!("scene {:?}", scene.name),
            "camera.width x camera.height",
            format!("{w} x {h} (x {bytes_per_pixel} bytes per pixel = {bytes} bytes)"),
            format!(
                "must fit in {} bytes, the device's max_storage_buffer_binding_size",
                limits.max_storage_buffer_binding_size
            ),
        ));
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

    /// Why a `w` x `h` image of `bytes_per_pixel` is refused.
    fn refused(w: u32, h: u32, bytes_per_pixel: u64) -> SceneError {
        check_resolution(&with_size(w, h), &limits(), bytes_per_pixel).unwrap_err()
    }

    #[test]
    fn resolution_within_limits_passes() {
        check_resolution(&with_size(8192, 1024), &limits(), 16).unwrap();
        // Exactly at the buffer limit: 4096 x 2048 x 16 bytes = 128 MiB.
        check_resolution(&with_size(4096, 2048), &limits(), 16).unwrap();
    }

    #[test]
    fn resolution_beyond_the_texture_limit_names_it() {
        let label = "scene \"test\"";
        let err = refused(8193, 16, 16);
        check_invalid(
            &err,
            label,
            "camera.width",
            "8193",
            "must be at most 8192, the device's max_texture_dimension_2d",
        );
        let err = refused(16, 10000, 16);
        check_invalid(&err, label, "camera.height", "10000", "max_texture_dimension_2d");
    }

    #[test]
    fn resolution_beyond_the_buffer_limit_names_it() {
        let err = refused(4096, 2049, 16);
        // 4096 * 2049 * 16 = 134283264 bytes > 134217728.
        check_invalid(
            &err,
            "scene \"test\"",
            "camera.width x camera.height",
            "4096 x 2049 (x 16 bytes per pixel = 134283264 bytes)",
            "must fit in 134217728 bytes, the device's max_storage_buffer_binding_size",
        );
        // An absurd per-pixel size saturates instead of wrapping around to a small number.
        let err = refused(8192, 8192, u64::MAX);
        assert!(err.to_string().contains("max_storage_buffer_binding_size"), "{err}");
    }
}
