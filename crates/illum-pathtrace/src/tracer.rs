//! The path tracer: a scene's buffers on the GPU, and the submit-readback-fold loop that renders
//! it progressively, band by band, into the f64 accumulator.
//!
//! The pipeline comes from `shaders.rs`, the batch buffers and their decoding from `batch.rs`,
//! the size of each submission from `planner.rs`; one submission (a band traced, read back and
//! folded) is `tracer/submit.rs`.

use illum_gpu::timing::PassTimer;
use illum_gpu::{GpuContext, wgpu};
use illum_scene::Scene;
use wgpu::util::DeviceExt;

use crate::batch::{self, BatchBuffers, CHUNK_SAMPLES, SLOT_BYTES};
use crate::display_sum::DisplaySum;
use crate::gpu_scene::{self, GpuParams, GpuScene};
use crate::options::{TracerOptions, Traversal};
use crate::planner::{BatchPlanner, DEFAULT_TARGET_SECONDS, PassPlan};
use crate::{Accumulator, PathTraceError, limits, shaders, specialise};

mod caustic;
mod submit;

pub use caustic::{CausticParams, bounding_sphere, fixed_point};

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
    ahead: Option<submit::AheadBand>,
    /// When the last band was folded: a band launched ahead counts its wall time from there.
    last_fold: Option<web_time::Instant>,
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
        let (pipeline, traversal_source) = shaders::pathtrace_pipeline(gpu, scene, &gpu_scene, options)?;

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
            ahead: None,
            last_fold: None,
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
            polled_readback: false,
            in_flight: None,
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
        let gpu_scene = GpuScene::new(scene)?;
        if scene.objects != self.scene.objects || scene.materials != self.scene.materials {
            let needed = specialise::specialise(scene, &gpu_scene);
            let what = if self.options.traversal == Traversal::Specialised
                && needed.source != self.traversal_source
            {
                format!(
                    "its geometry needs a pipeline specialised for shapes {:?}, {} light(s) and shadow-ray occluders {:?}",
                    needed.kind_names(),
                    needed.lights,
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
            || gpu_scene.defs != GpuScene::new(&self.scene)?.defs;
        if rebuild {
            let mut resized = Self::with_options(&self.gpu, scene, self.options)?;
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
        )?;
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

    /// With `true`, every pass [`Self::render_step`] plans ends on a multiple of the chunk size in
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

    /// The statistics at the last chunk boundary and their spp, when the samples taken so far
    /// (or the pass in progress) end inside a chunk: what a checkpoint stores so that a resumed
    /// render can go on from that boundary (see [`Self::set_chunk_aligned_passes`]).
    pub fn aligned_prefix(&self) -> Option<(&Accumulator, u32)> {
        let chunk = self.chunk_samples.max(1);
        let end = self.sample_offset + self.spp_done + self.pass.as_ref().map_or(0, |p| p.plan.spp);
        let (accumulator, spp) = self.aligned_prefix.as_ref()?;
        (!end.is_multiple_of(chunk)).then_some((accumulator, *spp))
    }

    /// Continues from a checkpoint: the accumulator, the spp of the completed passes, and a pass
    /// stopped inside (its spp and the rows done), which the next steps finish first. The
    /// accumulator must have this tracer's resolution. `aligned_prefix`: the checkpoint's
    /// statistics at its last chunk boundary (see [`Self::aligned_prefix`]), kept for the next
    /// checkpoint when the pass in progress ends inside a chunk.
    pub fn restore(
        &mut self,
        mut accumulator: Accumulator,
        spp_done: u32,
        partial_pass: Option<(u32, u32)>,
        aligned_prefix: Option<(Accumulator, u32)>,
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
        self.aligned_prefix = aligned_prefix.map(|(mut prefix, spp)| {
            prefix.set_radiance_exponent(self.radiance_exponent);
            (prefix, spp)
        });
        self.pass =
            partial_pass.filter(|&(_, rows)| rows > 0 && rows < camera.height).map(|(spp, next_row)| {
                let planned = self.planner.plan(camera.width, camera.height, spp);
                let rows = if planned.spp >= spp { camera.height } else { planned.rows.max(1) };
                ActivePass::new(self.fit(PassPlan { spp, rows }), spp_done, next_row)
            });
        if let Some(display) = &self.display_sum {
            display.seed(&self.gpu, &self.accumulator, self.radiance_exponent);
        }
        Ok(())
    }

    /// Discards everything accumulated; the next step starts again at sample 0.
    pub fn reset(&mut self) {
        self.in_flight = None;
        self.ahead = None;
        self.last_fold = None;
        self.accumulator.reset();
        if let Some(caustic) = &mut self.caustic {
            caustic.discard_pass();
        }
        if let Some(display) = &self.display_sum {
            display.clear(&self.gpu);
        }
        self.pass = None;
        self.spp_done = 0;
        self.aligned_prefix = None;
        self.wall_seconds = 0.0;
        self.gpu_seconds = 0.0;
    }

    /// Runs one short submission (one band of rows of the current pass; about 0.15 s, see
    /// [`Self::set_target_seconds`]) toward `target_spp` samples per pixel (`None`: no limit).
    /// Returns a report with `samples == 0` once the target is reached. Progressive renderers
    /// call it in a loop, between frames or checks of their stop rules.
    ///
    /// With [`Self::set_polled_readback`] it never waits: a call submits a band, and later calls
    /// report `samples == 0` until its results are back, then fold it and report it.
    pub fn render_step(&mut self, target_spp: Option<u32>) -> Result<StepReport, PathTraceError> {
        let camera = self.scene.camera;
        if self.pass.is_none() {
            let remaining = match target_spp {
                Some(t) if t <= self.spp_done => return Ok(StepReport::default()),
                Some(t) => t - self.spp_done,
                None => u32::MAX - self.spp_done,
            };
            let mut plan = self.fit(self.planner.plan(camera.width, camera.height, remaining));
            if self.chunk_aligned {
                let start = self.sample_offset + self.spp_done;
                plan = align_pass(plan, start, remaining, self.chunk_samples);
                let chunk = self.chunk_samples.max(1);
                if start.is_multiple_of(chunk) {
                    // The last pass of a render that ends inside a chunk: keep the statistics
                    // at this boundary (see `aligned_prefix`), if the host has the memory for
                    // the copy with a fifth to spare (at 8192 x 8192 on 24 GB it has not: such
                    // a render, resumed, then differs from a straight one by f32 rounding, and
                    // the resume says so).
                    let copy_fits = || {
                        use crate::accumulator::{ALIGNED_COPY_BYTES_PER_PIXEL, RENDER_HOST_BYTES_PER_PIXEL};
                        let pixels = u64::from(self.accumulator.width) * u64::from(self.accumulator.height);
                        let peak = pixels * (RENDER_HOST_BYTES_PER_PIXEL + ALIGNED_COPY_BYTES_PER_PIXEL);
                        crate::accumulator::available_host_memory()
                            .is_none_or(|available| peak <= available / 5 * 4)
                    };
                    self.aligned_prefix = (!(start + plan.spp).is_multiple_of(chunk) && copy_fits())
                        .then(|| (self.accumulator.clone(), self.spp_done));
                }
            }
            self.pass = Some(ActivePass::new(plan, self.spp_done, 0));
        }
        let report = if self.polled_readback {
            match self.poll_band()? {
                Some(report) => report,
                None => return Ok(StepReport::default()),
            }
        } else {
            self.submit_band()?
        };
        // A polled band's wall time includes the frames drawn while it was read back; its GPU
        // time (timestamp queries), where the adapter has them, is what it cost.
        let seconds = if self.polled_readback {
            report.gpu_seconds.unwrap_or(report.wall_seconds)
        } else {
            report.wall_seconds
        };
        self.planner.record(report.samples, seconds);
        // Later bands of the pass follow what the planner has learnt: a pass planned before
        // the first measurement (at 1024 x 1024 with chunk-aligned passes, bands of one row)
        // would otherwise be a thousand tiny submissions, each paying the driver's fixed cost.
        // Bands are rows, so their size never changes which samples a pixel's chunks hold.
        if let Some(spp) = self.pass.as_ref().map(|p| p.plan.spp) {
            let rows = self.planner.rows_for(camera.width, camera.height, spp);
            let fitted = self.fit(PassPlan { spp, rows });
            if let Some(pass) = self.pass.as_mut().filter(|_| fitted.spp == spp) {
                pass.plan.rows = fitted.rows;
            }
        }
        Ok(report)
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

    /// Makes [`Self::render_step`] poll for each band's results instead of waiting for them:
    /// what a web page needs, since the browser maps buffers only between frames. The samples,
    /// the f64 fold and the statistics are the same; only the waiting differs.
    /// [`Self::render_to_spp`] and [`Self::add_samples_in_one_pass`] always wait.
    pub fn set_polled_readback(&mut self, polled: bool) {
        self.polled_readback = polled;
    }

    /// Renders until every pixel has `spp` samples in all (those already taken count), in
    /// submissions sized by the measured speed.
    pub fn render_to_spp(&mut self, spp: u32) -> Result<(), PathTraceError> {
        while self.spp_done < spp {
            self.render_step(Some(spp))?;
        }
        Ok(())
    }

    /// Adds exactly `spp` samples per pixel in one pass over the image when the device allows
    /// (split into bands only if the image is too large for one short submission or one storage
    /// binding, and into several passes only if one dispatch cannot carry `spp` chunks). Unlike
    /// [`Self::render_to_spp`], the grouping of samples into f32 chunk sums then depends on the
    /// call alone, never on measured speed: tests use it to compare renders bit for bit and to
    /// control batching.
    pub fn add_samples_in_one_pass(&mut self, spp: u32) -> Result<(), PathTraceError> {
        assert!(self.pass.is_none(), "add_samples_in_one_pass called in the middle of a pass");
        let camera = self.scene.camera;
        let mut remaining = spp;
        while remaining > 0 {
            let planned = self.planner.plan(camera.width, camera.height, remaining);
            let rows = if planned.spp >= remaining { camera.height } else { planned.rows.max(1) };
            let plan = self.fit(PassPlan { spp: remaining, rows });
            self.pass = Some(ActivePass::new(plan, self.spp_done, 0));
            while self.pass.is_some() {
                let report = self.submit_band()?;
                self.planner.record(report.samples, report.wall_seconds);
            }
            remaining -= plan.spp;
        }
        Ok(())
    }
}
/// A pass plan changed so that the pass ends on a multiple of `chunk` in absolute sample indices
/// (`start` is the pass's first index), or at the end of the render (`remaining` samples): one
/// chunk more when the plan would end inside the first chunk, fewer when it ends past a chunk
/// boundary. The rows shrink or grow with the spp so that a submission keeps its size.
fn align_pass(plan: PassPlan, start: u32, remaining: u32, chunk: u32) -> PassPlan {
    let chunk = chunk.max(1);
    if plan.spp >= remaining {
        // The last pass. Where the render ends inside a chunk, the whole chunks come first and
        // the rest in a pass of its own, so that the statistics at the last chunk boundary can be
        // kept for a resumed render (see `PathTracer::aligned_prefix`).
        let end = start.saturating_add(remaining);
        let boundary = end / chunk * chunk;
        let spp = if !end.is_multiple_of(chunk) && boundary > start { boundary - start } else { remaining };
        return PassPlan { spp, ..plan };
    }
    let end = start.saturating_add(plan.spp) / chunk * chunk;
    let spp = if end > start { end - start } else { chunk - start % chunk }.min(remaining);
    let rows = (u64::from(plan.rows) * u64::from(plan.spp) / u64::from(spp)).clamp(1, u64::from(u32::MAX));
    PassPlan { spp, rows: rows as u32 }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every pass ends on a chunk boundary or at the render's end, and a render that ends inside
    /// a chunk gets its whole chunks first and the rest in a last pass of its own.
    #[test]
    fn passes_end_on_chunk_boundaries_and_the_tail_comes_alone() {
        let ends = |start: u32, target: u32, plan_spp: u32| {
            let mut ends = Vec::new();
            let mut at = start;
            while at < target {
                let plan = align_pass(PassPlan { spp: plan_spp, rows: 8 }, at, target - at, 16);
                assert!(plan.spp >= 1 && plan.rows >= 1);
                at += plan.spp;
                ends.push(at);
            }
            ends
        };
        assert_eq!(ends(0, 50, 1000), [48, 50]);
        assert_eq!(ends(0, 50, 20), [16, 32, 48, 50]);
        assert_eq!(ends(0, 10, 1000), [10]);
        assert_eq!(ends(0, 64, 1000), [64]);
        assert_eq!(ends(16, 100, 1000), [96, 100]);
        assert_eq!(ends(0, 100, 1), [16, 32, 48, 64, 80, 96, 100]);
        // A resumed render going on from an unaligned count reaches the next boundary first.
        assert_eq!(ends(50, 100, 1000), [96, 100]);
        assert_eq!(ends(50, 100, 4), [64, 80, 96, 100]);
    }
}
