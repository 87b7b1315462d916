//! What the passes bind: the uniform buffers (group 0), the samplers, and the texture groups
//! (group 1) as each kind of pass sees them.

use illum_gpu::{GpuContext, GpuError, wgpu};

use crate::frame::VIEW_COUNT;
use crate::targets::{CubeSet, ShadowMap};
use crate::uniforms::{SceneUniform, ViewUniform};

/// Group 0: the scene uniform and the views, one per slot of `frame` (main, cube faces, shadow)
/// at `view_stride` bytes apart, selected by dynamic offset.
pub struct Uniforms {
    pub scene: wgpu::Buffer,
    pub views: wgpu::Buffer,
    pub view_stride: u64,
    pub group: wgpu::BindGroup,
}

impl Uniforms {
    pub fn new(gpu: &GpuContext, layout: &wgpu::BindGroupLayout) -> Result<Self, GpuError> {
        let device = &gpu.device;
        let alignment = u64::from(device.limits().min_uniform_buffer_offset_alignment);
        let view_stride = (std::mem::size_of::<ViewUniform>() as u64).next_multiple_of(alignment);
        let (scene, views) = gpu.scoped("allocating the raster uniforms", || {
            let buffer = |label: &str, size: u64| illum_gpu::buffers::uniform_buffer(device, label, size);
            (
                buffer("raster scene uniform", std::mem::size_of::<SceneUniform>() as u64),
                buffer("raster view uniforms", view_stride * VIEW_COUNT as u64),
            )
        })?;
        let group = gpu.scoped("binding the raster uniforms", || {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("raster uniforms"),
                layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: scene.as_entire_binding() },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                            buffer: &views,
                            offset: 0,
                            size: wgpu::BufferSize::new(std::mem::size_of::<ViewUniform>() as u64),
                        }),
                    },
                ],
            })
        })?;
        Ok(Uniforms { scene, views, view_stride, group })
    }

    /// Writes the scene uniform and the views (in slot order).
    pub fn write(&self, gpu: &GpuContext, scene: &SceneUniform, views: &[ViewUniform; VIEW_COUNT]) {
        gpu.queue.write_buffer(&self.scene, 0, bytemuck::bytes_of(scene));
        let stride = self.view_stride as usize;
        let mut bytes = vec![0u8; stride * VIEW_COUNT];
        for (slot, view) in views.iter().enumerate() {
            bytes[slot * stride..slot * stride + std::mem::size_of::<ViewUniform>()]
                .copy_from_slice(bytemuck::bytes_of(view));
        }
        gpu.queue.write_buffer(&self.views, 0, &bytes);
    }
}

/// The shadow map's two comparison samplers (linear: each tap a 2 x 2 PCF; nearest: one hard
/// test) and the cube maps' bilinear sampler.
pub struct Samplers {
    shadow_filtered: wgpu::Sampler,
    shadow_point: wgpu::Sampler,
    environment: wgpu::Sampler,
}

/// Group 1 as each kind of pass sees it.
pub struct TextureGroups {
    pub glass_capture: wgpu::BindGroup,
    pub metal_capture: wgpu::BindGroup,
    pub main: wgpu::BindGroup,
}

impl Samplers {
    pub fn new(gpu: &GpuContext) -> Result<Self, GpuError> {
        let device = &gpu.device;
        gpu.scoped("creating the raster samplers", || {
            let comparison = |filter: wgpu::FilterMode| {
                device.create_sampler(&wgpu::SamplerDescriptor {
                    label: Some("raster shadow comparison"),
                    address_mode_u: wgpu::AddressMode::ClampToEdge,
                    address_mode_v: wgpu::AddressMode::ClampToEdge,
                    mag_filter: filter,
                    min_filter: filter,
                    // Lit where reference <= stored depth: nothing between the point and the light.
                    compare: Some(wgpu::CompareFunction::LessEqual),
                    ..Default::default()
                })
            };
            Samplers {
                shadow_filtered: comparison(wgpu::FilterMode::Linear),
                shadow_point: comparison(wgpu::FilterMode::Nearest),
                environment: device.create_sampler(&wgpu::SamplerDescriptor {
                    label: Some("raster environment"),
                    mag_filter: wgpu::FilterMode::Linear,
                    min_filter: wgpu::FilterMode::Linear,
                    ..Default::default()
                }),
            }
        })
    }
}

impl TextureGroups {
    /// The shadow map and the cube maps, bound three ways: the glass capture reads no cube map,
    /// the metal capture reads the glass's, the main pass reads both (a placeholder stands in
    /// for a cube map a pass renders).
    pub fn new(
        gpu: &GpuContext,
        layout: &wgpu::BindGroupLayout,
        samplers: &Samplers,
        shadow_map: &ShadowMap,
        cubes: &CubeSet,
    ) -> Result<Self, GpuError> {
        let (glass, coarse, metal, placeholder) =
            (&cubes.glass, &cubes.glass_coarse, &cubes.metal, &cubes.placeholder);
        let group = |label: &str, [glass_view, coarse_view, metal_view]: [&wgpu::TextureView; 3]| {
            gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(label),
                layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(&shadow_map.view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::Sampler(&samplers.shadow_filtered),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: wgpu::BindingResource::Sampler(&samplers.shadow_point),
                    },
                    wgpu::BindGroupEntry {
                        binding: 3,
                        resource: wgpu::BindingResource::TextureView(glass_view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 4,
                        resource: wgpu::BindingResource::TextureView(metal_view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 5,
                        resource: wgpu::BindingResource::Sampler(&samplers.environment),
                    },
                    wgpu::BindGroupEntry {
                        binding: 6,
                        resource: wgpu::BindingResource::TextureView(coarse_view),
                    },
                ],
            })
        };
        gpu.scoped("binding the raster textures", || TextureGroups {
            glass_capture: group("raster glass capture", [&placeholder.cube_view; 3]),
            metal_capture: group(
                "raster metal capture",
                [&glass.cube_view, &coarse.cube_view, &placeholder.cube_view],
            ),
            main: group("raster main", [&glass.cube_view, &coarse.cube_view, &metal.cube_view]),
        })
    }
}
