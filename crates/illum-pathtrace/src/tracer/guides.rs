//! A denoiser's guide buffers: per pixel, the albedo and normal of the first non-specular
//! surface its camera paths meet, through mirrors and glass (`shaders/guides.wgsl` says how).
//!
//! A pass of its own, compiled only when a caller asks for guides, from the path tracer's
//! modules and shader defs: it follows the same camera rays as the image's samples of the
//! same indices, and adds no code to the integrator. Read back either
//! waiting ([`PathTracer::guides`], native) or polled over later frames
//! ([`PathTracer::start_guides`], the viewer, which must not wait in a web page).

use illum_gpu::buffers::{buffer_bind_group, dispatch};
#[cfg(not(target_arch = "wasm32"))]
use illum_gpu::readback;
use illum_gpu::readback::PendingRead;
use illum_gpu::wgpu;
use wgpu::util::DeviceExt;

use super::PathTracer;
use crate::bindings::Binding;
use crate::gpu_scene::GpuScene;
use crate::{PathTraceError, shaders};

/// Samples per pixel the guides of a denoised image average at least: below about 16 a pixel
/// that straddles an edge gets a guide far from its image's mix of the two sides.
pub const GUIDE_SAMPLES_MIN: u32 = 16;
/// Samples per pixel one guide pass averages at most: one dispatch, so it stays short on any
/// GPU (256 guide samples cost about 50 spp of the path tracer on lavapipe).
pub const GUIDE_SAMPLES_MAX: u32 = 256;

/// The guide samples for an image of `image_spp` samples per pixel: as many as the image has,
/// within [`GUIDE_SAMPLES_MIN`] ..= [`GUIDE_SAMPLES_MAX`]. A pixel across an edge (a checker
/// square's, an object's) mixes the two sides in the proportion its samples fell; a guide of
/// the same samples mixes them alike, so the filter's albedo stop compares like with like (the
/// guides see the image's camera rays: `shaders/guides.wgsl`). With 16 guide samples at every
/// spp the filter lost to the raw image on the Whitted scene from 64 spp on (docs/denoising.md).
pub fn guide_samples(image_spp: u32) -> u32 {
    image_spp.clamp(GUIDE_SAMPLES_MIN, GUIDE_SAMPLES_MAX)
}

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

/// The guide pass submitted: its two output buffers, `bytes` long each.
struct GuideOutput {
    width: u32,
    height: u32,
    samples: u32,
    bytes: u64,
    albedo: wgpu::Buffer,
    normal: wgpu::Buffer,
}

impl GuideOutput {
    /// The guides from the albedo buffer's bytes followed by the normal buffer's.
    fn decode(&self, albedo: &[u8], normal: &[u8]) -> Guides {
        let decode = |bytes: &[u8]| -> Vec<[f32; 3]> {
            crate::batch::decode_slots(bytes).into_iter().map(|[x, y, z, _]| [x, y, z]).collect()
        };
        Guides {
            width: self.width,
            height: self.height,
            samples: self.samples,
            albedo: decode(albedo),
            normal: decode(normal),
        }
    }
}

/// Guide buffers being read back without waiting ([`PathTracer::start_guides`]).
pub struct PendingGuides {
    output: GuideOutput,
    read: PendingRead,
}

impl PendingGuides {
    /// `None` while the readback is under way, then the guides or the mapping's error. Never
    /// waits.
    pub fn poll(&self, gpu: &illum_gpu::GpuContext) -> Option<Result<Guides, PathTraceError>> {
        let bytes = match self.read.poll(gpu)? {
            Ok(bytes) => bytes,
            Err(e) => return Some(Err(e.into())),
        };
        let half = self.output.bytes as usize;
        Some(Ok(self.output.decode(&bytes[..half], &bytes[half..2 * half])))
    }
}

impl PathTracer {
    /// The guide buffers over this tracer's sample indices `offset .. offset + n`, with
    /// `offset` its [`Self::sample_offset`] and `n = samples.clamp(1, GUIDE_SAMPLES_MAX)`. Blocks
    /// until the GPU is done (native only: a web page cannot wait). Fails, naming the limit,
    /// for an image whose guides do not fit one storage binding of the device.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn guides(&self, samples: u32) -> Result<Guides, PathTraceError> {
        let output = self.submit_guides(samples)?;
        let gpu = &self.pipeline.gpu;
        let read = |buffer: &wgpu::Buffer| {
            readback::read_buffer(gpu, buffer, 0, output.bytes, "reading back the guide buffers")
        };
        let (albedo, normal) = (read(&output.albedo)?, read(&output.normal)?);
        Ok(output.decode(&albedo, &normal))
    }

    /// [`Self::guides`] without waiting: submits the pass and a copy of both buffers into one
    /// mappable buffer, whose readback [`PendingGuides::poll`] collects on later frames.
    pub fn start_guides(&self, samples: u32) -> Result<PendingGuides, PathTraceError> {
        let output = self.submit_guides(samples)?;
        let gpu = &self.pipeline.gpu;
        let staging = gpu.scoped("allocating the guides' readback buffer", || {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("guide readback"),
                size: 2 * output.bytes,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        })?;
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&output.albedo, 0, &staging, 0, output.bytes);
        encoder.copy_buffer_to_buffer(&output.normal, 0, &staging, output.bytes, output.bytes);
        gpu.queue.submit([encoder.finish()]);
        let read = PendingRead::start(staging, 2 * output.bytes, "reading back the guide buffers");
        Ok(PendingGuides { output, read })
    }

    /// Encodes and submits the guide pass.
    fn submit_guides(&self, samples: u32) -> Result<GuideOutput, PathTraceError> {
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
        let samples = samples.clamp(1, GUIDE_SAMPLES_MAX);
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
        let mut bound: Vec<(u32, &wgpu::Buffer)> = pipeline
            .inputs()
            .into_iter()
            .filter(|&(binding, _)| {
                binding == Binding::Objects.index() || binding == Binding::Materials.index()
            })
            .collect();
        bound.extend([
            (Binding::Params.index(), &params_buffer),
            (Binding::GuideAlbedo.index(), &albedo),
            (Binding::GuideNormal.index(), &normal),
        ]);
        let layout = compute.get_bind_group_layout(0);
        let bind_group = buffer_bind_group(device, "guide buffers", &layout, &bound);
        // A bind group of an automatic layout serves that pipeline only: the guides bind the BVH
        // anew.
        let bvh = super::pipeline::bvh_bind_group(device, &compute, scene, &gpu_scene, pipeline.options);
        let mut encoder = device.create_command_encoder(&Default::default());
        let workgroups = [width.div_ceil(8), height.div_ceil(8), 1];
        match &bvh {
            None => dispatch(&mut encoder, "guide buffers", &compute, &bind_group, workgroups),
            Some(bvh) => {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("guide buffers"),
                    timestamp_writes: None,
                });
                pass.set_pipeline(&compute);
                pass.set_bind_group(0, &bind_group, &[]);
                bvh.set(&mut pass);
                pass.dispatch_workgroups(workgroups[0], workgroups[1], workgroups[2]);
            }
        }
        gpu.queue.submit([encoder.finish()]);
        Ok(GuideOutput { width, height, samples, bytes, albedo, normal })
    }
}
