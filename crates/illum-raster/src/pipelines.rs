//! Bind group layouts and the render pipelines of the three passes.
//!
//! Group 0 (every pass): the scene uniform and, at a dynamic offset, the current view.
//! Group 1 (floor and spheres): the shadow map, its two comparison samplers, the two cube maps
//! and their sampler, and the glass cube map's coarse copy. The shadow pass uses group 0 only, since it renders the shadow map.
//!
//! A floor or sphere pipeline is fixed to a target (format and sample count) and to the effect
//! switches of its shader (see `variants.rs`); each is made when a frame first needs it.

use std::collections::HashMap;

use illum_gpu::buffers::pipeline_layout;
use illum_gpu::{GpuContext, GpuError, shader, wgpu};

use crate::mesh::MeshVertex;
use crate::shaders::{self, FLOOR_SHADER, MESH_SHADER, SHADOW_SHADER, SPHERES_SHADER};
use crate::targets::{CUBE_FORMAT, DEPTH_FORMAT, OUTPUT_FORMAT};
use crate::uniforms::{SceneUniform, ViewUniform};
use crate::variants::{PipelineKey, Surface, Target};

pub struct Pipelines {
    pub uniforms_layout: wgpu::BindGroupLayout,
    pub textures_layout: wgpu::BindGroupLayout,
    surface_layout: wgpu::PipelineLayout,
    floor_module: wgpu::ShaderModule,
    spheres_module: wgpu::ShaderModule,
    mesh_module: wgpu::ShaderModule,
    pub shadow: wgpu::RenderPipeline,
    /// The meshes' depth into the shadow map (shadow.wgsl's vs_mesh).
    pub mesh_shadow: wgpu::RenderPipeline,
    /// Floor and sphere pipelines, made on first use.
    surfaces: HashMap<PipelineKey, wgpu::RenderPipeline>,
}

fn module(gpu: &GpuContext, file: &shader::ShaderFile) -> Result<wgpu::ShaderModule, GpuError> {
    shader::create_module(gpu, shaders::compose(file)?, &file.path)
}

fn uniform_entry(binding: u32, size: usize, dynamic: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: dynamic,
            min_binding_size: wgpu::BufferSize::new(size as u64),
        },
        count: None,
    }
}

fn fragment_entry(binding: u32, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry { binding, visibility: wgpu::ShaderStages::FRAGMENT, ty, count: None }
}

fn depth_state(compare: wgpu::CompareFunction) -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(true),
        depth_compare: Some(compare),
        stencil: Default::default(),
        bias: Default::default(),
    }
}

/// The bias of the floor drawn after its shadow receiver: its depth must lose to the receiver's
/// on the same plane (two triangulations of one plane differ by a few units in the last place,
/// more at grazing angles, hence the slope term) and nothing else: a few float ulps are far
/// below any gap between the floor and another surface.
const FLOOR_AFTER_RECEIVER_BIAS: wgpu::DepthBiasState =
    wgpu::DepthBiasState { constant: 16, slope_scale: 1.0, clamp: 0.0 };

/// The bias of the umbra discs drawn after the penumbra rings: half the floor's (see
/// FLOOR_AFTER_RECEIVER_BIAS), so that ring < umbra < rest of the floor in depth.
const UMBRA_AFTER_RING_BIAS: wgpu::DepthBiasState =
    wgpu::DepthBiasState { constant: 8, slope_scale: 0.5, clamp: 0.0 };

/// Anti-aliased edges: a sphere fragment's alpha is the fraction of its pixel that the sphere
/// covers, and the sphere goes over what is already there (the floor and the background, and the
/// sphere behind it), `colour x alpha + behind x (1 - alpha)`. The alpha channel composes the
/// same way and stays 1 over the opaque background.
const COVERAGE_BLEND: wgpu::BlendState = wgpu::BlendState {
    color: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::SrcAlpha,
        dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
        operation: wgpu::BlendOperation::Add,
    },
    alpha: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
        operation: wgpu::BlendOperation::Add,
    },
};

/// Whether `key`'s pipeline blends. Only the spheres in an anti-aliased main view: the floor is
/// drawn first, over nothing but the background, a constant, so its shader mixes its outline
/// with the background itself and writes opaque pixels. Blending costs a read of the target for
/// every fragment, and the floor fills half the frame.
fn blends(key: &PipelineKey) -> bool {
    key.target.antialiased() && matches!(key.surface, Surface::Glass | Surface::Metal)
}

/// Impostor squares, the floor rectangle and meshes (open ones too) are drawn from either side,
/// and cube faces use mirrored frames (views.rs), so nothing is culled by winding.
fn primitive() -> wgpu::PrimitiveState {
    wgpu::PrimitiveState { cull_mode: None, ..Default::default() }
}

fn surface_pipeline(
    gpu: &GpuContext,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    key: &PipelineKey,
) -> Result<wgpu::RenderPipeline, GpuError> {
    let (format, label) = match key.target {
        Target::Cube => (CUBE_FORMAT, "raster cube-map surface"),
        Target::Main { .. } => (OUTPUT_FORMAT, "raster main surface"),
    };
    let constants = key.constants();
    gpu.scoped(label, || {
        let options = wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() };
        gpu.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(layout),
            vertex: wgpu::VertexState {
                module,
                entry_point: Some("vs_main"),
                compilation_options: options.clone(),
                buffers: if key.surface == Surface::Mesh { &[Some(MeshVertex::LAYOUT)] } else { &[] },
            },
            primitive: primitive(),
            depth_stencil: Some(if key.surface == Surface::FloorUmbra {
                // Between the rings (no bias) and the rest of the floor (FLOOR_AFTER_RECEIVER_BIAS):
                // it fails where a ring drew, and the rest fails where it drew.
                wgpu::DepthStencilState {
                    bias: UMBRA_AFTER_RING_BIAS,
                    ..depth_state(wgpu::CompareFunction::Less)
                }
            } else if matches!(key.surface, Surface::Floor | Surface::FloorInterior) {
                // The biased floor compares LessEqual: near the far plane its bias pushes the
                // depth past 1, where it is clamped to 1, the cleared value; with Less the floor's
                // far end would vanish (a band of background before the far plane, which
                // tests/raster/extremes.rs checks for). Where the receiver drew, the floor's biased depth is
                // still greater and fails; only within one bias of the far plane (both clamped to
                // 1) may it draw over the receiver, losing a shadow there.
                wgpu::DepthStencilState {
                    bias: FLOOR_AFTER_RECEIVER_BIAS,
                    ..depth_state(wgpu::CompareFunction::LessEqual)
                }
            } else {
                depth_state(wgpu::CompareFunction::Less)
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some("fs_main"),
                compilation_options: options,
                targets: &[Some(wgpu::ColorTargetState {
                    format,
                    blend: blends(key).then_some(COVERAGE_BLEND),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        })
    })
}

impl Pipelines {
    pub fn new(gpu: &GpuContext) -> Result<Self, GpuError> {
        let device = &gpu.device;
        let (uniforms_layout, textures_layout) =
            gpu.scoped("creating the raster bind group layouts", || {
                let uniforms = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some("raster uniforms"),
                    entries: &[
                        uniform_entry(0, std::mem::size_of::<SceneUniform>(), false),
                        uniform_entry(1, std::mem::size_of::<ViewUniform>(), true),
                    ],
                });
                let cube = wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: true },
                    view_dimension: wgpu::TextureViewDimension::Cube,
                    multisampled: false,
                };
                let comparison = wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison);
                let textures = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some("raster textures"),
                    entries: &[
                        fragment_entry(
                            0,
                            wgpu::BindingType::Texture {
                                sample_type: wgpu::TextureSampleType::Depth,
                                view_dimension: wgpu::TextureViewDimension::D2,
                                multisampled: false,
                            },
                        ),
                        fragment_entry(1, comparison),
                        fragment_entry(2, comparison),
                        fragment_entry(3, cube),
                        fragment_entry(4, cube),
                        fragment_entry(5, wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering)),
                        fragment_entry(6, cube),
                    ],
                });
                (uniforms, textures)
            })?;
        let (shadow_layout, surface_layout) = gpu.scoped("creating the raster pipeline layouts", || {
            let shadow = pipeline_layout(device, "raster shadow", &[&uniforms_layout]);
            let surface = pipeline_layout(device, "raster surfaces", &[&uniforms_layout, &textures_layout]);
            (shadow, surface)
        })?;

        let shadow_module = module(gpu, &SHADOW_SHADER)?;
        let shadow = gpu.scoped("creating the shadow pipeline", || {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("raster shadow"),
                layout: Some(&shadow_layout),
                vertex: wgpu::VertexState {
                    module: &shadow_module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: primitive(),
                depth_stencil: Some(depth_state(wgpu::CompareFunction::Less)),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &shadow_module,
                    entry_point: Some("fs_main"),
                    compilation_options: Default::default(),
                    targets: &[],
                }),
                multiview_mask: None,
                cache: None,
            })
        })?;
        let mesh_shadow = gpu.scoped("creating the mesh shadow pipeline", || {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("raster mesh shadow"),
                layout: Some(&shadow_layout),
                vertex: wgpu::VertexState {
                    module: &shadow_module,
                    entry_point: Some("vs_mesh"),
                    compilation_options: Default::default(),
                    buffers: &[Some(MeshVertex::LAYOUT)],
                },
                primitive: primitive(),
                depth_stencil: Some(depth_state(wgpu::CompareFunction::Less)),
                multisample: Default::default(),
                fragment: None,
                multiview_mask: None,
                cache: None,
            })
        })?;
        let floor_module = module(gpu, &FLOOR_SHADER)?;
        let spheres_module = module(gpu, &SPHERES_SHADER)?;
        let mesh_module = module(gpu, &MESH_SHADER)?;
        Ok(Pipelines {
            uniforms_layout,
            textures_layout,
            surface_layout,
            floor_module,
            spheres_module,
            mesh_module,
            shadow,
            mesh_shadow,
            surfaces: HashMap::new(),
        })
    }

    /// Makes the pipeline for `key` unless it exists.
    pub fn ensure(&mut self, gpu: &GpuContext, key: PipelineKey) -> Result<(), GpuError> {
        if !self.surfaces.contains_key(&key) {
            let module = match key.surface {
                Surface::Floor
                | Surface::FloorReceiver
                | Surface::FloorPenumbra
                | Surface::FloorUmbra
                | Surface::FloorInterior => &self.floor_module,
                Surface::Glass | Surface::Metal => &self.spheres_module,
                Surface::Mesh => &self.mesh_module,
            };
            let pipeline = surface_pipeline(gpu, &self.surface_layout, module, &key)?;
            self.surfaces.insert(key, pipeline);
        }
        Ok(())
    }

    /// The pipeline for `key`.
    ///
    /// # Panics
    /// When [`Self::ensure`] has not made it (a programming error).
    pub fn get(&self, key: &PipelineKey) -> &wgpu::RenderPipeline {
        self.surfaces.get(key).unwrap_or_else(|| panic!("pipeline {key:?} used before ensure()"))
    }
}
