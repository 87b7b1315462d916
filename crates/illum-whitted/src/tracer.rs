//! The Whitted ray tracer's GPU side: buffers, the compute pipeline, one dispatch, readback.

use illum_gpu::shader::{self, ShaderFile};
use illum_gpu::{GpuContext, GpuError, readback, shader_file, wgpu};
use illum_image::RgbImage32;
use illum_pathtrace::gpu_scene::{ObjectRecord, ordered_objects};
use illum_pathtrace::{GEOMETRY_MODULE, SPAWN_MODULE};
use illum_scene::{Scene, SceneError};
use wgpu::util::DeviceExt;

use crate::encode::{self, FEATURES_BUT, WhittedLight, WhittedMaterial};

/// The entry shader (entry point `main`).
pub const WHITTED_SHADER: ShaderFile = shader_file!("shaders/whitted/whitted.wgsl");

/// Workgroup side of the entry point (8 x 8 pixels).
const WORKGROUP: u32 = 8;
/// Bytes per pixel of the output buffer (a vec4 of f32).
const PIXEL_BYTES: u64 = 16;

/// Why the Whitted ray tracer could not render.
#[derive(Debug, thiserror::Error)]
pub enum WhittedError {
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error(transparent)]
    Scene(#[from] SceneError),
}

/// The modules the entry shader imports, in import order.
pub fn shader_modules() -> Vec<ShaderFile> {
    vec![SPAWN_MODULE, GEOMETRY_MODULE]
}

/// Whitted's algorithm on one scene, at the scene's resolution, depth and anti-aliasing.
pub struct WhittedTracer {
    gpu: GpuContext,
    width: u32,
    height: u32,
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    image: wgpu::Buffer,
}

impl WhittedTracer {
    /// Uploads `scene`, or says which of its features Whitted's algorithm does not model or why
    /// the device cannot hold its image.
    pub fn new(gpu: &GpuContext, scene: &Scene) -> Result<Self, WhittedError> {
        scene.require_where("Whitted ray tracer", |f| f != FEATURES_BUT)?;
        let (width, height) = (scene.camera.width, scene.camera.height);
        let bytes = u64::from(width) * u64::from(height) * PIXEL_BYTES;
        let limit = gpu.device.limits().max_storage_buffer_binding_size;
        if bytes > limit {
            return Err(SceneError::invalid(
                &format!("scene {:?}", scene.name),
                "camera.width x camera.height",
                format!("{width} x {height} ({bytes} bytes of image)"),
                format!("must fit in {limit} bytes, the device's max_storage_buffer_binding_size"),
            )
            .into());
        }
        let (objects, first_emitter) = ordered_objects(scene);
        let records: Vec<ObjectRecord> = objects.iter().map(|(_, o)| o.record()).collect();
        let materials = encode::materials(scene);
        let lights = encode::lights(scene);
        let params = encode::params(scene, records.len() as u32, first_emitter, lights.len() as u32);

        let device = &gpu.device;
        // Storage buffers may not be empty: a scene without lights binds one unused record.
        let storage =
            |label: &str, contents: &[u8]| illum_gpu::buffers::storage_buffer(device, label, contents);
        let lights_or_one = if lights.is_empty() { vec![WhittedLight::default()] } else { lights };
        let materials_or_one =
            if materials.is_empty() { vec![WhittedMaterial::default()] } else { materials };
        let pipeline =
            shader::compute_pipeline(gpu, &shader_modules(), &WHITTED_SHADER, &[], "whitted ray tracer")?;
        let (bind_group, image) = gpu.scoped("creating the Whitted ray tracer's buffers", || {
            let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("whitted params"),
                contents: bytemuck::bytes_of(&params),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let objects = storage("whitted objects", bytemuck::cast_slice(&records));
            let materials = storage("whitted materials", bytemuck::cast_slice(&materials_or_one));
            let lights = storage("whitted lights", bytemuck::cast_slice(&lights_or_one));
            let image = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("whitted image"),
                size: bytes,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("whitted"),
                layout: &pipeline.get_bind_group_layout(0),
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: params.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: objects.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: materials.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 3, resource: lights.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 4, resource: image.as_entire_binding() },
                ],
            });
            (bind_group, image)
        })?;
        Ok(WhittedTracer { gpu: gpu.clone(), width, height, pipeline, bind_group, image })
    }

    /// Renders the image: linear radiance per pixel, row-major from the top-left.
    pub fn render(&self) -> Result<RgbImage32, WhittedError> {
        self.dispatch();
        let bytes = u64::from(self.width) * u64::from(self.height) * PIXEL_BYTES;
        let data = readback::read_buffer(&self.gpu, &self.image, 0, bytes, "reading the Whitted image")?;
        self.gpu.check()?;
        Ok(self.decode(&data))
    }

    /// [`Self::render`] without waiting (what a web page needs): submits the frame and starts
    /// its readback; [`PendingImage::poll`] on later frames returns the image.
    pub fn render_polled(&self) -> PendingImage {
        self.dispatch();
        let bytes = u64::from(self.width) * u64::from(self.height) * PIXEL_BYTES;
        let staging = self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("whitted staging"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("whitted readback") });
        encoder.copy_buffer_to_buffer(&self.image, 0, &staging, 0, bytes);
        self.gpu.queue.submit([encoder.finish()]);
        PendingImage {
            read: readback::PendingRead::start(staging, bytes, "reading the Whitted image"),
            width: self.width,
            height: self.height,
        }
    }

    fn decode(&self, data: &[u8]) -> RgbImage32 {
        decode_image(self.width, self.height, data)
    }

    fn dispatch(&self) {
        let mut encoder = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("whitted") });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("whitted"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.bind_group, &[]);
            pass.dispatch_workgroups(self.width.div_ceil(WORKGROUP), self.height.div_ceil(WORKGROUP), 1);
        }
        self.gpu.queue.submit([encoder.finish()]);
    }
}

/// A Whitted frame whose readback is under way ([`WhittedTracer::render_polled`]).
pub struct PendingImage {
    read: readback::PendingRead,
    width: u32,
    height: u32,
}

impl PendingImage {
    /// `None` while the image is still being read back; never waits.
    pub fn poll(&self, gpu: &GpuContext) -> Option<Result<RgbImage32, WhittedError>> {
        let data = self.read.poll(gpu)?;
        Some(data.map_err(WhittedError::from).and_then(|data| {
            gpu.check()?;
            Ok(decode_image(self.width, self.height, &data))
        }))
    }
}

/// The image buffer's RGBA f32 texels as linear RGB.
fn decode_image(width: u32, height: u32, data: &[u8]) -> RgbImage32 {
    // The mapped copy has no alignment guarantee, so read the floats one by one.
    let floats: Vec<f32> =
        data.chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes"))).collect();
    let mut image = RgbImage32::new(width, height);
    for (pixel, texel) in image.pixels.iter_mut().zip(floats.chunks_exact(4)) {
        *pixel = [texel[0], texel[1], texel[2]];
    }
    image
}

#[cfg(test)]
mod tests {
    use std::mem::size_of;

    use illum_gpu::members;
    use illum_gpu::shader::wgsl_struct;

    use super::*;
    use crate::encode::WhittedParams;

    /// The shader composes and validates without a GPU, and the Rust records have naga's layout
    /// of the WGSL structs.
    #[test]
    fn the_shader_validates_and_the_records_match_its_structs() {
        let module =
            shader::compose(&shader_modules(), &WHITTED_SHADER, &[]).unwrap_or_else(|e| panic!("{e}"));
        let mut validator = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        );
        validator.validate(&module).unwrap_or_else(|e| panic!("whitted.wgsl: {e:?}"));
        let wgsl = |name: &str| {
            wgsl_struct(&module, "", name).unwrap_or_else(|| panic!("no struct {name} in whitted.wgsl"))
        };
        wgsl("Params").assert_matches(
            size_of::<WhittedParams>(),
            &members!(WhittedParams: eye, right, up, forward, background, ambient, mirror_specular, shading,
                sizes, counts),
        );
        wgsl("Material").assert_matches(
            size_of::<WhittedMaterial>(),
            &members!(WhittedMaterial: kind, pad0, pad1, pad2, a, b),
        );
        wgsl("Light").assert_matches(
            size_of::<WhittedLight>(),
            &members!(WhittedLight: kind, pad0, pad1, pad2, a, normal, power),
        );
    }
}
