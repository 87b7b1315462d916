//! The scene on the GPU: its parameters, objects, materials and lights in buffers, the compute
//! pipeline compiled (specialised) for it, adaptive sampling's block counts, and the caustic's
//! light tracer. What a band needs to be traced, and nothing of how bands are run or folded.

use illum_gpu::{GpuContext, wgpu};
use illum_rtcore::BvhBindGroup;
use illum_scene::Scene;
use wgpu::util::DeviceExt;

use super::caustic::CausticTracer;
use crate::allocation::BLOCK;
use crate::bindings::Binding;
use crate::gpu_scene::{self, GpuParams, GpuScene};
use crate::options::{TracerOptions, Traversal};
use crate::{PathTraceError, SampleAllocation, shaders, specialise};

/// The placeholder record bound when a scene has no area light.
const EMPTY_LIGHT: crate::gpu_scene::GpuLight = crate::gpu_scene::GpuLight {
    corner: [0.0; 4],
    edge_u: [0.0; 4],
    edge_v: [0.0; 4],
    normal: [0.0; 4],
    emission: [0.0; 4],
};

pub(super) struct ScenePipeline {
    pub(super) gpu: GpuContext,
    pub(super) scene: Scene,
    pub(super) options: TracerOptions,
    /// The traversal module's source: the specialisation this pipeline was built for.
    traversal_source: String,
    /// The parameters every band starts from (it writes its rows and samples over them).
    pub(super) base_params: GpuParams,
    /// Compiled with shader def ADAPTIVE exactly when `allocation` is set.
    pub(super) compute: wgpu::ComputePipeline,
    pub(super) params_buffer: wgpu::Buffer,
    objects_buffer: wgpu::Buffer,
    materials_buffer: wgpu::Buffer,
    lights_buffer: wgpu::Buffer,
    /// Adaptive sampling: the samples of each block of pixels, and the buffer the shader reads
    /// them from (see [`super::PathTracer::set_sample_allocation`]).
    pub(super) allocation: Option<(SampleAllocation, wgpu::Buffer)>,
    /// 2^-k scale of the uploaded emission (see `accumulator::radiance_exponent`).
    pub(super) radiance_exponent: i32,
    /// The caustic's light tracer, when the scene asks for it and can have a caustic.
    pub(super) caustic: Option<CausticTracer>,
    /// The hierarchies' and shading normals' buffers (group 1), for a scene with a mesh or many
    /// spheres.
    pub(super) bvh: Option<BvhBindGroup>,
}

/// The group 1 buffers bound to `pipeline`, which a pipeline has when its specialised traversal
/// walks a hierarchy or its shading reads smooth meshes' normals; the generic traversal reads
/// every analytic object from the objects buffer (and is refused a mesh) and binds no group 1.
pub(crate) fn bvh_bind_group(
    device: &wgpu::Device,
    pipeline: &wgpu::ComputePipeline,
    scene: &Scene,
    gpu_scene: &GpuScene,
    options: TracerOptions,
) -> Option<BvhBindGroup> {
    match options.traversal {
        Traversal::Generic => None,
        Traversal::Specialised => BvhBindGroup::new(device, pipeline, scene, &gpu_scene.geometry),
    }
}

impl ScenePipeline {
    /// Uploads `gpu_scene` (the encoding of `scene`) and compiles its pipeline, adaptive when
    /// `allocation` is given (checked against the scene by [`Self::check_allocation`] first).
    pub(super) fn new(
        gpu: &GpuContext,
        scene: &Scene,
        gpu_scene: &GpuScene,
        options: TracerOptions,
        allocation: Option<SampleAllocation>,
    ) -> Result<Self, PathTraceError> {
        if gpu_scene.geometry.meshes.is_some() && options.traversal == Traversal::Generic {
            return Err(PathTraceError::Unsupported {
                scene: scene.name.clone(),
                message: "the generic traversal reads objects from a buffer and has no triangles: a \
                          scene with a mesh needs the specialised traversal"
                    .to_owned(),
            });
        }
        // Group 1 is the specialised traversal's only: the generic one reads every object from
        // a buffer.
        if options.traversal == Traversal::Specialised {
            let limits = gpu.device.limits();
            BvhBindGroup::check_size(
                scene,
                &gpu_scene.geometry,
                limits.max_storage_buffer_binding_size,
                limits.max_uniform_buffer_binding_size,
            )?;
        }
        let base_params = gpu_scene::params(scene, gpu_scene);
        let (compute, traversal_source) =
            shaders::pathtrace_pipeline(gpu, scene, gpu_scene, options, allocation.is_some())?;

        let device = &gpu.device;
        let storage =
            |label: &str, contents: &[u8]| illum_gpu::buffers::storage_buffer(device, label, contents);
        let (params_buffer, objects_buffer, materials_buffer, lights_buffer) =
            gpu.scoped("allocating path-tracer buffers", || {
                let params_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("pathtrace params"),
                    contents: bytemuck::bytes_of(&base_params),
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                });
                (
                    params_buffer,
                    storage("pathtrace objects", bytemuck::cast_slice(&gpu_scene.object_records())),
                    storage("pathtrace materials", bytemuck::cast_slice(&gpu_scene.materials)),
                    // A storage buffer may not be empty: a scene lit only by the sun or the sky
                    // binds one unused record (num_lights = 0, no AREA_LIGHTS code reads it).
                    storage(
                        "pathtrace lights",
                        if gpu_scene.lights.is_empty() {
                            bytemuck::bytes_of(&EMPTY_LIGHT)
                        } else {
                            bytemuck::cast_slice(&gpu_scene.lights)
                        },
                    ),
                )
            })?;
        let caustic = CausticTracer::new(
            gpu,
            scene,
            gpu_scene,
            options,
            [&params_buffer, &objects_buffer, &materials_buffer],
            base_params,
        )?;
        let bvh = bvh_bind_group(device, &compute, scene, gpu_scene, options);
        let mut pipeline = ScenePipeline {
            gpu: gpu.clone(),
            scene: scene.clone(),
            options,
            traversal_source,
            base_params,
            compute,
            params_buffer,
            objects_buffer,
            materials_buffer,
            lights_buffer,
            allocation: None,
            radiance_exponent: gpu_scene.radiance_exponent,
            caustic,
            bvh,
        };
        if let Some(allocation) = allocation {
            pipeline.check_allocation(&allocation)?;
            pipeline.allocation = Some(pipeline.upload_allocation(allocation)?);
        }
        Ok(pipeline)
    }

    /// Refuses an allocation of another resolution, one that leaves a block without samples,
    /// and any with the caustic's light tracer (whose passes cover the whole image at one spp).
    pub(super) fn check_allocation(&self, a: &SampleAllocation) -> Result<(), PathTraceError> {
        let camera = self.scene.camera;
        let refuse =
            |message: String| PathTraceError::Unsupported { scene: self.scene.name.clone(), message };
        let (bx, by) = SampleAllocation::blocks(camera.width, camera.height);
        if (a.width, a.height) != (camera.width, camera.height) || a.samples.len() != (bx * by) as usize {
            return Err(refuse(format!(
                "a sample allocation for {} x {} pixels ({} blocks) cannot drive a {} x {} render ({} blocks)",
                a.width,
                a.height,
                a.samples.len(),
                camera.width,
                camera.height,
                bx * by
            )));
        }
        if let Some(block) = a.samples.iter().position(|&n| n == 0) {
            return Err(refuse(format!(
                "a sample allocation gives block {block} no samples: every pixel needs at least one"
            )));
        }
        if self.caustic.is_some() {
            return Err(refuse(
                "adaptive sampling is not available with the caustic's light tracer (its passes cover the \
                 whole image at one spp); render with caustics off or without adaptive sampling"
                    .to_owned(),
            ));
        }
        Ok(())
    }

    /// Switches to `allocation` (checked by [`Self::check_allocation`]), compiling the pipeline
    /// again when adaptivity is turned on or off.
    pub(super) fn set_allocation(
        &mut self,
        allocation: Option<SampleAllocation>,
    ) -> Result<(), PathTraceError> {
        let adaptive = allocation.is_some();
        if adaptive != self.allocation.is_some() {
            let gpu_scene = GpuScene::new(&self.scene)?;
            self.compute =
                shaders::pathtrace_pipeline(&self.gpu, &self.scene, &gpu_scene, self.options, adaptive)?.0;
        }
        self.allocation = match allocation {
            Some(a) => Some(self.upload_allocation(a)?),
            None => None,
        };
        Ok(())
    }

    fn upload_allocation(
        &self,
        allocation: SampleAllocation,
    ) -> Result<(SampleAllocation, wgpu::Buffer), PathTraceError> {
        let device = &self.gpu.device;
        let buffer = self.gpu.scoped("allocating the adaptive sample counts", || {
            illum_gpu::buffers::storage_buffer(
                device,
                "pathtrace block samples",
                bytemuck::cast_slice(&allocation.samples),
            )
        })?;
        Ok((allocation, buffer))
    }

    /// Refuses `scene` (encoded as `gpu_scene`) unless it has the objects and materials this
    /// pipeline was built for, naming what differs.
    pub(super) fn check_same_geometry(
        &self,
        scene: &Scene,
        gpu_scene: &GpuScene,
    ) -> Result<(), PathTraceError> {
        if scene.objects == self.scene.objects && scene.materials == self.scene.materials {
            return Ok(());
        }
        let needed = specialise::traversal(gpu_scene);
        let what = if self.options.traversal == Traversal::Specialised
            && needed.source != self.traversal_source
        {
            format!(
                "its geometry needs a pipeline specialised for shapes {:?}, {} light(s) and shadow-ray occluders {:?}",
                needed.kind_names(),
                gpu_scene.lights.len(),
                needed.occluders
            )
        } else {
            "its objects or materials differ from the uploaded ones".to_owned()
        };
        Err(PathTraceError::Unsupported {
            scene: scene.name.clone(),
            message: format!(
                "this path tracer was built for scene {:?} and cannot render it: {what}; create a new PathTracer",
                self.scene.name
            ),
        })
    }

    /// Whether `scene` (same geometry) needs another pipeline or buffers: another resolution,
    /// or settings that choose other scene code (the caustic on or off, the hemisphere
    /// sampling, bounded or unbounded paths).
    pub(super) fn needs_rebuild(&self, scene: &Scene, gpu_scene: &GpuScene) -> Result<bool, PathTraceError> {
        Ok((scene.camera.width, scene.camera.height) != (self.scene.camera.width, self.scene.camera.height)
            || gpu_scene.code != GpuScene::new(&self.scene)?.code)
    }

    /// Takes `scene`'s camera and render settings, which the pipeline and buffers serve as they
    /// are (see [`Self::needs_rebuild`]).
    pub(super) fn retarget(&mut self, scene: &Scene, gpu_scene: &GpuScene) -> Result<(), PathTraceError> {
        self.base_params = gpu_scene::params(scene, gpu_scene);
        // The caustic's parameters follow the camera and the seed.
        self.caustic = CausticTracer::new(
            &self.gpu,
            scene,
            gpu_scene,
            self.options,
            [&self.params_buffer, &self.objects_buffer, &self.materials_buffer],
            self.base_params,
        )?;
        self.scene = scene.clone();
        Ok(())
    }

    /// The buffers the pipeline's bind group takes besides the batch buffers, by binding.
    pub(super) fn inputs(&self) -> Vec<(u32, &wgpu::Buffer)> {
        let mut inputs = vec![(Binding::Params.index(), &self.params_buffer)];
        // A specialised pipeline has its objects and materials as literals (specialise.rs).
        if self.options.traversal == Traversal::Generic {
            inputs.extend([
                (Binding::Objects.index(), &self.objects_buffer),
                (Binding::Materials.index(), &self.materials_buffer),
            ]);
        }
        // A pipeline without area lights does not declare them.
        if self.base_params.num_lights > 0 {
            inputs.push((Binding::Lights.index(), &self.lights_buffer));
        }
        // Adaptive sampling's block counts (shader def ADAPTIVE).
        if let Some((_, block_samples)) = &self.allocation {
            inputs.push((Binding::BlockSamples.index(), block_samples));
        }
        inputs
    }

    /// The height of an image with as many pixels as a pass from absolute sample index `start`
    /// traces, for the planner, which sizes passes by pixels: the image's, or with adaptive
    /// sampling the rows' worth of pixels whose blocks are not done yet.
    pub(super) fn active_height(&self, start: u32) -> u32 {
        let camera = self.scene.camera;
        match &self.allocation {
            None => camera.height,
            Some((allocation, _)) => {
                let active = allocation.pixels_beyond(start);
                (active.div_ceil(u64::from(camera.width)) as u32).clamp(1, camera.height)
            }
        }
    }

    /// The rows from row `from` on that a pass starting at absolute sample index `start` traces:
    /// (first, end), all rows to the image's end, or with adaptive sampling from the first to
    /// the last block row with a block not done yet; `None` when no such row is left (a band
    /// there would trace nothing, and its workgroups would still cost their dispatch).
    pub(super) fn active_rows(&self, from: u32, start: u32) -> Option<(u32, u32)> {
        let height = self.scene.camera.height;
        if from >= height {
            return None;
        }
        let Some((allocation, _)) = &self.allocation else {
            return Some((from, height));
        };
        let (bx, by) = SampleAllocation::blocks(allocation.width, allocation.height);
        let busy = |j: u32| {
            allocation.samples[(j * bx) as usize..((j + 1) * bx) as usize].iter().any(|&n| n > start)
        };
        let first = (from / BLOCK..by).find(|&j| busy(j))?;
        // `first` is busy, so the search from the end finds a row at or after it.
        let last = (first..by).rev().find(|&j| busy(j)).unwrap_or(first);
        Some(((first * BLOCK).max(from), ((last + 1) * BLOCK).min(height)))
    }

    /// Rows of the image holding `rows` rows' worth of traced pixels of a pass from absolute
    /// sample index `start`: with adaptive sampling the pixels still traced are spread over the
    /// whole image.
    pub(super) fn spread_rows(&self, rows: u32, start: u32) -> u32 {
        let height = self.scene.camera.height;
        let active = self.active_height(start);
        (u64::from(rows) * u64::from(height) / u64::from(active)).clamp(1, u64::from(height)) as u32
    }
}
