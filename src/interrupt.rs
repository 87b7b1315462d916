//! Ctrl-C (SIGINT) and SIGTERM for long renders: the first one asks the render to stop, so that
//! what has accumulated is still written; a second one of either ends the process at once.
//! After an interruption the program exits with the shell's convention, 128 + the signal's
//! number: 130 for SIGINT, 143 for SIGTERM (what `timeout`, systemd and job schedulers send),
//! so that `render && next-step` does not go on with a partial image.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use anyhow::Context;
use signal_hook::consts::{SIGINT, SIGTERM};

/// The installed handlers.
pub struct Interrupt {
    requested: Arc<AtomicBool>,
    /// The signal that asked first (0: none).
    signal: Arc<AtomicUsize>,
}

impl Interrupt {
    /// Installs the handlers for SIGINT and SIGTERM.
    pub fn install() -> anyhow::Result<Self> {
        let requested = Arc::new(AtomicBool::new(false));
        let signal = Arc::new(AtomicUsize::new(0));
        for sig in [SIGINT, SIGTERM] {
            // Registered first, so it runs first: a signal that finds a stop already requested
            // ends the process now.
            signal_hook::flag::register_conditional_shutdown(sig, 128 + sig, requested.clone())
                .with_context(|| format!("installing the handler for signal {sig}"))?;
            signal_hook::flag::register_usize(sig, signal.clone(), sig as usize)
                .with_context(|| format!("installing the handler for signal {sig}"))?;
            signal_hook::flag::register(sig, requested.clone())
                .with_context(|| format!("installing the handler for signal {sig}"))?;
        }
        Ok(Interrupt { requested, signal })
    }

    /// Set once a stop was asked for; the render polls it between submissions.
    pub fn flag(&self) -> &AtomicBool {
        &self.requested
    }

    /// The signal's name and the exit status to leave with (130, 143), once one arrived.
    pub fn exit_status(&self) -> Option<(&'static str, i32)> {
        if !self.requested.load(Ordering::SeqCst) {
            return None;
        }
        // The flag can be seen before the signal number is stored; SIGINT is the default.
        match self.signal.load(Ordering::SeqCst) as i32 {
            SIGTERM => Some(("SIGTERM", 128 + SIGTERM)),
            _ => Some(("SIGINT", 128 + SIGINT)),
        }
    }
}
