//! Ctrl-C (SIGINT) and SIGTERM for long renders: the first one asks the render to stop, so that
//! what has accumulated is still written. Repeats of either signal within
//! [`REPEAT_WINDOW`] of the first are the same request; one later than that ends the process at
//! once (a user pressing Ctrl-C again because the render does not stop).
//!
//! Why a window: GNU `timeout` signals the child and then its whole process group, Slurm and
//! systemd signal every process of a job or unit, and a shell's Ctrl-C reaches every process
//! of the foreground group. A render started that way receives each stop twice, microseconds
//! apart; taken as a second request, the repeat would end the process before anything was written.
//!
//! After an interruption the program exits with the shell's convention, 128 + the signal's
//! number of the first request: 130 for SIGINT, 143 for SIGTERM, so that `render && next-step`
//! does not go on with a partial image.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::time::Duration;

use anyhow::Context;
use signal_hook::consts::{SIGINT, SIGTERM};

/// Signals within this time of the first request repeat it. Long enough for every copy a
/// scheduler sends at one stop (they come within microseconds to milliseconds), short enough
/// that a user's second Ctrl-C, a deliberate "now", still ends the process.
pub const REPEAT_WINDOW: Duration = Duration::from_secs(1);

/// What a signal arriving at a given time means.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Arrival {
    /// The first: a stop is asked for.
    Request,
    /// Within [`REPEAT_WINDOW`] of the first: the same request again, ignored.
    Repeat,
    /// Later: end the process now.
    Exit,
}

/// State shared with the signal handlers. Only atomics, which a handler may touch.
#[derive(Default)]
struct Shared {
    requested: AtomicBool,
    /// The signal of the first request (0: none).
    signal: AtomicUsize,
    /// CLOCK_MONOTONIC time of the first request in nanoseconds, plus one (0: none yet).
    first: AtomicU64,
}

/// Classifies a signal arriving at `now_ns` (CLOCK_MONOTONIC nanoseconds), recording it in
/// `first` if it is the first. Lock-free and allocation-free: it runs inside a signal handler.
fn arrive(first: &AtomicU64, now_ns: u64) -> Arrival {
    // Stored plus one so that 0 keeps meaning "none" even for a clock reading of 0.
    match first.compare_exchange(0, now_ns.saturating_add(1), Ordering::SeqCst, Ordering::SeqCst) {
        Ok(_) => Arrival::Request,
        Err(stored) => {
            let since = now_ns.saturating_sub(stored - 1);
            if u128::from(since) <= REPEAT_WINDOW.as_nanos() { Arrival::Repeat } else { Arrival::Exit }
        }
    }
}

/// CLOCK_MONOTONIC in nanoseconds. `clock_gettime` is async-signal-safe (POSIX lists it);
/// `std::time::Instant::now` makes no such promise, so the handler calls libc directly.
#[cfg(unix)]
fn monotonic_ns() -> u64 {
    let mut now = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: a valid pointer to a timespec; CLOCK_MONOTONIC exists on every Unix we build for.
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut now) };
    (now.tv_sec as u64).saturating_mul(1_000_000_000).saturating_add(now.tv_nsec as u64)
}

/// Elsewhere (Windows) a console handler runs on a thread of its own, where `Instant` is safe.
#[cfg(not(unix))]
fn monotonic_ns() -> u64 {
    static START: std::sync::OnceLock<std::time::Instant> = std::sync::OnceLock::new();
    START.get_or_init(std::time::Instant::now).elapsed().as_nanos() as u64
}

/// The installed handlers.
pub struct Interrupt {
    shared: Arc<Shared>,
}

impl Interrupt {
    /// Installs the handlers for SIGINT and SIGTERM.
    ///
    /// A low-level handler rather than `signal_hook::iterator::Signals` on a thread: the window
    /// is measured from the moment each signal arrives, not from when a thread that two busy
    /// cores may not schedule for a while reads it, and the handler itself does only what a
    /// signal handler may (atomics, `clock_gettime`, `_exit`).
    pub fn install() -> anyhow::Result<Self> {
        let shared = Arc::new(Shared::default());
        for sig in [SIGINT, SIGTERM] {
            let state = shared.clone();
            let action = move || match arrive(&state.first, monotonic_ns()) {
                Arrival::Request => {
                    // The signal first, so that whoever sees the flag sees which signal it was.
                    state.signal.store(sig as usize, Ordering::SeqCst);
                    state.requested.store(true, Ordering::SeqCst);
                }
                Arrival::Repeat => {}
                Arrival::Exit => signal_hook::low_level::exit(128 + sig),
            };
            // SAFETY: the action only loads and stores atomics, reads the monotonic clock and
            // calls _exit, all async-signal-safe; it neither allocates nor locks.
            unsafe { signal_hook::low_level::register(sig, action) }
                .with_context(|| format!("installing the handler for signal {sig}"))?;
        }
        Ok(Interrupt { shared })
    }

    /// Set once a stop was asked for; the render polls it between submissions.
    pub fn flag(&self) -> &AtomicBool {
        &self.shared.requested
    }

    /// Whether a stop was asked for.
    pub fn requested(&self) -> bool {
        self.shared.requested.load(Ordering::SeqCst)
    }

    /// The signal's name and the exit status to leave with (130, 143), once one arrived.
    pub fn exit_status(&self) -> Option<(&'static str, i32)> {
        if !self.requested() {
            return None;
        }
        match self.shared.signal.load(Ordering::SeqCst) as i32 {
            SIGTERM => Some(("SIGTERM", 128 + SIGTERM)),
            _ => Some(("SIGINT", 128 + SIGINT)),
        }
    }

    /// Ends the process with the first signal's status after saying why nothing was written,
    /// when a stop was asked for; `what` says what was under way ("while compiling the
    /// pipelines"). Returns when no stop was asked for.
    pub fn exit_if_requested(&self, what: &str) {
        if let Some((signal, code)) = self.exit_status() {
            eprintln!("error: {signal} {what}: nothing was written");
            std::process::exit(code);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SECOND: u64 = 1_000_000_000;

    #[test]
    fn copies_within_the_window_are_one_request_and_a_later_one_exits() {
        let first = AtomicU64::new(0);
        assert_eq!(arrive(&first, 5 * SECOND), Arrival::Request);
        // timeout's second copy to the process group, microseconds later; then one 1 ms later.
        assert_eq!(arrive(&first, 5 * SECOND + 3_000), Arrival::Repeat);
        assert_eq!(arrive(&first, 5 * SECOND + 1_000_000), Arrival::Repeat);
        assert_eq!(arrive(&first, 6 * SECOND), Arrival::Repeat, "the window includes its end");
        assert_eq!(arrive(&first, 6 * SECOND + 1), Arrival::Exit);
        // The window runs from the first request, not from the latest repeat.
        assert_eq!(arrive(&first, 9 * SECOND), Arrival::Exit);
    }

    #[test]
    fn a_first_signal_at_clock_zero_is_still_recorded() {
        let first = AtomicU64::new(0);
        assert_eq!(arrive(&first, 0), Arrival::Request);
        assert_eq!(arrive(&first, 0), Arrival::Repeat);
        assert_eq!(arrive(&first, 2 * SECOND), Arrival::Exit);
    }

    /// The handler's clock counts nanoseconds: a sleep of 2 ms (which lasts at least that) moves
    /// it by at least 2e6.
    #[test]
    fn the_clock_counts_nanoseconds() {
        let a = monotonic_ns();
        std::thread::sleep(Duration::from_millis(2));
        let b = monotonic_ns();
        assert!(b >= a + 2_000_000, "{a} then {b}");
    }
}
