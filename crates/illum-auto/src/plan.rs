//! The planner of `--renderer auto`: from what the pilot measured for every way of rendering
//! the scene (its bias, how its noise falls with the samples, its cost), the cheapest one
//! predicted to meet an error target, or the most accurate one predicted to finish within a time
//! budget.
//!
//! The model of a render's error is the expected relMSE against the truth (the ladder's and
//! `--target-error`'s measure: relative error = its square root):
//!
//! ```text
//! relMSE(setting, N spp) = bias²(setting) + noise_rel_mse(noise curve(setting), N)
//! seconds(setting, N spp) = fixed seconds + N · seconds per spp
//! ```
//!
//! where bias² is what the setting keeps however long it runs (a rasterizer's missing light
//! paths, a path tracer's cut bounces) and the noise term is zero for the deterministic
//! renderers. A path tracer's noise curve is what the pilot measured at a few spp, with the law
//! beyond them: 1/N for independent samples (and adaptive sampling, which spreads N over the
//! pixels in fixed proportions), for the low-discrepancy sequence the exponent measured between
//! its last two spp less how much it changed from the segment before
//! ([`NoiseCurve::with_measured_law`]), and for a denoised image its measured error at each spp
//! (the denoiser's bias included), held beyond the last. [`noise_rel_mse`] is the one place the curve is read.
//!
//! The files: `plan/candidate.rs` (what is chosen among), `plan/noise.rs` (the noise model) and
//! this one, the search for the fewest spp, the choice and the refusal.

mod candidate;
mod noise;

pub use candidate::{Candidate, Setting};
pub use noise::{NoiseCurve, noise_rel_mse};

/// What the user asks for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Goal {
    /// The relative error (square root of the relMSE) to reach.
    Error(f64),
    /// The wall-clock seconds the render may take.
    Seconds(f64),
}

/// One candidate with its samples per pixel and its prediction.
#[derive(Clone, Debug, PartialEq)]
pub struct Planned {
    pub candidate: Candidate,
    /// Samples per pixel (the path tracer only).
    pub spp: Option<u32>,
    pub predicted_error: f64,
    pub predicted_seconds: f64,
}

impl Planned {
    /// "path tracer, bounces 8, caustic light tracer on, 212 spp".
    pub fn describe(&self) -> String {
        match self.spp {
            Some(spp) => format!("{}, {spp} spp", self.candidate.setting),
            None => self.candidate.setting.to_string(),
        }
    }
}

/// The choice and the next best, each with its prediction.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    pub choice: Planned,
    pub runners_up: Vec<Planned>,
}

/// The most samples per pixel a plan may ask for (spp is a `u32`; far beyond any render that
/// ends within [`MAX_SECONDS`] on any machine illum runs on).
pub const MAX_SPP: u32 = 1 << 30;

/// The longest render a plan may predict or a budget may give: 30 days.
pub const MAX_SECONDS: f64 = 30.0 * 86_400.0;

/// How many runners-up a plan lists.
pub const RUNNERS_UP: usize = 4;

/// The relative error of `candidate` at `spp` (ignored by deterministic renderers).
pub fn predicted_error(candidate: &Candidate, spp: u32) -> f64 {
    let noise = candidate.noise.as_ref().map_or(0.0, |curve| noise_rel_mse(curve, f64::from(spp)));
    (candidate.bias_rel_mse + noise).sqrt()
}

/// The seconds `candidate` takes at `spp`.
pub fn predicted_seconds(candidate: &Candidate, spp: u32) -> f64 {
    candidate.fixed_seconds + f64::from(spp) * candidate.seconds_per_spp
}

/// The smallest relative error the candidate reaches however long it runs.
pub fn error_floor(candidate: &Candidate) -> f64 {
    candidate.bias_rel_mse.sqrt()
}

/// Refuses a goal no plan can have: an error target that is not a finite number above 0, a
/// time budget that is not above 0 or exceeds [`MAX_SECONDS`].
pub fn check_goal(goal: Goal) -> Result<(), String> {
    match goal {
        Goal::Error(e) if !(e > 0.0 && e.is_finite()) => {
            Err(format!("--target-error {e}: a target error must be a finite number above 0"))
        }
        Goal::Seconds(s) if !(s > 0.0 && s <= MAX_SECONDS) => Err(format!(
            "--time-budget {s}: a time budget for --renderer auto must be above 0 and at most {MAX_SECONDS} s (30 days)"
        )),
        _ => Ok(()),
    }
}

/// The candidate's best plan for the goal, or why it has none.
fn plan_one(candidate: &Candidate, goal: Goal) -> Result<Planned, String> {
    let planned = |spp: Option<u32>| Planned {
        candidate: candidate.clone(),
        spp,
        predicted_error: predicted_error(candidate, spp.unwrap_or(1)),
        predicted_seconds: predicted_seconds(candidate, spp.unwrap_or(0)),
    };
    let floor = error_floor(candidate);
    let multiple = candidate.spp_multiple.max(1);
    match (goal, &candidate.noise) {
        (Goal::Error(target), None) => {
            if floor <= target {
                Ok(planned(None))
            } else {
                Err(format!("its error is {floor:.3} whatever the settings allow it"))
            }
        }
        (Goal::Error(target), Some(curve)) => {
            let room = target * target - candidate.bias_rel_mse;
            if room <= 0.0 {
                return Err(format!("its bias alone is {floor:.3} however many samples it takes"));
            }
            // The fewest samples whose noise fits in the room the bias leaves: the model's
            // inverse (ceil(per sample / room) for 1/N), found by doubling then bisection over
            // multiples of the setting's spp step; it holds for any curve that never rises.
            let meets = |k: u32| {
                let n = f64::from(k) * f64::from(multiple);
                candidate.bias_rel_mse + noise_rel_mse(curve, n) <= target * target
            };
            let max_steps = MAX_SPP / multiple;
            if !meets(max_steps) {
                return Err(format!("it would need more than {MAX_SPP} samples per pixel"));
            }
            let (mut low, mut high) = (0u32, 1u32);
            while !meets(high) {
                low = high;
                high *= 2;
            }
            while high - low > 1 {
                let mid = low + (high - low) / 2;
                if meets(mid) { high = mid } else { low = mid }
            }
            let high = high * multiple;
            let plan = planned(Some(high));
            if plan.predicted_seconds > MAX_SECONDS {
                return Err(format!(
                    "it would need {high} samples per pixel, {:.0} days",
                    plan.predicted_seconds / 86_400.0
                ));
            }
            Ok(plan)
        }
        (Goal::Seconds(budget), None) => {
            if candidate.fixed_seconds <= budget {
                Ok(planned(None))
            } else {
                Err(format!("one image takes {:.2} s", candidate.fixed_seconds))
            }
        }
        (Goal::Seconds(budget), Some(_)) => {
            let spare = budget - candidate.fixed_seconds;
            let spp = if candidate.seconds_per_spp > 0.0 { spare / candidate.seconds_per_spp } else { 0.0 };
            let spp = (spp.min(f64::from(MAX_SPP)) / f64::from(multiple)).floor() as u32 * multiple;
            if spp < 1 {
                return Err(format!(
                    "its setup and {multiple} sample{} per pixel take {:.2} s",
                    if multiple == 1 { "" } else { "s" },
                    predicted_seconds(candidate, multiple)
                ));
            }
            Ok(planned(Some(spp)))
        }
    }
}

/// The plan for `goal` over `candidates`: the cheapest predicted to meet an error target (ties
/// to the more accurate), or the most accurate predicted to finish within a budget (ties to the
/// faster). The runners-up are the next best, best first. When none qualifies, the error says
/// what each renderer's best can do and why.
pub fn plan(candidates: &[Candidate], goal: Goal) -> Result<Plan, String> {
    check_goal(goal)?;
    let mut feasible = Vec::new();
    let mut reasons: Vec<(&Candidate, String)> = Vec::new();
    for candidate in candidates {
        match plan_one(candidate, goal) {
            Ok(p) => feasible.push(p),
            Err(why) => reasons.push((candidate, why)),
        }
    }
    let key = |p: &Planned| match goal {
        Goal::Error(_) => (p.predicted_seconds, p.predicted_error),
        Goal::Seconds(_) => (p.predicted_error, p.predicted_seconds),
    };
    feasible.sort_by(|a, b| key(a).partial_cmp(&key(b)).unwrap_or(std::cmp::Ordering::Equal));
    let mut feasible = feasible.into_iter();
    match feasible.next() {
        Some(choice) => Ok(Plan { choice, runners_up: feasible.take(RUNNERS_UP).collect() }),
        None => Err(refusal(goal, &reasons)),
    }
}

/// Why nothing meets the goal: per renderer, its closest setting and what holds it back.
fn refusal(goal: Goal, reasons: &[(&Candidate, String)]) -> String {
    if reasons.is_empty() {
        return "no renderer can draw this scene".to_owned();
    }
    let mut text = match goal {
        Goal::Error(e) => format!("no renderer is predicted to reach a relative error of {e}:"),
        Goal::Seconds(s) => format!("no renderer is predicted to finish within {s} s:"),
    };
    for renderer in ["raster", "whitted", "pathtrace"] {
        let closest = reasons.iter().filter(|(c, _)| c.setting.renderer() == renderer).min_by(|a, b| {
            let measure = |c: &Candidate| match goal {
                Goal::Error(_) => error_floor(c),
                Goal::Seconds(_) => predicted_seconds(c, c.spp_multiple.max(1)),
            };
            measure(a.0).partial_cmp(&measure(b.0)).unwrap_or(std::cmp::Ordering::Equal)
        });
        if let Some((candidate, why)) = closest {
            text.push_str(&format!("\n  {}: {why}", candidate.setting));
            if let (Goal::Error(_), Some((region, ratio))) = (goal, &candidate.worst_region) {
                text.push_str(&format!(
                    " (its worst region, {region}, has {:.0}% of the truth's brightness)",
                    ratio * 100.0
                ));
            }
        }
    }
    text
}

#[cfg(test)]
mod tests {
    use illum_scene::{Bounces, DenoiserKind, Sequence};

    use super::*;

    fn deterministic(depth: u32, bias_rel_mse: f64, seconds: f64) -> Candidate {
        Candidate {
            setting: Setting::Whitted { depth, aa: 2 },
            bias_rel_mse,
            noise: None,
            spp_multiple: 1,
            fixed_seconds: seconds,
            seconds_per_spp: 0.0,
            worst_region: Some(("floor in the glass sphere's shadow".into(), 0.27)),
        }
    }

    fn path_tracer(caustics: bool, bias_rel_mse: f64, per_sample: f64, per_spp: f64) -> Candidate {
        Candidate {
            setting: Setting::PathTrace {
                bounces: Bounces::Fixed(8),
                caustics,
                sequence: Sequence::Independent,
                adaptive: false,
                denoise: None,
            },
            bias_rel_mse,
            noise: NoiseCurve::independent(per_sample, 1.0),
            spp_multiple: 1,
            fixed_seconds: 0.5,
            seconds_per_spp: per_spp,
            worst_region: None,
        }
    }

    #[test]
    fn the_fewest_samples_that_meet_the_target_are_the_model_inverted() {
        // bias 0.001, 0.1 per sample, target 0.05: room 0.0025 - 0.001 = 0.0015, N = 0.1 / 0.0015 = 66.7 -> 67.
        let c = path_tracer(true, 0.001, 0.1, 0.01);
        let p = plan(std::slice::from_ref(&c), Goal::Error(0.05)).unwrap().choice;
        assert_eq!(p.spp, Some(67));
        assert!(p.predicted_error <= 0.05 && predicted_error(&c, 66) > 0.05, "{p:?}");
        assert!((p.predicted_seconds - (0.5 + 0.67)).abs() < 1e-12, "{p:?}");
    }

    #[test]
    fn an_error_target_takes_the_cheapest_that_meets_it_and_a_budget_the_most_accurate_within_it() {
        let raster_like = deterministic(1, 0.2 * 0.2, 0.05);
        let whitted = deterministic(8, 0.1 * 0.1, 0.3);
        let pt = path_tracer(true, 0.0, 0.08, 0.02);
        let all = [raster_like.clone(), whitted.clone(), pt.clone()];
        // 0.3: all three meet it; the 0.05 s one is cheapest.
        assert_eq!(plan(&all, Goal::Error(0.3)).unwrap().choice.candidate, raster_like);
        // 0.15: the 0.2 one cannot; the path tracer needs 0.08 / 0.0225 -> 4 spp, 0.58 s; Whitted 0.3 s wins.
        let p = plan(&all, Goal::Error(0.15)).unwrap();
        assert_eq!(p.choice.candidate, whitted);
        assert_eq!(p.runners_up[0].spp, Some(4));
        // 0.05: only the path tracer, 32 spp.
        assert_eq!(plan(&all, Goal::Error(0.05)).unwrap().choice.spp, Some(32));
        // 1 s: the path tracer gets 25 spp, error sqrt(0.08 / 25) = 0.057 < 0.1: it wins.
        let p = plan(&all, Goal::Seconds(1.0)).unwrap();
        assert_eq!(p.choice.spp, Some(25));
        assert_eq!(p.runners_up.len(), 2);
        // 0.4 s: the path tracer cannot do one sample (0.52 s); Whitted fits and beats the raster.
        assert_eq!(plan(&all, Goal::Seconds(0.4)).unwrap().choice.candidate, whitted);
    }

    #[test]
    fn an_unreachable_target_is_refused_with_each_renderers_reason() {
        let all = [deterministic(8, 0.06, 0.2), path_tracer(false, 0.004, 0.08, 0.02)];
        let why = plan(&all, Goal::Error(0.01)).unwrap_err();
        assert!(why.contains("relative error of 0.01"), "{why}");
        assert!(why.contains("Whitted ray tracer, depth 8") && why.contains("0.245"), "{why}");
        assert!(why.contains("27% of the truth's brightness"), "{why}");
        assert!(why.contains("caustic light tracer off: its bias alone is 0.063"), "{why}");
        let why = plan(&all, Goal::Seconds(0.1)).unwrap_err();
        assert!(why.contains("within 0.1 s") && why.contains("one image takes 0.20 s"), "{why}");
    }

    #[test]
    fn a_setting_renders_in_multiples_of_its_step_and_a_denoised_one_wins_where_cheaper() {
        // Raw: 0.1 per sample, 0.05 s per spp. Denoised: its measured error 0.002 at 16 spp,
        // 0.0012 from 64 on, one second of guides and filter; both unbiased.
        let raw = path_tracer(false, 0.0, 0.1, 0.05);
        let mut denoised = path_tracer(false, 0.0, 0.1, 0.05);
        if let Setting::PathTrace { denoise, .. } = &mut denoised.setting {
            *denoise = Some(DenoiserKind::Atrous);
        }
        denoised.noise = NoiseCurve::new(vec![(4.0, 0.008), (16.0, 0.002), (64.0, 0.0012)], 0.0);
        denoised.spp_multiple = 2;
        denoised.fixed_seconds = 1.5;
        assert_eq!(
            denoised.setting.to_string(),
            "path tracer, bounces 8, caustic light tracer off, denoised by à-trous"
        );
        let both = [raw.clone(), denoised.clone()];
        // 0.05 (relMSE 0.0025): raw needs 40 spp (2.5 s); denoised 4 < N < 16 on the curve,
        // 0.008 (4/N)^1 <= 0.0025 -> N >= 12.8 -> 14 (even): 1.5 + 0.7 = 2.2 s.
        let p = plan(&both, Goal::Error(0.05)).unwrap();
        assert_eq!((p.choice.candidate.setting.clone(), p.choice.spp), (denoised.setting.clone(), Some(14)));
        assert_eq!(p.runners_up[0].spp, Some(40));
        // 0.03 (relMSE 0.0009): below the denoised curve's floor 0.0012: raw only, 112 spp.
        let p = plan(&both, Goal::Error(0.03)).unwrap();
        assert_eq!((p.choice.candidate.setting.clone(), p.choice.spp), (raw.setting.clone(), Some(112)));
        assert_eq!(p.runners_up.len(), 0);
        // A budget of 2.25 s: the denoised gets 0.75 s / 0.05 = 15 spp, floored to 14 (even).
        let denoised_alone = std::slice::from_ref(&denoised);
        assert_eq!(plan(denoised_alone, Goal::Seconds(2.25)).unwrap().choice.spp, Some(14));
    }

    #[test]
    fn bad_goals_are_refused() {
        let all = [path_tracer(true, 0.0, 0.08, 0.02)];
        for goal in [Goal::Error(0.0), Goal::Error(-0.1), Goal::Error(f64::NAN), Goal::Error(f64::INFINITY)] {
            assert!(plan(&all, goal).unwrap_err().contains("target error"), "{goal:?}");
        }
        for goal in [Goal::Seconds(0.0), Goal::Seconds(-1.0), Goal::Seconds(f64::NAN), Goal::Seconds(1e12)] {
            assert!(plan(&all, goal).unwrap_err().contains("time budget"), "{goal:?}");
        }
        // A target so small it would take more than 30 days.
        assert!(plan(&all, Goal::Error(1e-5)).unwrap_err().contains("days"));
    }
}
