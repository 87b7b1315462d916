//! The path tracer's GPU side: pipeline, buffers, and the submit-readback-fold loop.

use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};
use std::time::Instant;

use illum_gpu::shader::{self, COMMON_MODULES, Def, ShaderFile};
use illum_gpu::shader_file;
use illum_gpu::timing::PassTimer;
use illum_gpu::{GpuContext, readback, wgpu};
use illum_scene::{DeviceLimits, Scene};
use wgpu::util::DeviceExt;

use crate::gpu_scene::{self, GpuParams, GpuScene};
use crate::planner::{BatchPlanner, DEFAULT_TARGET_SECONDS, PassPlan};
use crate::{Accumulator, PathTraceError, specialise};

/// The integrator (entry point `main`).
pub const PATHTRACE_SHADER: ShaderFile = shader_file!("shaders/pathtrace/pathtrace.wgsl");
/// Scene layout, bindings and ray-shape tests.
pub const SCENE_MODULE: ShaderFile = shader_file!("shaders/pathtrace/scene.wgsl");
/// The generic traversal (a loop over the object buffer).
pub const GENERIC_TRAVERSAL: ShaderFile = shader_file!("shaders/pathtrace/traversal.wgsl");

/// How rays find what they hit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Traversal {
    /// Traversal code generated from the scene: every object's test unrolled with its numbers as
    /// constants (see `specialise.rs`). The default.
    #[default]
    Specialised,
    /// One loop over the object buffer, the same pipeline for every scene.
    Generic,
}

/// Where a path's random sample values come from (see shaders/common/sampler.wgsl).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Sequence {
    /// Independent uniform numbers from a PCG stream per (seed, pixel, sample index).
    #[default]
    Independent,
    /// A randomly shifted Kronecker (R_d) low-discrepancy sequence for the first 16 dimensions.
    LowDiscrepancy,
}

impl std::str::FromStr for Sequence {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "independent" => Ok(Self::Independent),
            "low-discrepancy" => Ok(Self::LowDiscrepancy),
            other => Err(format!("unknown sequence {other:?}; allowed: independent, low-discrepancy")),
        }
    }
}

impl std::fmt::Display for Sequence {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Independent => "independent",
            Self::LowDiscrepancy => "low-discrepancy",
        })
    }
}

/// Pipeline choices that do not change the expected image, only speed or noise.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct TracerOptions {
    pub traversal: Traversal,
    pub sequence: Sequence,
}

impl TracerOptions {
    /// naga_oil shader defs for these options.
    pub fn shader_defs(&self) -> Vec<(&'static str, Def)> {
        match self.sequence {
            Sequence::Independent => Vec::new(),
            Sequence::LowDiscrepancy => vec![("LOW_DISCREPANCY", Def::Bool(true))],
        }
    }
}

/// Compiled pipelines by (device, traversal source, shader defs): two scenes with the same
/// specialisation share one pipeline, so switching back to a scene does not recompile.
type PipelineKey = (wgpu::Device, String, Vec<(&'static str, Def)>);

fn pipeline_cache() -> &'static Mutex<HashMap<PipelineKey, wgpu::ComputePipeline>> {
    static CACHE: OnceLock<Mutex<HashMap<PipelineKey, wgpu::ComputePipeline>>> = OnceLock::new();
    CACHE.get_or_init(Mutex::default)
}

/// Number of pipelines compiled so far in this process (the cache's misses).
pub fn pipelines_compiled() -> usize {
    pipeline_cache().lock().unwrap_or_else(|p| p.into_inner()).len()
}

/// The shader modules, in import order, for `scene` with `traversal`.
pub fn shader_modules(scene: &Scene, gpu_scene: &GpuScene, traversal: Traversal) -> Vec<ShaderFile> {
    let mut modules = COMMON_MODULES.to_vec();
    modules.push(SCENE_MODULE);
    modules.push(match traversal {
        Traversal::Generic => GENERIC_TRAVERSAL,
        Traversal::Specialised => specialise::traversal_module(scene, gpu_scene),
    });
    modules
}

/// Bytes per pixel of the batch buffers: vec4 sum plus vec4 sum of squares.
pub const BYTES_PER_PIXEL: u64 = 32;
const WORKGROUP: u32 = 8;
const TIMED_PASS: &str = "pathtrace";

/// What one submission did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepReport {
    /// Paths traced (pixels in the band x spp of the pass).
    pub samples: u64,
    /// Wall time of the submission, including readback and the f64 fold.
    pub wall_seconds: f64,
    /// GPU time of the compute pass, from timestamp queries, when the adapter has them.
    pub gpu_seconds: Option<f64>,
    /// True when this submission finished a pass over the whole image.
    pub pass_completed: bool,
}

struct ActivePass {
    plan: PassPlan,
    sample_base: u32,
    next_row: u32,
}

pub struct PathTracer {
    gpu: GpuContext,
    scene: Scene,
    options: TracerOptions,
    /// The traversal module's source: the specialisation this pipeline was built for.
    traversal_source: String,
    base_params: GpuParams,
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    params_buffer: wgpu::Buffer,
    sum_buffer: wgpu::Buffer,
    sum_sq_buffer: wgpu::Buffer,
    staging: Option<wgpu::Buffer>,
    timer: PassTimer,
    planner: BatchPlanner,
    accumulator: Accumulator,
    pass: Option<ActivePass>,
    /// Samples per pixel of all completed passes.
    spp_done: u32,
    /// Wall and GPU seconds spent on submissions since the last reset.
    wall_seconds: f64,
    gpu_seconds: f64,
}

impl PathTracer {
    /// Validates `scene` against the device, compiles the (specialised) pipeline and allocates
    /// the buffers.
    pub fn new(gpu: &GpuContext, scene: &Scene) -> Result<Self, PathTraceError> {
        Self::with_options(gpu, scene, TracerOptions::default())
    }

    /// As [`Self::new`], choosing the traversal and the sample sequence.
    pub fn with_options(
        gpu: &GpuContext,
        scene: &Scene,
        options: TracerOptions,
    ) -> Result<Self, PathTraceError> {
        let limits = gpu.device.limits();
        scene.check_device_limits(
            &DeviceLimits {
                max_texture_dimension_2d: limits.max_texture_dimension_2d,
                max_storage_buffer_binding_size: limits
                    .max_storage_buffer_binding_size
                    .min(limits.max_buffer_size),
            },
            BYTES_PER_PIXEL / 2,
        )?;
        let gpu_scene = GpuScene::new(scene)?;
        let base_params = gpu_scene::params(scene, &gpu_scene);

        let modules = shader_modules(scene, &gpu_scene, options.traversal);
        let defs = options.shader_defs();
        let key: PipelineKey =
            (gpu.device.clone(), modules.last().expect("traversal").source.to_string(), defs.clone());
        let cached = pipeline_cache().lock().unwrap_or_else(|p| p.into_inner()).get(&key).cloned();
        let pipeline = match cached {
            Some(pipeline) => pipeline,
            None => {
                let module = shader::compose(&modules, &PATHTRACE_SHADER, &defs)?;
                let module = shader::create_module(gpu, module, &PATHTRACE_SHADER.path)?;
                let pipeline = gpu.scoped("creating the path-tracing pipeline", || {
                    gpu.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                        label: Some("pathtrace"),
                        layout: None,
                        module: &module,
                        entry_point: Some("main"),
                        compilation_options: Default::default(),
                        cache: None,
                    })
                })?;
                pipeline_cache()
                    .lock()
                    .unwrap_or_else(|p| p.into_inner())
                    .insert(key.clone(), pipeline.clone());
                pipeline
            }
        };

        let device = &gpu.device;
        let storage = |label: &str, contents: &[u8]| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::STORAGE,
            })
        };
        let pixels = scene.camera.width as u64 * scene.camera.height as u64;
        let (params_buffer, objects, materials, lights, sum_buffer, sum_sq_buffer) =
            gpu.scoped("allocating path-tracer buffers", || {
                let params_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("pathtrace params"),
                    contents: bytemuck::bytes_of(&base_params),
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                });
                let batch = |label: &str| {
                    device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some(label),
                        size: pixels * BYTES_PER_PIXEL / 2,
                        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                        mapped_at_creation: false,
                    })
                };
                (
                    params_buffer,
                    storage("pathtrace objects", bytemuck::cast_slice(&gpu_scene.objects)),
                    storage("pathtrace materials", bytemuck::cast_slice(&gpu_scene.materials)),
                    storage("pathtrace lights", bytemuck::cast_slice(&gpu_scene.lights)),
                    batch("pathtrace batch sum"),
                    batch("pathtrace batch sum of squares"),
                )
            })?;
        let bind_group = gpu.scoped("binding path-tracer buffers", || {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("pathtrace"),
                layout: &pipeline.get_bind_group_layout(0),
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: params_buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: objects.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: materials.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 3, resource: lights.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 4, resource: sum_buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 5, resource: sum_sq_buffer.as_entire_binding() },
                ],
            })
        })?;

        Ok(Self {
            gpu: gpu.clone(),
            scene: scene.clone(),
            options,
            traversal_source: key.1,
            base_params,
            pipeline,
            bind_group,
            params_buffer,
            sum_buffer,
            sum_sq_buffer,
            staging: None,
            timer: PassTimer::new(gpu, &[TIMED_PASS]),
            planner: BatchPlanner::new(DEFAULT_TARGET_SECONDS),
            accumulator: Accumulator::new(scene.camera.width, scene.camera.height),
            pass: None,
            spp_done: 0,
            wall_seconds: 0.0,
            gpu_seconds: 0.0,
        })
    }

    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    pub fn accumulator(&self) -> &Accumulator {
        &self.accumulator
    }

    /// Samples per pixel in every pixel (completed passes).
    pub fn spp_done(&self) -> u32 {
        self.spp_done
    }

    /// Wall seconds spent in submissions since the last reset.
    pub fn wall_seconds(&self) -> f64 {
        self.wall_seconds
    }

    /// GPU seconds of the compute passes since the last reset (0 without timestamp queries).
    pub fn gpu_seconds(&self) -> f64 {
        self.gpu_seconds
    }

    /// Sets the wall time aimed at per submission (default 0.15 s).
    pub fn set_target_seconds(&mut self, seconds: f64) {
        self.planner = BatchPlanner::new(seconds);
    }

    /// Takes a new camera and render settings (spp, bounces, seed, sampling) without rebuilding
    /// the pipeline, and restarts the accumulation. The geometry and materials must be the ones
    /// the pipeline was built for: a scene that differs in them (another specialisation, or
    /// other object data) is refused with an error naming what changed; build a new
    /// `PathTracer` for it. The resolution may change (the buffers are reallocated).
    pub fn update_scene(&mut self, scene: &Scene) -> Result<(), PathTraceError> {
        if scene.objects != self.scene.objects || scene.materials != self.scene.materials {
            let gpu_scene = GpuScene::new(scene)?;
            let needed = specialise::specialise(scene, &gpu_scene);
            let what = if self.options.traversal == Traversal::Specialised
                && needed.source != self.traversal_source
            {
                format!(
                    "its geometry needs a pipeline specialised for shapes {:?}, {} light(s) and shadow-ray occluders {:?}",
                    needed.kinds, needed.lights, needed.occluders
                )
            } else {
                "its objects or materials differ from the uploaded ones".to_owned()
            };
            return Err(PathTraceError::Unsupported {
                scene: scene.name.clone(),
                message: format!(
                    "this path tracer was built for scene {:?} and cannot render it: {what}; create a new PathTracer",
                    self.scene.name
                ),
            });
        }
        let resized =
            (scene.camera.width, scene.camera.height) != (self.scene.camera.width, self.scene.camera.height);
        if resized {
            *self = Self::with_options(&self.gpu, scene, self.options)?;
            return Ok(());
        }
        let gpu_scene = GpuScene::new(scene)?;
        self.base_params = gpu_scene::params(scene, &gpu_scene);
        self.scene = scene.clone();
        self.reset();
        Ok(())
    }

    /// Discards everything accumulated; the next step starts again at sample 0.
    pub fn reset(&mut self) {
        self.accumulator.reset();
        self.pass = None;
        self.spp_done = 0;
        self.wall_seconds = 0.0;
        self.gpu_seconds = 0.0;
    }

    /// Runs one short submission toward `target_spp` samples per pixel (`None`: no limit).
    /// Returns a report with `samples == 0` once the target is reached.
    pub fn step(&mut self, target_spp: Option<u32>) -> Result<StepReport, PathTraceError> {
        let camera = self.scene.camera;
        if self.pass.is_none() {
            let remaining = match target_spp {
                Some(t) if t <= self.spp_done => return Ok(StepReport::default()),
                Some(t) => t - self.spp_done,
                None => u32::MAX - self.spp_done,
            };
            let plan = self.planner.plan(camera.width, camera.height, remaining);
            self.pass = Some(ActivePass { plan, sample_base: self.spp_done, next_row: 0 });
        }
        let report = self.submit_band()?;
        self.planner.record(report.samples, report.wall_seconds);
        Ok(report)
    }

    /// Renders exactly `spp` more samples per pixel as one pass (split into bands only if the
    /// image is too large for one short submission). Tests use it to control batching.
    pub fn render_pass(&mut self, spp: u32) -> Result<(), PathTraceError> {
        assert!(self.pass.is_none(), "render_pass called in the middle of a pass");
        let camera = self.scene.camera;
        let planned = self.planner.plan(camera.width, camera.height, spp);
        let rows = if planned.spp >= spp { camera.height } else { planned.rows.max(1) };
        self.pass =
            Some(ActivePass { plan: PassPlan { spp, rows }, sample_base: self.spp_done, next_row: 0 });
        while self.pass.is_some() {
            let report = self.submit_band()?;
            self.planner.record(report.samples, report.wall_seconds);
        }
        Ok(())
    }

    /// Steps until every pixel has `spp` samples.
    pub fn render(&mut self, spp: u32) -> Result<(), PathTraceError> {
        while self.spp_done < spp {
            self.step(Some(spp))?;
        }
        Ok(())
    }

    fn submit_band(&mut self) -> Result<StepReport, PathTraceError> {
        let started = Instant::now();
        let width = self.scene.camera.width;
        let height = self.scene.camera.height;
        let pass = self.pass.as_ref().expect("submit_band needs an active pass");
        let row_offset = pass.next_row;
        let rows = pass.plan.rows.min(height - row_offset);
        let spp = pass.plan.spp;

        let mut params = self.base_params;
        params.row_offset = row_offset;
        params.rows = rows;
        params.sample_base = pass.sample_base;
        params.sample_count = spp;
        self.gpu.queue.write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&params));

        let band_bytes = rows as u64 * width as u64 * BYTES_PER_PIXEL / 2;
        let band_offset = row_offset as u64 * width as u64 * BYTES_PER_PIXEL / 2;
        let staging_size = 2 * band_bytes + self.timer.result_size();
        if self.staging.as_ref().is_none_or(|s| s.size() < staging_size) {
            self.staging = Some(self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pathtrace staging"),
                size: staging_size,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }));
        }
        let staging = self.staging.as_ref().expect("allocated above");

        let mut encoder = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("pathtrace band") });
        {
            let mut compute = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("pathtrace"),
                timestamp_writes: self.timer.compute_writes(TIMED_PASS),
            });
            compute.set_pipeline(&self.pipeline);
            compute.set_bind_group(0, &self.bind_group, &[]);
            compute.dispatch_workgroups(width.div_ceil(WORKGROUP), rows.div_ceil(WORKGROUP), 1);
        }
        encoder.copy_buffer_to_buffer(&self.sum_buffer, band_offset, staging, 0, band_bytes);
        encoder.copy_buffer_to_buffer(&self.sum_sq_buffer, band_offset, staging, band_bytes, band_bytes);
        self.timer.copy_results(&mut encoder, staging, 2 * band_bytes);
        self.gpu.queue.submit([encoder.finish()]);

        let bytes =
            readback::read_mapped(&self.gpu, staging, staging_size, "reading back a path-tracing batch")?;
        let floats: Vec<[f32; 4]> = bytes[..(2 * band_bytes) as usize]
            .chunks_exact(16)
            .map(|c| {
                let f = |i: usize| f32::from_le_bytes(c[4 * i..4 * i + 4].try_into().expect("4 bytes"));
                [f(0), f(1), f(2), f(3)]
            })
            .collect();
        let (sums, sums_sq) = floats.split_at(floats.len() / 2);
        self.accumulator.fold(row_offset as usize * width as usize, sums, sums_sq);
        let gpu_seconds =
            self.timer.decode(&bytes[(2 * band_bytes) as usize..]).map(|timings| timings[0].1 * 1e-3);

        let pass = self.pass.as_mut().expect("still active");
        pass.next_row += rows;
        let pass_completed = pass.next_row >= height;
        if pass_completed {
            self.spp_done += spp;
            self.pass = None;
        }
        let wall_seconds = started.elapsed().as_secs_f64();
        self.wall_seconds += wall_seconds;
        self.gpu_seconds += gpu_seconds.unwrap_or(0.0);
        Ok(StepReport {
            samples: rows as u64 * width as u64 * spp as u64,
            wall_seconds,
            gpu_seconds,
            pass_completed,
        })
    }
}

#[cfg(test)]
mod tests {
    /// The WGSL constant LD_INV_PHI is 1/phi_16, phi_16 the positive root of x^17 = x + 1
    /// (Roberts' generalised golden ratio), and its powers are the R_16 sequence's alphas.
    #[test]
    fn ld_alpha_matches_roberts_definition() {
        let source = include_str!("../../../shaders/common/sampler.wgsl");
        let constant: f64 = source
            .split("const LD_INV_PHI: f32 = ")
            .nth(1)
            .and_then(|rest| rest.split(';').next())
            .expect("LD_INV_PHI present")
            .parse()
            .expect("a number");
        // Fixed-point iteration x <- (1 + x)^(1/17) converges to phi_16.
        let mut phi = 2.0f64;
        for _ in 0..200 {
            phi = (1.0 + phi).powf(1.0 / 17.0);
        }
        assert!((phi.powi(17) - phi - 1.0).abs() < 1e-12);
        assert!(((constant as f32) as f64 - 1.0 / phi).abs() < 1e-7, "{constant} vs {}", 1.0 / phi);
        // The shader's f32 recurrence stays within 1e-6 of (1/phi)^(j+1) over the 16 dimensions.
        let mut alpha = constant as f32;
        for j in 0..16 {
            let exact = (1.0 / phi).powi(j + 1);
            assert!((alpha as f64 - exact).abs() < 1e-6, "alpha_{j}: {alpha} vs {exact}");
            alpha *= constant as f32;
        }
    }
}
