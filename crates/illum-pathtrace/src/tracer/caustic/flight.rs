//! A submission of the light tracer's in flight: what a polled caller holds between its looks,
//! and what a dispatch's staging copy holds. A leaf of the caustic's modules: the pass holds one,
//! the dispatch fills one, the polled caller reads one.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use illum_gpu::readback::PendingRead;
use web_time::Instant;

use super::schedule::{Submission, Took};

/// What a dispatch's staging copy holds: its frames' bytes, then the timestamps (if timed).
#[derive(Clone, Copy)]
pub(super) struct DispatchBytes {
    pub(super) frames: u64,
    pub(super) total: u64,
}

/// A polled submission: frames whose readback is under way, or a piece whose work is.
pub(super) struct InFlight {
    pub(super) what: Flight,
    pub(super) submission: Submission,
    pub(super) launched: Instant,
    /// Looks that found it not yet done.
    pub(super) looks: u32,
}

/// What the `seconds` from a submission to the look that saw it done say of its cost, after
/// `looks` that saw it not done: a bound (see [`Took`]).
pub(super) fn seen_done(looks: u32, seconds: f64) -> Took {
    if looks == 0 { Took::WithinOneLook(seconds) } else { Took::AtMost(seconds) }
}

/// What is in flight.
pub(super) enum Flight {
    /// Frames to read back (whole ones, or a frame's last piece).
    Read { read: PendingRead, bytes: DispatchBytes, count: u32 },
    /// A piece of a frame, set done when the GPU has finished it.
    Piece(Arc<AtomicBool>),
}
