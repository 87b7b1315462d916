//! Per-pixel statistics folded in f64.
//!
//! The GPU returns, per pixel and batch, the f32 sum and sum of squares of its finite samples, the
//! number of finite samples, and the number of dropped (NaN/Inf) ones. Folding those batch sums in
//! f64 keeps 10^6 spp free of drift: f32 only ever sums one short batch.
//!
//! This file holds the statistics and their fold; what they estimate (means, variances, the
//! relative error) is `accumulator/estimates.rs`, the radiance scale the fold undoes
//! `accumulator/radiance_scale.rs`, and the host memory a render needs
//! `accumulator/host_memory.rs`.

mod estimates;
mod exact_slot;
mod host_memory;
mod parts;
mod radiance_scale;

use exact_slot::ExactSlot;
pub use exact_slot::StopFlag;
pub use host_memory::{
    ALIGNED_COPY_BYTES_PER_PIXEL, RENDER_HOST_BYTES_PER_PIXEL, STATISTICS_BYTES_PER_PIXEL,
    available_host_memory, check_host_memory,
};
pub use parts::{ExactPart, ImageParts};
pub use radiance_scale::{UNSCALED_RADIANCE_LIMIT, radiance_exponent};

use crate::replicates::Replicates;

#[derive(Clone, Debug)]
pub struct Accumulator {
    pub width: u32,
    pub height: u32,
    sum: Vec<[f64; 3]>,
    sum_sq: Vec<[f64; 3]>,
    count: Vec<u64>,
    /// Sum of `count`, kept as batches are folded so that reading it does not cost a pass over
    /// the image (progress reports read it after every band).
    total: u64,
    dropped: u64,
    /// 2^k: what the GPU's values are multiplied by when folded (see [`radiance_exponent`]).
    sum_scale: f64,
    /// Per-replicate sums of a low-discrepancy render (see `replicates.rs`): when present, the
    /// variance of each pixel's mean comes from their spread instead of s^2 / n.
    replicates: Option<Replicates>,
    /// The image's exact part (the sun's glint, `glint.rs`), joined to the sampled means by
    /// [`ImageParts`] alone. Solved exactly, it has no variance: the statistics, the error
    /// estimate and the checkpoints' statistics layers hold the samples alone. It may still be
    /// being solved (see `exact_slot.rs`): [`Self::exact`] waits for it.
    exact: ExactSlot,
    /// False for samples whose error the statistics cannot estimate (the low-discrepancy
    /// sequence without replicates: its per-sample spread overstates it, by 2 to 5 times):
    /// the estimate is then infinite, and the front ends say "not estimated".
    estimates_error: bool,
}

impl Accumulator {
    pub fn new(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        Self::from_state(width, height, vec![[0.0; 3]; n], vec![[0.0; 3]; n], vec![0; n], 0)
            .expect("n entries each, as from_state checks")
    }

    /// As [`Self::new`], but reports the bytes it needed instead of aborting when the host cannot
    /// allocate them (a very large image: 56 bytes per pixel).
    pub fn try_new(width: u32, height: u32) -> Result<Self, u64> {
        let n = width as usize * height as usize;
        let bytes = n as u64 * STATISTICS_BYTES_PER_PIXEL;
        let mut sum = Vec::new();
        let mut sum_sq = Vec::new();
        let mut count = Vec::new();
        sum.try_reserve_exact(n).map_err(|_| bytes)?;
        sum_sq.try_reserve_exact(n).map_err(|_| bytes)?;
        count.try_reserve_exact(n).map_err(|_| bytes)?;
        sum.resize(n, [0.0; 3]);
        sum_sq.resize(n, [0.0; 3]);
        count.resize(n, 0);
        Ok(Self::from_state(width, height, sum, sum_sq, count, 0)
            .expect("n entries each, as from_state checks"))
    }

    /// Folds from now on values the GPU computed with radiance scaled by 2^-`exponent` (see
    /// [`radiance_exponent`]): sums are multiplied by 2^k, sums of squares by 2^(2k).
    pub fn set_radiance_exponent(&mut self, exponent: i32) {
        self.sum_scale = 2f64.powi(exponent);
    }

    /// The exact state, for checkpoints (see `checkpoint.rs`): per pixel the sum and sum of
    /// squares of its finite samples (f64, unscaled) and their count, plus the dropped total.
    pub fn state(&self) -> AccumulatorState<'_> {
        AccumulatorState { sum: &self.sum, sum_sq: &self.sum_sq, count: &self.count, dropped: self.dropped }
    }

    /// Rebuilds an accumulator from a saved state (its vectors must have `width x height`
    /// entries). The running total is recomputed; folding goes on exactly where it stopped.
    pub fn from_state(
        width: u32,
        height: u32,
        sum: Vec<[f64; 3]>,
        sum_sq: Vec<[f64; 3]>,
        count: Vec<u64>,
        dropped: u64,
    ) -> Result<Self, String> {
        let n = width as usize * height as usize;
        if sum.len() != n || sum_sq.len() != n || count.len() != n {
            return Err(format!(
                "the statistics have {} / {} / {} entries for a {width} x {height} image ({n} pixels)",
                sum.len(),
                sum_sq.len(),
                count.len()
            ));
        }
        let total = count.iter().sum();
        Ok(Self {
            width,
            height,
            sum,
            sum_sq,
            count,
            total,
            dropped,
            sum_scale: 1.0,
            replicates: None,
            exact: ExactSlot::Ready(ExactPart::default()),
            estimates_error: true,
        })
    }

    /// Keeps per-replicate sums from now on (a low-discrepancy render, see `replicates.rs`); the
    /// accumulator must be empty. Fold its slots with [`Self::fold_slots`].
    pub fn enable_replicates(&mut self) {
        debug_assert_eq!(self.total, 0, "replicates enabled on a started accumulator");
        self.replicates = Some(Replicates::new(self.count.len()));
    }

    /// Says whether the statistics estimate their error (see `estimates_error`, and
    /// [`crate::TracerOptions::estimates_error`], which the tracer sets it from).
    pub fn set_estimates_error(&mut self, estimates_error: bool) {
        self.estimates_error = estimates_error;
    }

    /// Whether [`Self::estimated_rel_mse`] estimates anything (else it is infinite).
    pub fn estimates_error(&self) -> bool {
        self.estimates_error
    }

    /// Sets the per-replicate sums (a checkpoint's); `None`: independent samples.
    pub fn set_replicates(&mut self, replicates: Option<Replicates>) -> Result<(), String> {
        if let Some(r) = &replicates
            && r.pixels() != self.count.len()
        {
            return Err(format!(
                "the replicate statistics have {} pixels for a {} x {} image",
                r.pixels(),
                self.width,
                self.height
            ));
        }
        self.replicates = replicates;
        Ok(())
    }

    /// The per-replicate sums, when kept.
    pub fn replicates(&self) -> Option<&Replicates> {
        self.replicates.as_ref()
    }

    /// [`Self::fold`] for one layer of slots (`batch::Layers`): with replicates kept, its sums
    /// also go to `replicate`, the replicate whose samples the layer holds.
    pub fn fold_slots(
        &mut self,
        first_pixel: usize,
        replicate: Option<usize>,
        sums: &[[f32; 4]],
        sums_sq: &[[f32; 4]],
    ) {
        debug_assert!(
            self.replicates.is_none() || replicate.is_some(),
            "replicates kept, but a slot of none"
        );
        self.fold(first_pixel, sums, sums_sq);
        let scale = self.sum_scale;
        if let (Some(replicates), Some(replicate)) = (&mut self.replicates, replicate) {
            for (i, s) in sums.iter().enumerate() {
                if s[3] > 0.0 {
                    let sum = [s[0] as f64 * scale, s[1] as f64 * scale, s[2] as f64 * scale];
                    replicates.add(first_pixel + i, replicate, sum, s[3] as u64);
                }
            }
        }
    }

    /// Adds another accumulator's samples of the same image (a disjoint set of sample indices:
    /// see the `merge` example), pixel by pixel in f64.
    pub fn merge(&mut self, other: &Accumulator) {
        assert_eq!(
            (self.width, self.height),
            (other.width, other.height),
            "merging images of different sizes"
        );
        for p in 0..self.count.len() {
            for c in 0..3 {
                self.sum[p][c] += other.sum[p][c];
                self.sum_sq[p][c] += other.sum_sq[p][c];
            }
            self.count[p] += other.count[p];
        }
        self.total += other.total;
        self.dropped += other.dropped;
        self.estimates_error &= other.estimates_error;
        // Replicates add only when both sides kept them (a merge refuses mixed sequences first).
        match (&mut self.replicates, &other.replicates) {
            (Some(a), Some(b)) => a.merge(b),
            _ => self.replicates = None,
        }
    }

    /// Folds one batch for consecutive pixels starting at `first_pixel`. `sums[i]` is (sum, finite
    /// count), `sums_sq[i]` is (sum of squares, dropped count), as the shader writes them.
    pub fn fold(&mut self, first_pixel: usize, sums: &[[f32; 4]], sums_sq: &[[f32; 4]]) {
        // With scale 1 (every scene whose lights are below 2^16) the products are exact no-ops.
        let scale = self.sum_scale;
        let scale_sq = scale * scale;
        for (i, (s, q)) in sums.iter().zip(sums_sq).enumerate() {
            let p = first_pixel + i;
            for c in 0..3 {
                self.sum[p][c] += s[c] as f64 * scale;
                self.sum_sq[p][c] += q[c] as f64 * scale_sq;
            }
            self.count[p] += s[3] as u64;
            self.total += s[3] as u64;
            self.dropped += q[3] as u64;
        }
    }

    /// Folds, beside a camera chunk just folded with [`Self::fold`] (`camera`: its sums as the
    /// shader wrote them), a second, independent estimator's values for the same samples: per
    /// pixel the true-radiance sum `sum` and sum of squares `sum_sq` of its `frames` values,
    /// one per sample index of the chunk (the caustic's light tracer, `tracer/caustic.rs`).
    /// Sample k of the pixel is then c_k + s_k: the sums gain S1 and the sums of squares
    /// S2 + 2 C S1 / n (C the camera sum of n samples), whose expectation is that of the paired
    /// sum of (c_k + s_k)^2 since the two are independent; so the sample variance estimates
    /// var(c) + var(s). When some camera samples of the chunk were dropped (n < frames), S1
    /// and S2 are scaled by n / frames, the expected share of the kept samples. With replicates
    /// kept, S1 joins `replicate`, the camera layer's: frame k pairs with sample k, and the
    /// caustic's sampler deals frames to replicates as the camera's.
    pub fn fold_independent(
        &mut self,
        first_pixel: usize,
        replicate: Option<usize>,
        camera: &[[f32; 4]],
        sum: &[[f64; 3]],
        sum_sq: &[[f64; 3]],
        frames: u32,
    ) {
        if frames == 0 {
            return;
        }
        let scale = self.sum_scale;
        let frames = f64::from(frames);
        for (i, chunk) in camera.iter().enumerate() {
            let n = f64::from(chunk[3]);
            if n == 0.0 {
                continue;
            }
            let p = first_pixel + i;
            let share = n / frames;
            for c in 0..3 {
                self.sum[p][c] += sum[i][c] * share;
                self.sum_sq[p][c] +=
                    sum_sq[i][c] * share + 2.0 * f64::from(chunk[c]) * scale * sum[i][c] / frames;
            }
            if let (Some(replicates), Some(replicate)) = (&mut self.replicates, replicate) {
                replicates.add_values(p, replicate, sum[i].map(|v| v * share));
            }
        }
    }

    /// Counts `n` more dropped values (the caustic's particles too bright for its fixed point).
    pub fn add_dropped(&mut self, n: u64) {
        self.dropped += n;
    }

    /// Samples dropped because they were NaN or Inf.
    pub fn dropped_samples(&self) -> u64 {
        self.dropped
    }

    /// Finite samples in the pixel with the fewest (the spp every pixel has reached).
    pub fn min_samples(&self) -> u64 {
        self.count.iter().copied().min().unwrap_or(0)
    }

    /// Finite samples over all pixels (kept as a running total: constant time).
    pub fn total_samples(&self) -> u64 {
        self.total
    }

    /// Sum of the pixel's finite samples, per channel.
    pub fn pixel_sum(&self, pixel: usize) -> [f64; 3] {
        self.sum[pixel]
    }

    /// Finite samples in the pixel.
    pub fn pixel_count(&self, pixel: usize) -> u64 {
        self.count[pixel]
    }

    /// Sets the image's exact part (see [`ImageParts`]); it stays across [`Self::reset`].
    pub fn set_exact(&mut self, exact: ExactPart) {
        debug_assert!(
            exact.entries().last().is_none_or(|e| e.0 < self.count.len()),
            "built for another size"
        );
        self.exact = ExactSlot::Ready(exact);
    }

    /// Sets the image's exact part to what `solve` returns, solved on a thread of its own
    /// (inline where there are none), so that sampling starts without waiting for it: the first
    /// reader of [`Self::exact`] (or of an image) waits instead. `solve` may stop early once its
    /// flag is set: the part was replaced or dropped unread. It must return a part of this
    /// accumulator's size.
    pub fn set_exact_solving(&mut self, solve: impl FnOnce(&StopFlag) -> ExactPart + Send + 'static) {
        self.exact = ExactSlot::solving(solve);
    }

    /// The image's exact part, all of it (see [`ImageParts::shown_exact`] for the part an image
    /// shows), once solved: the first call after [`Self::set_exact_solving`] waits for the solve.
    pub fn exact(&self) -> &ExactPart {
        self.exact.get()
    }

    /// Whether [`Self::exact`] would return without waiting for a solve: a front end that must
    /// not stall (a viewer's frame) shows the samples alone until then, and the error estimate,
    /// relative to the whole image, is unknown until then ([`crate::Progressive`]).
    pub fn exact_solved(&self) -> bool {
        self.exact.is_ready()
    }

    /// The image as its sampled and exact parts: the view every consumer takes.
    pub fn parts(&self) -> ImageParts<'_> {
        ImageParts::of(self)
    }

    /// Starts over (same size and radiance scale). Zeroes the statistics in place: fresh
    /// vectors would come from the system as untouched pages, and the first fold after a reset
    /// (a viewer's camera move) would pay a page fault per 4 KiB of statistics.
    pub fn reset(&mut self) {
        self.sum.fill([0.0; 3]);
        self.sum_sq.fill([0.0; 3]);
        self.count.fill(0);
        self.total = 0;
        self.dropped = 0;
        if let Some(replicates) = &mut self.replicates {
            replicates.reset();
        }
    }
}

/// A borrowed view of an [`Accumulator`]'s exact state (see [`Accumulator::state`]).
#[derive(Clone, Copy, Debug)]
pub struct AccumulatorState<'a> {
    pub sum: &'a [[f64; 3]],
    pub sum_sq: &'a [[f64; 3]],
    pub count: &'a [u64],
    pub dropped: u64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fold_matches_direct_f64_statistics() {
        // Two batches of known samples for one pixel: 1, 2, 3 then 4, 5.
        let mut acc = Accumulator::new(1, 1);
        acc.fold(0, &[[6.0, 6.0, 6.0, 3.0]], &[[14.0, 14.0, 14.0, 0.0]]);
        acc.fold(0, &[[9.0, 9.0, 9.0, 2.0]], &[[41.0, 41.0, 41.0, 1.0]]);
        assert_eq!(acc.min_samples(), 5);
        assert_eq!(acc.total_samples(), 5);
        assert_eq!(acc.dropped_samples(), 1);
        assert_eq!(acc.pixel_mean(0), [3.0; 3]);
        // Sample variance of 1..5 is 2.5; of the mean, 2.5 / 5 = 0.5.
        let v = acc.pixel_variance_of_mean(0);
        assert!((v[0] - 0.5).abs() < 1e-12, "{v:?}");
    }

    #[test]
    fn reset_starts_over_and_keeps_the_radiance_scale() {
        let mut acc = Accumulator::new(2, 1);
        acc.set_radiance_exponent(3);
        acc.fold(
            0,
            &[[1.0, 1.0, 1.0, 1.0], [2.0, 2.0, 2.0, 1.0]],
            &[[1.0, 1.0, 1.0, 1.0], [4.0, 4.0, 4.0, 0.0]],
        );
        acc.reset();
        let state = acc.state();
        assert!(state.sum.iter().chain(state.sum_sq).all(|v| *v == [0.0; 3]));
        assert!(state.count.iter().all(|&c| c == 0));
        assert_eq!((acc.total_samples(), acc.dropped_samples()), (0, 0));
        // Still scaled by 2^3 after the reset: one sample of 1 folds to a mean of 8.
        acc.fold(0, &[[1.0, 1.0, 1.0, 1.0]], &[[1.0, 1.0, 1.0, 0.0]]);
        assert_eq!(acc.pixel_mean(0), [8.0; 3]);
    }

    #[test]
    fn state_round_trips_and_merges_add() {
        let mut a = Accumulator::new(2, 1);
        a.fold(
            0,
            &[[1.0, 2.0, 3.0, 2.0], [4.0, 5.0, 6.0, 2.0]],
            &[[1.0, 4.0, 9.0, 0.0], [16.0, 25.0, 36.0, 1.0]],
        );
        let s = a.state();
        let b = Accumulator::from_state(2, 1, s.sum.to_vec(), s.sum_sq.to_vec(), s.count.to_vec(), s.dropped)
            .unwrap();
        assert_eq!(b.total_samples(), 4);
        assert_eq!(b.dropped_samples(), 1);
        assert_eq!(b.pixel_sum(1), [4.0, 5.0, 6.0]);
        let mut c = b.clone();
        c.merge(&a);
        assert_eq!(c.pixel_sum(0), [2.0, 4.0, 6.0]);
        assert_eq!(c.pixel_count(1), 4);
        assert!(Accumulator::from_state(3, 1, vec![], vec![], vec![], 0).unwrap_err().contains("3 x 1"));
    }
}
