//! The stop rules: when a render stops (a sample target, a relative-error target, a time
//! budget), how far it is toward the nearest rule, and the user's values they are made of.

use std::time::Duration;

/// When to stop. With every field `None` the render runs until cancelled. The first rule that
/// holds stops the render.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StopRules {
    /// Stop when every pixel has this many samples.
    pub spp: Option<u32>,
    /// Stop when the estimated relative standard error (the square root of the per-pixel
    /// variance-based relMSE estimate, [`crate::Accumulator::estimated_relative_error`]) falls
    /// to this value. Checked only after each completed pass with at least 2 spp.
    pub target_error: Option<f64>,
    /// Stop after this much wall-clock time ([`super::RenderClock`]), once at least one pass is
    /// complete.
    pub time_budget: Option<Duration>,
}

impl StopRules {
    /// The rules of a command line. `scene_spp` is the scene file's spp, `spp` the value of an
    /// `--spp` flag. A target error or a time budget given without `--spp` lifts the scene's spp:
    /// the render runs until the error or the time rule fires (a target error that is never
    /// reached runs until cancelled). With `--spp` too, whichever rule holds first stops it.
    /// With neither, the render stops at `spp` or else the scene's spp.
    pub fn from_command_line(
        scene_spp: u32,
        spp: Option<u32>,
        target_error: Option<f64>,
        time_budget: Option<Duration>,
    ) -> Self {
        let open_ended = target_error.is_some() || time_budget.is_some();
        StopRules {
            spp: if open_ended { spp } else { Some(spp.unwrap_or(scene_spp)) },
            target_error,
            time_budget,
        }
    }

    /// The first rule that holds for `status`, in the order spp, error, time.
    pub fn check(&self, status: &Status) -> Option<StopReason> {
        if self.spp.is_some_and(|spp| status.spp_done >= spp) {
            return Some(StopReason::SppReached);
        }
        if let (Some(target), Some(error)) = (self.target_error, status.relative_error)
            && error <= target
        {
            return Some(StopReason::ErrorReached);
        }
        if status.spp_done >= 1 && self.time_budget.is_some_and(|budget| status.elapsed >= budget) {
            return Some(StopReason::TimeBudget);
        }
        None
    }

    /// How far the render is toward the rule that will stop it first: the largest fraction
    /// among the rules given (`None` when no rule is given). For the error rule the fraction is
    /// (target / error)^2, the share of the samples needed that are done, since the error falls
    /// as 1 / sqrt(samples). The spp rule's fraction is of spp, counting the pass in progress by
    /// its share done, or with adaptive sampling of `adaptive_samples`, its allocation's total (the
    /// pixels do not all take `spp`, which is then the largest block count). The time rule's is
    /// at most the first pass's share until that pass is complete, since the rule waits for it.
    pub fn progress(&self, status: &Status, adaptive_samples: Option<u64>) -> Option<Progress> {
        let mut best: Option<Progress> = None;
        let mut consider = |rule: Rule, fraction: f64| {
            let fraction = if fraction.is_finite() { fraction.clamp(0.0, 1.0) } else { 0.0 };
            if best.is_none_or(|b| fraction > b.fraction) {
                best = Some(Progress { rule, fraction });
            }
        };
        if let Some(spp) = self.spp {
            // Within a long pass, not by complete passes alone, so the bar moves: by the pass's
            // share done (its caustic frames count, which hold no samples until its bands fold),
            // or with adaptive sampling by the samples of its allocation.
            let fraction = match adaptive_samples {
                Some(planned) => status.samples as f64 / planned.max(1) as f64,
                None => {
                    let done = f64::from(status.spp_done) + status.pass_fraction * f64::from(status.pass_spp);
                    done / f64::from(spp.max(1))
                }
            };
            consider(Rule::Spp, fraction);
        }
        if let Some(target) = self.target_error {
            let fraction =
                status.relative_error.map_or(0.0, |e| if e > 0.0 { (target / e).powi(2) } else { 1.0 });
            consider(Rule::Error, fraction);
        }
        if let Some(budget) = self.time_budget {
            let spent = status.elapsed.as_secs_f64() / budget.as_secs_f64().max(1e-9);
            // The time rule waits for the first complete pass: until then the render is as far
            // as that pass, if that is less (a bar at 100% with an ETA of 0 s for a first pass
            // that still runs would say the render is over).
            let fraction = if status.spp_done == 0 { spent.min(status.pass_fraction) } else { spent };
            consider(Rule::Time, fraction);
        }
        best
    }
}

/// Checks a target relative error given by the user: a finite number above 0. `name` is the
/// flag or field, for the message.
pub fn parse_target_error(name: &str, value: f64) -> Result<f64, String> {
    if value > 0.0 && value.is_finite() {
        Ok(value)
    } else {
        Err(format!("{name} = {}: must be a finite number above 0 (for example 0.01 for 1%)", number(value)))
    }
}

/// Checks a time budget in seconds given by the user: a finite number above 0 that a
/// [`Duration`] can hold. `name` is the flag or field, for the message.
pub fn parse_time_budget(name: &str, seconds: f64) -> Result<Duration, String> {
    if !(seconds > 0.0 && seconds.is_finite()) {
        return Err(format!("{name} = {}: must be a finite number of seconds above 0", number(seconds)));
    }
    Duration::try_from_secs_f64(seconds).map_err(|_| {
        format!(
            "{name} = {}: too large; at most {:e} seconds",
            number(seconds),
            Duration::MAX.as_secs() as f64
        )
    })
}

/// A number as a user would write it: 1e30 rather than thirty-one digits.
fn number(value: f64) -> String {
    if value != 0.0 && value.is_finite() && !(1e-4..1e9).contains(&value.abs()) {
        format!("{value:e}")
    } else {
        format!("{value}")
    }
}

/// Why a progressive render stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    SppReached,
    ErrorReached,
    TimeBudget,
    Cancelled,
}

impl StopReason {
    /// A short name, as stored in EXR metadata (`illum.stopped_by`).
    pub fn name(self) -> &'static str {
        match self {
            StopReason::SppReached => "spp",
            StopReason::ErrorReached => "target_error",
            StopReason::TimeBudget => "time_budget",
            StopReason::Cancelled => "cancelled",
        }
    }

    /// What happened, for people.
    pub fn describe(self) -> &'static str {
        match self {
            StopReason::SppReached => "spp target reached",
            StopReason::ErrorReached => "error target reached",
            StopReason::TimeBudget => "time budget spent",
            StopReason::Cancelled => "interrupted",
        }
    }
}

/// The rule a [`Progress`] measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rule {
    Spp,
    Error,
    Time,
}

/// Progress toward the nearest stop rule.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Progress {
    pub rule: Rule,
    /// In [0, 1].
    pub fraction: f64,
}

impl Progress {
    /// Time left at the rate so far, once there is a rate to go by.
    pub fn eta(&self, elapsed: Duration) -> Option<Duration> {
        (self.fraction > 0.0).then(|| {
            let left = elapsed.as_secs_f64() * (1.0 - self.fraction) / self.fraction;
            Duration::try_from_secs_f64(left).unwrap_or(Duration::MAX)
        })
    }
}

/// What the stop rules look at.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Status {
    /// Samples per pixel of the completed passes.
    pub spp_done: u32,
    /// Finite samples taken, over all pixels (including any a resumed render started with).
    pub samples: u64,
    /// Of those, the samples taken since this render's clock started (what the clock's time
    /// was spent on).
    pub run_samples: u64,
    /// Wall-clock time of the render ([`super::RenderClock`]).
    pub elapsed: Duration,
    /// The estimated relative error after the last completed pass, once there are samples
    /// enough to estimate it ([`crate::Accumulator::spp_for_error_estimate`]).
    pub relative_error: Option<f64>,
    /// Samples per pixel of the pass in progress (0: none), and the share of its work done, in
    /// [0, 1] ([`crate::PathTracer::pass_fraction`]).
    pub pass_spp: u32,
    pub pass_fraction: f64,
}

impl Status {
    /// Samples taken per second of this render's wall-clock time (0 before any time has passed).
    pub fn samples_per_second(&self) -> f64 {
        let seconds = self.elapsed.as_secs_f64();
        if seconds > 0.0 { self.run_samples as f64 / seconds } else { 0.0 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn status(spp_done: u32, seconds: f64, error: Option<f64>) -> Status {
        Status {
            spp_done,
            samples: 0,
            run_samples: 0,
            elapsed: Duration::from_secs_f64(seconds),
            relative_error: error,
            pass_spp: 0,
            pass_fraction: 0.0,
        }
    }

    #[test]
    fn command_line_rules_lift_the_scene_spp() {
        let plain = StopRules::from_command_line(16, None, None, None);
        assert_eq!(plain.spp, Some(16));
        let error = StopRules::from_command_line(16, None, Some(0.01), None);
        assert_eq!(error.spp, None, "--target-error alone must not stop at the scene's 16 spp");
        let both = StopRules::from_command_line(16, Some(64), Some(0.01), None);
        assert_eq!(both.spp, Some(64));
        let time = StopRules::from_command_line(16, None, None, Some(Duration::from_secs(1)));
        assert_eq!(time.spp, None);
    }

    #[test]
    fn the_time_budget_waits_for_a_complete_pass() {
        let rules = StopRules { time_budget: Some(Duration::from_millis(1)), ..Default::default() };
        assert_eq!(rules.check(&status(0, 10.0, None)), None);
        assert_eq!(rules.check(&status(1, 10.0, None)), Some(StopReason::TimeBudget));
    }

    #[test]
    fn the_error_rule_needs_an_estimate() {
        let rules = StopRules { target_error: Some(0.1), ..Default::default() };
        assert_eq!(rules.check(&status(1, 0.0, None)), None);
        assert_eq!(rules.check(&status(4, 0.0, Some(0.2))), None);
        assert_eq!(rules.check(&status(16, 0.0, Some(0.1))), Some(StopReason::ErrorReached));
    }

    #[test]
    fn progress_follows_the_nearest_rule() {
        let rules = StopRules {
            spp: Some(100_000),
            target_error: Some(0.01),
            time_budget: Some(Duration::from_secs(4)),
        };
        let s = Status { samples: 10 * 100, ..status(10, 1.0, Some(0.04)) };
        let p = rules.progress(&s, None).unwrap();
        assert_eq!(p.rule, Rule::Time);
        assert!((p.fraction - 0.25).abs() < 1e-12);
        assert!((p.eta(s.elapsed).unwrap().as_secs_f64() - 3.0).abs() < 1e-9);
        let s = status(10, 1.0, Some(0.011));
        let p = rules.progress(&s, None).unwrap();
        assert_eq!(p.rule, Rule::Error);
        assert!((p.fraction - (0.01f64 / 0.011).powi(2)).abs() < 1e-12);
        assert_eq!(StopRules::default().progress(&s, None), None);
        // Adaptive sampling: the spp rule's target is the blocks' largest count, and its
        // progress the share of the allocation's samples taken.
        let rules = StopRules { spp: Some(4000), ..Default::default() };
        let s = Status { samples: 50_000, ..status(900, 1.0, None) };
        assert!((rules.progress(&s, Some(100_000)).unwrap().fraction - 0.5).abs() < 1e-12);
    }

    /// The bar moves within a pass whose first part holds no samples (the caustic's frames),
    /// and the time rule, which waits for the first complete pass, is never further along than
    /// that pass: not at 100% with an ETA of 0 s while the render goes on.
    #[test]
    fn progress_moves_within_a_pass_and_the_time_rule_waits_for_the_first() {
        let first_pass = |seconds: f64, share: f64| Status {
            pass_spp: 16,
            pass_fraction: share,
            ..status(0, seconds, None)
        };
        let spp = StopRules { spp: Some(32), ..Default::default() };
        assert_eq!(spp.progress(&first_pass(3.0, 0.25), None).unwrap().fraction, 0.125);
        let after = Status { pass_spp: 16, pass_fraction: 0.5, ..status(16, 9.0, None) };
        assert_eq!(spp.progress(&after, None).unwrap().fraction, 0.75);
        let time = StopRules { time_budget: Some(Duration::from_secs(5)), ..Default::default() };
        let p = time.progress(&first_pass(8.0, 0.8), None).unwrap();
        assert_eq!((p.rule, p.fraction), (Rule::Time, 0.8));
        assert!((p.eta(Duration::from_secs(8)).unwrap().as_secs_f64() - 2.0).abs() < 1e-9);
        let p = time.progress(&first_pass(1.0, 0.8), None).unwrap();
        assert!((p.fraction - 0.2).abs() < 1e-12, "the budget is then the nearer end");
        // Once a pass is complete the budget alone counts.
        let p = time.progress(&Status { pass_fraction: 0.1, ..status(16, 4.0, None) }, None).unwrap();
        assert!((p.fraction - 0.8).abs() < 1e-12);
    }

    #[test]
    fn user_values_are_checked_with_their_name() {
        assert!(
            parse_time_budget("--time-budget", 1e30).unwrap_err().contains("--time-budget = 1e30: too large")
        );
        assert!(parse_time_budget("--time-budget", 0.0).unwrap_err().contains("above 0"));
        assert!(parse_time_budget("--time-budget", f64::NAN).is_err());
        assert_eq!(parse_time_budget("x", 1.5), Ok(Duration::from_millis(1500)));
        assert!(parse_target_error("--target-error", -0.1).unwrap_err().contains("--target-error = -0.1"));
        assert!(parse_target_error("--target-error", 0.0).is_err());
        assert!(parse_target_error("--target-error", f64::INFINITY).is_err());
    }

    #[test]
    fn the_sample_rate_counts_only_this_runs_samples() {
        // A render resumed with 1000 samples that took 100 more in 2 s runs at 50 per second,
        // not (1000 + 100) / 2.
        let s = Status { samples: 1100, run_samples: 100, ..status(10, 2.0, None) };
        assert_eq!(s.samples_per_second(), 50.0);
    }
}
