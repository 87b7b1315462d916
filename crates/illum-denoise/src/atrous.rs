//! The edge-avoiding à-trous wavelet filter on the GPU (`shaders/atrous.wgsl` has the
//! formula): `iterations` dispatches of a 5 x 5 kernel whose taps spread 1, 2, 4, ... pixels,
//! ping-ponging between two storage buffers, in one submission. Read back either waiting
//! ([`AtrousDenoiser::denoise`], native) or polled over later frames
//! ([`AtrousDenoiser::start`], the viewer, which must not wait in a web page).

use illum_gpu::buffers::{buffer_bind_group, dispatch};
#[cfg(not(target_arch = "wasm32"))]
use illum_gpu::readback;
use illum_gpu::readback::PendingRead;
use illum_gpu::shader::{self, ShaderFile};
use illum_gpu::{GpuContext, GpuError, shader_file, wgpu};
use illum_image::RgbImage32;
use wgpu::util::DeviceExt;

use crate::DenoiseError;
use crate::input::DenoiseInput;
use crate::spread::filter_variance;
pub use crate::stops::{NO_NORMAL, NORMAL_POWER, TINY, unit_normals};

/// One iteration of the filter (entry point `main`).
pub const ATROUS_SHADER: ShaderFile = shader_file!("shaders/atrous.wgsl");

/// The filter's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AtrousSettings {
    /// Iterations: the kernel's taps reach 2 x (2^iterations - 1) pixels away.
    pub iterations: u32,
    /// The colour stop's width in standard errors of the pixel's channel (SVGF's sigma_l,
    /// applied to each channel instead of the luminance).
    pub sigma_colour: f32,
    /// The albedo stop's width (a Gaussian in the albedo's Euclidean distance).
    pub sigma_albedo: f32,
}

impl Default for AtrousSettings {
    /// Four iterations (taps up to 30 pixels away), SVGF's sigma_l = 4, and an albedo
    /// difference of 0.05 weighing e^-1: of iterations 4 and 5, sigma_l 2, 4, 8 and 16 and
    /// sigma_a 0.05 and 0.1, the lowest relMSE on the 16-spp Cornell box (docs/denoising.md).
    fn default() -> Self {
        AtrousSettings { iterations: 4, sigma_colour: 4.0, sigma_albedo: 0.05 }
    }
}

/// The filter's output: the image, and each pixel's channel variances after the filter.
pub type Filtered = (RgbImage32, Vec<[f32; 3]>);

/// Bytes of one pixel in the filter's ping-pong buffers: the WGSL `Pixel`, two vec4<f32>.
pub const PIXEL_BYTES: u64 = 32;

/// Mirrors the WGSL `Params`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuParams {
    pub width: u32,
    pub height: u32,
    pub step: u32,
    pub padding: u32,
    pub sigma_colour: f32,
    pub sigma_albedo: f32,
    pub padding_b: f32,
    pub padding_c: f32,
}

/// The compiled filter.
pub struct AtrousDenoiser {
    gpu: GpuContext,
    pipeline: wgpu::ComputePipeline,
}

impl AtrousDenoiser {
    pub fn new(gpu: &GpuContext) -> Result<Self, GpuError> {
        let pipeline = shader::compute_pipeline(gpu, &[], &ATROUS_SHADER, &[], "à-trous denoiser")?;
        Ok(AtrousDenoiser { gpu: gpu.clone(), pipeline })
    }

    /// The filtered image, and the variance of each pixel's channels after the filter. Blocks
    /// until the GPU is done. Fails, naming the limit, for an image whose buffers do not fit
    /// one storage binding of the device.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn denoise(&self, input: &DenoiseInput, settings: &AtrousSettings) -> Result<Filtered, DenoiseError> {
        let (result, bytes) = self.submit(input, settings)?;
        let bytes = readback::read_buffer(&self.gpu, &result, 0, bytes, "reading back the denoised image")?;
        Ok(decode(input.width(), input.height(), &bytes))
    }

    /// [`Self::denoise`] without waiting: submits the filter and a copy of its result into a
    /// mappable buffer, whose readback [`PendingDenoise::poll`] collects on later frames.
    pub fn start(
        &self,
        input: &DenoiseInput,
        settings: &AtrousSettings,
    ) -> Result<PendingDenoise, DenoiseError> {
        let (result, bytes) = self.submit(input, settings)?;
        let gpu = &self.gpu;
        let staging = gpu.scoped("allocating the denoiser's readback buffer", || {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("à-trous readback"),
                size: bytes,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        })?;
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&result, 0, &staging, 0, bytes);
        gpu.queue.submit([encoder.finish()]);
        Ok(PendingDenoise {
            width: input.width(),
            height: input.height(),
            read: PendingRead::start(staging, bytes, "reading back the denoised image"),
        })
    }

    /// Encodes and submits the filter's iterations; returns the buffer holding the result
    /// (colour and channel variances per pixel, [`PIXEL_BYTES`]) and its size in bytes.
    fn submit(
        &self,
        input: &DenoiseInput,
        settings: &AtrousSettings,
    ) -> Result<(wgpu::Buffer, u64), DenoiseError> {
        let (gpu, device) = (&self.gpu, &self.gpu.device);
        let (width, height) = (input.width(), input.height());
        let pixels = width as usize * height as usize;
        let bytes = pixels as u64 * PIXEL_BYTES;
        let limits = device.limits();
        let max_binding = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
        if bytes > max_binding {
            return Err(DenoiseError::Unsupported(format!(
                "denoising a {width} x {height} image needs {bytes}-byte buffers ({PIXEL_BYTES} bytes per pixel), over the \
                 device's storage binding limit of {max_binding}"
            )));
        }
        let vec4 = |rows: &mut dyn Iterator<Item = [f32; 4]>| -> Vec<u8> {
            rows.flat_map(|v| v.map(f32::to_le_bytes)).flatten().collect()
        };
        let variance = filter_variance(input, settings.sigma_albedo);
        let colour = vec4(
            &mut input
                .image
                .pixels
                .iter()
                .zip(&variance)
                .flat_map(|(c, v)| [[c[0], c[1], c[2], 0.0], [v[0], v[1], v[2], 0.0]]),
        );
        let albedo = vec4(&mut input.albedo.iter().map(|a| [a[0], a[1], a[2], 0.0]));
        let normal = vec4(&mut unit_normals(&input.normal).into_iter());
        let iterations = settings.iterations.max(1);
        let (ping, pong, albedo, normal, params) = gpu.scoped("allocating the denoiser's buffers", || {
            let storage = |label: &str, contents: &[u8]| {
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                })
            };
            let params: Vec<wgpu::Buffer> = (0..iterations)
                .map(|i| {
                    let p = GpuParams {
                        width,
                        height,
                        step: 1 << i,
                        padding: 0,
                        sigma_colour: settings.sigma_colour,
                        sigma_albedo: settings.sigma_albedo,
                        padding_b: 0.0,
                        padding_c: 0.0,
                    };
                    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("à-trous params"),
                        contents: bytemuck::bytes_of(&p),
                        usage: wgpu::BufferUsages::UNIFORM,
                    })
                })
                .collect();
            (
                storage("à-trous ping", &colour),
                storage("à-trous pong", &colour),
                storage("à-trous albedo", &albedo),
                storage("à-trous normal", &normal),
                params,
            )
        })?;
        let layout = self.pipeline.get_bind_group_layout(0);
        let mut encoder = device.create_command_encoder(&Default::default());
        let groups = [width.div_ceil(8), height.div_ceil(8), 1];
        for (i, params) in params.iter().enumerate() {
            let (from, to) = if i % 2 == 0 { (&ping, &pong) } else { (&pong, &ping) };
            let bind_group = buffer_bind_group(
                device,
                "à-trous",
                &layout,
                &[(0, params), (1, from), (2, &albedo), (3, &normal), (4, to)],
            );
            dispatch(&mut encoder, "à-trous iteration", &self.pipeline, &bind_group, groups);
        }
        gpu.queue.submit([encoder.finish()]);
        let result = if iterations % 2 == 1 { pong } else { ping };
        Ok((result, bytes))
    }
}

/// A denoised image being read back without waiting ([`AtrousDenoiser::start`]).
pub struct PendingDenoise {
    width: u32,
    height: u32,
    read: PendingRead,
}

impl PendingDenoise {
    /// `None` while the readback is under way, then the filtered image and the variance of each
    /// pixel's channels after the filter, or the mapping's error. Never waits.
    pub fn poll(&self, gpu: &GpuContext) -> Option<Result<Filtered, DenoiseError>> {
        Some(self.read.poll(gpu)?.map(|bytes| decode(self.width, self.height, &bytes)).map_err(Into::into))
    }
}

/// The filter's output buffer (per pixel the WGSL `Pixel`: colour and channel variances, f32)
/// as an image and the variances.
fn decode(width: u32, height: u32, bytes: &[u8]) -> Filtered {
    let values: Vec<f32> =
        bytes.chunks_exact(4).map(|b| f32::from_le_bytes(b.try_into().expect("4 bytes"))).collect();
    let image =
        RgbImage32 { width, height, pixels: values.chunks_exact(8).map(|v| [v[0], v[1], v[2]]).collect() };
    let variance = values.chunks_exact(8).map(|v| [v[4], v[5], v[6]]).collect();
    (image, variance)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shader validates without a GPU, its `Params` has the Rust mirror's layout, and its
    /// `Pixel` the size the buffers are made with.
    #[test]
    fn the_shader_validates_and_its_params_match() {
        let module = shader::compose(&[], &ATROUS_SHADER, &[]).unwrap_or_else(|e| panic!("{e}"));
        shader::validate(&module, &ATROUS_SHADER.path).unwrap_or_else(|e| panic!("{e}"));
        shader::wgsl_struct(&module, "", "Params").expect("struct Params").assert_matches(
            size_of::<GpuParams>(),
            &illum_gpu::members!(GpuParams: width, height, step, padding, sigma_colour, sigma_albedo,
                padding_b, padding_c),
        );
        let pixel = shader::wgsl_struct(&module, "", "Pixel").expect("struct Pixel");
        assert_eq!(u64::from(pixel.size), PIXEL_BYTES, "size of the WGSL Pixel");
    }
}
