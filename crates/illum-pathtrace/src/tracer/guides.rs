//! A denoiser's guide buffers: per pixel, the albedo and normal of the first non-specular
//! surface its camera paths meet, through mirrors and glass (`shaders/guides.wgsl` says how).
//!
//! A pass of its own, compiled only when a caller asks for guides, from the path tracer's
//! modules and shader defs: it follows the same camera rays and specular choices as the
//! image's samples of the same indices, and adds no code to the integrator.

#[cfg(not(target_arch = "wasm32"))]
use illum_gpu::buffers::{buffer_bind_group, dispatch};
#[cfg(not(target_arch = "wasm32"))]
use illum_gpu::readback;
#[cfg(not(target_arch = "wasm32"))]
use illum_gpu::wgpu;
#[cfg(not(target_arch = "wasm32"))]
use wgpu::util::DeviceExt;

#[cfg(not(target_arch = "wasm32"))]
use super::PathTracer;
#[cfg(not(target_arch = "wasm32"))]
use crate::gpu_scene::GpuScene;
#[cfg(not(target_arch = "wasm32"))]
use crate::{PathTraceError, shaders};

/// Samples per pixel the guides average at most: albedo and normal are bounded and mostly
/// constant over a pixel, so their mean settles long before the radiance's does. On lavapipe a
/// guide sample costs about a fifth of a path (the camera ray and its specular chain only), so
/// 16 of them cost about 3 spp of the path tracer (docs/denoising.md).
pub const GUIDE_SAMPLES: u32 = 16;

/// The guide buffers of an image, row-major like it.
#[derive(Clone, Debug, PartialEq)]
pub struct Guides {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel averaged.
    pub samples: u32,
    /// Mean albedo of the first non-specular surface (times the specular chain's reflectance).
    pub albedo: Vec<[f32; 3]>,
    /// Mean world-space normal there, facing the camera ray (shorter than 1 across an edge).
    pub normal: Vec<[f32; 3]>,
}

// Native only: it waits for the GPU, which a web page cannot.
#[cfg(not(target_arch = "wasm32"))]
impl PathTracer {
    /// The guide buffers over this tracer's sample indices `offset .. offset + n`, with
    /// `offset` its [`Self::sample_offset`] and `n = samples.clamp(1, GUIDE_SAMPLES)`. Blocks
    /// until the GPU is done. Fails, naming the limit, for an image whose guides do not fit one
    /// storage binding of the device.
    pub fn guides(&self, samples: u32) -> Result<Guides, PathTraceError> {
        let pipeline = &self.pipeline;
        let (gpu, scene) = (&pipeline.gpu, &pipeline.scene);
        let (width, height) = (scene.camera.width, scene.camera.height);
        let pixels = u64::from(width) * u64::from(height);
        let bytes = pixels * 16;
        let limits = gpu.device.limits();
        let max_binding = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
        if bytes > max_binding {
            return Err(PathTraceError::Unsupported {
                scene: scene.name.clone(),
                message: format!(
                    "camera.width x camera.height = {width} x {height}: a guide buffer (16 bytes per pixel) needs \
                     {bytes} bytes, over the device's storage binding limit of {max_binding}; render smaller or \
                     without a denoiser"
                ),
            });
        }
        let samples = samples.clamp(1, GUIDE_SAMPLES);
        let gpu_scene = GpuScene::new(scene)?;
        let compute = shaders::companion_pipeline(
            gpu,
            scene,
            &gpu_scene,
            pipeline.options,
            &shaders::GUIDES_SHADER,
            "guide buffers",
        )?;
        let mut params = pipeline.base_params;
        params.row_offset = 0;
        params.rows = height;
        params.sample_base = self.sample_offset();
        params.sample_count = samples;
        let device = &gpu.device;
        let output = |label: &str| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            })
        };
        let (params_buffer, albedo, normal) = gpu.scoped("allocating the guide buffers", || {
            let params_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("guide params"),
                contents: bytemuck::bytes_of(&params),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            (params_buffer, output("guide albedo"), output("guide normal"))
        })?;
        // The scene's inputs the guides read: parameters (their own), and with the generic
        // traversal the objects and materials; never the lights or adaptive sampling's counts.
        let mut bound: Vec<(u32, &wgpu::Buffer)> =
            pipeline.inputs().into_iter().filter(|&(binding, _)| binding == 1 || binding == 2).collect();
        bound.extend([(0, &params_buffer), (8, &albedo), (9, &normal)]);
        let layout = compute.get_bind_group_layout(0);
        let bind_group = buffer_bind_group(device, "guide buffers", &layout, &bound);
        let mut encoder = device.create_command_encoder(&Default::default());
        dispatch(
            &mut encoder,
            "guide buffers",
            &compute,
            &bind_group,
            [width.div_ceil(8), height.div_ceil(8), 1],
        );
        gpu.queue.submit([encoder.finish()]);
        let read = |buffer: &wgpu::Buffer| -> Result<Vec<[f32; 3]>, PathTraceError> {
            let bytes = readback::read_buffer(gpu, buffer, 0, bytes, "reading back the guide buffers")?;
            Ok(crate::batch::decode_slots(&bytes).into_iter().map(|[x, y, z, _]| [x, y, z]).collect())
        };
        Ok(Guides { width, height, samples, albedo: read(&albedo)?, normal: read(&normal)? })
    }
}
