//! What `render --renderer auto` prints: the pilot's cost, the plan, and what was reached.

use illum_auto::plan::{self, Goal, Plan, Planned};
use illum_scene::Scene;

use super::pilot::Pilot;

/// What `render --renderer auto` prints before it renders: what the pilot cost, the goal, the
/// choice with its prediction, the runners-up, and one line starting with `auto plan:` with
/// the choice as `key=value` fields for tools (the ladder's check of the planner reads it).
pub fn describe(scene: &Scene, pilot: &Pilot, goal: Goal, plan: &Plan) -> String {
    let cached = |seconds: f64| if seconds == 0.0 { "cached".to_owned() } else { format!("{seconds:.1} s") };
    let mut text = format!(
        "auto: pilot at {}x{}: truth {} spp ({}), bias and noise of {} settings ({}), throughput measured now \
         ({:.1} s)\n",
        pilot.size.0,
        pilot.size.1,
        pilot.truth_spp,
        cached(pilot.truth_seconds),
        pilot.candidates.len(),
        cached(pilot.bias_seconds),
        pilot.throughput_seconds
    );
    text.push_str(&match goal {
        Goal::Error(e) => format!(
            "auto: the fastest render of {} at {}x{} predicted to reach a relative error of {e}:\n",
            scene.name, scene.camera.width, scene.camera.height
        ),
        Goal::Seconds(s) => format!(
            "auto: the most accurate render of {} at {}x{} predicted to finish within {s:.1} s:\n",
            scene.name, scene.camera.width, scene.camera.height
        ),
    });
    let line = |p: &Planned| {
        format!(
            "{}: predicted relative error {:.4} in {:.2} s (bias {:.4}{})",
            p.describe(),
            p.predicted_error,
            p.predicted_seconds,
            plan::error_floor(&p.candidate),
            if p.spp.is_some() { ", the rest noise" } else { ", no noise" }
        )
    };
    text.push_str(&format!("  choice: {}\n", line(&plan.choice)));
    if !plan.runners_up.is_empty() {
        text.push_str("  runners-up:\n");
        for p in &plan.runners_up {
            text.push_str(&format!("    {}\n", line(p)));
        }
    }
    let c = &plan.choice;
    text.push_str(&format!(
        "auto plan: renderer={} spp={} predicted_error={} predicted_seconds={} pilot_seconds={}\n",
        c.candidate.setting.renderer(),
        c.spp.map_or("-".to_owned(), |n| n.to_string()),
        significant(c.predicted_error),
        significant(c.predicted_seconds),
        significant(pilot.seconds())
    ));
    text
}

/// `x` to 4 significant digits, as plain decimals (`0.04855`, `12.30`) from 1e-4 to 1e4, else in
/// scientific notation: what the `auto plan:` line shows, readable and exact enough for the
/// tools that read it.
fn significant(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return x.to_string();
    }
    let magnitude = x.abs().log10().floor();
    if (-4.0..4.0).contains(&magnitude) {
        format!("{x:.*}", (3.0 - magnitude) as usize)
    } else {
        format!("{x:.3e}")
    }
}

/// What `render --renderer auto` prints after it rendered: the time and the error reached
/// against the prediction. `noise` is the path tracer's own estimated relative error from its
/// noise; the estimated error adds the pilot's bias to it. A deterministic image has no
/// estimate of its own: its error is the bias the pilot measured.
pub fn reached(choice: &Planned, noise: Option<f64>, seconds: f64) -> String {
    let bias = choice.candidate.bias_rel_mse;
    let timing = format!("rendered in {seconds:.2} s (predicted {:.2} s)", choice.predicted_seconds);
    match noise {
        Some(noise) => format!(
            "auto: {timing}; estimated relative error {:.4} (predicted {:.4}): the pilot's bias {:.4} and the \
             render's own estimate {noise:.4} ({})",
            (bias + noise * noise).sqrt(),
            choice.predicted_error,
            bias.sqrt(),
            match choice.candidate.setting {
                plan::Setting::PathTrace { denoise: Some(_), .. } => {
                    "the denoised error from its two halves, of a denoised half: above the written image's"
                }
                _ => "of its noise",
            }
        ),
        None => format!(
            "auto: {timing}; a deterministic image: its relative error is the one the pilot measured, {:.4}",
            choice.predicted_error
        ),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn plan_numbers_show_four_significant_digits() {
        assert_eq!(super::significant(4.855354961257205e-2), "0.04855");
        assert_eq!(super::significant(12.3), "12.30");
        assert_eq!(super::significant(3210.4), "3210");
        assert_eq!(super::significant(2.5e-7), "2.500e-7");
        assert_eq!(super::significant(0.0), "0");
        assert_eq!("0.04855".parse::<f64>(), Ok(0.04855), "the tools read it back");
    }
}
