//! The error of a denoised image without a reference, from two independent halves A and B of
//! its samples: for a denoiser D applied to A, and B unbiased and independent of A,
//!     E (D(A) - B)^2 = E (D(A) - I)^2 + Var(B),
//! with I the converged image, pixel by pixel: the squared difference from the other half, less
//! that half's variance, is an unbiased estimate of D(A)'s mean squared error, bias included.
//! Var(B) comes from B's own sample variance (`Accumulator::pixel_variance_of_mean`), so each
//! half needs 2 samples: below that the estimate is infinite (unknown), as the raw image's is
//! below 2 spp. Both halves swap roles and the two estimates are averaged.
//!
//! The relMSE divides each pixel's term by (I^2 + 1e-2) (`illum_image::metrics::rel_mse`), and
//! I is unknown; the estimate divides by (den^2 + 1e-2) with den = max(raw mean of both halves,
//! denoised whole), per channel. Why not the raw mean alone: it contains B, so it is
//! correlated with the term's numerator. Where B's few samples all missed a bright light, B is
//! dark, its sample variance is 0 (nothing to subtract) and (D(A) - B)^2 is large; the raw mean
//! is then dark too, and its 1/den^2 multiplies exactly those large terms (up to a hundredfold
//! at a light's edge), while the pixels where B hit the light, whose large variance would
//! cancel them on average, are divided by a bright mean. The numerator is unbiased; the weight
//! is not independent of it. A denoiser that restores such pixels (Open Image Denoise) made
//! the estimate 3 to 13 times its true error below 64 spp that way; with the reference's
//! values as the denominator the same numerators were within 0.78 to 1.25 of it. The denoised
//! whole is the best estimate of I that a render has where the filter works, and hardly moves
//! with one half's pixel; the raw mean stays as the floor, because where a filter darkens a
//! pixel that truly is bright (à-trous at a light's edge) the denoised value alone would
//! inflate that pixel's term a hundredfold. The maximum is never below the raw mean, so a term
//! is never larger than with the raw mean alone; its cost is a slight upward bias of den where
//! both agree within the raw mean's noise. docs/denoising.md has the measured ratios for both
//! denoisers from 4 to 1024 spp.
//!
//! What it estimates is the error of a denoised half. The image a render writes is the
//! denoised whole, from twice the samples, whose error is lower: the estimate is conservative
//! for it (docs/denoising.md has the measured ratio).

use illum_image::RgbImage32;
use illum_image::metrics::REL_MSE_EPSILON;

/// The halves' estimate of a denoised image's relMSE.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HalvesError {
    /// Estimated relMSE of a denoised half (mean of the two directions); may come out slightly
    /// negative by chance when the true value is near 0; infinite below 2 samples per half.
    pub rel_mse: f64,
}

impl HalvesError {
    /// The estimate from the two halves' mean images `a`, `b`, their variances of the mean per
    /// channel (`var_a`, `var_b`: infinite where a pixel had fewer than 2 samples), their
    /// denoised images `da`, `db`, and the denoised image of both halves merged, `whole`.
    pub fn new(
        (a, var_a, da): (&RgbImage32, &RgbImage32, &RgbImage32),
        (b, var_b, db): (&RgbImage32, &RgbImage32, &RgbImage32),
        whole: &RgbImage32,
    ) -> Self {
        let den = RgbImage32 {
            width: a.width,
            height: a.height,
            pixels: a
                .pixels
                .iter()
                .zip(&b.pixels)
                .zip(&whole.pixels)
                .map(|((x, y), d)| [0, 1, 2].map(|c| (0.5 * (x[c] + y[c])).max(d[c])))
                .collect(),
        };
        let forward = halves_rel_mse(da, b, var_b, &den);
        let backward = halves_rel_mse(db, a, var_a, &den);
        HalvesError { rel_mse: 0.5 * (forward + backward) }
    }

    /// The estimated relative error, sqrt(max(relMSE, 0)): the quantity
    /// `illum.estimated_relative_error` and `--target-error` use.
    pub fn relative_error(&self) -> f64 {
        self.rel_mse.max(0.0).sqrt()
    }
}

/// One direction: the estimated relMSE of `denoised` against the independent half `other`
/// with variances of the mean `other_variance`, relative to `den`. Infinite where a variance
/// is (fewer than 2 samples).
pub fn halves_rel_mse(
    denoised: &RgbImage32,
    other: &RgbImage32,
    other_variance: &RgbImage32,
    den: &RgbImage32,
) -> f64 {
    let mut total = 0.0;
    for p in 0..denoised.pixels.len() {
        for c in 0..3 {
            let d = f64::from(denoised.pixels[p][c]);
            let b = f64::from(other.pixels[p][c]);
            let v = f64::from(other_variance.pixels[p][c]);
            if !v.is_finite() {
                return f64::INFINITY;
            }
            let r = f64::from(den.pixels[p][c]);
            total += ((d - b).powi(2) - v) / (r * r + REL_MSE_EPSILON);
        }
    }
    total / (3 * denoised.pixels.len().max(1)) as f64
}
