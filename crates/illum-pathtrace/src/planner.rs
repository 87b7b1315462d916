//! Sizing GPU submissions.
//!
//! Every submission should take about `target_seconds` (default 0.15 s, well under the quarter
//! second a UI frame and a GPU watchdog tolerate). The planner learns the cost of one sample from
//! the submissions so far and chooses, for a new pass over the image, how many samples per pixel
//! it carries and into how many bands of rows it is split.

/// Default wall time aimed at per submission.
pub const DEFAULT_TARGET_SECONDS: f64 = 0.15;

/// Samples in the first, measuring submission (before any cost is known).
const PROBE_SAMPLES: u64 = 16 * 1024;

#[derive(Clone, Debug)]
pub struct BatchPlanner {
    target_seconds: f64,
    /// Smoothed wall seconds per sample (one path), once measured.
    seconds_per_sample: Option<f64>,
}

/// What the next pass does: `spp` samples for every pixel, in bands of `rows` rows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PassPlan {
    pub spp: u32,
    pub rows: u32,
}

impl BatchPlanner {
    pub fn new(target_seconds: f64) -> Self {
        Self { target_seconds, seconds_per_sample: None }
    }

    /// Plans a pass over a `width` x `height` image with at most `max_spp` samples per pixel.
    pub fn plan(&self, width: u32, height: u32, max_spp: u32) -> PassPlan {
        let max_spp = max_spp.max(1);
        let pixels = width as u64 * height as u64;
        let budget = match self.seconds_per_sample {
            None => PROBE_SAMPLES,
            Some(cost) => (self.target_seconds / cost).max(1.0) as u64,
        };
        // The path tracer traces a pixel's samples two at a time (pathtrace.wgsl, main), so a
        // pass of odd spp wastes the second half of its last pair, and a pass of 1 spp costs
        // what 2 do. Where the budget allows, passes get an even spp; where the image does not
        // fit in one submission, a pass of 2 spp in bands rather than 1 (unless `max_spp` is 1).
        // One that reaches `max_spp` keeps it, not to add a pass.
        let pass_spp = if max_spp >= 2 { 2 } else { 1 };
        if pixels * u64::from(pass_spp) <= budget {
            let spp = (budget / pixels).clamp(1, max_spp as u64) as u32;
            let spp = if spp > 1 && spp < max_spp { spp & !1 } else { spp };
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
        let budget = match self.seconds_per_sample {
            None => PROBE_SAMPLES,
            Some(cost) => (self.target_seconds / cost).max(1.0) as u64,
        };
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
        // A budget of 1e6 samples over 300 x 300 pixels allows 11 spp: 10, an even number.
        assert_eq!(planner.plan(300, 300, 1000).spp, 10);
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
