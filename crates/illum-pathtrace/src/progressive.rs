//! Progressive rendering with stop rules: a sample target, a relative-error target, a time budget,
//! and cancellation (Ctrl-C), checked between short submissions.
//!
//! This is the one implementation of the stop rules: the `render` example, the convergence tool
//! and the viewer all drive a [`Progressive`]. Its time is **wall-clock time** since the render
//! started ([`RenderClock`]), paused only while a caller pauses it (the viewer's Pause button):
//! it includes the host's readback and f64 fold and, in the viewer, drawing the window, so
//! "samples per second" and "after a time budget" mean what a stopwatch would say.
//!
//! Every rule but cancellation waits for a **complete pass**: a pass covers the whole image, so
//! a render that stops by spp, error or time always has at least one sample in every pixel.
//!
//! This file is the loop that checks the rules; the rules themselves are `progressive/rules.rs`,
//! the clock `progressive/clock.rs`.

mod clock;
mod rules;

#[cfg(not(target_arch = "wasm32"))]
use std::sync::atomic::{AtomicBool, Ordering};

pub use clock::RenderClock;
pub use rules::{Progress, Rule, Status, StopReason, StopRules, parse_target_error, parse_time_budget};

use crate::error_map::ErrorScope;
use crate::{PathTraceError, PathTracer};

/// A progressive render of one [`PathTracer`] under [`StopRules`]: its clock, the error after
/// the last completed pass, and the reason it stopped.
#[derive(Clone, Debug)]
pub struct Progressive {
    pub rules: StopRules,
    clock: RenderClock,
    relative_error: Option<f64>,
    /// `spp_done` when `relative_error` was computed.
    error_at_spp: u32,
    stopped: Option<StopReason>,
    /// Whether the stopped render's last error was taken ([`Self::finish`]).
    finished: bool,
    /// The tracer's samples when this render first stepped (a resumed render starts with some).
    start_samples: Option<u64>,
    /// What the error rule measures: the whole image (the default), a percentile of the pixels
    /// or a region ([`ErrorScope`]).
    error_scope: ErrorScope,
}

impl Progressive {
    /// Starts the clock now.
    pub fn new(rules: StopRules) -> Self {
        Progressive {
            rules,
            clock: RenderClock::started(),
            relative_error: None,
            error_at_spp: 0,
            stopped: None,
            finished: false,
            start_samples: None,
            error_scope: ErrorScope::Image,
        }
    }

    /// What the error is measured over.
    pub fn error_scope(&self) -> &ErrorScope {
        &self.error_scope
    }

    /// Measures the error (shown, and for the error rule) over `scope` instead of the image.
    pub fn with_error_scope(mut self, scope: ErrorScope) -> Self {
        self.error_scope = scope;
        self
    }

    /// Starts again (after the tracer was reset): a new clock (paused if this one was), no error,
    /// not stopped.
    pub fn restart(&mut self) {
        let running = self.clock.is_running();
        let scope = std::mem::take(&mut self.error_scope);
        *self = Progressive::new(self.rules).with_error_scope(scope);
        if !running {
            self.clock.pause();
        }
    }

    pub fn clock(&self) -> &RenderClock {
        &self.clock
    }

    pub fn clock_mut(&mut self) -> &mut RenderClock {
        &mut self.clock
    }

    /// Why it stopped, once it has.
    pub fn stopped(&self) -> Option<StopReason> {
        self.stopped
    }

    /// Marks the render as cancelled, and stops its clock.
    pub fn cancel(&mut self) {
        self.stopped.get_or_insert(StopReason::Cancelled);
        self.clock.pause();
    }

    /// The tracer's status now. The error is the one of the last completed pass (computing it
    /// reads every pixel, so it is done once per pass, not per submission).
    pub fn status(&self, tracer: &PathTracer) -> Status {
        Status {
            spp_done: tracer.spp_done(),
            samples: tracer.accumulator().total_samples(),
            run_samples: tracer.accumulator().total_samples().saturating_sub(self.start_samples.unwrap_or(0)),
            elapsed: self.clock.elapsed(),
            relative_error: self.relative_error,
            pass_spp: tracer.partial_pass().map_or(0, |(spp, _)| spp),
            pass_fraction: tracer.pass_fraction(),
        }
    }

    /// Progress toward the nearest rule.
    pub fn progress(&self, tracer: &PathTracer) -> Option<Progress> {
        let adaptive_samples = tracer.sample_allocation().map(crate::SampleAllocation::total);
        self.rules.progress(&self.status(tracer), adaptive_samples)
    }

    /// Checks the rules, and when none holds runs one submission. Returns why the render
    /// stopped, once it has (and from then on without doing anything).
    pub fn step(&mut self, tracer: &mut PathTracer) -> Result<Option<StopReason>, PathTraceError> {
        if self.stopped.is_some() {
            // Cancelled between steps, or stepped again after the end.
            self.finish(tracer);
            return Ok(self.stopped);
        }
        self.start_samples.get_or_insert(tracer.accumulator().total_samples());
        self.refresh_error(tracer, false);
        self.stopped = self.rules.check(&self.status(tracer));
        if self.stopped.is_none() {
            let report = tracer.render_step(self.rules.spp)?;
            if report.pass_completed {
                // Tools and tests watch for this line (RUST_LOG=illum_pathtrace=debug).
                log::debug!("pass complete: {} spp", tracer.spp_done());
                self.refresh_error(tracer, false);
                self.stopped = self.rules.check(&self.status(tracer));
            }
        }
        if self.stopped.is_some() {
            self.finish(tracer);
        }
        Ok(self.stopped)
    }

    /// Once, when the render is over: its time stands, and its error is that of the image as
    /// it will be read.
    fn finish(&mut self, tracer: &PathTracer) {
        if std::mem::replace(&mut self.finished, true) {
            return;
        }
        self.clock.pause();
        // Stopped inside a pass, the image holds more samples than its complete passes: its
        // error is that of the image as written (what a summary and the file report), not the
        // last complete pass's.
        if tracer.partial_pass().is_some() {
            self.error_at_spp = u32::MAX;
        }
        // The image is about to be read: its exact part is waited for now, if still solving.
        self.refresh_error(tracer, true);
    }

    /// The error estimate of the image as it stands, recomputed when a pass has completed. While
    /// the image's exact part is still being solved (a glint, beside the first samples) and
    /// `wait_for_exact` is false, it stays unknown rather than stall the render: the estimate is
    /// relative to the whole image, exact part included, and a stop rule on it can wait a step.
    fn refresh_error(&mut self, tracer: &PathTracer, wait_for_exact: bool) {
        let spp = tracer.spp_done();
        let accumulator = tracer.accumulator();
        let known = accumulator.estimates_error()
            && spp >= accumulator.spp_for_error_estimate()
            && (wait_for_exact || accumulator.exact_solved());
        if spp != self.error_at_spp || (self.relative_error.is_none() && known) {
            self.error_at_spp = spp;
            self.relative_error = known.then(|| match &self.error_scope {
                ErrorScope::Image => accumulator.estimated_relative_error(),
                scope => crate::error_map::ErrorMap::of(accumulator).error(scope),
            });
        }
    }
}

/// An estimated relative error as every front end writes it (the CLI's progress line and summary,
/// the viewer's panel), so that they agree at the same spp: a percentage with 2 decimals, or, when there is none yet,
/// the spp it needs ([`crate::Accumulator::spp_for_error_estimate`]).
pub fn error_text(error: Option<f64>, needs_spp: u32) -> String {
    match error {
        Some(e) => format!("{:.2}%", e * 100.0),
        None => format!("unknown until {needs_spp} spp"),
    }
}

/// [`error_text`] for the render `accumulator` holds: its spp needed, what it waits for (the
/// exact part's solve, see [`Progressive::step`]), or, for samples without an estimate
/// (`TracerOptions::replicates` off), what was left out and why.
pub fn render_error_text(accumulator: &crate::Accumulator, error: Option<f64>) -> String {
    if !accumulator.estimates_error() {
        "none (low-discrepancy without replicates)".to_owned()
    } else {
        let needs_spp = accumulator.spp_for_error_estimate();
        let pixels = u64::from(accumulator.width) * u64::from(accumulator.height);
        let has_spp = accumulator.total_samples() >= u64::from(needs_spp) * pixels;
        if error.is_none() && has_spp && !accumulator.exact_solved() {
            "unknown until the glint is solved".to_owned()
        } else {
            error_text(error, needs_spp)
        }
    }
}

/// Renders until a rule fires or `cancel` is set. `on_step` runs after every submission (for
/// progress bars). A loop that never returns to its caller until the end: native only (a web
/// page steps a [`Progressive`] once per frame instead).
#[cfg(not(target_arch = "wasm32"))]
pub fn render_progressive(
    tracer: &mut PathTracer,
    rules: &StopRules,
    cancel: &AtomicBool,
    on_step: impl FnMut(&PathTracer, &Progressive),
) -> Result<(StopReason, Progressive), PathTraceError> {
    render_progressive_over(tracer, rules, ErrorScope::Image, cancel, on_step)
}

/// [`render_progressive`] with the error measured over `scope` (`--error-percentile`, `--region`).
#[cfg(not(target_arch = "wasm32"))]
pub fn render_progressive_over(
    tracer: &mut PathTracer,
    rules: &StopRules,
    scope: ErrorScope,
    cancel: &AtomicBool,
    mut on_step: impl FnMut(&PathTracer, &Progressive),
) -> Result<(StopReason, Progressive), PathTraceError> {
    let mut progressive = Progressive::new(*rules).with_error_scope(scope);
    log::debug!("render started: {rules:?}");
    loop {
        if cancel.load(Ordering::Relaxed) {
            progressive.cancel();
        }
        if let Some(reason) = progressive.step(tracer)? {
            return Ok((reason, progressive));
        }
        on_step(tracer, &progressive);
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn an_error_is_a_percentage_or_unknown_until_the_spp_it_needs() {
        assert_eq!(super::error_text(Some(0.012_345), 2), "1.23%");
        assert_eq!(super::error_text(None, 8), "unknown until 8 spp");
    }

    /// While the image's exact part is still being solved, the error estimate (relative to the
    /// whole image) is unknown, so an error target that any estimate meets does not stop the
    /// render, and no step waits for the solve (the solve here waits for the test, or 20 s, so a
    /// step that waited would return only then, with an estimate); once the solve has ended,
    /// the next step stops.
    #[test]
    #[cfg(not(target_arch = "wasm32"))]
    fn the_error_is_unknown_while_the_exact_part_is_solved_and_no_step_waits_for_it() {
        use super::*;
        let scene = illum_scene::testing::shipped_scene("cornell.toml", 8, 8);
        let mut tracer = PathTracer::new(illum_gpu::testing::gpu(), &scene).expect("a tracer");
        let (go, told) = std::sync::mpsc::channel::<()>();
        tracer.accumulator_mut().set_exact_solving(move |_| {
            let _ = told.recv_timeout(std::time::Duration::from_secs(20));
            crate::ExactPart::new(&[(0, [0.5; 3])], 64).expect("one pixel")
        });
        let rules = StopRules { spp: None, target_error: Some(1e9), time_budget: None };
        let mut progressive = Progressive::new(rules);
        let needed = tracer.accumulator().spp_for_error_estimate();
        while tracer.spp_done() < 4 * needed {
            assert_eq!(progressive.step(&mut tracer).expect("a step"), None, "no estimate yet");
        }
        assert_eq!(progressive.status(&tracer).relative_error, None);
        let said = render_error_text(tracer.accumulator(), None);
        assert_eq!(said, "unknown until the glint is solved");
        go.send(()).expect("the solve listens");
        let waited = std::time::Instant::now();
        while !tracer.accumulator().exact_solved() {
            assert!(waited.elapsed().as_secs() < 60, "the solve never ended");
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
        assert_eq!(progressive.step(&mut tracer).expect("a step"), Some(StopReason::ErrorReached));
        assert!(progressive.status(&tracer).relative_error.is_some_and(f64::is_finite));
    }
}
