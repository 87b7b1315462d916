//! Ctrl-C (SIGINT) and SIGTERM for long renders: the first one asks the render to stop, so that
//! what has accumulated is still written. Repeats of either signal within
//! [`REPEAT_WINDOW`] of the first are the same request; one later than that ends the process at
//! once (a user pressing Ctrl-C again because the render does not stop), never silently: it
//! prints one line saying what was kept (the last checkpoint, or nothing) and what was
//! abandoned, as the render last told [`Interrupt::set_note`].
//!
//! Why a window: GNU `timeout` signals the child and then its whole process group, Slurm and
//! systemd signal every process of a job or unit, and a shell's Ctrl-C reaches every process
//! of the foreground group. A render started that way receives each stop twice, microseconds
//! apart; taken as a second request, the repeat would end the process before anything was written.
//!
//! After an interruption the program exits with the shell's convention, 128 + the signal's
//! number of the first request: 130 for SIGINT, 143 for SIGTERM, so that `render && next-step`
//! does not go on with a partial image.

use std::sync::atomic::{AtomicBool, AtomicPtr, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
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
    /// The line a later signal prints before it ends the process (null: none set). It points
    /// into `notes`, which keeps every line ever set alive, since a handler may be reading an
    /// older one while a new one is set.
    note: AtomicPtr<Vec<u8>>,
    // Boxed so that each line's Vec stays at one address as `notes` grows: `note` is a thin
    // pointer to it, which an atomic can hold (a pointer to a slice is two words).
    #[allow(clippy::vec_box)]
    notes: Mutex<Vec<Box<Vec<u8>>>>,
}

/// The line a signal that ends the process at once prints: which signal, what was kept and what
/// was abandoned.
pub fn exit_line(signal: &str, note: &str) -> String {
    format!("{}{signal}{}{note}\n", EXIT_LINE_HEAD, EXIT_LINE_MIDDLE)
}

/// [`exit_line`]'s fixed parts, which the handler writes around the signal's name.
const EXIT_LINE_HEAD: &str = "error: a second ";
const EXIT_LINE_MIDDLE: &str = " ended the render at once; ";

/// The note of [`Interrupt::set_note`]: "kept: ...; abandoned: ...".
pub fn note(kept: &str, abandoned: &str) -> String {
    format!("kept: {kept}; abandoned: {abandoned}")
}

/// Writes `bytes` to standard error with `write(2)`, which a signal handler may call.
#[cfg(unix)]
fn write_stderr(bytes: &[u8]) {
    let mut rest = bytes;
    while !rest.is_empty() {
        // SAFETY: a valid buffer of rest.len() bytes; write(2) is async-signal-safe.
        let written = unsafe { libc::write(2, rest.as_ptr().cast(), rest.len()) };
        if written <= 0 {
            return;
        }
        rest = &rest[written as usize..];
    }
}

#[cfg(not(unix))]
fn write_stderr(bytes: &[u8]) {
    use std::io::Write;
    let _ = std::io::stderr().write_all(bytes);
}

/// What a signal that ends the process prints: [`exit_line`], from the parts a handler can
/// reach without allocating.
fn say_exit(shared: &Shared, sig: i32) {
    let name: &[u8] = if sig == SIGTERM { b"SIGTERM" } else { b"SIGINT" };
    write_stderr(EXIT_LINE_HEAD.as_bytes());
    write_stderr(name);
    write_stderr(EXIT_LINE_MIDDLE.as_bytes());
    let note = shared.note.load(Ordering::SeqCst);
    // SAFETY: a non-null note points into `shared.notes`, whose boxes are never dropped while
    // `shared` lives (the handler holds an Arc of it).
    match unsafe { note.as_ref() } {
        Some(note) => write_stderr(note),
        None => write_stderr(b"kept: nothing; abandoned: the render"),
    }
    write_stderr(b"\n");
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
                Arrival::Exit => {
                    say_exit(&state, sig);
                    signal_hook::low_level::exit(128 + sig)
                }
            };
            // SAFETY: the action only loads and stores atomics, reads the monotonic clock, writes
            // bytes that outlive it with write(2) and calls _exit, all async-signal-safe; it
            // neither allocates nor locks.
            unsafe { signal_hook::low_level::register(sig, action) }
                .with_context(|| format!("installing the handler for signal {sig}"))?;
        }
        Ok(Interrupt { shared })
    }

    /// Sets what a signal that ends the process at once says was kept and abandoned (see
    /// [`note`]); the render calls it as that changes (a checkpoint written, the image being
    /// written). Each note is kept until the process ends, so a render sets a few.
    pub fn set_note(&self, note: &str) {
        let mut boxed = Box::new(note.as_bytes().to_vec());
        let pointer: *mut Vec<u8> = &mut *boxed;
        let mut notes = self.shared.notes.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        notes.push(boxed);
        self.shared.note.store(pointer, Ordering::SeqCst);
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

    /// The environment variable that makes [`a_child_that_is_signalled_twice`] act.
    const CHILD: &str = "ILLUM_INTERRUPT_TEST_CHILD";

    /// The process this test runs (its own test binary, the test below only) is signalled, and
    /// again after the first was answered and the window has passed: it ends at once with the
    /// first signal's status, and its one line says what was kept and what was abandoned.
    #[cfg(unix)]
    #[test]
    fn a_second_signal_ends_the_process_with_a_line_of_what_was_kept() {
        let out = std::process::Command::new(std::env::current_exe().expect("the test binary"))
            .args([
                "--exact",
                "interrupt::tests::a_child_that_is_signalled_twice",
                "--nocapture",
                "--test-threads=1",
            ])
            .env(CHILD, "1")
            .output()
            .expect("the test binary runs");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(143), "{stderr}");
        let expected =
            exit_line("SIGTERM", &note("the checkpoint out/w.exr (48 spp)", "the samples after it"));
        assert!(stderr.contains(&expected), "expected {expected:?} in:\n{stderr}");
        assert_eq!(stderr.matches("ended the render at once").count(), 1, "{stderr}");
        assert!(!String::from_utf8_lossy(&out.stdout).contains("child survived"));
    }

    /// The child of the test above: does nothing unless [`CHILD`] is set.
    #[cfg(unix)]
    #[test]
    fn a_child_that_is_signalled_twice() {
        if std::env::var_os(CHILD).is_none() {
            return;
        }
        let interrupt = Interrupt::install().expect("handlers");
        interrupt.set_note(&note("nothing yet", "everything"));
        interrupt.set_note(&note("the checkpoint out/w.exr (48 spp)", "the samples after it"));
        // SAFETY: raising a signal this process handles.
        unsafe { libc::raise(SIGTERM) };
        assert!(interrupt.requested(), "the first signal asks for a stop");
        // Beyond the window of repeats: the next one is a second request.
        std::thread::sleep(REPEAT_WINDOW + Duration::from_millis(200));
        unsafe { libc::raise(SIGTERM) };
        println!("child survived");
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
