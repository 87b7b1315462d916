//! Sizing GPU submissions.
//!
//! Every submission should take about `target_seconds` (default 0.15 s, well under the quarter
//! second a UI frame and a GPU watchdog tolerate). The planner learns the cost of one sample from
//! the submissions so far and chooses, for a new pass over the image, how many samples per pixel
//! it carries and into how many bands of rows it is split.

/// Default wall time aimed at per submission.
pub const DEFAULT_TARGET_SECONDS: f64 = 0.15;

/// Samples in the first, measuring submission (before any cost is known).
pub(crate) const PROBE_SAMPLES: u64 = 16 * 1024;

#[derive(Clone, Debug)]
pub struct BatchPlanner {
    target_seconds: f64,
    /// Smoothed wall seconds per sample (one path), once measured.
    seconds_per_sample: Option<f64>,
    /// When set, a pass over the whole image is not split into bands as long as one pass of the
    /// smallest spp traces at most this many paths (see [`Self::set_whole_passes_up_to`]).
    whole_passes_up_to: Option<u64>,
}

/// What the next pass does: `spp` samples for every pixel, in bands of `rows` rows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PassPlan {
    pub spp: u32,
    pub rows: u32,
}

impl BatchPlanner {
    pub fn new(target_seconds: f64) -> Self {
        Self { target_seconds, seconds_per_sample: None, whole_passes_up_to: None }
    }

    /// Changes the wall time aimed at per submission, keeping the learnt cost of a sample (a
    /// viewer gives its path tracer more or less of each frame as the frame's other work
    /// changes).
    pub fn set_target_seconds(&mut self, seconds: f64) {
        self.target_seconds = seconds;
    }

    /// The wall time aimed at per submission.
    pub fn target_seconds(&self) -> f64 {
        self.target_seconds
    }

    /// The learnt wall seconds per sample, once measured.
    pub fn seconds_per_sample(&self) -> Option<f64> {
        self.seconds_per_sample
    }

    /// With `Some(cap)`, a pass of the smallest spp is one submission over the whole image
    /// whenever it traces at most `cap` paths, even when that takes longer than the target: an
    /// interactive viewer then shows a complete image after every submission, instead of bands
    /// of a pass spread over several frames. A count, not a time: which submissions are whole
    /// passes does not depend on how busy the machine is.
    pub fn set_whole_passes_up_to(&mut self, cap: Option<u64>) {
        self.whole_passes_up_to = cap;
    }

    /// Samples one submission may carry over an image of `pixels` pixels whose passes take at
    /// least `pass_spp` spp: the target's worth at the learnt cost (the probe's size before
    /// any measurement), raised to a whole pass where [`Self::set_whole_passes_up_to`] allows.
    fn budget(&self, pixels: u64, pass_spp: u32) -> u64 {
        let Some(cost) = self.seconds_per_sample else { return PROBE_SAMPLES };
        let budget = (self.target_seconds / cost).max(1.0) as u64;
        let pass = pixels * u64::from(pass_spp);
        match self.whole_passes_up_to {
            Some(cap) if pass <= cap => budget.max(pass),
            _ => budget,
        }
    }

    /// Plans a pass over a `width` x `height` image with at most `max_spp` samples per pixel.
    pub fn plan(&self, width: u32, height: u32, max_spp: u32) -> PassPlan {
        let max_spp = max_spp.max(1);
        let pixels = width as u64 * height as u64;
        // The path tracer traces a pixel's samples two at a time (pathtrace.wgsl, main), so a
        // pass of odd spp wastes the second half of its last pair, and a pass of 1 spp costs
        // what 2 do. Where the budget allows, passes get an even spp; where the image does not
        // fit in one submission, a pass of 2 spp in bands rather than 1 (unless `max_spp` is 1).
        // One that reaches `max_spp` keeps it, not to add a pass.
        let pass_spp = if max_spp >= 2 { 2 } else { 1 };
        let budget = self.budget(pixels, pass_spp);
        if pixels * u64::from(pass_spp) <= budget {
            // The even spp nearest the budget, so that submissions take the target on average
            // (rounding down left a viewer's frame a quarter short); at most a third over it,
            // when the budget is just over 3 spp.
            let spp = if max_spp == 1 {
                1
            } else {
                let nearest_even = 2 * ((budget as f64 / pixels as f64 / 2.0).round() as u64).max(1);
                nearest_even.min(u64::from(max_spp)) as u32
            };
            PassPlan { spp, rows: height }
        } else {
            let rows = (budget / (width as u64 * u64::from(pass_spp))).clamp(1, height as u64) as u32;
            PassPlan { spp: pass_spp, rows }
        }
    }

    /// Rows per band for a pass of `spp` samples per pixel over a `width` x `height` image:
    /// what the learnt cost of a sample allows in one submission (at least one row, at most
    /// the image). Before any measurement: the probe's size.
    pub fn rows_for(&self, width: u32, height: u32, spp: u32) -> u32 {
        let budget = self.budget(u64::from(width) * u64::from(height), spp.max(1));
        (budget / (u64::from(width) * u64::from(spp.max(1)))).clamp(1, u64::from(height)) as u32
    }

    /// Records that `samples` paths took `seconds` of wall time.
    pub fn record(&mut self, samples: u64, seconds: f64) {
        if samples == 0 || seconds.is_nan() || seconds <= 0.0 {
            return;
        }
        let cost = seconds / samples as f64;
        // Exponential smoothing: quick to follow a change of settings, steady under noise.
        self.seconds_per_sample = Some(match self.seconds_per_sample {
            None => cost,
            Some(old) => 0.5 * old + 0.5 * cost,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_pass_is_a_small_probe() {
        let p = BatchPlanner::new(0.15).plan(1024, 1024, 64);
        assert_eq!(p.spp, 2, "samples are traced in pairs");
        assert_eq!(p.rows as u64 * 1024 * 2, PROBE_SAMPLES);
        let single = BatchPlanner::new(0.15).plan(1024, 1024, 1);
        assert_eq!((single.spp, single.rows as u64 * 1024), (1, PROBE_SAMPLES), "a 1-spp render");
    }

    #[test]
    fn cheap_samples_pack_many_spp_per_pass_and_respect_the_cap() {
        let mut planner = BatchPlanner::new(0.1);
        planner.record(1_000_000, 0.1); // 1e-7 s per sample: 1e6 samples per submission
        let p = planner.plan(100, 100, 1000);
        assert_eq!(p, PassPlan { spp: 100, rows: 100 });
        assert_eq!(planner.plan(100, 100, 7).spp, 7);
        // A budget of 1e6 samples over 300 x 300 pixels allows 11.1 spp: the nearest even
        // number is 12, over 400 x 400 (6.25 spp) it is 6.
        assert_eq!(planner.plan(300, 300, 1000).spp, 12);
        assert_eq!(planner.plan(400, 400, 1000).spp, 6);
        assert_eq!(planner.plan(300, 300, 11).spp, 11, "the cap is reached in one pass");
    }

    #[test]
    fn expensive_images_are_split_into_bands_of_at_least_one_row() {
        let mut planner = BatchPlanner::new(0.1);
        planner.record(1000, 1.0); // 1 ms per sample: 100 samples per submission
        let p = planner.plan(50, 40, 16);
        assert_eq!(p, PassPlan { spp: 2, rows: 1 });
        assert_eq!(planner.plan(25, 40, 16), PassPlan { spp: 2, rows: 2 });
        assert_eq!(planner.plan(50, 40, 1), PassPlan { spp: 1, rows: 2 });
        planner.record(1, 10.0);
        assert_eq!(planner.plan(50, 40, 16).rows, 1);
    }

    /// A viewer's planner keeps whole passes in one submission up to its cap, and splits them
    /// beyond it; the target alone still sizes the spp of a pass it can cover several times.
    #[test]
    fn whole_passes_stay_whole_up_to_the_cap() {
        // Powers of two, so that the budgets are exact: 2^-23 s per sample, 2^-6 s per
        // submission, 2^17 = 131,072 samples.
        let mut planner = BatchPlanner::new(2f64.powi(-6));
        planner.record(1 << 20, 0.125);
        // 300 x 300 at 2 spp is 180,000 samples: more than the target's 131,072.
        assert_eq!(planner.plan(300, 300, 1000).rows, 131_072 / 600, "split without a cap");
        planner.set_whole_passes_up_to(Some(1 << 20));
        assert_eq!(planner.plan(300, 300, 1000), PassPlan { spp: 2, rows: 300 });
        assert_eq!(planner.rows_for(300, 300, 2), 300);
        // 2000 x 2000 at 2 spp is 8,000,000 paths: beyond the cap, in bands of the target's size.
        assert_eq!(planner.plan(2000, 2000, 1000), PassPlan { spp: 2, rows: 131_072 / 4000 });
        // A longer target (2^20 samples) packs more spp into the one pass, and keeps the learnt
        // cost: 11.65 spp, 12 (the nearest even number).
        planner.set_target_seconds(0.125);
        assert_eq!(planner.plan(300, 300, 1000), PassPlan { spp: 12, rows: 300 });
    }

    /// The rows of a band follow the learnt cost: a pass planned before the first measurement
    /// (one row of 16 spp at 1024 wide) gets bands of the submission's size once it is known.
    #[test]
    fn band_rows_follow_the_learnt_cost() {
        let mut planner = BatchPlanner::new(0.1);
        assert_eq!(planner.rows_for(1024, 1024, 16), 1);
        planner.record(1_000_000, 0.1); // 1e6 samples per submission
        assert_eq!(planner.rows_for(1024, 1024, 16), 61);
        assert_eq!(planner.rows_for(1024, 40, 1), 40);
        assert_eq!(planner.rows_for(100_000, 10, 64), 1);
    }
}
