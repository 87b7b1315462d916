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
//! Scheduling: one submission per step, sized like a band to the step's time target
//! (`caustic/schedule.rs`): whole frames when a frame fits it, else a frame in pieces (ranges of
//! its particles, then of its gathering pixels), the frame read back and folded with its last.
//! Natively the tools wait for each submission ([`CausticTracer::prepare_pass`]); a web page
//! cannot wait, so there each submission's completion or mapping is asked again on later frames
//! ([`CausticTracer::poll_pass`]). Frames are folded in order whatever the cut, so the pass's
//! statistics are the same bit for bit.
//!
//! Fixed point: see [`fixed_point`].
//!
//! With a delta sun each dispatch also runs the photon gather (`shaders/gather.wgsl`) after the
//! particles, into the same frames: its photon maps and grid are allocated and cleared here.
//!
//! This file holds a pass's frames from submission to fold, waited for or polled; its
//! resources (pipelines, buffers, bind groups) are made in `caustic/resources.rs`, its
//! parameters and fixed point are `caustic/params.rs`, its scheduling `caustic/schedule.rs`
//! (both pure, tested without a GPU).

use illum_gpu::readback::PendingRead;
use illum_gpu::timing::PassTimer;
use illum_gpu::{GpuContext, wgpu};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use web_time::Instant;

use crate::accumulator::Accumulator;
use crate::batch::{self, Layers};

use crate::PathTraceError;
use crate::gpu_scene::GpuParams;
use schedule::{Costs, Cursor, FrameShape, Stage, Submission, Took, WORKGROUP, next_submission};

mod params;
mod resources;
mod schedule;

pub use params::{CausticParams, bounding_sphere, fixed_point};
use params::{PASS_BYTES, PASS_BYTES_PER_PIXEL_LAYER, WORDS_PER_PIXEL};

/// Which pass a caustic pass belongs to: its first absolute sample index, its spp, the slot
/// layers of the camera's sums that its statistics are grouped by, and the render's first
/// sample index (which the gather's radius counts from).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct PassKey {
    pub first_sample: u32,
    pub spp: u32,
    pub layers: Layers,
    pub origin: u32,
}

/// One pass's caustic statistics: per slot layer and pixel, S1 and S2 of its frames, complete once
/// `frames_done` reaches the pass's spp.
struct CausticPass {
    key: PassKey,
    sum: Vec<[f64; 3]>,
    sum_sq: Vec<[f64; 3]>,
    dropped: u64,
    /// Frames folded so far: frames `key.first_sample..key.first_sample + frames_done`.
    frames_done: u32,
    /// Where the next frame stands (traced in pieces, see `schedule.rs`).
    cursor: Cursor,
    /// Seconds the pieces of the frame at `cursor` took so far.
    frame_seconds: f64,
    /// Whether the frame at `cursor` was begun by polling (a waiting caller starts it again:
    /// its last polled piece may not be done).
    polled_frame: bool,
    /// The submission whose polled readback, or polled completion, is under way.
    in_flight: Option<InFlight>,
}

impl CausticPass {
    fn new(key: PassKey, pixels: usize) -> Self {
        let layers = key.layers.count(key.spp) as usize;
        CausticPass {
            key,
            sum: vec![[0.0; 3]; layers * pixels],
            sum_sq: vec![[0.0; 3]; layers * pixels],
            dropped: 0,
            frames_done: 0,
            cursor: Cursor::FrameStart,
            frame_seconds: 0.0,
            polled_frame: false,
            in_flight: None,
        }
    }

    fn complete(&self) -> bool {
        self.frames_done >= self.key.spp
    }

    /// Forgets the pieces of the frame in progress: it is traced again from its start (by the
    /// blocking `prepare_pass`, which a browser does not have).
    #[cfg(not(target_arch = "wasm32"))]
    fn restart_frame(&mut self) {
        self.cursor = Cursor::FrameStart;
        self.frame_seconds = 0.0;
        self.polled_frame = false;
    }

    /// Folds `count` frames of `pixels` pixels read back from a dispatch (the splat buffer's
    /// words, frames first, then one dropped-particle counter per frame): they are the pass's
    /// next frames. A fixed-point unit is worth `unit` in true radiance.
    fn fold_frames(&mut self, words: &[u32], count: u32, pixels: usize, unit: f64) {
        let words_per_frame = WORDS_PER_PIXEL as usize * pixels;
        for f in 0..count as usize {
            let relative = self.frames_done as usize + f;
            let offset = self.key.layers.layer_of(self.key.first_sample, relative as u32) as usize * pixels;
            let frame = &words[f * words_per_frame..(f + 1) * words_per_frame];
            for (p, w) in frame.chunks_exact(WORDS_PER_PIXEL as usize).enumerate() {
                for c in 0..3 {
                    let q = (u64::from(w[2 * c + 1]) << 32) | u64::from(w[2 * c]);
                    if q != 0 {
                        let v = q as f64 * unit;
                        self.sum[offset + p][c] += v;
                        self.sum_sq[offset + p][c] += v * v;
                    }
                }
            }
            self.dropped += u64::from(words[count as usize * words_per_frame + f]);
        }
        self.frames_done += count;
    }
}

/// A polled submission: frames whose readback is under way, or a piece whose work is.
struct InFlight {
    what: Flight,
    submission: Submission,
    launched: Instant,
    /// Looks that found it not yet done.
    looks: u32,
}

/// What the `seconds` from a submission to the look that saw it done say of its cost, after
/// `looks` that saw it not done: a bound (see [`Took`]).
fn seen_done(looks: u32, seconds: f64) -> Took {
    if looks == 0 { Took::WithinOneLook(seconds) } else { Took::AtMost(seconds) }
}

enum Flight {
    /// Frames to read back (whole ones, or a frame's last piece).
    Read { read: PendingRead, bytes: DispatchBytes, count: u32 },
    /// A piece of a frame, set done when the GPU has finished it.
    Piece(Arc<AtomicBool>),
}

/// What [`CausticTracer::launch`] submitted.
enum Launched {
    /// A piece of a frame, not read back.
    Piece(Submission),
    /// Frames to read back: whole ones, or a frame's last piece.
    Frames { staging: wgpu::Buffer, bytes: DispatchBytes, count: u32, submission: Submission },
}

/// What a dispatch's staging copy holds: its frames' bytes, then the timestamps (if timed).
#[derive(Clone, Copy)]
struct DispatchBytes {
    frames: u64,
    total: u64,
}

/// The timer's names of the light tracer's and the photon gather's passes.
const CAUSTIC_PASS: &str = "caustic";
const GATHER_PASS: &str = "photon gather";

/// The photon gather's pipeline and grid (shader def CAUSTIC_GATHER).
struct Gather {
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    /// The grid's bucket heads, cleared before each dispatch.
    heads: wgpu::Buffer,
    heads_frame_bytes: u64,
}

pub(crate) struct CausticTracer {
    pipeline: wgpu::ComputePipeline,
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

impl CausticTracer {
    /// Seconds the light tracer's frames folded so far took (see `seconds_spent`).
    pub(crate) fn seconds_spent(&self) -> f64 {
        self.seconds_spent
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

    /// Traces the frames of pass `key` (absolute sample indices `key.first_sample..`, grouped
    /// in the slot layers `key.layers`) and folds them, one submission per call sized to `target`
    /// seconds (`schedule.rs`), waiting for it. Returns true only when the pass's frames were all
    /// folded before this call (so a step is one submission of caustic work or one band, never
    /// both).
    #[cfg(not(target_arch = "wasm32"))]
    pub(crate) fn prepare_pass(
        &mut self,
        gpu: &GpuContext,
        key: PassKey,
        target: f64,
    ) -> Result<bool, PathTraceError> {
        let mut pass = self.take_pass(key);
        // A polled submission left in flight is abandoned, and so is a frame begun by polling
        // (its last piece may not be done): the frame is traced again from its start here.
        if pass.in_flight.take().is_some() || pass.polled_frame {
            pass.restart_frame();
        }
        let ready = pass.complete();
        let (pixels, unit) = (self.pixels, self.unit);
        let started = Instant::now();
        match self.launch(gpu, &mut pass, target)? {
            None => {}
            Some(Launched::Piece(submission)) => {
                gpu.wait_idle("tracing a piece of a caustic frame")?;
                let seconds = started.elapsed().as_secs_f64();
                self.record(&mut pass, submission, seconds, Took::Seconds(seconds));
            }
            Some(Launched::Frames { staging, bytes, count, submission }) => {
                let mut fold_seconds = 0.0;
                illum_gpu::readback::with_mapped(
                    gpu,
                    &staging,
                    bytes.total,
                    "reading back caustic frames",
                    |data| {
                        let fold = Instant::now();
                        pass.fold_frames(
                            bytemuck::cast_slice(&data[..bytes.frames as usize]),
                            count,
                            pixels,
                            unit,
                        );
                        fold_seconds = fold.elapsed().as_secs_f64();
                    },
                )?;
                self.staging = Some(staging);
                let seconds = started.elapsed().as_secs_f64();
                self.record(&mut pass, submission, seconds, Took::Seconds(seconds - fold_seconds));
            }
        }
        self.pass = Some(pass);
        Ok(ready)
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

    /// The polled form of [`Self::prepare_pass`]: true once the frames of pass `key` are all
    /// folded. Each call folds the frames in flight if their mapping is done, or sees whether
    /// the piece in flight is done, and then submits the next work; it never waits. Times are
    /// taken from the submission to the call that sees it done (they count the frames a page
    /// drew meanwhile, so submissions stay short), or from the GPU's timestamps for whole frames
    /// where the device has them.
    pub(crate) fn poll_pass(
        &mut self,
        gpu: &GpuContext,
        key: PassKey,
        target: f64,
    ) -> Result<bool, PathTraceError> {
        let mut pass = self.take_pass(key);
        if let Some(flight) = pass.in_flight.take() {
            let seconds = flight.launched.elapsed().as_secs_f64();
            match flight.what {
                Flight::Read { read, bytes, count } => {
                    let Some(result) = read.poll(gpu) else {
                        pass.in_flight = Some(InFlight {
                            what: Flight::Read { read, bytes, count },
                            looks: flight.looks + 1,
                            ..flight
                        });
                        self.pass = Some(pass);
                        return Ok(false);
                    };
                    let data = result?;
                    let frames = bytes.frames as usize;
                    pass.fold_frames(bytemuck::cast_slice(&data[..frames]), count, self.pixels, self.unit);
                    let gpu_seconds = matches!(flight.submission, Submission::Frames { .. })
                        .then(|| self.timer.decode(&data[frames..]))
                        .flatten()
                        .map(|passes| passes.iter().map(|p| p.1).sum::<f64>() * 1e-3);
                    let took = match gpu_seconds {
                        Some(gpu) => Took::Seconds(gpu),
                        None => seen_done(flight.looks, seconds),
                    };
                    let seconds = gpu_seconds.unwrap_or(seconds);
                    self.record(&mut pass, flight.submission, seconds, took);
                    self.staging = Some(read.into_buffer());
                }
                Flight::Piece(done) => {
                    // One piece on the GPU at a time: the queue never holds more than a step's work.
                    if let Err(e) = gpu.device.poll(wgpu::PollType::Poll) {
                        return Err(illum_gpu::GpuError::DeviceLost { message: e.to_string() }.into());
                    }
                    if !done.load(Ordering::Acquire) {
                        pass.in_flight =
                            Some(InFlight { what: Flight::Piece(done), looks: flight.looks + 1, ..flight });
                        self.pass = Some(pass);
                        return Ok(false);
                    }
                    let took = seen_done(flight.looks, seconds);
                    self.record(&mut pass, flight.submission, seconds, took);
                }
            }
        }
        let launched = self.launch(gpu, &mut pass, target)?;
        let complete = launched.is_none();
        let now = Instant::now();
        pass.in_flight = match launched {
            Some(Launched::Frames { staging, bytes, count, submission }) => Some(InFlight {
                what: Flight::Read {
                    read: PendingRead::start(staging, bytes.total, "reading back caustic frames"),
                    bytes,
                    count,
                },
                submission,
                launched: now,
                looks: 0,
            }),
            Some(Launched::Piece(submission)) => {
                pass.polled_frame = true;
                let done = Arc::new(AtomicBool::new(false));
                let flag = done.clone();
                gpu.queue.on_submitted_work_done(move || flag.store(true, Ordering::Release));
                Some(InFlight { what: Flight::Piece(done), submission, launched: now, looks: 0 })
            }
            None => None,
        };
        self.pass = Some(pass);
        Ok(complete)
    }

    /// The shape of this tracer's frames, for `schedule.rs`.
    fn frame_shape(&self) -> FrameShape {
        FrameShape {
            invocations: self.base.particles,
            gather: self.gather.is_some(),
            max_frames: self.max_frames_per_dispatch,
        }
    }

    /// The staging buffer for a dispatch's frames (the one read last, or a new one).
    fn take_staging(&mut self, gpu: &GpuContext) -> Result<wgpu::Buffer, PathTraceError> {
        match self.staging.take() {
            Some(staging) => Ok(staging),
            None => Ok(gpu.scoped("allocating the caustic's staging buffer", || {
                gpu.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("caustic staging"),
                    size: self.splat_size + self.timer.result_size(),
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                })
            })?),
        }
    }

    /// Submits the next work of `pass`, as [`next_submission`] plans it at the measured costs
    /// and `target` seconds, and moves the pass's cursor past it. `None` when the pass is
    /// complete.
    fn launch(
        &mut self,
        gpu: &GpuContext,
        pass: &mut CausticPass,
        target: f64,
    ) -> Result<Option<Launched>, PathTraceError> {
        if pass.complete() {
            return Ok(None);
        }
        let shape = self.frame_shape();
        let submission =
            next_submission(shape, &self.costs, target, pass.cursor, pass.key.spp - pass.frames_done);
        let frame = pass.key.first_sample + pass.frames_done;
        let read = self.submit(gpu, frame, pass.key.origin, submission)?;
        if pass.cursor == Cursor::FrameStart {
            pass.polled_frame = false;
        }
        pass.cursor = submission.cursor_after(shape.invocations, shape.gather);
        Ok(Some(match (read, submission) {
            (Some((staging, bytes)), Submission::Frames { count }) => {
                Launched::Frames { staging, bytes, count, submission }
            }
            (Some((staging, bytes)), Submission::Piece { .. }) => {
                Launched::Frames { staging, bytes, count: 1, submission }
            }
            (None, _) => Launched::Piece(submission),
        }))
    }

    /// Workgroups (x, y) and the invocations per row for a dispatch of `count` invocations.
    fn layout(&self, count: u32) -> (u32, u32, u32) {
        let groups = count.div_ceil(WORKGROUP).max(1);
        let gx = groups.min(self.max_groups_x.max(1));
        (gx, groups.div_ceil(gx), gx * WORKGROUP)
    }

    /// Records and submits `submission` from sample index `frame` of a render whose first is
    /// `origin`. Returns the staging buffer and what to read from it when it completes frames
    /// (whole ones, or a frame's last piece).
    fn submit(
        &mut self,
        gpu: &GpuContext,
        frame: u32,
        origin: u32,
        submission: Submission,
    ) -> Result<Option<(wgpu::Buffer, DispatchBytes)>, PathTraceError> {
        let n = self.base.particles;
        let (frames, first, count, clear, particles, gather, read) = match submission {
            Submission::Frames { count } => (count, 0, n, true, true, true, true),
            Submission::Piece { stage, first, count, clear, read } => {
                let particles = stage == Stage::Particles;
                (1, first, count, clear, particles, !particles, read)
            }
        };
        let (gx, gy, row_stride) = self.layout(count);
        let params = CausticParams {
            frame_base: frame,
            frame_count: frames,
            first_index: first,
            index_end: first + count,
            row_stride,
            radius_origin: origin,
            ..self.base
        };
        let words_per_frame = WORDS_PER_PIXEL * self.pixels as u64;
        let bytes = (words_per_frame + 1) * 4 * u64::from(frames);
        // Whole frames are timed; a piece is timed by its caller.
        let timed = matches!(submission, Submission::Frames { .. });
        let staging = if read { Some(self.take_staging(gpu)?) } else { None };
        gpu.queue.write_buffer(&self.scene_params_buffer, 0, bytemuck::bytes_of(&self.scene_params));
        gpu.queue.write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&params));
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("caustic frames") });
        if clear {
            encoder.clear_buffer(&self.splat, 0, Some(bytes));
            if let Some(gather) = &self.gather {
                encoder.clear_buffer(&gather.heads, 0, Some(gather.heads_frame_bytes * u64::from(frames)));
            }
        }
        if particles {
            let mut compute = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("caustic"),
                timestamp_writes: if timed { self.timer.compute_writes(CAUSTIC_PASS) } else { None },
            });
            compute.set_pipeline(&self.pipeline);
            compute.set_bind_group(0, &self.bind_group, &[]);
            compute.dispatch_workgroups(gx, gy, frames);
        }
        // Its own pass: the gather reads what every particle of the frames stored.
        if let Some(gather) = self.gather.as_ref().filter(|_| gather) {
            let mut compute = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("photon gather"),
                timestamp_writes: if timed { self.timer.compute_writes(GATHER_PASS) } else { None },
            });
            compute.set_pipeline(&gather.pipeline);
            compute.set_bind_group(0, &gather.bind_group, &[]);
            compute.dispatch_workgroups(gx, gy, frames);
        }
        let result = staging.map(|staging| {
            encoder.copy_buffer_to_buffer(&self.splat, 0, &staging, 0, bytes);
            let timestamps = if timed && self.timer.enabled() {
                self.timer.copy_results(&mut encoder, &staging, bytes);
                self.timer.result_size()
            } else {
                0
            };
            (staging, DispatchBytes { frames: bytes, total: bytes + timestamps })
        });
        gpu.queue.submit([encoder.finish()]);
        Ok(result)
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
