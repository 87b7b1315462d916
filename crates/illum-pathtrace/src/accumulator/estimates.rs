//! What the statistics estimate: each pixel's mean (with the image's exact part, `parts.rs`), the
//! variance of that mean, and the image's relative error.

use illum_image::RgbImage32;
// The epsilon of `illum_image::metrics::rel_mse` itself, so that the estimated and the measured
// relMSE are the same quantity.
use illum_image::metrics::REL_MSE_EPSILON;

use super::Accumulator;

impl Accumulator {
    /// The pixel's estimate ([`super::ImageParts::pixel_mean`]).
    pub fn pixel_mean(&self, pixel: usize) -> [f64; 3] {
        self.parts().pixel_mean(pixel)
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

    /// The whole image ([`super::ImageParts::mean`]).
    pub fn mean_image(&self) -> RgbImage32 {
        self.parts().mean()
    }

    /// Per-pixel variance of the mean, as an image (for Z-tests and the viewer's error view).
    pub fn variance_image(&self) -> RgbImage32 {
        self.parts().variance()
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
    fn single_sample_has_unknown_variance() {
        let mut acc = Accumulator::new(1, 1);
        acc.fold(0, &[[1.0, 1.0, 1.0, 1.0]], &[[1.0, 1.0, 1.0, 0.0]]);
        assert!(acc.pixel_variance_of_mean(0)[0].is_infinite());
    }
}
