//! The path tracer's display on the GPU.
//!
//! The path tracer keeps its statistics on the CPU by design (batches of f32 sums folded into
//! f64 per pixel), so its mean image is uploaded once per frame in which new samples arrived, as
//! linear f32 RGBA. A render pass then applies the display exposure and the PNG output's gamma
//! 2.2 into an 8-bit texture registered with egui_wgpu, on eframe's device. Changing the
//! exposure re-runs only that pass; nothing is read back.

use egui_wgpu::wgpu;
use illum_gpu::GpuContext;
use illum_image::RgbImage32;

const SHADER: &str = include_str!("../../../shaders/viewer/display.wgsl");
/// The texture egui shows: 8-bit, already gamma-encoded (egui's convention for native textures).
const TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// The uploaded linear mean image.
const SOURCE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

struct Textures {
    width: u32,
    height: u32,
    source: wgpu::Texture,
    target_view: wgpu::TextureView,
    bind_group: wgpu::BindGroup,
}

/// Tone mapping from the uploaded mean image into the texture egui shows.
pub struct Display {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    textures: Option<Textures>,
    /// The egui texture id of the target, once registered.
    texture_id: Option<egui::TextureId>,
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
                    ty: wgpu::BindingType::Texture {
                        // f32 textures are not filterable everywhere; the shader only loads texels.
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
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
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("viewer display"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
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
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("viewer display params"),
            size: 16,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Display { pipeline, layout, params, textures: None, texture_id: None }
    }

    /// Uploads `image` (linear RGB) and draws it with `exposure` stops into the shown texture,
    /// (re)registering that texture with egui when its size changed. Returns its egui id.
    pub fn show(
        &mut self,
        gpu: &GpuContext,
        renderer: &mut egui_wgpu::Renderer,
        image: &RgbImage32,
        exposure: f32,
    ) -> Option<egui::TextureId> {
        if image.width == 0 || image.height == 0 || !image.is_consistent() {
            return self.texture_id;
        }
        let resized =
            self.textures.as_ref().is_none_or(|t| (t.width, t.height) != (image.width, image.height));
        if resized {
            self.textures = Some(self.create_textures(gpu, image.width, image.height));
        }
        let textures = self.textures.as_ref()?;
        let texels: Vec<[f32; 4]> = image.pixels.iter().map(|&[r, g, b]| [r, g, b, 1.0]).collect();
        gpu.queue.write_texture(
            textures.source.as_image_copy(),
            bytemuck::cast_slice(&texels),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(image.width * 16),
                rows_per_image: Some(image.height),
            },
            wgpu::Extent3d { width: image.width, height: image.height, depth_or_array_layers: 1 },
        );
        self.redraw(gpu, exposure);
        let textures = self.textures.as_ref()?;
        let id = match (self.texture_id, resized) {
            (Some(id), false) => id,
            (Some(id), true) => {
                renderer.update_egui_texture_from_wgpu_texture(
                    &gpu.device,
                    &textures.target_view,
                    wgpu::FilterMode::Linear,
                    id,
                );
                id
            }
            (None, _) => {
                renderer.register_native_texture(&gpu.device, &textures.target_view, wgpu::FilterMode::Linear)
            }
        };
        self.texture_id = Some(id);
        Some(id)
    }

    /// Re-encodes the last uploaded image with another exposure (no upload).
    pub fn redraw(&self, gpu: &GpuContext, exposure: f32) {
        let Some(textures) = &self.textures else { return };
        let scale = 2f32.powf(exposure);
        gpu.queue.write_buffer(&self.params, 0, bytemuck::cast_slice(&[scale, 0.0, 0.0, 0.0]));
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("viewer display") });
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("viewer display"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &textures.target_view,
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
            pass.set_bind_group(0, &textures.bind_group, &[]);
            pass.draw(0..3, 0..1);
        }
        gpu.queue.submit([encoder.finish()]);
    }

    /// The egui id of the shown texture, once an image has been shown.
    pub fn texture_id(&self) -> Option<egui::TextureId> {
        self.texture_id
    }

    fn create_textures(&self, gpu: &GpuContext, width: u32, height: u32) -> Textures {
        let size = wgpu::Extent3d { width, height, depth_or_array_layers: 1 };
        let texture = |label, format, usage| {
            gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let source = texture(
            "viewer display source",
            SOURCE_FORMAT,
            wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        );
        let target = texture(
            "viewer display target",
            TARGET_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let source_view = source.create_view(&Default::default());
        let target_view = target.create_view(&Default::default());
        let bind_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("viewer display"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&source_view),
                },
                wgpu::BindGroupEntry { binding: 1, resource: self.params.as_entire_binding() },
            ],
        });
        Textures { width, height, source, target_view, bind_group }
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
