//! The rasterizer's textures and readback against what the device allows. A scene is data and
//! validates without a device; the real `wgpu::Limits` are checked here, by the crate that
//! allocates on the device.

use illum_gpu::wgpu;
use illum_scene::SceneError;

use crate::scene::RasterScene;

/// Bytes per output pixel (RGBA, 8 bits per channel) and the row alignment GPU copies need
/// (`wgpu::COPY_BYTES_PER_ROW_ALIGNMENT`).
const READBACK_BYTES_PER_PIXEL: u64 = 4;
const READBACK_ROW_ALIGNMENT: u64 = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT as u64;

/// Checks that the output and the cube maps of `scene` fit the device: every texture side within
/// `max_texture_dimension_2d`, and the readback buffer (4 bytes per pixel, rows padded to
/// 256 bytes) and the meshes' vertex buffer within `max_buffer_size`. Errors are labelled
/// `scene "NAME"`, since the resolution may come from the file or from the command line.
pub fn check_device_limits(scene: &RasterScene, limits: &wgpu::Limits) -> Result<(), SceneError> {
    let label = format!("scene {:?}", scene.name);
    let max = limits.max_texture_dimension_2d;
    let (w, h) = (scene.camera.width, scene.camera.height);
    for (field, side) in
        [("camera.width", w), ("camera.height", h), ("raster.cube_size", scene.quality.cube_size)]
    {
        if side > max {
            return Err(SceneError::invalid(
                &label,
                field,
                side.to_string(),
                format!("must be at most {max}, the device's max_texture_dimension_2d"),
            ));
        }
    }
    let row = (u64::from(w) * READBACK_BYTES_PER_PIXEL).next_multiple_of(READBACK_ROW_ALIGNMENT);
    let bytes = row.saturating_mul(u64::from(h));
    if bytes > limits.max_buffer_size {
        return Err(SceneError::invalid(
            &label,
            "camera.width x camera.height",
            format!("{w} x {h} ({bytes} bytes to read back)"),
            format!("must fit in {} bytes, the device's max_buffer_size", limits.max_buffer_size),
        ));
    }
    crate::mesh::check_size(scene, limits.max_buffer_size)
}
