//! The path tracer's GPU side: pipeline, buffers, and the submit-readback-fold loop.

use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};
use std::time::Instant;

use illum_gpu::shader::{self, COMMON_MODULES, Def, ShaderFile};
use illum_gpu::shader_file;
use illum_gpu::timing::PassTimer;
use illum_gpu::{GpuContext, readback, wgpu};
use illum_scene::{DeviceLimits, Scene, Sequence};
use wgpu::util::DeviceExt;

use crate::display_sum::DisplaySum;
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

/// Compiled pipelines by (GPU context id, traversal source, shader defs): two scenes with the
/// same specialisation share one pipeline, so switching back to a scene does not recompile.
/// (Keyed by illum's context id, not `wgpu::Device`, whose ids repeat across wgpu instances.)
type PipelineKey = (u64, String, Vec<(&'static str, Def)>);

fn pipeline_cache() -> &'static Mutex<HashMap<PipelineKey, wgpu::ComputePipeline>> {
    static CACHE: OnceLock<Mutex<HashMap<PipelineKey, wgpu::ComputePipeline>>> = OnceLock::new();
    CACHE.get_or_init(Mutex::default)
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

/// Bytes of one slot of a batch buffer: a vec4 of f32 (the sum buffer and the sum-of-squares
/// buffer each hold one per slot).
pub const SLOT_BYTES: u64 = 16;
/// Default samples per invocation (one chunk, one slot). An f32 sum of n positive terms is within
/// (n - 1) u of the exact sum, relatively (u = 2^-24): with 16, 15 u < 1e-6, so every batch the
/// CPU folds in f64 is within 1e-6 of the f64 fold of the very same samples. It also bounds one
/// invocation's work: lavapipe silently ends an invocation's loops after 65535 iterations (in
/// total), which a single invocation looping over thousands of samples used to hit, losing them.
pub const CHUNK_SAMPLES: u32 = 16;
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

struct BatchBuffers {
    slots: u64,
    sum: wgpu::Buffer,
    sum_sq: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
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
    params_buffer: wgpu::Buffer,
    objects_buffer: wgpu::Buffer,
    materials_buffer: wgpu::Buffer,
    lights_buffer: wgpu::Buffer,
    /// The batch buffers (sum, sum of squares) and the bind group that uses them; grown on demand
    /// up to `max_slots`.
    batch: Option<BatchBuffers>,
    staging: Option<wgpu::Buffer>,
    /// Samples per invocation.
    chunk_samples: u32,
    /// Most slots one batch buffer may hold: the device's storage binding limit (or a lower cap
    /// set by [`PathTracer::limit_batch_bytes`]) over [`SLOT_BYTES`].
    max_slots: u64,
    /// Most chunks one dispatch may carry (its z dimension).
    max_chunks: u32,
    timer: PassTimer,
    planner: BatchPlanner,
    accumulator: Accumulator,
    /// The GPU-resident running image for viewers, when enabled (see `display_sum.rs`).
    display_sum: Option<DisplaySum>,
    pass: Option<ActivePass>,
    /// Samples per pixel of all completed passes.
    spp_done: u32,
    /// The sample index of this tracer's first sample (see [`Self::set_sample_offset`]).
    sample_offset: u32,
    /// Whether [`Self::step`] ends passes on multiples of the chunk (see
    /// [`Self::set_chunk_aligned_passes`]).
    chunk_aligned: bool,
    /// 2^-k scale of the uploaded emission (see `accumulator::radiance_exponent`).
    radiance_exponent: i32,
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
        // The batch buffers hold one band of rows at a time (the image is tiled into bands that
        // fit one storage binding, see `fit`), so the storage limit applies to a band, not to the
        // whole image: only the texture-size limit is checked against the full resolution here,
        // and one row of one chunk must fit (below).
        scene.check_device_limits(
            &DeviceLimits {
                max_texture_dimension_2d: limits.max_texture_dimension_2d,
                max_storage_buffer_binding_size: limits
                    .max_storage_buffer_binding_size
                    .min(limits.max_buffer_size),
            },
            0,
        )?;
        let max_slots = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size) / SLOT_BYTES;
        check_row_fits(scene, max_slots)?;
        crate::accumulator::check_host_memory(
            scene.camera.width,
            scene.camera.height,
            crate::accumulator::available_host_memory(),
        )
        .map_err(|message| PathTraceError::Unsupported { scene: scene.name.clone(), message })?;
        let mut accumulator = Accumulator::try_new(scene.camera.width, scene.camera.height).map_err(|bytes| {
            PathTraceError::Unsupported {
                scene: scene.name.clone(),
                message: format!(
                    "camera.width x camera.height = {} x {}: its f64 statistics need {:.1} GiB of host memory, \
                     which could not be allocated",
                    scene.camera.width,
                    scene.camera.height,
                    bytes as f64 / (1u64 << 30) as f64
                ),
            }
        })?;
        let gpu_scene = GpuScene::new(scene)?;
        let base_params = gpu_scene::params(scene, &gpu_scene);
        accumulator.set_radiance_exponent(gpu_scene.radiance_exponent);

        let modules = shader_modules(scene, &gpu_scene, options.traversal);
        let defs = options.shader_defs();
        let key: PipelineKey =
            (gpu.id(), modules.last().expect("traversal").source.to_string(), defs.clone());
        let cached = pipeline_cache().lock().unwrap_or_else(|p| p.into_inner()).get(&key).cloned();
        let pipeline = match cached {
            Some(pipeline) => pipeline,
            None => {
                let pipeline =
                    shader::compute_pipeline(gpu, &modules, &PATHTRACE_SHADER, &defs, "path-tracing")?;
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
        let (params_buffer, objects_buffer, materials_buffer, lights_buffer) =
            gpu.scoped("allocating path-tracer buffers", || {
                let params_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("pathtrace params"),
                    contents: bytemuck::bytes_of(&base_params),
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                });
                (
                    params_buffer,
                    storage("pathtrace objects", bytemuck::cast_slice(&gpu_scene.objects)),
                    storage("pathtrace materials", bytemuck::cast_slice(&gpu_scene.materials)),
                    storage("pathtrace lights", bytemuck::cast_slice(&gpu_scene.lights)),
                )
            })?;

        Ok(Self {
            gpu: gpu.clone(),
            scene: scene.clone(),
            options,
            traversal_source: key.1,
            base_params,
            pipeline,
            params_buffer,
            objects_buffer,
            materials_buffer,
            lights_buffer,
            batch: None,
            staging: None,
            chunk_samples: CHUNK_SAMPLES,
            max_slots,
            max_chunks: limits.max_compute_workgroups_per_dimension,
            timer: PassTimer::new(gpu, &[TIMED_PASS]),
            planner: BatchPlanner::new(DEFAULT_TARGET_SECONDS),
            accumulator,
            display_sum: None,
            pass: None,
            spp_done: 0,
            sample_offset: 0,
            chunk_aligned: false,
            radiance_exponent: gpu_scene.radiance_exponent,
            wall_seconds: 0.0,
            gpu_seconds: 0.0,
        })
    }

    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Whether `self` and `other` run the very same compiled pipeline: the cache found an equal
    /// specialisation instead of compiling again.
    pub fn shares_pipeline_with(&self, other: &PathTracer) -> bool {
        self.pipeline == other.pipeline
    }

    pub fn accumulator(&self) -> &Accumulator {
        &self.accumulator
    }

    /// The traversal and sample sequence this tracer was built with.
    pub fn options(&self) -> TracerOptions {
        self.options
    }

    /// The name of the GPU adapter it renders on.
    pub fn adapter_name(&self) -> &str {
        &self.gpu.adapter_info.name
    }

    /// Keeps, from now on, a running sum of the image on the GPU for display: one storage buffer
    /// of `width x height` `vec4<f32>` (rgb = sum of finite samples, w = their count; pixel
    /// `y * width + x`), updated by every band's submission, cleared by [`Self::reset`] and by
    /// [`Self::update_scene`], reallocated when the resolution changes. A viewer binds it
    /// ([`Self::display_sum_buffer`]) and shows rgb / w without copying the image through the
    /// CPU. Samples taken before the call are copied in once. Fails, naming the limit, when the
    /// whole image does not fit one storage binding of the device (the statistics, which go band
    /// by band, have no such limit). Enabling it twice does nothing.
    pub fn enable_display_sum(&mut self) -> Result<(), PathTraceError> {
        if self.display_sum.is_some() {
            return Ok(());
        }
        let camera = self.scene.camera;
        let display = DisplaySum::new(&self.gpu, &self.scene.name, camera.width, camera.height)?;
        if self.accumulator.total_samples() > 0 {
            display.seed(&self.gpu, &self.accumulator, self.radiance_exponent);
        }
        self.display_sum = Some(display);
        Ok(())
    }

    /// What the display sum's values must be multiplied by to be radiance: 2^k, where the
    /// scene's emission was uploaded scaled by 2^-k so that no f32 sum or square on the GPU
    /// overflows (1 for every light up to 2^16; see `accumulator::radiance_exponent`). A viewer
    /// folds it into its exposure.
    pub fn display_scale(&self) -> f32 {
        2f32.powi(self.radiance_exponent)
    }

    /// The display sum's buffer (usage `STORAGE | COPY_SRC | COPY_DST`) once
    /// [`Self::enable_display_sum`] was called. It is replaced by a new buffer when the
    /// resolution changes, so bind it anew whenever this returns another buffer.
    pub fn display_sum_buffer(&self) -> Option<&wgpu::Buffer> {
        self.display_sum.as_ref().map(DisplaySum::buffer)
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
            let mut resized = Self::with_options(&self.gpu, scene, self.options)?;
            // What the caller chose and the planner learnt (the cost of a sample) carry over:
            // a viewer that set short submissions keeps them after the window is resized.
            resized.planner = self.planner.clone();
            resized.chunk_samples = self.chunk_samples;
            resized.sample_offset = self.sample_offset;
            resized.chunk_aligned = self.chunk_aligned;
            if self.display_sum.is_some() {
                resized.enable_display_sum()?;
            }
            *self = resized;
            return Ok(());
        }
        let gpu_scene = GpuScene::new(scene)?;
        self.base_params = gpu_scene::params(scene, &gpu_scene);
        self.scene = scene.clone();
        self.reset();
        Ok(())
    }

    /// Sets the samples per invocation (default [`CHUNK_SAMPLES`]; values below 1 count as 1),
    /// from the next pass on. With 1 every sample reaches the f64 fold as its own f32 value, which
    /// makes the result the exact f64 fold of the samples (tests use it as the reference); larger
    /// chunks round each chunk's f32 sum by up to (n - 1) x 2^-24 relative.
    pub fn set_chunk_samples(&mut self, samples: u32) {
        self.chunk_samples = samples.max(1);
    }

    /// Caps each batch buffer at `bytes` (at most the device's storage binding limit, which is the
    /// default; at least one row of one chunk), from the next pass on. The image is then rendered
    /// in bands of rows that fit; tests use it to force that tiling on small images.
    pub fn limit_batch_bytes(&mut self, bytes: u64) -> Result<(), PathTraceError> {
        let limits = self.gpu.device.limits();
        let device_slots = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size) / SLOT_BYTES;
        let slots = (bytes / SLOT_BYTES).min(device_slots);
        check_row_fits(&self.scene, slots)?;
        self.max_slots = slots;
        Ok(())
    }

    /// Makes every sample index start at `offset`: the tracer renders sample indices `offset`,
    /// `offset + 1`, ... of each pixel (`render --sample-range A..B` sets A). Takes effect from
    /// the next pass; call it before rendering.
    pub fn set_sample_offset(&mut self, offset: u32) {
        self.sample_offset = offset;
    }

    /// The first sample index (see [`Self::set_sample_offset`]).
    pub fn sample_offset(&self) -> u32 {
        self.sample_offset
    }

    /// With `true`, every pass [`Self::step`] plans ends on a multiple of the chunk size in
    /// absolute sample indices (or where the render ends), so each pixel's chunks are always the
    /// same samples, whatever the batching: two renders with the same seed, or one resumed from
    /// a checkpoint, fold the same f32 chunk sums in the same order and agree bit for bit. The
    /// first pass then has a whole chunk (16 spp) rather than the planner's 1-spp probe; the
    /// bands shrink to keep each submission short. The `render` example turns it on.
    pub fn set_chunk_aligned_passes(&mut self, aligned: bool) {
        self.chunk_aligned = aligned;
    }

    /// The pass in progress, if a render stopped inside one: (its spp, rows done from row 0).
    pub fn partial_pass(&self) -> Option<(u32, u32)> {
        self.pass.as_ref().map(|p| (p.plan.spp, p.next_row))
    }

    /// Continues from a checkpoint: the accumulator, the spp of the completed passes, and a pass
    /// stopped inside (its spp and the rows done), which the next steps finish first. The
    /// accumulator must have this tracer's resolution.
    pub fn restore(
        &mut self,
        mut accumulator: Accumulator,
        spp_done: u32,
        partial_pass: Option<(u32, u32)>,
    ) -> Result<(), PathTraceError> {
        let camera = self.scene.camera;
        if (accumulator.width, accumulator.height) != (camera.width, camera.height) {
            return Err(PathTraceError::Unsupported {
                scene: self.scene.name.clone(),
                message: format!(
                    "a checkpoint of {} x {} pixels cannot continue a {} x {} render",
                    accumulator.width, accumulator.height, camera.width, camera.height
                ),
            });
        }
        accumulator.set_radiance_exponent(self.radiance_exponent);
        self.reset();
        self.accumulator = accumulator;
        self.spp_done = spp_done;
        self.pass =
            partial_pass.filter(|&(_, rows)| rows > 0 && rows < camera.height).map(|(spp, next_row)| {
                let planned = self.planner.plan(camera.width, camera.height, spp);
                let rows = if planned.spp >= spp { camera.height } else { planned.rows.max(1) };
                ActivePass { plan: self.fit(PassPlan { spp, rows }), sample_base: spp_done, next_row }
            });
        if let Some(display) = &self.display_sum {
            display.seed(&self.gpu, &self.accumulator, self.radiance_exponent);
        }
        Ok(())
    }

    /// Discards everything accumulated; the next step starts again at sample 0.
    pub fn reset(&mut self) {
        self.accumulator.reset();
        if let Some(display) = &self.display_sum {
            display.clear(&self.gpu);
        }
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
            let mut plan = self.fit(self.planner.plan(camera.width, camera.height, remaining));
            if self.chunk_aligned {
                plan = align_pass(plan, self.sample_offset + self.spp_done, remaining, self.chunk_samples);
            }
            self.pass = Some(ActivePass { plan, sample_base: self.spp_done, next_row: 0 });
        }
        let report = self.submit_band()?;
        self.planner.record(report.samples, report.wall_seconds);
        Ok(report)
    }

    /// Renders exactly `spp` more samples per pixel, as one pass when the device allows (split
    /// into bands only if the image is too large for one short submission or one storage binding,
    /// and into several passes only if one dispatch cannot carry `spp` chunks). Tests use it to
    /// control batching.
    pub fn render_pass(&mut self, spp: u32) -> Result<(), PathTraceError> {
        assert!(self.pass.is_none(), "render_pass called in the middle of a pass");
        let camera = self.scene.camera;
        let mut remaining = spp;
        while remaining > 0 {
            let planned = self.planner.plan(camera.width, camera.height, remaining);
            let rows = if planned.spp >= remaining { camera.height } else { planned.rows.max(1) };
            let plan = self.fit(PassPlan { spp: remaining, rows });
            self.pass = Some(ActivePass { plan, sample_base: self.spp_done, next_row: 0 });
            while self.pass.is_some() {
                let report = self.submit_band()?;
                self.planner.record(report.samples, report.wall_seconds);
            }
            remaining -= plan.spp;
        }
        Ok(())
    }

    /// Shrinks a pass plan to what the device can take: at most `max_chunks` chunks per dispatch
    /// (the z dimension), and a band of at most `max_slots` slots (rows x width x chunks) per
    /// batch buffer, so an image of any size is rendered band by band.
    fn fit(&self, plan: PassPlan) -> PassPlan {
        let width = u64::from(self.scene.camera.width);
        let chunk = u64::from(self.chunk_samples);
        // check_row_fits guarantees max_slots >= width, so at least one chunk fits.
        let max_chunks = u64::from(self.max_chunks).min(self.max_slots / width).max(1);
        let spp = u64::from(plan.spp.max(1)).min(max_chunks * chunk);
        let chunks = spp.div_ceil(chunk);
        let max_rows = (self.max_slots / (width * chunks)).max(1);
        let rows = u64::from(plan.rows).clamp(1, max_rows);
        PassPlan { spp: spp as u32, rows: rows as u32 }
    }

    /// Steps until every pixel has `spp` samples.
    pub fn render(&mut self, spp: u32) -> Result<(), PathTraceError> {
        while self.spp_done < spp {
            self.step(Some(spp))?;
        }
        Ok(())
    }

    /// Makes sure the batch buffers hold at least `slots` slots (growing them, within
    /// `max_slots`, and rebinding).
    fn ensure_batch_capacity(&mut self, slots: u64) -> Result<(), PathTraceError> {
        if self.batch.as_ref().is_some_and(|b| b.slots >= slots) {
            return Ok(());
        }
        // Grow geometrically (within max_slots) so that passes of slowly rising spp do not
        // reallocate every time; never below what this band needs (a pass planned before a
        // lower cap was set still needs its own size).
        let doubled = self.batch.as_ref().map_or(0, |b| 2 * b.slots).min(self.max_slots);
        let slots = slots.max(doubled);
        let device = &self.gpu.device;
        let batch = self.gpu.scoped("allocating path-tracer batch buffers", || {
            let buffer = |label: &str| {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size: slots * SLOT_BYTES,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                })
            };
            let sum = buffer("pathtrace batch sum");
            let sum_sq = buffer("pathtrace batch sum of squares");
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("pathtrace"),
                layout: &self.pipeline.get_bind_group_layout(0),
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: self.params_buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: self.objects_buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: self.materials_buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 3, resource: self.lights_buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 4, resource: sum.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 5, resource: sum_sq.as_entire_binding() },
                ],
            });
            BatchBuffers { slots, sum, sum_sq, bind_group }
        })?;
        self.batch = Some(batch);
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
        let sample_base = pass.sample_base;
        let chunk = self.chunk_samples;
        let chunks = spp.div_ceil(chunk);
        let band_pixels = rows as usize * width as usize;
        let slots = band_pixels as u64 * u64::from(chunks);
        self.ensure_batch_capacity(slots)?;

        let mut params = self.base_params;
        params.row_offset = row_offset;
        params.rows = rows;
        params.sample_base = self.sample_offset + sample_base;
        params.sample_count = spp;
        params.chunk_samples = chunk;
        self.gpu.queue.write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&params));

        let bytes = slots * SLOT_BYTES;
        let staging_size = 2 * bytes + self.timer.result_size();
        if self.staging.as_ref().is_none_or(|s| s.size() < staging_size) {
            self.staging = Some(self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pathtrace staging"),
                size: staging_size,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }));
        }
        let staging = self.staging.as_ref().expect("allocated above");
        let batch = self.batch.as_ref().expect("allocated above");

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
            compute.set_bind_group(0, &batch.bind_group, &[]);
            compute.dispatch_workgroups(width.div_ceil(WORKGROUP), rows.div_ceil(WORKGROUP), chunks);
        }
        // The display sum reads the slots on the GPU in the same submission (wgpu orders the two
        // passes); the copies below for the f64 fold are unchanged.
        if let Some(display) = &mut self.display_sum {
            display.record(&self.gpu, &mut encoder, &batch.sum, rows, row_offset, chunks);
        }
        encoder.copy_buffer_to_buffer(&batch.sum, 0, staging, 0, bytes);
        encoder.copy_buffer_to_buffer(&batch.sum_sq, 0, staging, bytes, bytes);
        self.timer.copy_results(&mut encoder, staging, 2 * bytes);
        self.gpu.queue.submit([encoder.finish()]);

        let data =
            readback::read_mapped(&self.gpu, staging, staging_size, "reading back a path-tracing batch")?;
        let floats: Vec<[f32; 4]> = data[..(2 * bytes) as usize]
            .chunks_exact(16)
            .map(|c| {
                let f = |i: usize| f32::from_le_bytes(c[4 * i..4 * i + 4].try_into().expect("4 bytes"));
                [f(0), f(1), f(2), f(3)]
            })
            .collect();
        let (sums, sums_sq) = floats.split_at(floats.len() / 2);
        // Every slot must account for all of its chunk's samples (finite + dropped). A shortfall
        // means the driver ended the invocation early; its statistics would silently be short.
        for k in 0..chunks {
            let expected = chunk.min(spp - k * chunk);
            let range = k as usize * band_pixels..(k as usize + 1) * band_pixels;
            for (s, q) in sums[range.clone()].iter().zip(&sums_sq[range]) {
                let found = s[3] as u64 + q[3] as u64;
                if found != u64::from(expected) {
                    // The accumulator drops this band, but the display pass already added it:
                    // set the display sum back to the accumulator's samples.
                    if let Some(display) = &self.display_sum {
                        display.seed(&self.gpu, &self.accumulator, self.radiance_exponent);
                    }
                    return Err(PathTraceError::IncompleteBatch { expected, found });
                }
            }
        }
        for k in 0..chunks as usize {
            let range = k * band_pixels..(k + 1) * band_pixels;
            self.accumulator.fold(
                row_offset as usize * width as usize,
                &sums[range.clone()],
                &sums_sq[range],
            );
        }
        let gpu_seconds = self.timer.decode(&data[(2 * bytes) as usize..]).map(|timings| timings[0].1 * 1e-3);

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

/// A pass plan changed so that the pass ends on a multiple of `chunk` in absolute sample indices
/// (`start` is the pass's first index), or at the end of the render (`remaining` samples): one
/// chunk more when the plan would end inside the first chunk, fewer when it ends past a chunk
/// boundary. The rows shrink or grow with the spp so that a submission keeps its size.
fn align_pass(plan: PassPlan, start: u32, remaining: u32, chunk: u32) -> PassPlan {
    if plan.spp >= remaining {
        return PassPlan { spp: remaining, ..plan };
    }
    let chunk = chunk.max(1);
    let end = start.saturating_add(plan.spp) / chunk * chunk;
    let spp = if end > start { end - start } else { chunk - start % chunk }.min(remaining);
    let rows = (u64::from(plan.rows) * u64::from(plan.spp) / u64::from(spp)).clamp(1, u64::from(u32::MAX));
    PassPlan { spp, rows: rows as u32 }
}

/// One row of one chunk is the smallest band; it must fit in one batch buffer.
fn check_row_fits(scene: &Scene, max_slots: u64) -> Result<(), PathTraceError> {
    let width = u64::from(scene.camera.width);
    if width > max_slots {
        return Err(PathTraceError::Unsupported {
            scene: scene.name.clone(),
            message: format!(
                "camera.width = {width}: one row needs {} bytes per batch buffer, more than the {} \
                 bytes allowed (the device's max_storage_buffer_binding_size, or a lower cap)",
                width * SLOT_BYTES,
                max_slots * SLOT_BYTES
            ),
        });
    }
    Ok(())
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
