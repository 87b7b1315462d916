//! The error of a low-discrepancy render, from independently randomised replicates.
//!
//! The variance of the mean that independent samples give, s^2 / n, is wrong for the
//! low-discrepancy sequence: its samples are negatively correlated, and its error falls faster
//! than 1/n (docs/accuracy.md measured s^2 / n at 4.5 times the true relMSE at 4096 spp). So
//! the sampler (shaders/sampler.wgsl) deals a pixel's sample indices, in runs of
//! [`REPLICATE_RUN`], to [`REPLICATES`] copies of the sequence, each with its own random
//! shuffles. The R replicate means m_r are then independent and identically distributed,
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
//! The replicate is a function of the sample index alone, so the GPU keeps replicates apart
//! inside any chunk: an invocation sums each replicate's samples of its chunk into a slot of its
//! own (one slot layer per replicate, `batch::Layers`), and the f64 fold adds each slot to its
//! replicate. Chunks, passes, resumed renders, `merge` and `--sample-range` parts may then start
//! and end at any sample index: every sample reaches its own replicate's sums, whatever the
//! batching (a chunk summed into the replicate of its first sample would mix replicates wherever
//! it crossed a run, and then their means spread more and the estimate errs high: up to 2.4 times
//! at 4096 spp, measured with that bookkeeping).
//!
//! The price of R replicates in error. One randomised sequence of N points has a relMSE falling
//! as N^-alpha (alpha > 1 for the low-discrepancy sequence, 1 for independent samples). The mean
//! of R independent replicates of N / R points each has relMSE (N / R)^-alpha / R, so its ratio
//! to one sequence of N points is R^(alpha - 1), alpha taken between N / R and N: nothing for
//! independent samples. On the 64 x 64 Cornell box (docs/accuracy.md, "The price"), one
//! sequence's alpha is 1.33 from 16 to 64 spp, 1.19 from 64 to 256, 1.08 from 256 to 1024 and
//! 1.06 from 1024 to 4096, so R = 4 predicts 1.57, 1.30, 1.12 and 1.09 times one sequence's
//! relMSE at 64, 256, 1024 and 4096 spp; measured: 2.0, 1.35, 1.22 and 0.99.

/// Independently randomised copies of the low-discrepancy sequence per pixel. R replicates of
/// N / R points each have more error than one sequence of N points, since the sequence's
/// advantage grows with its length; more replicates give a steadier per-pixel estimate (R - 1
/// degrees of freedom). Measured on the 64 x 64 Cornell box (docs/accuracy-estimate.md), relMSE over that
/// of one sequence at 64 / 256 / 1024 / 4096 spp: R = 4: 2.0 / 1.35 / 1.22 / 0.99; R = 8: 2.1 /
/// 2.1 / 1.56 / 1.16. 4 keeps most of the sequence's gain, with 3 degrees of freedom per pixel
/// (a per-pixel variance within about 82% relative, one standard deviation; the image's
/// estimate averages thousands of them).
pub const REPLICATES: usize = 4;

/// Consecutive sample indices that go to one replicate. 4: 16 spp reach every replicate, and
/// any interleaving of the indices by parity (two halves of a render) still reaches all of
/// them. The GPU's chunk does not depend on it: each replicate's samples of a chunk get a slot
/// of their own.
pub const REPLICATE_RUN: u32 = 4;

/// The replicate that sample index `sample` of a pixel belongs to (as the shader's replicate_of).
pub fn replicate_of(sample: u64) -> usize {
    ((sample / u64::from(REPLICATE_RUN)) % REPLICATES as u64) as usize
}

/// How many of the sample indices `start..start + len` belong to `replicate`.
pub fn samples_in(start: u64, len: u64, replicate: usize) -> u64 {
    let (run, cycle) = (u64::from(REPLICATE_RUN), u64::from(REPLICATE_RUN) * REPLICATES as u64);
    // Indices below n that belong to the replicate: whole cycles, then the part of its run
    // inside the last partial cycle.
    let below = |n: u64| n / cycle * run + (n % cycle).saturating_sub(replicate as u64 * run).min(run);
    below(start + len) - below(start)
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
        // One pass for the totals, one for the spread (every error estimate runs this for every
        // pixel, once per pass).
        let (mut total, mut filled, mut sum) = (0u64, 0usize, [0.0f64; 3]);
        for (s, &n) in sums.iter().zip(counts) {
            total += n;
            filled += usize::from(n > 0);
            for c in 0..3 {
                sum[c] += s[c];
            }
        }
        if filled < 2 {
            return [f64::INFINITY; 3];
        }
        let total = total as f64;
        let mean = sum.map(|s| s / total);
        let mut spread = [0.0f64; 3];
        for (s, &n) in sums.iter().zip(counts).filter(|(_, n)| **n > 0) {
            let share = n as f64 / total;
            for c in 0..3 {
                spread[c] += share * share * (s[c] / n as f64 - mean[c]).powi(2);
            }
        }
        spread.map(|v| v * filled as f64 / (filled as f64 - 1.0))
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

    /// The count of a range's indices in each replicate is the count of `replicate_of` over it,
    /// for ranges starting and ending anywhere in a run or a cycle.
    #[test]
    fn samples_in_counts_each_replicates_indices_of_any_range() {
        for start in [0u64, 1, 3, 5, 15, 16, 17, 61, 1 << 31, u64::from(u32::MAX) - 40] {
            for len in [0u64, 1, 2, 3, 4, 7, 16, 17, 33, 40] {
                for r in 0..REPLICATES {
                    let direct = (start..start + len).filter(|&s| replicate_of(s) == r).count() as u64;
                    assert_eq!(samples_in(start, len, r), direct, "{start}..+{len}, replicate {r}");
                }
            }
        }
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
