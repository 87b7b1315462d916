//! Progress of a long render on standard error, for every renderer of the `render` example.
//!
//! On a terminal: an indicatif bar, redrawn in place. Elsewhere (a job log, `> log 2>&1`), where
//! a bar draws nothing: a line starting with `progress: ` every [`DEFAULT_PERIOD`] (or
//! `--progress-seconds`) and at every tenth of the way, whichever comes first, so that a log
//! shows what a bar would have.
//!
//! The path tracer's bar and lines measure progress toward whichever stop rule will end the
//! render first (spp, estimated error or time), with the current error, the wall-clock sample
//! rate and the time left at that rate ([`describe`]).

use std::cell::Cell;
use std::io::IsTerminal;
use std::time::{Duration, Instant};

use illum_pathtrace::{PathTracer, Progressive, Rule};
use indicatif::{ProgressBar, ProgressStyle};

/// Steps of the bar (the fraction is shown to 0.1%).
const STEPS: u64 = 1000;

/// Time between progress lines in a log, unless `--progress-seconds` says otherwise.
pub const DEFAULT_PERIOD: Duration = Duration::from_secs(10);
/// `--progress-seconds` bounds: below a tenth of a second a log is mostly progress lines;
/// above a day no render would print one (the tenths still would).
pub const MIN_PERIOD_SECONDS: f64 = 0.1;
pub const MAX_PERIOD_SECONDS: f64 = 86_400.0;

/// Parses `--progress-seconds`: a number of seconds within
/// [`MIN_PERIOD_SECONDS`]..=[`MAX_PERIOD_SECONDS`].
pub fn period_arg(text: &str) -> Result<Duration, String> {
    let allowed =
        format!("allowed: a number of seconds from {MIN_PERIOD_SECONDS} to {MAX_PERIOD_SECONDS} (a day)");
    let seconds: f64 =
        text.trim().parse().map_err(|_| format!("--progress-seconds {text:?} is not a number; {allowed}"))?;
    if seconds.is_nan() {
        return Err(format!("--progress-seconds {text:?} is not a number; {allowed}"));
    }
    if !(MIN_PERIOD_SECONDS..=MAX_PERIOD_SECONDS).contains(&seconds) {
        return Err(format!("--progress-seconds {text:?} is out of range; {allowed}"));
    }
    Ok(Duration::from_secs_f64(seconds))
}

/// When a log gets its next progress line: `period` after the last one, or on reaching the
/// next tenth of the way. Kept apart from the clock and the output so that it can be tested
/// with made-up times.
#[derive(Clone, Copy, Debug)]
pub struct LineSchedule {
    period: Duration,
    last: Instant,
    /// The tenths of the way already announced (0..=10).
    tenths: u32,
}

impl LineSchedule {
    /// A schedule whose first period starts at `start`.
    pub fn new(period: Duration, start: Instant) -> Self {
        LineSchedule { period, last: start, tenths: 0 }
    }

    /// Whether a line is due at `now` with the render `fraction` of the way (`None`: no
    /// measure of the way, as for a render stopped only by Ctrl-C); if so, counts it printed.
    pub fn due(&mut self, now: Instant, fraction: Option<f64>) -> bool {
        let tenths = fraction.map_or(0, |f| (f.clamp(0.0, 1.0) * 10.0).floor() as u32);
        let due = tenths > self.tenths || now.saturating_duration_since(self.last) >= self.period;
        if due {
            self.last = now;
            // An error estimate can move back (a noisy pass): a tenth is announced once.
            self.tenths = self.tenths.max(tenths);
        }
        due
    }
}

enum Output {
    Bar(ProgressBar),
    Lines(Cell<LineSchedule>),
}

/// A bar on a terminal, `progress: ` lines elsewhere.
pub struct Reporter {
    output: Output,
    started: Instant,
    /// Whether a line was printed (then the log also hears of what follows the render).
    printed: Cell<bool>,
}

impl Reporter {
    /// Lines every `period` unless standard error is a terminal.
    pub fn new(period: Duration) -> Self {
        let started = Instant::now();
        let output = if std::io::stderr().is_terminal() {
            let bar = ProgressBar::new(STEPS);
            bar.set_style(ProgressStyle::with_template("{bar:40} {msg}").expect("valid template"));
            Output::Bar(bar)
        } else {
            Output::Lines(Cell::new(LineSchedule::new(period, started)))
        };
        Reporter { output, started, printed: Cell::new(false) }
    }

    /// Shows where the render is: `fraction` of the way, and what `describe` says (called only
    /// when something is shown).
    pub fn update(&self, fraction: Option<f64>, describe: impl FnOnce() -> String) {
        match &self.output {
            Output::Bar(bar) => {
                if let Some(f) = fraction {
                    bar.set_position((f.clamp(0.0, 1.0) * STEPS as f64) as u64);
                }
                bar.set_message(describe());
            }
            Output::Lines(schedule) => {
                let mut s = schedule.get();
                if s.due(Instant::now(), fraction) {
                    self.line(&describe());
                }
                schedule.set(s);
            }
        }
    }

    /// In a log that has progress lines, a line saying what the program does next (writing a
    /// large image can take a while); a short render's log stays without.
    pub fn note(&self, what: &str) {
        if matches!(self.output, Output::Lines(_)) && self.printed.get() {
            self.line(what);
        }
    }

    fn line(&self, text: &str) {
        eprintln!("progress: {:.1} s  {text}", self.started.elapsed().as_secs_f64());
        self.printed.set(true);
    }

    /// Removes the bar (a log keeps its lines).
    pub fn finish(&self) {
        if let Output::Bar(bar) = &self.output {
            bar.finish_and_clear();
        }
    }
}

/// The path tracer's progress: toward the nearest stop rule, with [`describe`]'s figures.
pub struct RenderProgress {
    reporter: Reporter,
}

impl Default for RenderProgress {
    fn default() -> Self {
        Self::new()
    }
}

impl RenderProgress {
    /// A bar on a terminal, lines every [`DEFAULT_PERIOD`] elsewhere.
    pub fn new() -> Self {
        Self::with_period(DEFAULT_PERIOD)
    }

    /// A bar on a terminal, lines every `period` elsewhere.
    pub fn with_period(period: Duration) -> Self {
        RenderProgress { reporter: Reporter::new(period) }
    }

    /// Shows where `progressive` is. Constant time: it reads running totals only.
    pub fn update(&self, tracer: &PathTracer, progressive: &Progressive) {
        let fraction = progressive.progress(tracer).map(|p| p.fraction);
        self.reporter.update(fraction, || describe(progressive, tracer));
    }

    pub fn finish(&self) {
        self.reporter.finish();
    }
}

/// One line: "37 spp  4.21 Msamples/s  error 2.31% (target 1%)  toward time budget: 41.0%, ETA 3 seconds".
pub fn describe(progressive: &Progressive, tracer: &PathTracer) -> String {
    let status = progressive.status(tracer);
    let spp = match tracer.sample_allocation() {
        // Adaptive sampling: blocks take different counts; show the mean so far.
        Some(_) => {
            let camera = tracer.scene().camera;
            let pixels = (f64::from(camera.width) * f64::from(camera.height)).max(1.0);
            format!("{:.0} spp on average", status.samples as f64 / pixels)
        }
        None => format!("{} spp", status.spp_done),
    };
    let mut text = format!("{spp}  {:.2} Msamples/s", status.samples_per_second() * 1e-6);
    text += &format!(
        "  error {}",
        illum_pathtrace::progressive::render_error_text(tracer.accumulator(), status.relative_error)
    );
    if let (Some(_), Some(target)) = (status.relative_error, progressive.rules.target_error) {
        text += &format!(" (target {}%)", target * 100.0);
    }
    if let Some(p) = progressive.progress(tracer) {
        let rule = match p.rule {
            Rule::Spp => format!("spp {}", progressive.rules.spp.unwrap_or(0)),
            Rule::Error => "error target".to_owned(),
            Rule::Time => "time budget".to_owned(),
        };
        text += &format!("  toward {rule}: {:.1}%", p.fraction * 100.0);
        if let Some(eta) = p.eta(status.elapsed) {
            text += &format!(", ETA {}", indicatif::HumanDuration(eta));
        }
    }
    text
}

/// Progress of a render made of parts (the Whitted ray tracer's bands of rows, the
/// rasterizer's stages): "rows 72 of 180 (40.0%)  0.45 Mrays/s  ETA 18 seconds".
pub fn describe_parts(
    done: u64,
    total: u64,
    unit: &str,
    rate: Option<(f64, &str)>,
    elapsed: Duration,
) -> String {
    let fraction = done as f64 / total.max(1) as f64;
    let mut text = format!("{unit} {done} of {total} ({:.1}%)", fraction * 100.0);
    if let Some((per_second, label)) = rate {
        text += &format!("  {:.2} {label}", per_second * 1e-6);
    }
    if fraction > 0.0 {
        let left = elapsed.as_secs_f64() * (1.0 - fraction) / fraction;
        if let Ok(left) = Duration::try_from_secs_f64(left) {
            text += &format!(", ETA {}", indicatif::HumanDuration(left));
        }
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_comes_every_period_and_at_every_tenth() {
        let t0 = Instant::now();
        let s = Duration::from_secs;
        let mut lines = LineSchedule::new(s(10), t0);
        assert!(!lines.due(t0 + s(1), Some(0.05)));
        assert!(lines.due(t0 + s(2), Some(0.1)), "the first tenth");
        assert!(!lines.due(t0 + s(3), Some(0.15)));
        assert!(!lines.due(t0 + s(4), Some(0.12)));
        assert!(lines.due(t0 + s(12), Some(0.18)), "10 s after the last line");
        assert!(!lines.due(t0 + s(13), Some(0.19)));
        // Two tenths at once: one line.
        assert!(lines.due(t0 + s(14), Some(0.35)));
        assert!(!lines.due(t0 + s(15), Some(0.39)));
        // A fraction that moves back (a noisy error estimate) announces no tenth again.
        assert!(!lines.due(t0 + s(16), Some(0.2)));
        assert!(!lines.due(t0 + s(17), Some(0.35)));
        assert!(lines.due(t0 + s(18), Some(1.0)));
        // Without a measure of the way, the period alone.
        let mut open = LineSchedule::new(s(10), t0);
        assert!(!open.due(t0 + s(9), None));
        assert!(open.due(t0 + s(10), None));
        assert!(!open.due(t0 + s(19), None));
        assert!(open.due(t0 + s(20), None));
    }

    #[test]
    fn progress_seconds_takes_a_sane_period_and_names_what_is_allowed() {
        assert_eq!(period_arg("10"), Ok(Duration::from_secs(10)));
        assert_eq!(period_arg("0.5"), Ok(Duration::from_millis(500)));
        assert_eq!(period_arg("86400"), Ok(Duration::from_secs(86_400)));
        for bad in ["0", "-1", "nan", "NaN", "inf", "-inf", "1e30", "0.01", "86401", "ten", ""] {
            let error = period_arg(bad).expect_err(bad);
            assert!(
                error.contains("--progress-seconds")
                    && error.contains(&format!("{bad:?}"))
                    && error.contains("from 0.1 to 86400"),
                "{bad}: {error}"
            );
        }
    }

    #[test]
    fn parts_show_their_share_rate_and_time_left() {
        let text = describe_parts(72, 180, "rows", Some((450_000.0, "Mrays/s")), Duration::from_secs(12));
        assert_eq!(text, "rows 72 of 180 (40.0%)  0.45 Mrays/s, ETA 18 seconds");
        assert_eq!(describe_parts(0, 180, "rows", None, Duration::ZERO), "rows 0 of 180 (0.0%)");
    }
}
