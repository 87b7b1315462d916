//! The band runner's state: how bands come back to the CPU ([`Readback`]), where the render
//! stands between two calls ([`State`]: no pass, a pass, a pass with one of its bands on the
//! GPU), the buffers bands are traced into and read from, how passes are sized, and the pacing
//! that decides whether a band may be launched ahead of its caller.
//!
//! A band on the GPU belongs to the state of its pass, so a band without a pass, or two bands
//! on the GPU at once, cannot be written; how a band is read (waited for in place or through a
//! staging copy, or polled) is one value, not a combination of flags.

use std::time::Duration;

use illum_gpu::readback::PendingRead;
use illum_gpu::timing::PassTimer;
use illum_gpu::{GpuContext, wgpu};
use web_time::Instant;

use super::StepReport;
use super::pipeline::ScenePipeline;
use crate::PathTraceError;
use crate::batch::{BatchBuffers, CHUNK_SAMPLES, Layers};
use crate::planner::{BatchPlanner, DEFAULT_TARGET_SECONDS, PassPlan};

pub(super) const TIMED_PASS: &str = "pathtrace";

/// Longest time a caller may take between two `render_step` calls and still have bands launched
/// ahead for it (see `submit.rs`, `launch_ahead`): a render loop's progress bar takes
/// microseconds, a viewer's frame tens of milliseconds.
#[cfg(not(target_arch = "wasm32"))]
const AHEAD_MAX_ABSENCE: Duration = Duration::from_millis(1);

/// How the results of a band (its sums, sums of squares and timestamps) come back to the CPU.
/// The samples, the f64 fold and the statistics are the same bit for bit in every mode; only
/// the copying and the waiting differ.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Readback {
    /// Copied into a mappable staging buffer, and waited for: what a discrete GPU needs.
    Staging,
    /// Mapped where the shader wrote them, and waited for: on a device that computes in the
    /// host's memory (lavapipe, integrated GPUs; see `illum_gpu::policy::shares_host_memory`)
    /// the copy is saved. The default there.
    Mapped,
    /// Copied into a staging buffer whose mapping later calls poll, never waiting: what a web
    /// page needs, since the browser maps buffers only between frames. The only mode on `wasm32`.
    Polled,
}

impl Readback {
    /// The default on `gpu`: polled on `wasm32`, else mapped where the device can map its batch
    /// buffers, else a staging copy.
    pub(super) fn default_for(gpu: &GpuContext) -> Readback {
        Readback::Mapped.available_on(gpu)
    }

    /// This mode, or the nearest one `gpu` has: on `wasm32` nothing can wait, so every mode is
    /// polled; a device that cannot map its batch buffers copies them.
    pub(super) fn available_on(self, gpu: &GpuContext) -> Readback {
        let mappable = gpu.device.features().contains(wgpu::Features::MAPPABLE_PRIMARY_BUFFERS);
        match self {
            _ if cfg!(target_arch = "wasm32") => Readback::Polled,
            Readback::Mapped if !mappable => Readback::Staging,
            other => other,
        }
    }

    /// How a call that waits reads its bands ([`super::PathTracer::add_samples_in_one_pass`]):
    /// a polled band is a staging copy, so waiting for it is [`Readback::Staging`].
    #[cfg(not(target_arch = "wasm32"))]
    pub(super) fn waited(self) -> Readback {
        if self == Readback::Polled { Readback::Staging } else { self }
    }
}

/// A pass over the image in progress: `plan.spp` samples from sample index `sample_base`
/// (relative to the sample offset) for every pixel, in bands of `plan.rows` rows.
#[derive(Clone, Copy, Debug)]
pub(super) struct ActivePass {
    pub(super) plan: PassPlan,
    pub(super) sample_base: u32,
    /// Rows folded so far (from row 0); the next band starts here unless one is on the GPU.
    pub(super) next_row: u32,
}

/// Where the render stands between two calls.
pub(super) enum State {
    /// No pass in progress: the next step plans one.
    Idle,
    /// A pass in progress, and which of its bands, if any, is on the GPU and not yet folded.
    Pass { pass: ActivePass, submitted: Submitted },
}

/// The band of the active pass that is on the GPU, submitted by an earlier call. Its rows
/// follow the pass's `next_row`; dropping it (a reset, an error, another readback) leaves
/// them to be traced again.
pub(super) enum Submitted {
    Nothing,
    /// Submitted while the band before it was folded, to be waited for (see `submit.rs`; never
    /// on `wasm32`, whose readback is polled).
    #[cfg(not(target_arch = "wasm32"))]
    Ahead {
        band: Band,
        results: Results,
    },
    /// Submitted with its staging buffer's mapping under way, to be polled.
    Polled {
        band: Band,
        read: PendingRead,
    },
}

/// What a submitted band covers, for folding it when its bytes are back.
#[derive(Clone, Copy, Debug)]
pub(super) struct Band {
    pub(super) started: Instant,
    pub(super) row_offset: u32,
    pub(super) rows: u32,
    pub(super) spp: u32,
    /// The pass's first sample index (absolute: the sample offset included).
    pub(super) sample_start: u32,
    /// Its slot layout when it was recorded (a later `set_chunk_samples` must not change it).
    pub(super) layers: Layers,
    /// Chunks (the dispatch's z dimension) and slot layers (chunks x layers per chunk).
    pub(super) chunks: u32,
    pub(super) slot_layers: u32,
    pub(super) band_pixels: usize,
    /// Bytes of each of the two slot arrays (sums, sums of squares).
    pub(super) bytes: u64,
    /// Paths the band traces: its pixels x spp, or with adaptive sampling what the blocks'
    /// counts leave in its sample range.
    pub(super) scheduled: u64,
    /// Bytes of the staging copy (0 when read where the GPU wrote them).
    pub(super) staging_size: u64,
}

impl Band {
    /// The row after the band's last.
    pub(super) fn end(&self) -> u32 {
        self.row_offset + self.rows
    }
}

/// Where a band waited for is read (never on `wasm32`, whose readback is polled).
#[cfg(not(target_arch = "wasm32"))]
pub(super) enum Results {
    /// A staging buffer its results were copied into: the sums, then the sums of squares, then
    /// the timestamps.
    Staging(wgpu::Buffer),
    /// The batch buffers the shader wrote.
    Mapped(Written),
}

/// The batch buffers a band was traced into, and its timestamps there (when it is timed and
/// read in place).
#[cfg_attr(target_arch = "wasm32", allow(dead_code))]
pub(super) struct Written {
    pub(super) sum: wgpu::Buffer,
    pub(super) sum_sq: wgpu::Buffer,
    pub(super) timestamps: Option<wgpu::Buffer>,
}

/// When the caller comes and goes, and when bands were folded: a band launched ahead is timed
/// from the last fold to its own, which is its cost only for a caller that comes straight back.
#[derive(Default)]
pub(super) struct Pacing {
    /// When the last band was folded.
    last_fold: Option<Instant>,
    /// When `render_step` last returned, and how long its caller then took to call it again.
    returned_at: Option<Instant>,
    caller_absence: Duration,
}

impl Pacing {
    /// The caller is back: measures how long it was away.
    pub(super) fn enter(&mut self) {
        let entered = Instant::now();
        self.caller_absence = self.returned_at.map_or(Duration::ZERO, |t| entered.duration_since(t));
    }

    /// The caller has its result.
    pub(super) fn leave(&mut self) {
        self.returned_at = Some(Instant::now());
    }

    /// Whether a band may be launched ahead: only for a caller that came straight back last time
    /// (a render loop). One that goes away in between (a viewer drawing its window) would have
    /// its absence counted as the band's cost; the planner would then shrink every later band
    /// toward one row.
    #[cfg(not(target_arch = "wasm32"))]
    pub(super) fn may_launch_ahead(&self) -> bool {
        self.caller_absence <= AHEAD_MAX_ABSENCE
    }

    /// The wall time of a band submitted at `started` and folded now. A band launched ahead ran
    /// while the previous one was folded: its time starts where that fold ended, so that the
    /// bands' times add up to the elapsed time.
    pub(super) fn band_folded(&mut self, started: Instant) -> f64 {
        let now = Instant::now();
        let from = self.last_fold.filter(|&t| t > started).unwrap_or(started);
        self.last_fold = Some(now);
        now.duration_since(from).as_secs_f64()
    }

    /// Forgets the last fold (the render starts again).
    pub(super) fn restart(&mut self) {
        self.last_fold = None;
    }
}

/// Runs a render's passes band by band: the pass state, the buffers, and the settings that
/// size passes.
pub(super) struct BandRunner {
    readback: Readback,
    pub(super) state: State,
    pub(super) planner: BatchPlanner,
    /// Samples per invocation.
    pub(super) chunk_samples: u32,
    /// The sample index of the tracer's first sample.
    pub(super) sample_offset: u32,
    /// Whether passes end on multiples of the chunk (see `passes.rs`).
    pub(super) chunk_aligned: bool,
    /// Most slots one batch buffer may hold: the device's storage binding limit (or a lower cap)
    /// over `SLOT_BYTES`.
    pub(super) max_slots: u64,
    /// Most chunks one dispatch may carry (its z dimension).
    pub(super) max_chunks: u32,
    pub(super) buffers: BandBuffers,
    pub(super) timer: PassTimer,
    pub(super) pacing: Pacing,
    /// What the last `render_step` did.
    pub(super) last_step: StepReport,
}

impl BandRunner {
    pub(super) fn new(gpu: &GpuContext, max_slots: u64) -> Self {
        BandRunner {
            readback: Readback::default_for(gpu),
            state: State::Idle,
            planner: BatchPlanner::new(DEFAULT_TARGET_SECONDS),
            chunk_samples: CHUNK_SAMPLES,
            sample_offset: 0,
            chunk_aligned: false,
            max_slots,
            max_chunks: gpu.device.limits().max_compute_workgroups_per_dimension,
            buffers: BandBuffers::default(),
            timer: PassTimer::new(gpu, &[TIMED_PASS]),
            pacing: Pacing::default(),
            last_step: StepReport::default(),
        }
    }

    /// Takes what a caller chose and the planner learnt (the cost of a sample) from `other`, a
    /// runner of the same tracer before it was built anew.
    pub(super) fn carry_settings(&mut self, other: &BandRunner) {
        self.planner = other.planner.clone();
        self.chunk_samples = other.chunk_samples;
        self.sample_offset = other.sample_offset;
        self.chunk_aligned = other.chunk_aligned;
        self.readback = other.readback;
    }

    pub(super) fn readback(&self) -> Readback {
        self.readback
    }

    /// Reads bands with `readback` from now on (as `gpu` can); a band on the GPU read another
    /// way is dropped, and its rows traced again.
    pub(super) fn set_readback(&mut self, readback: Readback, gpu: &GpuContext) {
        let readback = readback.available_on(gpu);
        if readback != self.readback {
            self.take_submitted();
        }
        self.readback = readback;
    }

    pub(super) fn pass(&self) -> Option<&ActivePass> {
        match &self.state {
            State::Idle => None,
            State::Pass { pass, .. } => Some(pass),
        }
    }

    pub(super) fn pass_mut(&mut self) -> Option<&mut ActivePass> {
        match &mut self.state {
            State::Idle => None,
            State::Pass { pass, .. } => Some(pass),
        }
    }

    /// Forgets the pass in progress, any band of it on the GPU, the last fold and the last step:
    /// the render starts again.
    pub(super) fn restart(&mut self) {
        self.state = State::Idle;
        self.pacing.restart();
        self.last_step = StepReport::default();
    }

    /// Starts `pass`, with nothing of it on the GPU.
    pub(super) fn start_pass(&mut self, pass: ActivePass) {
        self.state = State::Pass { pass, submitted: Submitted::Nothing };
    }

    /// Takes the band on the GPU, if any, out of the state.
    pub(super) fn take_submitted(&mut self) -> Submitted {
        match &mut self.state {
            State::Idle => Submitted::Nothing,
            State::Pass { submitted, .. } => std::mem::replace(submitted, Submitted::Nothing),
        }
    }

    /// Records `band` as the active pass's band on the GPU. Without an active pass it has no
    /// rows to belong to, and is dropped.
    pub(super) fn put_submitted(&mut self, band: Submitted) {
        if let State::Pass { submitted, .. } = &mut self.state {
            *submitted = band;
        }
    }

    /// A band ending at row `end` was folded: the pass goes on from there, or is over when
    /// `completed`.
    pub(super) fn band_folded(&mut self, end: u32, completed: bool) {
        match (&mut self.state, completed) {
            (State::Pass { pass, .. }, false) => pass.next_row = end,
            _ => self.state = State::Idle,
        }
    }
}

/// The buffers bands are traced into and read from.
#[derive(Default)]
pub(super) struct BandBuffers {
    /// The batch buffers (sum, sum of squares) and the bind group that uses them; grown on
    /// demand up to the runner's `max_slots`.
    batch: Option<BatchBuffers>,
    /// With mapped readback, the other set of batch buffers: bands alternate between the two, so
    /// that the next band is traced while the CPU folds the last one from its mapping.
    spare_batch: Option<BatchBuffers>,
    /// The staging buffer the next copied band goes to (a band holds its own until read).
    staging: Option<wgpu::Buffer>,
}

impl BandBuffers {
    /// Forgets the batch buffers (their bind groups name the bindings of a pipeline replaced).
    pub(super) fn forget_batch(&mut self) {
        self.batch = None;
        self.spare_batch = None;
    }

    /// The batch buffers for a band of `slots` slots, grown (within `max_slots`) and bound to
    /// `pipeline`'s inputs as needed; `mapped`: the band is read where the GPU writes it, from
    /// the set the band before it did not use (with room for the timestamps `timer` writes).
    pub(super) fn batch_for(
        &mut self,
        pipeline: &ScenePipeline,
        slots: u64,
        mapped: bool,
        max_slots: u64,
        timer: &PassTimer,
    ) -> Result<&BatchBuffers, PathTraceError> {
        if mapped {
            // The set the previous band wrote may still be mapped, or about to be.
            std::mem::swap(&mut self.batch, &mut self.spare_batch);
        }
        // Buffers made for copied bands cannot be mapped: made anew.
        let fits = |b: &BatchBuffers| {
            b.slots >= slots && (!mapped || b.sum.usage().contains(wgpu::BufferUsages::MAP_READ))
        };
        let batch = match self.batch.take() {
            Some(batch) if fits(&batch) => batch,
            old => {
                // Grow geometrically (within max_slots) so that passes of slowly rising spp do
                // not reallocate every time; never below what this band needs (a pass planned
                // before a lower cap was set still needs its own size).
                let doubled = old.as_ref().map_or(0, |b| 2 * b.slots).min(max_slots);
                let layout = pipeline.compute.get_bind_group_layout(0);
                let timestamps = mapped.then(|| timer.result_size());
                let inputs = pipeline.inputs();
                match BatchBuffers::new(&pipeline.gpu, slots.max(doubled), &layout, &inputs, timestamps) {
                    Ok(batch) => batch,
                    Err(e) => {
                        self.batch = old;
                        return Err(e.into());
                    }
                }
            }
        };
        Ok(self.batch.insert(batch))
    }

    /// A staging buffer of at least `size` bytes for a band to copy its results into, taken
    /// from the runner: the band holds it until its bytes are read (nothing may copy into it
    /// then).
    pub(super) fn take_staging(&mut self, gpu: &GpuContext, size: u64) -> wgpu::Buffer {
        match self.staging.take() {
            Some(staging) if staging.size() >= size => staging,
            _ => gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pathtrace staging"),
                size,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
        }
    }

    /// Gives back a staging buffer whose band was read.
    pub(super) fn put_staging(&mut self, staging: wgpu::Buffer) {
        self.staging = Some(staging);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A band launched ahead, submitted before the last fold, is timed from that fold: the
    /// bands' times add up to the elapsed time instead of counting the overlap twice.
    #[test]
    fn a_band_launched_ahead_is_timed_from_the_last_fold() {
        let mut pacing = Pacing::default();
        let first = Instant::now();
        let ahead = Instant::now();
        std::thread::sleep(Duration::from_millis(2));
        let first_seconds = pacing.band_folded(first);
        assert!(first_seconds >= 0.002, "{first_seconds}");
        let ahead_seconds = pacing.band_folded(ahead);
        assert!(ahead_seconds < ahead.elapsed().as_secs_f64() - 0.001, "{ahead_seconds}");
        // After a restart a band is timed from its own submission again.
        pacing.restart();
        let band = Instant::now();
        std::thread::sleep(Duration::from_millis(1));
        assert!(pacing.band_folded(band) >= 0.001);
    }

    /// Bands are launched ahead for a caller seen for the first time, and not for one that
    /// stayed away longer than [`AHEAD_MAX_ABSENCE`] (a viewer drawing its window).
    #[test]
    fn only_a_caller_that_comes_straight_back_gets_bands_ahead() {
        let mut pacing = Pacing::default();
        pacing.enter();
        assert!(pacing.may_launch_ahead(), "no absence before the first call");
        pacing.leave();
        std::thread::sleep(AHEAD_MAX_ABSENCE * 5);
        pacing.enter();
        assert!(!pacing.may_launch_ahead(), "away {:?}", pacing.caller_absence);
    }

    #[test]
    fn a_call_that_waits_reads_a_polled_band_from_its_staging_copy() {
        assert_eq!(Readback::Polled.waited(), Readback::Staging);
        assert_eq!(Readback::Mapped.waited(), Readback::Mapped);
        assert_eq!(Readback::Staging.waited(), Readback::Staging);
    }
}
