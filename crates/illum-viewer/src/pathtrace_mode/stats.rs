//! The path-tracer mode's numbers: the statistics the panel shows and the status publishes,
//! the submissions since the last restart, and the summary line a `--screenshot` run prints.

use illum_pathtrace::{PathTracer, Progressive};

use super::PathTraceMode;

/// The statistics shown in the panel, refreshed as samples arrive.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stats {
    pub spp: u32,
    /// Samples per second of wall-clock rendering time.
    pub samples_per_second: f64,
    /// Wall-clock time spent rendering (not paused, not in the other mode).
    pub elapsed_seconds: f64,
    /// Estimated relative standard error; `None` before two samples per pixel.
    pub relative_error: Option<f64>,
    pub dropped_samples: u64,
    pub width: u32,
    pub height: u32,
}

/// The submissions since the accumulation last restarted: what the planner scheduled and what
/// the frames carried (a check that every frame's share of samples arrives).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WorkLog {
    /// Submissions folded.
    pub submissions: u64,
    /// Paths they were planned to trace.
    pub scheduled_samples: u64,
    /// The smallest submission's planned paths (`u64::MAX` before the first).
    pub smallest_submission: u64,
    /// Submissions that completed a pass over the whole image.
    pub passes: u64,
    /// Wall seconds the frames spent in the path tracer's steps (submitting, waiting, folding).
    pub step_seconds: f64,
}

impl PathTraceMode {
    /// One line of the mode's statistics, as a `--screenshot` run prints them on exit.
    pub fn summary(&self) -> String {
        let st = &self.stats;
        let error = self.error_text();
        // The share of the wall time in the path tracer's steps: what the window's drawing
        // leaves it (samples/s over that share is the rate while it runs). Over the elapsed time
        // now, as the steps' seconds are counted to now; the statistics' samples/s is measured
        // at the last fold, where the samples counted and the time agree.
        let elapsed = self
            .tracer
            .as_ref()
            .map_or(st.elapsed_seconds, |tracer| self.progressive.status(tracer).elapsed.as_secs_f64());
        let stepping = if elapsed > 0.0 { self.work.step_seconds / elapsed } else { 0.0 };
        let line = format!(
            "pathtrace: {} x {}, spp done {}, samples/s (wall) {:.3} M, elapsed {:.2} s, estimated error {error}, stepping {:.0}% of the wall time",
            st.width,
            st.height,
            st.spp,
            st.samples_per_second / 1e6,
            st.elapsed_seconds,
            100.0 * stepping
        );
        if self.settings.denoise { format!("{line}; {}", self.denoise.statistics()) } else { line }
    }
    pub(super) fn measure(tracer: &PathTracer, progressive: &Progressive) -> Stats {
        let accumulator = tracer.accumulator();
        let status = progressive.status(tracer);
        Stats {
            spp: status.spp_done,
            samples_per_second: status.samples_per_second(),
            elapsed_seconds: status.elapsed.as_secs_f64(),
            relative_error: status.relative_error,
            dropped_samples: accumulator.dropped_samples(),
            width: accumulator.width,
            height: accumulator.height,
        }
    }
}
