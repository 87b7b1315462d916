//! The path tracer's display on the GPU.
//!
//! The path tracer keeps its statistics on the CPU by design (batches of f32 sums folded into
//! f64 per pixel), but the viewer does not show those: it enables the tracer's display sum
//! (`PathTracer::enable_display_sum`), a storage buffer on eframe's device to which every band's
//! submission adds its samples on the GPU (rgb = sum of finite samples, w = their count). A
//! render pass here reads that buffer directly in its fragment shader, divides rgb by w, applies
//! the display exposure and the PNG output's gamma 2.2, and writes an 8-bit texture registered
//! with egui_wgpu. The image never goes through the CPU on its way to the screen; nothing is
//! uploaded or read back. The pass re-runs when new samples arrived or the exposure changed.
//! Saving still uses the f64 mean (`Accumulator::mean_image`). The image's exact part (the sun's
//! glint, `illum_pathtrace::ImageParts`), which the tracer solves on the host and which the display
//! sum's samples do not hold, comes as a second per-pixel buffer, written when it changes (a
//! camera move), and the shader adds it to every pixel with a sample, as `ImageParts` does.

use bytemuck::{Pod, Zeroable};
use egui_wgpu::wgpu;
use illum_gpu::GpuContext;
use illum_pathtrace::{DISPLAY_PIXEL_BYTES, ExactPart};

const SHADER: &str = include_str!("../shaders/display.wgsl");
/// The texture egui shows: 8-bit, already gamma-encoded (egui's convention for native textures).
const TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// Mirrors `Params` in display.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct Params {
    width: u32,
    /// 2^exposure.
    scale: f32,
    pad: [u32; 2],
}

/// The texture egui shows.
struct Target {
    width: u32,
    height: u32,
    /// Read back by `read_shown` (native tests); the window shows `view`.
    #[cfg_attr(target_arch = "wasm32", allow(dead_code))]
    texture: wgpu::Texture,
    view: wgpu::TextureView,
}

/// Tone mapping from the path tracer's display sum into the texture egui shows.
pub struct Display {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    target: Option<Target>,
    /// The display-sum buffer read and its bind group: a tracer rebuilt for a new resolution
    /// brings a new buffer, and the bind group is made again for it.
    source: Option<(wgpu::Buffer, wgpu::BindGroup)>,
    /// The egui texture id of the target, once registered.
    texture_id: Option<egui::TextureId>,
    /// The exact part per pixel (`vec4<f32>` each, rgb in the display sum's units), and the
    /// exact part and scale it was written from.
    exact: Option<(wgpu::Buffer, ExactPart, f32)>,
}

impl Display {
    pub fn new(gpu: &GpuContext) -> Self {
        let device = &gpu.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("viewer display"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("viewer display"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: true },
                        has_dynamic_offset: false,
                        min_binding_size: wgpu::BufferSize::new(DISPLAY_PIXEL_BYTES),
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: true },
                        has_dynamic_offset: false,
                        min_binding_size: wgpu::BufferSize::new(16),
                    },
                    count: None,
                },
            ],
        });
        let pipeline_layout = illum_gpu::buffers::pipeline_layout(device, "viewer display", &[&layout]);
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("viewer display"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(TARGET_FORMAT.into())],
            }),
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            multiview_mask: None,
            cache: None,
        });
        let params = illum_gpu::buffers::uniform_buffer(
            device,
            "viewer display params",
            std::mem::size_of::<Params>() as u64,
        );
        Display { pipeline, layout, params, target: None, source: None, texture_id: None, exact: None }
    }

    /// Draws the `width` x `height` image held by `display_sum` (the path tracer's display-sum
    /// buffer, on the same device) with `exposure` stops into the shown texture, (re)creating
    /// and (re)registering that texture with egui when its size changed. `exact`: the image's
    /// exact part (`Accumulator::exact`, radiance), multiplied by `exact_scale` into the display
    /// sum's units. Returns its egui id.
    #[allow(clippy::too_many_arguments)]
    pub fn show(
        &mut self,
        gpu: &GpuContext,
        renderer: &mut egui_wgpu::Renderer,
        display_sum: &wgpu::Buffer,
        [width, height]: [u32; 2],
        exposure: f32,
        exact: &ExactPart,
        exact_scale: f32,
    ) -> Option<egui::TextureId> {
        let needed = u64::from(width) * u64::from(height) * DISPLAY_PIXEL_BYTES;
        if width == 0 || height == 0 || display_sum.size() < needed {
            log::warn!(
                "display sum of {} bytes cannot hold a {width} x {height} image; not shown",
                display_sum.size()
            );
            return self.texture_id;
        }
        let resized = self.target.as_ref().is_none_or(|t| (t.width, t.height) != (width, height));
        if resized {
            self.target = Some(Self::create_target(gpu, width, height));
        }
        let pixels = u64::from(width) * u64::from(height);
        let exact_changed = self.exact.as_ref().is_none_or(|(buffer, shown, scale)| {
            buffer.size() != pixels * 16 || shown != exact || *scale != exact_scale
        });
        if exact_changed {
            let values = exact.dense(pixels as usize, exact_scale);
            let reuse = self.exact.take().filter(|(buffer, _, _)| buffer.size() == pixels * 16);
            let buffer = reuse.map_or_else(
                || {
                    gpu.device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some("viewer display exact part"),
                        size: pixels * 16,
                        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                        mapped_at_creation: false,
                    })
                },
                |(buffer, _, _)| buffer,
            );
            gpu.queue.write_buffer(&buffer, 0, bytemuck::cast_slice(&values));
            self.exact = Some((buffer, exact.clone(), exact_scale));
            // The bind group names the exact part's buffer, which may be a new one.
            self.source = None;
        }
        if self.source.as_ref().is_none_or(|(bound, _)| bound != display_sum) {
            let exact_buffer = &self.exact.as_ref().expect("written above").0;
            let bind_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("viewer display"),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: display_sum.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: self.params.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: exact_buffer.as_entire_binding() },
                ],
            });
            self.source = Some((display_sum.clone(), bind_group));
        }
        self.redraw(gpu, exposure);
        let target = self.target.as_ref()?;
        let id = match (self.texture_id, resized) {
            (Some(id), false) => id,
            (Some(id), true) => {
                renderer.update_egui_texture_from_wgpu_texture(
                    &gpu.device,
                    &target.view,
                    wgpu::FilterMode::Linear,
                    id,
                );
                id
            }
            (None, _) => {
                renderer.register_native_texture(&gpu.device, &target.view, wgpu::FilterMode::Linear)
            }
        };
        self.texture_id = Some(id);
        Some(id)
    }

    /// Draws the display sum last shown again, with another exposure.
    pub fn redraw(&self, gpu: &GpuContext, exposure: f32) {
        let (Some(target), Some((_, bind_group))) = (&self.target, &self.source) else { return };
        let params = Params { width: target.width, scale: 2f32.powf(exposure), pad: [0; 2] };
        gpu.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("viewer display") });
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("viewer display"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &target.view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, bind_group, &[]);
            pass.draw(0..3, 0..1);
        }
        gpu.queue.submit([encoder.finish()]);
    }

    /// The egui id of the shown texture, once an image has been shown.
    pub fn texture_id(&self) -> Option<egui::TextureId> {
        self.texture_id
    }

    /// The shown texture read back (RGBA, gamma-encoded, top row first), once an image has been
    /// shown; for tests, which compare it with the saved PNG. The window itself never reads it.
    /// Waits for the GPU: native only.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn read_shown(&self, gpu: &GpuContext) -> Result<Option<image::RgbaImage>, illum_gpu::GpuError> {
        let Some(target) = &self.target else { return Ok(None) };
        let (width, height) = (target.width, target.height);
        // Texture-to-buffer copies need rows padded to 256 bytes.
        let row = u64::from(width) * 4;
        let padded = row.next_multiple_of(u64::from(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT));
        let staging = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("viewer display readback"),
            size: padded * u64::from(height),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("viewer display readback"),
        });
        encoder.copy_texture_to_buffer(
            target.texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &staging,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded as u32),
                    rows_per_image: Some(height),
                },
            },
            wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
        );
        gpu.queue.submit([encoder.finish()]);
        let bytes =
            illum_gpu::readback::read_mapped(gpu, &staging, staging.size(), "reading the display back")?;
        let pixels: Vec<u8> =
            bytes.chunks_exact(padded as usize).flat_map(|r| r[..row as usize].iter().copied()).collect();
        Ok(image::RgbaImage::from_raw(width, height, pixels))
    }

    fn create_target(gpu: &GpuContext, width: u32, height: u32) -> Target {
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("viewer display target"),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: TARGET_FORMAT,
            // COPY_SRC: tests read it back (`read_shown`).
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        Target { width, height, texture, view }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shader parses and validates without a GPU.
    #[test]
    fn display_shader_validates() {
        let module = wgpu::naga::front::wgsl::parse_str(SHADER)
            .unwrap_or_else(|e| panic!("{}", e.emit_to_string(SHADER)));
        wgpu::naga::valid::Validator::new(
            wgpu::naga::valid::ValidationFlags::all(),
            wgpu::naga::valid::Capabilities::empty(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{e:?}"));
    }
}
