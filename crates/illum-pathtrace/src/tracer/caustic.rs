//! The caustic's light tracer on the host (shader `crates/illum-pathtrace/shaders/caustic.wgsl`; the
//! estimator and its path space are in docs/caustics.md).
//!
//! Frame k, N = width x height particles, pairs with sample index k of every pixel: pixel p's
//! sample k is the camera path's estimate plus frame k's splat at p. Rather than adding the two
//! per sample on the GPU, each pass traces its frames first, reads each frame back and keeps, per slot layer of the pass
//! (the same groups of sample indices as the camera's f32 slot sums, `batch::Layers`) and pixel, the f64 sum S1 and sum
//! of squares S2 of the frames' values. Folding a camera chunk (sum C of n samples) then adds
//!     sum += S1,   sum of squares += S2 + 2 C S1 / n.
//! The last term replaces sum_k c_k s_k by its mean over the pairings of the chunk's camera and
//! caustic values, which has the same expectation n^2 mu_c mu_s / n as the paired sum because
//! the two estimators are independent. So the accumulator's mean is exactly the two
//! estimators' sum, and its sample variance is an unbiased estimate of var(c) + var(s): the
//! error estimate stays honest, and checkpoints, resume, merge and the stop rules work
//! unchanged. Frames depend only on (seed, particle, frame index), and integer atomics add in
//! any order to the same result, so the image does not depend on how a render is batched.
//!
//! Scheduling: submissions sized like a band to the step's time target
//! (`caustic/schedule.rs`): whole frames when a frame fits it, else a frame in pieces (ranges of
//! its particles, then of its gathering pixels), the frame read back and folded with its last.
//! Natively the tools wait for each submission ([`CausticTracer::prepare_pass`]), and a step
//! goes on with the next frame's pieces, sized to what is left of its target, while much of it
//! is (whole frames seldom fill it); a web page cannot wait, so there one submission's
//! completion or mapping is asked again on later frames ([`CausticTracer::poll_pass`]). Frames
//! are folded in order whatever the cut, so the pass's statistics are the same bit for bit.
//!
//! Fixed point: see [`fixed_point`].
//!
//! With a delta sun each dispatch also runs the photon gather (`shaders/gather.wgsl`) after the
//! particles, into the same frames: its photon maps and grid are allocated and cleared here.
//!
//! This file holds the tracer and what it learns from each submission; a pass's statistics are
//! `caustic/pass.rs`, the submissions that trace its frames `caustic/dispatch.rs`, a pass waited
//! for `caustic/waited.rs` and one polled `caustic/polled.rs`; its resources (pipelines,
//! buffers, bind groups) are made in `caustic/resources.rs`, its parameters and fixed point are
//! `caustic/params.rs`, its scheduling `caustic/schedule.rs` (both pure, tested without a GPU).

mod dispatch;
mod flight;
mod params;
mod pass;
mod polled;
mod resources;
mod schedule;
#[cfg(not(target_arch = "wasm32"))]
mod waited;

use illum_gpu::timing::PassTimer;
use illum_gpu::wgpu;

use crate::accumulator::Accumulator;
use crate::batch::{self, Layers};
use crate::gpu_scene::GpuParams;
pub use params::{CausticParams, bounding_sphere, fixed_point};
use params::{PASS_BYTES, PASS_BYTES_PER_PIXEL_LAYER};
use pass::CausticPass;
pub(crate) use pass::PassKey;
use schedule::{Costs, Cursor, Stage, Submission, Took};

/// The photon gather's pipeline and grid (shader def CAUSTIC_GATHER).
struct Gather {
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    /// The hierarchies' buffers (group 1), for a scene with a mesh or many spheres.
    bvh: Option<illum_rtcore::BvhBindGroup>,
    /// The grid's bucket heads, cleared before each dispatch.
    heads: wgpu::Buffer,
    heads_frame_bytes: u64,
}

pub(crate) struct CausticTracer {
    pipeline: wgpu::ComputePipeline,
    /// The hierarchies' buffers (group 1), for a scene with a mesh or many spheres.
    bvh: Option<illum_rtcore::BvhBindGroup>,
    /// The photon gather, with a delta sun.
    gather: Option<Gather>,
    params_buffer: wgpu::Buffer,
    /// The path tracer's parameters buffer, which the shader reads the camera from, and the
    /// scene's parameters to write there before each dispatch (a band writes its own fields
    /// there too; the camera's are the same).
    scene_params_buffer: wgpu::Buffer,
    scene_params: GpuParams,
    splat: wgpu::Buffer,
    /// The mappable copy of a dispatch's frames; taken by a polled read while it is mapped
    /// (`None` then, or after a read was abandoned: made again when needed).
    staging: Option<wgpu::Buffer>,
    splat_size: u64,
    bind_group: wgpu::BindGroup,
    base: CausticParams,
    /// The most frames one dispatch may carry (the splat and photon buffers' size).
    max_frames_per_dispatch: u32,
    /// What its submissions were measured to cost: sizes the next (see `schedule.rs`).
    costs: Costs,
    /// Seconds the frames folded so far took, each dispatch at the cost that sized the next
    /// one (its GPU time where the device has timestamps): the light tracer's share of a
    /// render's time, which the bands' own reports do not hold ([`crate::PathTracer::caustic_seconds`]).
    seconds_spent: f64,
    /// Where that time went ([`CausticParts`]).
    parts: CausticParts,
    /// Times the light tracer's and the gather's passes, where the device has timestamps.
    timer: PassTimer,
    /// The most workgroups of a dispatch along x (a piece of more is laid out in rows).
    max_groups_x: u32,
    pixels: usize,
    /// What a fixed-point unit is worth in true radiance: 2^radiance_exponent / S.
    unit: f64,
    /// The pass being gathered or held, with its dispatch in flight.
    pass: Option<CausticPass>,
}

/// Where the light tracer's time went, summed over the frames folded so far, so that a
/// benchmark can give each part its own row: its two stages over the frames whose stages were
/// timed (traced whole on a device with timestamps: their GPU time; or in pieces, each waited
/// for: the pieces' wall time, the GPU's work and the submissions' latency), and the host's fold
/// of every frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CausticParts {
    /// Frames folded.
    pub frames: u64,
    /// Frames whose stages were timed (the two stages' seconds are theirs).
    pub timed_frames: u64,
    /// Seconds of the particles' stage: tracing from the sun through the specular objects,
    /// splatting to the eye, and storing the photons the gather reads.
    pub particles: f64,
    /// Seconds of the gather's stage (0 without a delta sun).
    pub gather: f64,
    /// Host seconds folding every frame's splat into the pass's f64 sums.
    pub fold_host: f64,
}

impl CausticTracer {
    /// Seconds the light tracer's frames folded so far took (see `seconds_spent`).
    pub(crate) fn seconds_spent(&self) -> f64 {
        self.seconds_spent
    }

    /// Where the light tracer's time went so far.
    pub(crate) fn parts(&self) -> CausticParts {
        self.parts
    }

    /// Counts what a submission's frames cost: `count` frames (whole, or a frame's last piece)
    /// folded in `fold_seconds`, with the GPU's `timestamps` (the bytes after the frames in the
    /// staging copy) where whole frames were timed. A waited piece adds its `waited` seconds to
    /// its stage, and its frame counts as timed when its last piece was waited for too.
    fn record_parts(
        &mut self,
        submission: Submission,
        count: u32,
        timestamps: &[u8],
        fold_seconds: f64,
        waited: Option<f64>,
    ) {
        let parts = &mut self.parts;
        parts.frames += u64::from(count);
        parts.fold_host += fold_seconds;
        match submission {
            Submission::Frames { .. } => {
                if let Some(passes) = self.timer.decode(timestamps) {
                    parts.timed_frames += u64::from(count);
                    for (name, ms) in passes {
                        match name.as_str() {
                            dispatch::CAUSTIC_PASS => parts.particles += ms * 1e-3,
                            dispatch::GATHER_PASS => parts.gather += ms * 1e-3,
                            _ => {}
                        }
                    }
                }
            }
            Submission::Piece { stage, read, .. } => {
                if let Some(seconds) = waited {
                    match stage {
                        Stage::Particles => parts.particles += seconds,
                        Stage::Gather => parts.gather += seconds,
                    }
                    parts.timed_frames += u64::from(read);
                }
            }
        }
    }

    /// The parameters the shader gets (for the layout test and the overflow tests).
    pub(crate) fn params(&self) -> CausticParams {
        self.base
    }

    /// The most samples per pixel one pass may have so that its layers' statistics fit
    /// [`PASS_BYTES`] (at least one chunk).
    pub(crate) fn max_pass_spp(&self, layers: Layers) -> u32 {
        let per_chunk = PASS_BYTES_PER_PIXEL_LAYER * u64::from(layers.per_chunk()) * self.pixels as u64;
        let chunks = (PASS_BYTES / per_chunk).max(1);
        (chunks * u64::from(layers.chunk)).min(u64::from(u32::MAX)) as u32
    }

    /// The share of pass `key`'s frames folded, counting the frame in pieces by the share of its
    /// invocations traced (0 when another pass, or none, is held).
    pub(crate) fn pass_share(&self, key: PassKey) -> f64 {
        let Some(pass) = self.pass.as_ref().filter(|p| p.key == key) else { return 0.0 };
        let n = f64::from(self.base.particles.max(1));
        let stages = if self.gather.is_some() { 2.0 } else { 1.0 };
        let within = match pass.cursor {
            Cursor::FrameStart => 0.0,
            Cursor::Within { stage: Stage::Particles, next } => f64::from(next) / n / stages,
            Cursor::Within { stage: Stage::Gather, next } => (1.0 + f64::from(next) / n) / stages,
        };
        ((f64::from(pass.frames_done) + within) / f64::from(pass.key.spp.max(1))).min(1.0)
    }

    /// What one whole frame was measured to cost, in seconds.
    pub(crate) fn frame_seconds(&self) -> Option<f64> {
        self.costs.frame
    }

    /// Whether the frames of pass `key` are all traced and folded.
    pub(crate) fn holds(&self, key: PassKey) -> bool {
        self.pass.as_ref().is_some_and(|p| p.key == key && p.complete())
    }

    /// Takes pass `key` out of the tracer to gather its frames: the one being gathered or held,
    /// or a new one (a pass of another key, and a dispatch in flight for it, are dropped). The
    /// caller puts it back once its step is done; after an error it is dropped, and its frames
    /// are traced again.
    fn take_pass(&mut self, key: PassKey) -> CausticPass {
        match self.pass.take() {
            Some(pass) if pass.key == key => pass,
            _ => CausticPass::new(key, self.pixels),
        }
    }

    /// Learns from a submission that took `seconds` in all as its caller saw it, `work` of
    /// them before its fold (the piece's own cost).
    fn record(&mut self, pass: &mut CausticPass, submission: Submission, seconds: f64, work: Took) {
        self.seconds_spent += seconds;
        match submission {
            Submission::Frames { count } => self.costs.record_frames(count, work),
            Submission::Piece { stage, count, read, .. } => {
                self.costs.record_piece(stage, count, work);
                pass.frame_seconds += seconds;
                if read {
                    self.costs.record_pieced_frame(pass.frame_seconds);
                    pass.frame_seconds = 0.0;
                }
            }
        }
    }

    /// Adds the held pass's layer `l` for the band's pixels `first_pixel..` to the accumulator,
    /// beside the camera's slot sums `camera` of that layer just folded for them (see the module
    /// documentation for the cross term).
    pub(crate) fn fold(
        &self,
        accumulator: &mut Accumulator,
        l: u32,
        first_pixel: usize,
        camera: &[[f32; 4]],
    ) {
        let pass = self.pass.as_ref().filter(|p| p.complete()).expect("prepare_pass before fold");
        let PassKey { first_sample, spp, layers, .. } = pass.key;
        let frames = layers.samples(first_sample, l, batch::chunk_taken(layers, spp, l));
        let at = l as usize * self.pixels + first_pixel;
        let range = at..at + camera.len();
        accumulator.fold_independent(
            first_pixel,
            layers.replicate(l),
            camera,
            &pass.sum[range.clone()],
            &pass.sum_sq[range],
            frames,
        );
    }

    /// Forgets the held pass and abandons its dispatch in flight (their frames belong to a
    /// render that was reset).
    pub(crate) fn discard_pass(&mut self) {
        self.pass = None;
    }

    /// Ends the held pass: its dropped particles are counted once, and its memory freed.
    pub(crate) fn finish_pass(&mut self, accumulator: &mut Accumulator) {
        if let Some(pass) = self.pass.take() {
            accumulator.add_dropped(pass.dropped);
        }
    }
}
