//! The `render` example's progress bar: progress toward whichever stop rule will end the render
//! first (spp, estimated error or time), with the current error, the wall-clock sample rate and
//! the time left at that rate.

use illum_pathtrace::{PathTracer, Progressive, Rule};
use indicatif::{ProgressBar, ProgressStyle};

/// Steps of the bar (the fraction is shown to 0.1%).
const STEPS: u64 = 1000;

pub struct RenderProgress {
    bar: ProgressBar,
}

impl Default for RenderProgress {
    fn default() -> Self {
        Self::new()
    }
}

impl RenderProgress {
    /// A bar on standard error (hidden when that is not a terminal).
    pub fn new() -> Self {
        let bar = ProgressBar::new(STEPS);
        bar.set_style(ProgressStyle::with_template("{bar:40} {msg}").expect("valid template"));
        RenderProgress { bar }
    }

    /// Shows where `progressive` is. Constant time: it reads running totals only.
    pub fn update(&self, tracer: &PathTracer, progressive: &Progressive) {
        if let Some(p) = progressive.progress(tracer) {
            self.bar.set_position((p.fraction * STEPS as f64) as u64);
        }
        self.bar.set_message(describe(progressive, tracer));
    }

    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// One line: "37 spp  4.21 Msamples/s  error 2.31% (target 1%)  to time budget: 41%, 3 s left".
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
    match (status.relative_error, progressive.rules.target_error) {
        (Some(e), Some(t)) => text += &format!("  error {:.2}% (target {}%)", e * 100.0, t * 100.0),
        (Some(e), None) => text += &format!("  error {:.2}%", e * 100.0),
        (None, _) => text += "  error (needs 2 spp)",
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
