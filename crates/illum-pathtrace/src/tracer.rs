//! The path tracer: a scene's buffers on the GPU, and the submit-readback-fold loop that renders
//! it progressively, band by band, into the f64 accumulator.
//!
//! A [`PathTracer`] is three parts, each in its own file:
//! - the scene pipeline (`tracer/pipeline.rs`): the scene, its buffers and the pipelines
//!   compiled for it, adaptive sampling's block counts and the caustic's light tracer
//!   (`tracer/caustic.rs`);
//! - the band runner (`tracer/runner.rs`): how bands are read back ([`Readback`]), the state of
//!   the render between calls (no pass, a pass, a pass with a band on the GPU), the buffers,
//!   the pass sizing and its pacing; the passes of a render are `tracer/passes.rs`, and one
//!   submission (a band traced, read back and folded) is `tracer/submit.rs`;
//! - the accumulation (`tracer/accumulation.rs`): the f64 statistics and what goes with them.
//!
//! This file builds a tracer for a scene (and rebuilds it when the scene changes) and holds the
//! settings callers choose.

use illum_gpu::{GpuContext, wgpu};
use illum_scene::Scene;

use crate::accumulator::ExactPart;
use crate::batch::{self, CHUNK_SAMPLES, Layers, SLOT_BYTES};
use crate::display_sum::DisplaySum;
use crate::gpu_scene::GpuScene;
use crate::options::TracerOptions;
use crate::{Accumulator, PathTraceError, SampleAllocation, limits};

mod accumulation;
mod caustic;
mod guides;
mod passes;
mod pipeline;
mod runner;
mod submit;

use accumulation::Accumulation;
pub use caustic::{CausticParams, CausticParts, bounding_sphere, fixed_point};
pub use guides::{GUIDE_SAMPLES_MAX, GUIDE_SAMPLES_MIN, Guides, PendingGuides, guide_samples};
use pipeline::ScenePipeline;
use runner::BandRunner;
pub use runner::Readback;

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

pub struct PathTracer {
    /// The scene on the GPU and the pipelines compiled for it.
    pipeline: ScenePipeline,
    /// The passes and bands on their way through the GPU.
    bands: BandRunner,
    /// What the folded bands add up to.
    accumulation: Accumulation,
}

/// Solves `scene`'s glint (`glint.rs`) as the accumulator's exact part, on a thread of its own
/// while the first samples are traced (the host's solve would otherwise be most of the set-up
/// before the first sample in a scene of many specular objects): none without a delta sun and
/// the caustic's estimators.
fn set_glint(accumulator: &mut Accumulator, scene: &Scene) {
    if !crate::glint::glint_active(scene) {
        accumulator.set_exact(ExactPart::default());
        return;
    }
    let pixels = accumulator.width as usize * accumulator.height as usize;
    let scene = scene.clone();
    accumulator.set_exact_solving(move |unread| {
        let points = crate::glint::solve_unless(&scene, &|| unread.is_set());
        let values = crate::glint::pixel_values(&points);
        ExactPart::new(&values, pixels).expect("the solve keeps only finite values inside the image")
    });
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
        Self::build(gpu, scene, options, None)
    }

    /// As [`Self::with_options`], with adaptive sampling from the start: the same as
    /// [`Self::set_sample_allocation`] after it, without compiling the pipeline without adaptive
    /// sampling first (a noticeable part of a short render on a software driver).
    pub fn with_sample_allocation(
        gpu: &GpuContext,
        scene: &Scene,
        options: TracerOptions,
        allocation: SampleAllocation,
    ) -> Result<Self, PathTraceError> {
        Self::build(gpu, scene, options, Some(allocation))
    }

    /// A tracer whose pipeline has adaptive sampling (shader def ADAPTIVE) with `allocation`,
    /// or not without one.
    fn build(
        gpu: &GpuContext,
        scene: &Scene,
        options: TracerOptions,
        allocation: Option<SampleAllocation>,
    ) -> Result<Self, PathTraceError> {
        let limits = gpu.device.limits();
        // The batch buffers hold one band of rows at a time (the image is tiled into bands that
        // fit one storage binding, see `fit`), so the storage limit applies to a band, not to the
        // whole image: only the texture-size limit is checked against the full resolution here,
        // and one row of one chunk must fit (below).
        limits::check_texture_size(scene, &limits)?;
        let max_slots = batch::device_max_slots(&limits);
        let layers = Layers { chunk: CHUNK_SAMPLES, replicated: options.replicated() };
        batch::check_row_fits(scene, layers.per_chunk(), max_slots)?;
        // A replicated render also keeps its replicates, and writes them into its EXR.
        let replicate_bytes =
            if layers.replicated { 2 * crate::replicates::Replicates::BYTES_PER_PIXEL } else { 0 };
        crate::accumulator::check_host_memory(
            scene.camera.width,
            scene.camera.height,
            replicate_bytes,
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
        accumulator.set_radiance_exponent(gpu_scene.radiance_exponent);
        set_glint(&mut accumulator, scene);
        let pipeline = ScenePipeline::new(gpu, scene, &gpu_scene, options, allocation)?;
        let bands = BandRunner::new(gpu, max_slots);
        if layers.replicated {
            // Its error comes from replicates, each summed in slots of its own (batch::Layers).
            accumulator.enable_replicates();
        }
        accumulator.set_estimates_error(options.estimates_error());
        Ok(PathTracer { pipeline, bands, accumulation: Accumulation::new(accumulator) })
    }

    pub fn scene(&self) -> &Scene {
        &self.pipeline.scene
    }

    /// Whether the caustic's light tracer runs (`[pathtrace] caustics = true` on a scene with a
    /// directional light and a mirror or dielectric).
    pub fn caustics(&self) -> bool {
        self.pipeline.caustic.is_some()
    }

    /// The caustic's shader parameters (fixed-point scale and cap, discs), when it runs.
    pub fn caustic_params(&self) -> Option<CausticParams> {
        self.pipeline.caustic.as_ref().map(|c| c.params())
    }

    /// Whether `self` and `other` run the very same compiled pipeline: the context's cache found
    /// an equal specialisation instead of compiling again.
    pub fn shares_pipeline_with(&self, other: &PathTracer) -> bool {
        self.pipeline.compute == other.pipeline.compute
    }

    pub fn accumulator(&self) -> &Accumulator {
        &self.accumulation.accumulator
    }

    /// For tests that set the image's exact part themselves (a solve they hold back).
    #[cfg(test)]
    pub(crate) fn accumulator_mut(&mut self) -> &mut Accumulator {
        &mut self.accumulation.accumulator
    }

    /// The traversal and sample sequence this tracer was built with.
    pub fn options(&self) -> TracerOptions {
        self.pipeline.options
    }

    /// The name of the GPU adapter it renders on.
    pub fn adapter_name(&self) -> &str {
        &self.pipeline.gpu.adapter_info.name
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
        if self.accumulation.display_sum.is_some() {
            return Ok(());
        }
        let (gpu, scene) = (&self.pipeline.gpu, &self.pipeline.scene);
        let display = DisplaySum::new(gpu, &scene.name, scene.camera.width, scene.camera.height)?;
        if self.accumulation.accumulator.total_samples() > 0 {
            display.seed(gpu, &self.accumulation.accumulator, self.pipeline.radiance_exponent);
        }
        self.accumulation.display_sum = Some(display);
        Ok(())
    }

    /// What the display sum's values must be multiplied by to be radiance: 2^k, where the
    /// scene's emission was uploaded scaled by 2^-k so that no f32 sum or square on the GPU
    /// overflows (1 for every light up to 2^16; see `accumulator::radiance_exponent`). A viewer
    /// folds it into its exposure.
    pub fn display_scale(&self) -> f32 {
        2f32.powi(self.pipeline.radiance_exponent)
    }

    /// The display sum's buffer (usage `STORAGE | COPY_SRC | COPY_DST`) once
    /// [`Self::enable_display_sum`] was called. It is replaced by a new buffer when the
    /// resolution changes, so bind it anew whenever this returns another buffer.
    pub fn display_sum_buffer(&self) -> Option<&wgpu::Buffer> {
        self.accumulation.display_sum.as_ref().map(DisplaySum::buffer)
    }

    /// Samples per pixel in every pixel (completed passes).
    pub fn spp_done(&self) -> u32 {
        self.accumulation.spp_done
    }

    /// The share of the pass in progress that is done, in [0, 1] (0 without one): its caustic
    /// frames and its bands' rows, each weighted by its measured cost (alike before they are
    /// measured). A pass's caustic frames come first and hold no samples until its bands fold,
    /// so this, not the samples, is how a progress bar moves through them.
    pub fn pass_fraction(&self) -> f64 {
        let Some(pass) = self.bands.pass() else { return 0.0 };
        let height = f64::from(self.pipeline.scene.camera.height.max(1));
        let rows = (f64::from(pass.next_row) / height).min(1.0);
        let Some(caustic) = &self.pipeline.caustic else { return rows };
        let frames = caustic.pass_share(self.caustic_key(pass));
        let camera = self.pipeline.scene.camera;
        let pixels = f64::from(camera.width) * f64::from(camera.height);
        let spp = f64::from(pass.plan.spp);
        let (caustic_cost, band_cost) =
            match (caustic.frame_seconds(), self.bands.planner.seconds_per_sample()) {
                (Some(frame), Some(sample)) => (frame * spp, sample * pixels * spp),
                _ => (1.0, 1.0),
            };
        (caustic_cost * frames + band_cost * rows) / (caustic_cost + band_cost).max(1e-300)
    }

    /// Wall seconds spent in submissions since the last reset.
    pub fn wall_seconds(&self) -> f64 {
        self.accumulation.wall_seconds
    }

    /// Seconds the caustic's light tracer and gather have taken since the tracer was built (0
    /// without them): their GPU time where the device has timestamps, else the wall time until
    /// their readback was seen done. Not in [`StepReport`]'s times, which are the camera
    /// bands': a caller that times a render by its steps adds this one's growth.
    pub fn caustic_seconds(&self) -> f64 {
        self.pipeline.caustic.as_ref().map_or(0.0, |c| c.seconds_spent())
    }

    /// Where the light tracer's time went so far, part by part (`None` without a light tracer).
    pub fn caustic_parts(&self) -> Option<CausticParts> {
        self.pipeline.caustic.as_ref().map(|c| c.parts())
    }

    /// GPU seconds of the compute passes since the last reset (0 without timestamp queries).
    pub fn gpu_seconds(&self) -> f64 {
        self.accumulation.gpu_seconds
    }

    /// Sets the wall time aimed at per submission (default 0.15 s): the bands of camera paths
    /// and the caustic's frames (or pieces of one) alike. The costs learnt so far are kept, so a
    /// viewer may change it every frame.
    pub fn set_target_seconds(&mut self, seconds: f64) {
        self.bands.planner.set_target_seconds(seconds);
    }

    /// With `Some(cap)`, a pass over the whole image is one submission whenever it traces at
    /// most `cap` paths (see `BatchPlanner::set_whole_passes_up_to`): what an interactive viewer
    /// wants, a complete image after every frame.
    pub fn set_whole_passes_up_to(&mut self, cap: Option<u64>) {
        self.bands.planner.set_whole_passes_up_to(cap);
    }

    /// What the last call of [`Self::render_step`] did (a default report before any, or when
    /// it had nothing to do or was still waiting for a polled readback).
    pub fn last_step(&self) -> StepReport {
        self.bands.last_step
    }

    /// Takes a new camera and render settings (spp, bounces, seed, sampling) without rebuilding
    /// the pipeline, and restarts the accumulation. The geometry and materials must be the ones
    /// the pipeline was built for: a scene that differs in them (another specialisation, or
    /// other object data) is refused with an error naming what changed; build a new
    /// `PathTracer` for it. The resolution may change (the buffers are reallocated).
    pub fn update_scene(&mut self, scene: &Scene) -> Result<(), PathTraceError> {
        let gpu_scene = GpuScene::new(scene)?;
        self.pipeline.check_same_geometry(scene, &gpu_scene)?;
        if self.pipeline.needs_rebuild(scene, &gpu_scene)? {
            // An allocation belongs to its resolution; with the same one it carries over.
            let allocation = self
                .pipeline
                .allocation
                .as_ref()
                .map(|(a, _)| a.clone())
                .filter(|a| (a.width, a.height) == (scene.camera.width, scene.camera.height));
            let mut resized = Self::build(&self.pipeline.gpu, scene, self.pipeline.options, allocation)?;
            // What the caller chose and the planner learnt (the cost of a sample) carry over:
            // a viewer that set short submissions keeps them after the window is resized.
            resized.bands.carry_settings(&self.bands);
            if self.accumulation.display_sum.is_some() {
                resized.enable_display_sum()?;
            }
            *self = resized;
            return Ok(());
        }
        self.pipeline.retarget(scene, &gpu_scene)?;
        self.reset();
        set_glint(&mut self.accumulation.accumulator, scene);
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
        if let Some(a) = &allocation {
            self.pipeline.check_allocation(a)?;
        }
        self.reset();
        self.pipeline.set_allocation(allocation)?;
        // The batch buffers' bind groups name the old pipeline's bindings: made anew.
        self.bands.buffers.forget_batch();
        Ok(())
    }

    /// The adaptive sample allocation, when one is set.
    pub fn sample_allocation(&self) -> Option<&SampleAllocation> {
        self.pipeline.allocation.as_ref().map(|(a, _)| a)
    }

    /// Sets the samples per invocation (default [`crate::CHUNK_SAMPLES`]; values below 1 count as 1),
    /// from the next pass on. With 1 every sample reaches the f64 fold as its own f32 value, which
    /// makes the result the exact f64 fold of the samples (tests use it as the reference); larger
    /// chunks round each chunk's f32 sum by up to (n - 1) x 2^-24 relative.
    pub fn set_chunk_samples(&mut self, samples: u32) {
        self.bands.chunk_samples = samples.max(1);
    }

    /// Caps each batch buffer at `bytes` (at most the device's storage binding limit, which is the
    /// default; at least one row of one chunk), from the next pass on. The image is then rendered
    /// in bands of rows that fit; tests use it to force that tiling on small images.
    pub fn limit_batch_bytes(&mut self, bytes: u64) -> Result<(), PathTraceError> {
        let limits = self.pipeline.gpu.device.limits();
        let slots = (bytes / SLOT_BYTES).min(batch::device_max_slots(&limits));
        batch::check_row_fits(&self.pipeline.scene, self.layers().per_chunk(), slots)?;
        self.bands.max_slots = slots;
        Ok(())
    }

    /// Makes every sample index start at `offset`: the tracer renders sample indices `offset`,
    /// `offset + 1`, ... of each pixel (`render --sample-range A..B` sets A). Takes effect from
    /// the next pass; call it before rendering.
    pub fn set_sample_offset(&mut self, offset: u32) {
        self.bands.sample_offset = offset;
    }

    /// The first sample index (see [`Self::set_sample_offset`]).
    pub fn sample_offset(&self) -> u32 {
        self.bands.sample_offset
    }

    /// Reads bands back with `readback` from the next band on (default: [`Readback::Mapped`]
    /// where the device can map its batch buffers, else [`Readback::Staging`]; on `wasm32`
    /// always [`Readback::Polled`], since nothing there can wait). A device that cannot map its
    /// batch buffers takes [`Readback::Mapped`] as [`Readback::Staging`]. The samples and
    /// statistics are the same bit for bit in every mode; tests use it to check that, on a
    /// software driver, for the path discrete GPUs take. [`Self::render_to_spp`] waits in every
    /// mode, and [`Self::add_samples_in_one_pass`] waits for a staging copy when polled. A band
    /// on the GPU read another way is dropped and traced again.
    pub fn set_readback(&mut self, readback: Readback) {
        self.bands.set_readback(readback, &self.pipeline.gpu);
    }

    /// How bands are read back (see [`Self::set_readback`]).
    pub fn readback(&self) -> Readback {
        self.bands.readback()
    }
}
