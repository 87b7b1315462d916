//! The path tracer: a scene's buffers on the GPU, and the submit-readback-fold loop that renders
//! it progressively, band by band, into the f64 accumulator.
//!
//! This file builds a tracer for a scene (and rebuilds it when the scene changes) and holds its
//! settings. The pipeline comes from `shaders.rs`, the batch buffers and their decoding from
//! `batch.rs`, the size of each submission from `planner.rs`; the passes of a render (planned,
//! reset, restored from a checkpoint) are `tracer/passes.rs`, and one submission (a band
//! traced, read back and folded) is `tracer/submit.rs`.
//!
//! About 450 lines, one concept: the `PathTracer` type, its fields and their settings.

use illum_gpu::timing::PassTimer;
use illum_gpu::{GpuContext, wgpu};
use illum_scene::Scene;
use wgpu::util::DeviceExt;

use crate::batch::{self, BatchBuffers, CHUNK_SAMPLES, SLOT_BYTES};
use crate::display_sum::DisplaySum;
use crate::gpu_scene::{self, GpuParams, GpuScene};
use crate::options::{TracerOptions, Traversal};
use crate::planner::{BatchPlanner, DEFAULT_TARGET_SECONDS, PassPlan};
use crate::{Accumulator, PathTraceError, SampleAllocation, limits, shaders, specialise};

mod caustic;
mod passes;
mod submit;

pub use caustic::{CausticParams, bounding_sphere, fixed_point};

const TIMED_PASS: &str = "pathtrace";

/// What one submission did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepReport {
    /// Paths traced: the band's pixels x the pass's spp, or with adaptive sampling the samples
    /// its blocks took.
    pub samples: u64,
    /// Wall time of the submission, including readback and the f64 fold.
    pub wall_seconds: f64,
    /// GPU time of the compute pass, from timestamp queries, when the adapter has them.
    pub gpu_seconds: Option<f64>,
    /// True when this submission finished a pass over the whole image.
    pub pass_completed: bool,
    /// Paths the band was planned to trace (its pixels x the pass's spp, or with adaptive
    /// sampling what its blocks' counts allow): `samples` falls short of it only by samples
    /// dropped as NaN or Inf.
    pub scheduled_samples: u64,
}

struct ActivePass {
    plan: PassPlan,
    sample_base: u32,
    /// Rows folded so far (from row 0).
    next_row: u32,
    /// Rows submitted so far: `next_row` plus a band launched ahead (see `submit.rs`).
    launched_row: u32,
}

impl ActivePass {
    fn new(plan: PassPlan, sample_base: u32, next_row: u32) -> Self {
        ActivePass { plan, sample_base, next_row, launched_row: next_row }
    }
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
    /// With mapped readback, the other set of batch buffers: bands alternate between the two, so
    /// that the next band is traced while the CPU folds the last one from its mapping.
    spare_batch: Option<BatchBuffers>,
    /// Whether the CPU reads the batch buffers where the GPU wrote them (a device that shares the
    /// host's memory, see `illum_gpu::policy::shares_host_memory`) instead of from a staging copy.
    mapped_readback: bool,
    staging: Option<wgpu::Buffer>,
    /// The next band of the pass, submitted before the current one was folded (see
    /// `submit.rs`).
    #[cfg(not(target_arch = "wasm32"))]
    ahead: Option<submit::AheadBand>,
    /// When the last band was folded: a band launched ahead counts its wall time from there.
    last_fold: Option<web_time::Instant>,
    /// When [`Self::render_step`] last returned, and how long its caller then took to call it
    /// again: a band is launched ahead only for a caller that comes straight back (see
    /// `submit.rs`, `launch_ahead`).
    returned_at: Option<web_time::Instant>,
    caller_absence: std::time::Duration,
    /// What the last submission did (see [`Self::last_step`]).
    last_step: StepReport,
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
    /// Whether [`Self::render_step`] ends passes on multiples of the chunk (see
    /// [`Self::set_chunk_aligned_passes`]).
    chunk_aligned: bool,
    /// With chunk-aligned passes, the statistics at the last chunk boundary before a pass that
    /// ends inside a chunk (the last pass of a render whose spp is not a multiple of the chunk),
    /// and their spp. A checkpoint stores them so that a resumed render can start again from that
    /// boundary: splitting the final chunk's f32 sum in two would differ from a straight render
    /// by f32 rounding.
    aligned_prefix: Option<(Accumulator, u32)>,
    /// 2^-k scale of the uploaded emission (see `accumulator::radiance_exponent`).
    radiance_exponent: i32,
    /// The caustic's light tracer, when the scene asks for it and can have a caustic.
    caustic: Option<caustic::CausticTracer>,
    /// Wall and GPU seconds spent on submissions since the last reset.
    wall_seconds: f64,
    gpu_seconds: f64,
    /// Whether [`Self::render_step`] polls its readback instead of waiting (see
    /// [`Self::set_polled_readback`]), and the band it is waiting for.
    polled_readback: bool,
    in_flight: Option<submit::InFlightBand>,
    /// Adaptive sampling: the samples of each block of pixels, and the buffer the shader reads
    /// them from (see [`Self::set_sample_allocation`]).
    allocation: Option<(SampleAllocation, wgpu::Buffer)>,
    /// Whether the pipeline was compiled for adaptive sampling (shader def ADAPTIVE).
    adaptive_pipeline: bool,
}

/// The placeholder record bound when a scene has no area light.
const EMPTY_LIGHT: crate::gpu_scene::GpuLight = crate::gpu_scene::GpuLight {
    corner: [0.0; 4],
    edge_u: [0.0; 4],
    edge_v: [0.0; 4],
    normal: [0.0; 4],
    emission: [0.0; 4],
};

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
        Self::build(gpu, scene, options, false)
    }

    /// As [`Self::with_options`], with adaptive sampling from the start: the same as
    /// [`Self::set_sample_allocation`] after it, without compiling the pipeline without adaptive
    /// sampling first (a tenth of a second on lavapipe, 2 to 3% of a 1024-spp render at 256 x 256).
    pub fn with_sample_allocation(
        gpu: &GpuContext,
        scene: &Scene,
        options: TracerOptions,
        allocation: SampleAllocation,
    ) -> Result<Self, PathTraceError> {
        let mut tracer = Self::build(gpu, scene, options, true)?;
        tracer.set_sample_allocation(Some(allocation))?;
        Ok(tracer)
    }

    /// A tracer whose pipeline has adaptive sampling (shader def ADAPTIVE) or not; with it, the
    /// caller sets an allocation before rendering.
    fn build(
        gpu: &GpuContext,
        scene: &Scene,
        options: TracerOptions,
        adaptive: bool,
    ) -> Result<Self, PathTraceError> {
        let limits = gpu.device.limits();
        // The batch buffers hold one band of rows at a time (the image is tiled into bands that
        // fit one storage binding, see `fit`), so the storage limit applies to a band, not to the
        // whole image: only the texture-size limit is checked against the full resolution here,
        // and one row of one chunk must fit (below).
        limits::check_texture_size(scene, &limits)?;
        let max_slots = batch::device_max_slots(&limits);
        batch::check_row_fits(scene, max_slots)?;
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
        let (pipeline, traversal_source) =
            shaders::pathtrace_pipeline(gpu, scene, &gpu_scene, options, adaptive)?;

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
        let caustic = caustic::CausticTracer::new(
            gpu,
            scene,
            &gpu_scene,
            options,
            [&params_buffer, &objects_buffer, &materials_buffer],
            base_params,
        )?;

        Ok(Self {
            gpu: gpu.clone(),
            scene: scene.clone(),
            options,
            traversal_source,
            base_params,
            pipeline,
            params_buffer,
            objects_buffer,
            materials_buffer,
            lights_buffer,
            batch: None,
            spare_batch: None,
            mapped_readback: gpu.device.features().contains(wgpu::Features::MAPPABLE_PRIMARY_BUFFERS),
            staging: None,
            #[cfg(not(target_arch = "wasm32"))]
            ahead: None,
            last_fold: None,
            returned_at: None,
            caller_absence: std::time::Duration::ZERO,
            last_step: StepReport::default(),
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
            aligned_prefix: None,
            radiance_exponent: gpu_scene.radiance_exponent,
            caustic,
            wall_seconds: 0.0,
            gpu_seconds: 0.0,
            polled_readback: cfg!(target_arch = "wasm32"),
            in_flight: None,
            allocation: None,
            adaptive_pipeline: adaptive,
        })
    }

    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Whether the caustic's light tracer runs (`[pathtrace] caustics = true` on a scene with a
    /// directional light and a mirror or dielectric).
    pub fn caustics(&self) -> bool {
        self.caustic.is_some()
    }

    /// The caustic's shader parameters (fixed-point scale and cap, discs), when it runs.
    pub fn caustic_params(&self) -> Option<CausticParams> {
        self.caustic.as_ref().map(|c| c.params())
    }

    /// Whether `self` and `other` run the very same compiled pipeline: the context's cache found
    /// an equal specialisation instead of compiling again.
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

    /// Sets the wall time aimed at per submission (default 0.15 s). The cost of a sample learnt
    /// so far is kept, so a viewer may change it every frame.
    pub fn set_target_seconds(&mut self, seconds: f64) {
        self.planner.set_target_seconds(seconds);
    }

    /// With `Some(cap)`, a pass over the whole image is one submission whenever it traces at
    /// most `cap` paths (see `BatchPlanner::set_whole_passes_up_to`): what an interactive viewer
    /// wants, a complete image after every frame.
    pub fn set_whole_passes_up_to(&mut self, cap: Option<u64>) {
        self.planner.set_whole_passes_up_to(cap);
    }

    /// What the last call of [`Self::render_step`] did (a default report before any, or when
    /// it had nothing to do or was still waiting for a polled readback).
    pub fn last_step(&self) -> StepReport {
        self.last_step
    }

    /// Takes a new camera and render settings (spp, bounces, seed, sampling) without rebuilding
    /// the pipeline, and restarts the accumulation. The geometry and materials must be the ones
    /// the pipeline was built for: a scene that differs in them (another specialisation, or
    /// other object data) is refused with an error naming what changed; build a new
    /// `PathTracer` for it. The resolution may change (the buffers are reallocated).
    pub fn update_scene(&mut self, scene: &Scene) -> Result<(), PathTraceError> {
        let gpu_scene = GpuScene::new(scene)?;
        if scene.objects != self.scene.objects || scene.materials != self.scene.materials {
            let needed = specialise::traversal(&gpu_scene);
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
            return Err(PathTraceError::Unsupported {
                scene: scene.name.clone(),
                message: format!(
                    "this path tracer was built for scene {:?} and cannot render it: {what}; create a new PathTracer",
                    self.scene.name
                ),
            });
        }
        // Another resolution, or settings that choose another pipeline (shader defs: the
        // caustic on or off, the hemisphere sampling, bounded or unbounded paths), build anew.
        let rebuild = (scene.camera.width, scene.camera.height)
            != (self.scene.camera.width, self.scene.camera.height)
            || gpu_scene.code != GpuScene::new(&self.scene)?.code;
        if rebuild {
            // An allocation belongs to its resolution; with the same one it carries over.
            let allocation = self
                .allocation
                .take()
                .map(|(a, _)| a)
                .filter(|a| (a.width, a.height) == (scene.camera.width, scene.camera.height));
            let mut resized = Self::build(&self.gpu, scene, self.options, allocation.is_some())?;
            // What the caller chose and the planner learnt (the cost of a sample) carry over:
            // a viewer that set short submissions keeps them after the window is resized.
            resized.planner = self.planner.clone();
            resized.chunk_samples = self.chunk_samples;
            resized.sample_offset = self.sample_offset;
            resized.chunk_aligned = self.chunk_aligned;
            resized.polled_readback = self.polled_readback;
            resized.mapped_readback = self.mapped_readback;
            if self.display_sum.is_some() {
                resized.enable_display_sum()?;
            }
            if allocation.is_some() {
                resized.set_sample_allocation(allocation)?;
            }
            *self = resized;
            return Ok(());
        }
        self.base_params = gpu_scene::params(scene, &gpu_scene);
        // The caustic's parameters follow the camera and the seed.
        self.caustic = caustic::CausticTracer::new(
            &self.gpu,
            scene,
            &gpu_scene,
            self.options,
            [&self.params_buffer, &self.objects_buffer, &self.materials_buffer],
            self.base_params,
        )?;
        self.scene = scene.clone();
        self.reset();
        Ok(())
    }

    /// Adaptive sampling (`allocation.rs`): from now on each block of 8 x 8 pixels takes the
    /// samples `allocation` gives it, sample indices `0..n` of each of its pixels, and a render
    /// to [`SampleAllocation::max`] spp is complete ([`Self::spp_done`] then counts sample
    /// indices reached, which every block below it has taken in full). `None`: every pixel takes
    /// every sample again. Restarts the accumulation, and switches the pipeline (shader def
    /// ADAPTIVE) when adaptivity is turned on or off. Refused for an allocation of another
    /// resolution and with the caustic's light tracer (whose passes cover the whole image at
    /// one spp). [`Self::update_scene`] keeps it while the resolution stays.
    pub fn set_sample_allocation(
        &mut self,
        allocation: Option<SampleAllocation>,
    ) -> Result<(), PathTraceError> {
        let camera = self.scene.camera;
        if let Some(a) = &allocation {
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
        }
        self.reset();
        if allocation.is_some() != self.adaptive_pipeline {
            let gpu_scene = GpuScene::new(&self.scene)?;
            let adaptive = allocation.is_some();
            self.pipeline =
                shaders::pathtrace_pipeline(&self.gpu, &self.scene, &gpu_scene, self.options, adaptive)?.0;
            self.adaptive_pipeline = adaptive;
        }
        let device = &self.gpu.device;
        self.allocation = match allocation {
            Some(a) => {
                let buffer = self.gpu.scoped("allocating the adaptive sample counts", || {
                    illum_gpu::buffers::storage_buffer(
                        device,
                        "pathtrace block samples",
                        bytemuck::cast_slice(&a.samples),
                    )
                })?;
                Some((a, buffer))
            }
            None => None,
        };
        // The batch buffers' bind groups name the old pipeline's bindings: made anew.
        self.batch = None;
        self.spare_batch = None;
        Ok(())
    }

    /// The adaptive sample allocation, when one is set.
    pub fn sample_allocation(&self) -> Option<&SampleAllocation> {
        self.allocation.as_ref().map(|(a, _)| a)
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
        let slots = (bytes / SLOT_BYTES).min(batch::device_max_slots(&limits));
        batch::check_row_fits(&self.scene, slots)?;
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

    /// With `false`, reads every band back through a staging copy even on a device whose batch
    /// buffers can be mapped where the GPU wrote them (the default there; elsewhere, and for
    /// polled readback, the copy is the only way). The samples and statistics are the same bit
    /// for bit; tests use it to check that, on a software driver, for the path discrete GPUs take.
    pub fn set_mapped_readback(&mut self, mapped: bool) {
        self.mapped_readback =
            mapped && self.gpu.device.features().contains(wgpu::Features::MAPPABLE_PRIMARY_BUFFERS);
    }

    /// Whether bands are read where the GPU wrote them (see [`Self::set_mapped_readback`]).
    pub fn mapped_readback(&self) -> bool {
        self.mapped_readback
    }

    /// Makes [`Self::render_step`] poll for each band's results (and the caustic's frames)
    /// instead of waiting for them: what a web page needs, since the browser maps buffers only
    /// between frames. The samples, the f64 fold and the statistics are the same; only the
    /// waiting differs. [`Self::render_to_spp`] and [`Self::add_samples_in_one_pass`] always
    /// wait. On `wasm32` readback is always polled (nothing there can wait), whatever `polled`.
    pub fn set_polled_readback(&mut self, polled: bool) {
        self.polled_readback = polled || cfg!(target_arch = "wasm32");
    }
}
