//! What a finished path-traced render prints: its summary line, and why it ran past its time
//! budget when it did.

use std::time::Duration;

use illum_pathtrace::{PathTracer, StopReason};

/// What a render stopped by its time budget says when it ran well past it (by more than a
/// submission's 0.15 s target and 5%): the budget is checked between submissions, and only
/// once a first pass is complete.
pub(crate) fn budget_overrun(reason: StopReason, budget: Option<Duration>, seconds: f64) -> Option<String> {
    let budget = budget?.as_secs_f64();
    let over = seconds - budget;
    (reason == StopReason::TimeBudget && over > 0.15_f64.max(0.05 * budget)).then(|| {
        format!(
            "the time budget was {budget} s and the render took {seconds:.2} s: a render stops only once its first \
             pass is complete, and then between submissions"
        )
    })
}

/// The line a finished render prints: the scene, size, spp, why it stopped, the settings, its
/// time, speed and estimated error.
pub(crate) fn summary(
    tracer: &PathTracer,
    reason: StopReason,
    seconds: f64,
    samples_per_second: f64,
) -> String {
    let scene = tracer.scene();
    let accumulator = tracer.accumulator();
    let spp = match tracer.sample_allocation() {
        // Mean over the image of what each pixel holds (the blocks' counts, or fewer if stopped early).
        Some(_) => format!(
            "{:.1} spp on average (adaptive)",
            accumulator.total_samples() as f64
                / (f64::from(scene.camera.width) * f64::from(scene.camera.height))
        ),
        // Stopped inside a pass, some rows hold more samples, and the error below is of them
        // all: said, so that it is not read as the complete passes' alone.
        None => match tracer.partial_pass() {
            Some((pass, rows)) => format!(
                "{} spp and {rows} of {} rows of a pass of {pass} more",
                tracer.spp_done(),
                scene.camera.height
            ),
            None => format!("{} spp", tracer.spp_done()),
        },
    };
    let error = illum_pathtrace::progressive::render_error_text(
        accumulator,
        Some(accumulator.estimated_relative_error()).filter(|e| e.is_finite()),
    );
    format!(
        "{}: {}x{}, {} ({}), bounces {}, {} sampling, {} samples, caustics {}, {:.2} s, {:.2} Msamples/s (wall clock), \
         estimated relative error {error}, dropped samples {}",
        scene.name,
        scene.camera.width,
        scene.camera.height,
        spp,
        match reason {
            StopReason::SppReached => "spp target reached",
            StopReason::ErrorReached => "stopped at the error target",
            StopReason::TimeBudget => "stopped by the time budget",
            StopReason::Cancelled => "interrupted; kept what had accumulated",
        },
        scene.pathtrace.bounces,
        scene.pathtrace.sampling,
        tracer.options().sequence_label(),
        illum_pathtrace::Estimators::of(scene).caustics_description(),
        seconds,
        samples_per_second * 1e-6,
        accumulator.dropped_samples(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A render stopped by its budget says so when it ran past it by more than a submission and
    /// 5%; a render stopped otherwise, or one without a budget, says nothing.
    #[test]
    fn a_render_past_its_time_budget_says_why() {
        let budget = Some(Duration::from_secs(10));
        let said = budget_overrun(StopReason::TimeBudget, budget, 12.0).expect("2 s past a 10 s budget");
        assert!(said.contains("10 s") && said.contains("12.00 s") && said.contains("first pass"), "{said}");
        assert_eq!(budget_overrun(StopReason::TimeBudget, budget, 10.3), None, "within 5%");
        assert_eq!(budget_overrun(StopReason::SppReached, budget, 12.0), None);
        assert_eq!(budget_overrun(StopReason::TimeBudget, None, 12.0), None);
        let small = Some(Duration::from_millis(500));
        assert_eq!(budget_overrun(StopReason::TimeBudget, small, 0.6), None, "within a submission");
        assert!(budget_overrun(StopReason::TimeBudget, small, 0.7).is_some());
    }
}
