//! The textures a frame renders into: the shadow map, the cube maps and the main targets.

use illum_gpu::{GpuContext, GpuError, wgpu};

/// Depth format of every pass (32-bit float: the shadow map's comparisons and the main view's
/// 0.1 .. 3000 depth range both want the precision).
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Cube maps hold linear radiance in half floats: no clipping or 8-bit banding before the
/// glass and mirror lookups filter them.
pub const CUBE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// The output: linear values written straight to 8 bits (no sRGB encoding), as the assignment's
/// figure was. The GPU rounds each value to the nearest of 256 levels.
pub const OUTPUT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

fn texture(
    gpu: &GpuContext,
    label: &str,
    size: (u32, u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: size.2 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// The light's depth map.
pub struct ShadowMap {
    pub size: u32,
    pub view: wgpu::TextureView,
}

impl ShadowMap {
    pub fn new(gpu: &GpuContext, size: u32) -> Result<Self, GpuError> {
        gpu.scoped("creating the shadow map", || {
            let t = texture(
                gpu,
                "raster shadow map",
                (size, size, 1),
                DEPTH_FORMAT,
                wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            );
            ShadowMap { size, view: t.create_view(&Default::default()) }
        })
    }
}

/// A cube map: one view of all six layers for sampling, one 2D view per layer to render into.
pub struct CubeMap {
    pub size: u32,
    pub cube_view: wgpu::TextureView,
    pub face_views: Vec<wgpu::TextureView>,
}

impl CubeMap {
    /// A renderable cube map of `size` x `size` texels per face.
    pub fn new(gpu: &GpuContext, label: &str, size: u32) -> Result<Self, GpuError> {
        Self::create(
            gpu,
            label,
            size,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        )
    }

    /// A 1 x 1 cube bound where a pass may not read the real one (the pass that renders it).
    /// Its content is never sampled: the shaders check `view.info` first.
    pub fn placeholder(gpu: &GpuContext) -> Result<Self, GpuError> {
        Self::create(gpu, "raster placeholder cube", 1, wgpu::TextureUsages::TEXTURE_BINDING)
    }

    fn create(
        gpu: &GpuContext,
        label: &str,
        size: u32,
        usage: wgpu::TextureUsages,
    ) -> Result<Self, GpuError> {
        gpu.scoped(label, || {
            let t = texture(gpu, label, (size, size, 6), CUBE_FORMAT, usage);
            let cube_view = t.create_view(&wgpu::TextureViewDescriptor {
                label: Some(label),
                dimension: Some(wgpu::TextureViewDimension::Cube),
                ..Default::default()
            });
            let face_views = if usage.contains(wgpu::TextureUsages::RENDER_ATTACHMENT) {
                (0..6)
                    .map(|layer| {
                        t.create_view(&wgpu::TextureViewDescriptor {
                            label: Some(label),
                            dimension: Some(wgpu::TextureViewDimension::D2),
                            base_array_layer: layer,
                            array_layer_count: Some(1),
                            ..Default::default()
                        })
                    })
                    .collect()
            } else {
                Vec::new()
            };
            CubeMap { size, cube_view, face_views }
        })
    }
}

/// Every cube map of a frame: the glass's, its coarse copy (an eighth of the side, the
/// prefiltered level for wide lookups), the metal's, the 1 x 1 placeholder, and the depth
/// buffers the faces share (each face clears its depth).
pub struct CubeSet {
    pub glass: CubeMap,
    pub glass_coarse: CubeMap,
    pub metal: CubeMap,
    pub placeholder: CubeMap,
    pub depth: wgpu::TextureView,
    pub coarse_depth: wgpu::TextureView,
}

impl CubeSet {
    pub fn new(gpu: &GpuContext, size: u32) -> Result<Self, GpuError> {
        let coarse = crate::uniforms::coarse_cube_size(size);
        Ok(CubeSet {
            glass: CubeMap::new(gpu, "raster glass cube", size)?,
            glass_coarse: CubeMap::new(gpu, "raster coarse glass cube", coarse)?,
            metal: CubeMap::new(gpu, "raster metal cube", size)?,
            placeholder: CubeMap::placeholder(gpu)?,
            depth: cube_depth(gpu, size)?,
            coarse_depth: cube_depth(gpu, coarse)?,
        })
    }
}

/// A depth buffer for cube faces of `size` x `size`.
fn cube_depth(gpu: &GpuContext, size: u32) -> Result<wgpu::TextureView, GpuError> {
    gpu.scoped("creating the cube-map depth buffer", || {
        texture(
            gpu,
            "raster cube depth",
            (size, size, 1),
            DEPTH_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        )
        .create_view(&Default::default())
    })
}

/// The main view's targets: the single-sample output (what is read back or shown) and the depth
/// buffer. Edges are anti-aliased by their analytic coverage, blended into the output, so one
/// sample per pixel suffices.
pub struct MainTargets {
    /// Read back by the native `RasterRenderer::render`; a web page shows `output_view`.
    #[cfg_attr(target_arch = "wasm32", allow(dead_code))]
    pub output: wgpu::Texture,
    pub output_view: wgpu::TextureView,
    pub depth: wgpu::TextureView,
}

/// Checks the main targets of a `width` x `height` frame before creating them: each texture must
/// fit the device's largest single allocation. wgpu has no limit for a texture's bytes;
/// `max_buffer_size` is the device's allocation limit that it does report, and a target beyond it
/// fails on lavapipe with an unhelpful "texture is invalid". The error names the size, the bytes
/// and the way out.
pub fn check_main_targets(limits: &wgpu::Limits, width: u32, height: u32) -> Result<(), String> {
    // The output (RGBA8) and the depth buffer (32-bit float) both take 4 bytes a pixel.
    let bytes = u64::from(width) * u64::from(height) * 4;
    if bytes > limits.max_buffer_size {
        return Err(format!(
            "camera.width x camera.height = {width} x {height}: the output and the depth buffer need \
             {:.2} GiB each, more than the {:.2} GiB the device allows in one allocation \
             (max_buffer_size); render at a smaller size",
            bytes as f64 / (1u64 << 30) as f64,
            limits.max_buffer_size as f64 / (1u64 << 30) as f64,
        ));
    }
    Ok(())
}

impl MainTargets {
    pub fn new(gpu: &GpuContext, width: u32, height: u32) -> Result<Self, GpuError> {
        gpu.scoped("creating the main render targets", || {
            let output = texture(
                gpu,
                "raster output",
                (width, height, 1),
                OUTPUT_FORMAT,
                wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::COPY_SRC
                    | wgpu::TextureUsages::TEXTURE_BINDING,
            );
            let output_view = output.create_view(&Default::default());
            let depth = texture(
                gpu,
                "raster main depth",
                (width, height, 1),
                DEPTH_FORMAT,
                wgpu::TextureUsages::RENDER_ATTACHMENT,
            )
            .create_view(&Default::default());
            MainTargets { output, output_view, depth }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn targets_beyond_one_allocation_are_refused_with_the_way_out() {
        let limits = wgpu::Limits { max_buffer_size: 512 << 20, ..wgpu::Limits::default() };
        let err = check_main_targets(&limits, 16384, 16384).unwrap_err();
        assert!(err.contains("16384 x 16384") && err.contains("smaller size"), "{err}");
        assert!(err.contains("1.00 GiB") && err.contains("0.50 GiB"), "{err}");
        assert!(check_main_targets(&limits, 8192, 8192).is_ok());
        assert!(check_main_targets(&limits, 1280, 720).is_ok());
    }
}
