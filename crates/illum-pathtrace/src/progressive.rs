//! Progressive rendering with stop rules: a sample target, a relative-error target, a time budget,
//! and cancellation (Ctrl-C), checked between short submissions.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use crate::{PathTraceError, PathTracer};

/// When to stop. With every field `None` the render runs until cancelled.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StopRules {
    /// Stop when every pixel has this many samples.
    pub spp: Option<u32>,
    /// Stop when the estimated relative standard error (the square root of the per-pixel
    /// variance-based relMSE estimate, [`crate::Accumulator::estimated_relative_error`]) falls
    /// to this value. Checked only after each completed pass with at least 2 spp.
    pub target_error: Option<f64>,
    /// Stop after this much wall time.
    pub time_budget: Option<Duration>,
}

/// Why a progressive render stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    SppReached,
    ErrorReached,
    TimeBudget,
    Cancelled,
}

/// Renders until a rule fires. `on_step` runs after every submission (for progress bars).
pub fn render_progressive(
    tracer: &mut PathTracer,
    rules: &StopRules,
    cancel: &AtomicBool,
    mut on_step: impl FnMut(&PathTracer),
) -> Result<StopReason, PathTraceError> {
    let started = Instant::now();
    loop {
        if cancel.load(Ordering::Relaxed) {
            return Ok(StopReason::Cancelled);
        }
        if rules.spp.is_some_and(|spp| tracer.spp_done() >= spp) {
            return Ok(StopReason::SppReached);
        }
        if rules.time_budget.is_some_and(|budget| started.elapsed() >= budget) {
            return Ok(StopReason::TimeBudget);
        }
        let report = tracer.step(rules.spp)?;
        on_step(tracer);
        if report.pass_completed
            && tracer.spp_done() >= 2
            && rules
                .target_error
                .is_some_and(|target| tracer.accumulator().estimated_relative_error() <= target)
        {
            return Ok(StopReason::ErrorReached);
        }
    }
}
