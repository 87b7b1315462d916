//! What the statistics estimate: each pixel's mean (with the glint solved into it), the variance
//! of that mean, and the image's relative error.

use illum_image::RgbImage32;
// The epsilon of `illum_image::metrics::rel_mse` itself, so that the estimated and the measured
// relMSE are the same quantity.
use illum_image::metrics::REL_MSE_EPSILON;

use super::Accumulator;

impl Accumulator {
    /// The pixel's estimate: the mean of its samples, plus the glint solved into it once it has
    /// a sample (0 before).
    pub fn pixel_mean(&self, pixel: usize) -> [f64; 3] {
        let n = self.count[pixel];
        let mean = self.sum[pixel].map(|s| s / n.max(1) as f64);
        match self.glint.binary_search_by_key(&pixel, |g| g.0) {
            Ok(i) if n > 0 => [0, 1, 2].map(|c| mean[c] + self.glint[i].1[c]),
            _ => mean,
        }
    }

    /// Variance of the pixel's mean, per channel: from the spread of the replicate means when
    /// replicates are kept (low-discrepancy), else sample variance / n; infinite with < 2 samples
    /// (or < 2 replicates).
    pub fn pixel_variance_of_mean(&self, pixel: usize) -> [f64; 3] {
        match &self.replicates {
            Some(replicates) => replicates.variance_of_mean(pixel),
            None => self.pixel_sample_variance_over_n(pixel),
        }
    }

    /// The sample variance over n per channel, s^2 / n, whatever the sequence (the variance of
    /// the mean for independent samples; for the low-discrepancy sequence an overestimate, used
    /// where the per-sample spread is wanted: adaptive sampling's pilot). Infinite with < 2 samples.
    pub fn pixel_sample_variance_over_n(&self, pixel: usize) -> [f64; 3] {
        let n = self.count[pixel] as f64;
        if n < 2.0 {
            return [f64::INFINITY; 3];
        }
        let mut out = [0.0; 3];
        for (c, value) in out.iter_mut().enumerate() {
            let mean = self.sum[pixel][c] / n;
            // Unbiased sample variance; clamp the rounding residue of a constant pixel at zero.
            let variance = ((self.sum_sq[pixel][c] - n * mean * mean) / (n - 1.0)).max(0.0);
            *value = variance / n;
        }
        out
    }

    pub fn mean_image(&self) -> RgbImage32 {
        let mut image = RgbImage32::new(self.width, self.height);
        for (p, px) in image.pixels.iter_mut().enumerate() {
            // A mean beyond f32's range (a light near f32::MAX seen through noise) is stored as
            // f32::MAX rather than infinity: EXR and PNG hold f32 at most.
            *px = self.pixel_mean(p).map(|v| v.min(f32::MAX as f64) as f32);
        }
        image
    }

    /// Per-pixel variance of the mean, as an image (for Z-tests and the viewer's error view).
    pub fn variance_image(&self) -> RgbImage32 {
        let mut image = RgbImage32::new(self.width, self.height);
        for (p, px) in image.pixels.iter_mut().enumerate() {
            *px = self.pixel_variance_of_mean(p).map(|v| v as f32);
        }
        image
    }

    /// The relMSE of the current mean image against the (unknown) converged image, estimated from
    /// the per-pixel variance alone: mean over pixels and channels of Var(mean) / (mean^2 + eps).
    /// This is the expectation of `rel_mse(mean, truth)` when the estimator is unbiased.
    pub fn estimated_rel_mse(&self) -> f64 {
        if !self.estimates_error {
            return f64::INFINITY;
        }
        let mut total = 0.0;
        let mut terms = 0usize;
        for p in 0..self.count.len() {
            let mean = self.pixel_mean(p);
            let var = self.pixel_variance_of_mean(p);
            for c in 0..3 {
                total += var[c] / (mean[c] * mean[c] + REL_MSE_EPSILON);
                terms += 1;
            }
        }
        if terms == 0 { f64::INFINITY } else { total / terms as f64 }
    }

    /// Samples per pixel from which [`Self::estimated_rel_mse`] is finite: 2 for independent
    /// samples (a sample variance needs two), and for a low-discrepancy render two replicates'
    /// runs (its variance comes from the spread of the replicates' means, and the first
    /// `REPLICATE_RUN` samples all go to one replicate; a range starts on a chunk, which starts
    /// a run of replicate 0).
    pub fn spp_for_error_estimate(&self) -> u32 {
        if self.replicates.is_some() { 2 * crate::replicates::REPLICATE_RUN } else { 2 }
    }

    /// Relative standard error of the image: the square root of [`Self::estimated_rel_mse`].
    pub fn estimated_relative_error(&self) -> f64 {
        self.estimated_rel_mse().sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_glint_adds_to_the_mean_of_sampled_pixels_and_to_nothing_else() {
        let mut acc = Accumulator::new(3, 1);
        acc.set_glint(&[(1, [5.0, 6.0, 7.0]), (1, [1.0, 1.0, 1.0])]).unwrap();
        assert_eq!(acc.glint(), &[(1, [6.0, 7.0, 8.0])], "entries of one pixel add");
        assert_eq!(acc.pixel_mean(1), [0.0; 3], "no sample yet: no glint");
        let sums = [[2.0, 2.0, 2.0, 2.0]; 3];
        let squares = [[2.0, 2.0, 2.0, 0.0]; 3];
        acc.fold(0, &sums, &squares);
        assert_eq!(acc.pixel_mean(0), [1.0; 3]);
        assert_eq!(acc.pixel_mean(1), [7.0, 8.0, 9.0]);
        assert_eq!(acc.pixel_variance_of_mean(1), acc.pixel_variance_of_mean(0), "no variance of its own");
        assert_eq!(acc.pixel_sum(1), [2.0; 3], "the statistics hold the samples alone");
        acc.reset();
        acc.fold(0, &sums, &squares);
        assert_eq!(acc.pixel_mean(1), [7.0, 8.0, 9.0], "kept across a reset");
        assert!(acc.set_glint(&[(3, [1.0; 3])]).unwrap_err().contains("outside the 3 x 1 image"));
    }

    #[test]
    fn single_sample_has_unknown_variance() {
        let mut acc = Accumulator::new(1, 1);
        acc.fold(0, &[[1.0, 1.0, 1.0, 1.0]], &[[1.0, 1.0, 1.0, 0.0]]);
        assert!(acc.pixel_variance_of_mean(0)[0].is_infinite());
    }
}
