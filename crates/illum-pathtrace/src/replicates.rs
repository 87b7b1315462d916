//! The error of a low-discrepancy render, from independently randomised replicates.
//!
//! The variance of the mean that independent samples give, s^2 / n, is wrong for the
//! low-discrepancy sequence: its samples are negatively correlated, and its error falls faster
//! than 1/n (docs/accuracy.md measured s^2 / n at 4.5 times the true relMSE at 4096 spp). So
//! the sampler (shaders/sampler.wgsl) deals a pixel's sample indices, in runs of
//! [`REPLICATE_RUN`], to [`REPLICATES`] copies of the sequence, each with its own random shifts
//! and shuffles. The R replicate means m_r are then independent and identically distributed,
//! each unbiased, and the pixel's mean is their average; its variance is estimated without
//! assuming anything about the sequence by
//!
//! ```text
//! Var(mean) = sum_r (m_r - m)^2 / (R (R - 1)),
//! ```
//!
//! unbiased for equal counts. With unequal counts n_r (a render whose spp is not a multiple of
//! R x REPLICATE_RUN, or dropped NaN samples) the mean is sum_r n_r m_r / N, and the same
//! formula weighted, R / (R - 1) sum_r (n_r / N)^2 (m_r - m)^2, reduces to it when the n_r are
//! equal. Fewer than two replicates with samples: unknown (infinite), as with one sample.
//!
//! The chunk of samples one GPU invocation sums must lie inside one run, so a low-discrepancy
//! render uses chunks of [`REPLICATE_RUN`] samples; its folded chunk sums then add into the
//! replicate of their first sample. The tracer therefore ends every planned pass of such a
//! render on a multiple of the run (`tracer/passes.rs`), as chunk-aligned passes do. A pass
//! that starts inside a run anyway (`add_samples_in_one_pass` with an spp that is not a multiple
//! of it, then more) has chunks across two runs, each counted in the replicate of its first
//! sample: that mixes replicates, whose means then spread more, and the estimate errs high.
//! Measured with unaligned passes of any spp: est./true up to 2.4 at 4096 spp.

/// Independently randomised copies of the low-discrepancy sequence per pixel. R replicates of
/// N / R points each have more error than one sequence of N points, since the sequence's
/// advantage grows with its length; more replicates give a steadier per-pixel estimate (R - 1
/// degrees of freedom). Measured on the 64 x 64 Cornell box (docs/accuracy-estimate.md), relMSE over that
/// of one sequence at 64 / 256 / 1024 / 4096 spp: R = 4: 2.0 / 1.35 / 1.22 / 0.99; R = 8: 2.1 /
/// 2.1 / 1.56 / 1.16. 4 keeps most of the sequence's gain, with 3 degrees of freedom per pixel
/// (a per-pixel variance within about 82% relative, one standard deviation; the image's
/// estimate averages thousands of them).
pub const REPLICATES: usize = 4;

/// Consecutive sample indices that go to one replicate (the chunk size of a low-discrepancy
/// render). 4: 16 spp reach every replicate. A chunk is one GPU invocation's samples, and
/// shorter chunks cost throughput on lavapipe (more invocations, more slots read back and
/// folded): at 256 x 256, 512 spp, low-discrepancy over independent samples/s measured about
/// 0.4 with runs of 2, 0.6 with runs of 4 and 0.85 with runs of 16 (docs/accuracy-estimate.md), while
/// runs of 16 would need 64 spp to reach every replicate.
pub const REPLICATE_RUN: u32 = 4;

/// The replicate that sample index `sample` of a pixel belongs to (as the shader's sampler_new).
pub fn replicate_of(sample: u64) -> usize {
    ((sample / u64::from(REPLICATE_RUN)) % REPLICATES as u64) as usize
}

/// Per pixel and replicate: the sum of its finite samples (f64, rgb) and their count.
#[derive(Clone, Debug, PartialEq)]
pub struct Replicates {
    /// `pixels x REPLICATES`, pixel-major.
    pub sum: Vec<[f64; 3]>,
    pub count: Vec<u64>,
}

impl Replicates {
    pub fn new(pixels: usize) -> Self {
        Replicates { sum: vec![[0.0; 3]; pixels * REPLICATES], count: vec![0; pixels * REPLICATES] }
    }

    /// Host bytes per pixel.
    pub const BYTES_PER_PIXEL: u64 = (REPLICATES * (3 * 8 + 8)) as u64;

    pub fn pixels(&self) -> usize {
        self.count.len() / REPLICATES
    }

    /// Adds a chunk's sum `sum` of `count` samples to `replicate` of `pixel`.
    pub fn add(&mut self, pixel: usize, replicate: usize, sum: [f64; 3], count: u64) {
        let slot = pixel * REPLICATES + replicate;
        for (total, value) in self.sum[slot].iter_mut().zip(sum) {
            *total += value;
        }
        self.count[slot] += count;
    }

    /// Adds values to `replicate` of `pixel` that come with no samples of their own (a second
    /// estimator's values for samples already counted, see `Accumulator::fold_independent`).
    pub fn add_values(&mut self, pixel: usize, replicate: usize, sum: [f64; 3]) {
        self.add(pixel, replicate, sum, 0);
    }

    /// Adds another set of replicates of the same image (a disjoint set of sample indices).
    pub fn merge(&mut self, other: &Replicates) {
        assert_eq!(self.count.len(), other.count.len(), "merging replicates of different sizes");
        for (a, b) in self.sum.iter_mut().zip(&other.sum) {
            for c in 0..3 {
                a[c] += b[c];
            }
        }
        for (a, b) in self.count.iter_mut().zip(&other.count) {
            *a += b;
        }
    }

    pub fn reset(&mut self) {
        self.sum.fill([0.0; 3]);
        self.count.fill(0);
    }

    /// The variance of the pixel's mean per channel, from the spread of its replicate means (see
    /// the module documentation); infinite with fewer than two replicates holding samples.
    pub fn variance_of_mean(&self, pixel: usize) -> [f64; 3] {
        let slots = pixel * REPLICATES..(pixel + 1) * REPLICATES;
        let (sums, counts) = (&self.sum[slots.clone()], &self.count[slots]);
        let total: u64 = counts.iter().sum();
        let filled = counts.iter().filter(|&&n| n > 0).count();
        if filled < 2 {
            return [f64::INFINITY; 3];
        }
        let total = total as f64;
        let mut out = [0.0; 3];
        for (c, value) in out.iter_mut().enumerate() {
            let mean = sums.iter().map(|s| s[c]).sum::<f64>() / total;
            let spread: f64 = sums
                .iter()
                .zip(counts)
                .filter(|(_, n)| **n > 0)
                .map(|(s, &n)| {
                    let share = n as f64 / total;
                    share * share * (s[c] / n as f64 - mean).powi(2)
                })
                .sum();
            *value = spread * filled as f64 / (filled as f64 - 1.0);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Rust constants are the shader's.
    #[test]
    fn constants_match_the_sampler() {
        let source = include_str!("../shaders/sampler.wgsl");
        assert!(source.contains(&format!("const REPLICATES: u32 = {REPLICATES}u;")));
        assert!(source.contains(&format!("const REPLICATE_RUN: u32 = {REPLICATE_RUN}u;")));
    }

    #[test]
    fn samples_are_dealt_in_runs_over_every_replicate() {
        let dealt: Vec<usize> = (0..18).map(replicate_of).collect();
        assert_eq!(dealt, [0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3, 0, 0]);
    }

    /// Equal counts: the textbook estimate sum (m_r - m)^2 / (R (R - 1)), by hand.
    #[test]
    fn equal_counts_give_the_spread_of_the_replicate_means() {
        let mut reps = Replicates::new(1);
        let means = [1.0, 2.0, 3.0, 6.0];
        assert_eq!(means.len(), REPLICATES);
        for (r, m) in means.iter().enumerate() {
            reps.add(0, r, [2.0 * m; 3], 2);
        }
        // mean 3; sum of squared deviations 4 + 1 + 0 + 9 = 14; / (4 x 3) = 7 / 6.
        assert!((reps.variance_of_mean(0)[0] - 7.0 / 6.0).abs() < 1e-12, "{:?}", reps.variance_of_mean(0));
    }

    #[test]
    fn fewer_than_two_replicates_is_unknown_and_a_constant_pixel_is_exact() {
        let mut reps = Replicates::new(2);
        reps.add(0, 3, [5.0; 3], 2);
        assert!(reps.variance_of_mean(0)[0].is_infinite());
        for r in 0..REPLICATES {
            reps.add(1, r, [0.5; 3], 2);
        }
        assert_eq!(reps.variance_of_mean(1), [0.0; 3]);
    }

    /// Merging halves gives the replicates of the whole.
    #[test]
    fn merge_adds_per_replicate() {
        let mut a = Replicates::new(1);
        let mut b = Replicates::new(1);
        a.add(0, 1, [1.0, 2.0, 3.0], 2);
        b.add(0, 1, [1.0, 1.0, 1.0], 2);
        b.add(0, 2, [4.0, 4.0, 4.0], 2);
        a.merge(&b);
        assert_eq!(a.sum[1], [2.0, 3.0, 4.0]);
        assert_eq!((a.count[1], a.count[2]), (4, 2));
    }
}
