//! Image error metrics against a reference, and the per-pixel Z-test.
//!
//! All sums are taken in f64. Every metric requires images of the same, non-zero size.
//! Non-finite pixel values are not filtered: they make RMSE / relMSE / bias NaN or infinite,
//! which is the honest answer (check [`RgbImage32::has_non_finite`] first if that matters);
//! in the Z-test a non-finite mean fails its pixel.

use crate::rgb_image::RgbImage32;

/// Why a metric could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MetricsError {
    #[error(
        "{what} is {}x{} but {against} is {}x{}; the images must have the same size",
        size.0, size.1, expected.0, expected.1
    )]
    SizeMismatch { what: &'static str, size: (u32, u32), against: &'static str, expected: (u32, u32) },
    #[error("{what} is {width}x{height} but holds {len} pixels (width * height expected)")]
    Inconsistent { what: &'static str, width: u32, height: u32, len: usize },
    #[error("{what} is empty ({width}x{height}); metrics need at least one pixel")]
    Empty { what: &'static str, width: u32, height: u32 },
    #[error("significance level alpha = {0} is outside the open interval (0, 1)")]
    InvalidAlpha(f64),
    #[error("the reference's mean luminance is {0}; a relative bias needs a positive, finite reference")]
    DegenerateReference(f64),
}

fn check_image(what: &'static str, img: &RgbImage32) -> Result<(), MetricsError> {
    if !img.is_consistent() {
        return Err(MetricsError::Inconsistent {
            what,
            width: img.width,
            height: img.height,
            len: img.pixels.len(),
        });
    }
    if img.pixels.is_empty() {
        return Err(MetricsError::Empty { what, width: img.width, height: img.height });
    }
    Ok(())
}

/// Checks that every image is consistent, non-empty and the size of the first one.
fn check_same_size(images: &[(&'static str, &RgbImage32)]) -> Result<(), MetricsError> {
    let (first_name, first) = images[0];
    for &(what, img) in images {
        check_image(what, img)?;
        if (img.width, img.height) != (first.width, first.height) {
            return Err(MetricsError::SizeMismatch {
                what,
                size: (img.width, img.height),
                against: first_name,
                expected: (first.width, first.height),
            });
        }
    }
    Ok(())
}

/// Mean over all pixels and channels of `f(a, r)`.
fn mean_over_channels(a: &RgbImage32, r: &RgbImage32, f: impl Fn(f64, f64) -> f64) -> f64 {
    let sum: f64 = a
        .pixels
        .iter()
        .zip(&r.pixels)
        .flat_map(|(pa, pr)| (0..3).map(move |c| (f64::from(pa[c]), f64::from(pr[c]))))
        .map(|(x, y)| f(x, y))
        .sum();
    sum / (3 * a.pixels.len()) as f64
}

/// Root-mean-square error over all pixels and all three channels:
/// `sqrt(mean((a - r)^2))`.
pub fn rmse(image: &RgbImage32, reference: &RgbImage32) -> Result<f64, MetricsError> {
    check_same_size(&[("the reference", reference), ("the image", image)])?;
    Ok(mean_over_channels(image, reference, |a, r| (a - r) * (a - r)).sqrt())
}

/// The epsilon in the denominator of [`rel_mse`].
pub const REL_MSE_EPSILON: f64 = 1e-2;

/// Relative mean squared error as used by pbrt and Mitsuba for convergence plots:
/// the mean over pixels and channels of `(a - r)^2 / (r^2 + 1e-2)`.
///
/// Dividing by `r^2` makes the error scale-invariant, so dark and bright regions count
/// alike; the epsilon `1e-2` ([`REL_MSE_EPSILON`]) keeps black reference pixels from
/// dominating (there the metric degrades to 100 times the absolute squared error).
pub fn rel_mse(image: &RgbImage32, reference: &RgbImage32) -> Result<f64, MetricsError> {
    check_same_size(&[("the reference", reference), ("the image", image)])?;
    Ok(mean_over_channels(image, reference, |a, r| (a - r) * (a - r) / (r * r + REL_MSE_EPSILON)))
}

/// Relative bias of the mean luminance:
/// `(meanlum(image) - meanlum(reference)) / meanlum(reference)`.
/// An unbiased estimator gives a value that shrinks towards 0 as samples are added; a
/// biased one (a missing light path, energy gain) converges to a non-zero value.
pub fn mean_luminance_bias(image: &RgbImage32, reference: &RgbImage32) -> Result<f64, MetricsError> {
    check_same_size(&[("the reference", reference), ("the image", image)])?;
    let lr = reference.mean_luminance();
    if !(lr.is_finite() && lr > 0.0) {
        return Err(MetricsError::DegenerateReference(lr));
    }
    Ok((image.mean_luminance() - lr) / lr)
}

/// The per-pixel two-sample Z-test, the statistical image comparison Mitsuba's test suite
/// uses: are two Monte Carlo estimates of the same picture consistent with each other given
/// their estimated variances?
///
/// Inputs are per-pixel per-channel means and the *variance of each mean* (the sample
/// variance divided by the number of samples, not the per-sample variance). For each channel
/// `z = (a - b) / sqrt(va + vb)`, standard normal under the hypothesis that both estimate
/// the same value (central limit theorem). A channel passes the two-sided test at level
/// `alpha / 3` when `|z| <= Φ⁻¹(1 - alpha/6)`; a pixel passes when all three of its channels
/// pass. By the Bonferroni inequality the chance that a pixel of two consistent images fails
/// is then at most `alpha`, so consistent images pass on at least about `1 - alpha` of their
/// pixels.
///
/// Special cases: where `va + vb == 0` (e.g. pixels that see only the background) the
/// channel passes only if `|a - b| <= 1e-6 max(|a|, |b|)`; a non-finite mean or a NaN
/// variance fails; a slightly negative variance (round-off in `E[x²] - E[x]²`) counts as 0.
///
/// Returns the fraction of pixels that pass, in [0, 1].
pub fn z_test_pass_fraction(
    mean_a: &RgbImage32,
    var_a_of_mean: &RgbImage32,
    mean_b: &RgbImage32,
    var_b_of_mean: &RgbImage32,
    alpha: f64,
) -> Result<f64, MetricsError> {
    check_same_size(&[
        ("mean_a", mean_a),
        ("var_a_of_mean", var_a_of_mean),
        ("mean_b", mean_b),
        ("var_b_of_mean", var_b_of_mean),
    ])?;
    if !(alpha > 0.0 && alpha < 1.0) {
        return Err(MetricsError::InvalidAlpha(alpha));
    }
    // Two-sided per-channel level alpha/3 puts alpha/6 in each tail.
    let z_critical = inverse_normal_cdf(1.0 - alpha / 6.0);

    let channel_passes = |a: f32, va: f32, b: f32, vb: f32| -> bool {
        let (a, b, va, vb) = (f64::from(a), f64::from(b), f64::from(va), f64::from(vb));
        if !a.is_finite() || !b.is_finite() || va.is_nan() || vb.is_nan() {
            return false;
        }
        let v = va.max(0.0) + vb.max(0.0);
        let d = (a - b).abs();
        if v == 0.0 {
            return d <= 1e-6 * a.abs().max(b.abs());
        }
        d / v.sqrt() <= z_critical
    };

    let passed = (0..mean_a.pixels.len())
        .filter(|&i| {
            let (a, va) = (mean_a.pixels[i], var_a_of_mean.pixels[i]);
            let (b, vb) = (mean_b.pixels[i], var_b_of_mean.pixels[i]);
            (0..3).all(|c| channel_passes(a[c], va[c], b[c], vb[c]))
        })
        .count();
    Ok(passed as f64 / mean_a.pixels.len() as f64)
}

/// The smallest count `k` such that a Binomial(`n`, `p`) count reaches `k` or more with
/// probability at most `alpha`: the critical count of a one-sided binomial test at level
/// `alpha`. A per-pixel test that fails a pixel of a correct image with probability at most `p`,
/// on `n` independent pixels, then fails `k` or more of them with probability at most `alpha`
/// (a count of failures at most Binomial(n, p) in distribution). Returns `n + 1` when even all
/// `n` failing is likelier than `alpha`.
///
/// The tail is summed from the top, P(K >= k) = sum over j >= k of C(n, j) p^j (1 - p)^(n - j),
/// each term from its logarithm (log-gamma), so that neither the underflow of (1 - p)^n at large
/// `n` nor the cancellation in 1 - cdf limits it.
pub fn binomial_critical_count(n: usize, p: f64, alpha: f64) -> usize {
    assert!((0.0..=1.0).contains(&p) && alpha > 0.0 && alpha < 1.0, "p = {p}, alpha = {alpha}");
    let ln_pmf = |k: usize| -> f64 {
        let (k64, n64) = (k as f64, n as f64);
        let ln_choose = ln_gamma(n64 + 1.0) - ln_gamma(k64 + 1.0) - ln_gamma(n64 - k64 + 1.0);
        let with = |count: f64, q: f64| if count == 0.0 { 0.0 } else { count * q.ln() };
        ln_choose + with(k64, p) + with(n64 - k64, 1.0 - p)
    };
    let mut tail = 0.0;
    for k in (0..=n).rev() {
        let with_k = tail + ln_pmf(k).exp();
        if with_k > alpha {
            return k + 1;
        }
        tail = with_k;
    }
    0
}

/// ln Γ(x) for x >= 1, by Stirling's series with the argument moved above 8 (absolute error
/// below 1e-12 there): enough for the binomial coefficients of [`binomial_critical_count`].
fn ln_gamma(x: f64) -> f64 {
    let mut x = x;
    let mut shift = 0.0;
    while x < 8.0 {
        shift -= x.ln();
        x += 1.0;
    }
    let inv = 1.0 / x;
    let inv2 = inv * inv;
    let series = inv * (1.0 / 12.0 - inv2 * (1.0 / 360.0 - inv2 * (1.0 / 1260.0 - inv2 / 1680.0)));
    shift + (x - 0.5) * x.ln() - x + 0.5 * (2.0 * std::f64::consts::PI).ln() + series
}

/// The standard normal quantile Φ⁻¹(p), by Peter J. Acklam's rational approximation
/// ("An algorithm for computing the inverse normal cumulative distribution function",
/// 2003): a rational function in `p - 1/2` on the central region [0.02425, 0.97575] and in
/// `sqrt(-2 ln p)` on the tails, with relative error below 1.15e-9 everywhere.
///
/// Returns -∞ for `p <= 0`, +∞ for `p >= 1` and NaN for NaN.
pub fn inverse_normal_cdf(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] =
        [7.784_695_709_041_462e-3, 3.224_671_290_700_398e-1, 2.445_134_137_142_996, 3.754_408_661_907_416];
    const P_LOW: f64 = 0.02425;

    if p.is_nan() {
        return f64::NAN;
    }
    if p <= 0.0 {
        return f64::NEG_INFINITY;
    }
    if p >= 1.0 {
        return f64::INFINITY;
    }
    // Lower tail: x(q) with q = sqrt(-2 ln p); the upper tail follows by symmetry.
    let tail = |p: f64| {
        let q = (-2.0 * p.ln()).sqrt();
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    if p < P_LOW {
        tail(p)
    } else if p <= 1.0 - P_LOW {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    } else {
        -tail(1.0 - p)
    }
}

/// The median of `values` (sorted in place): the middle value, or the mean of the two middle
/// values for an even count; NaN for an empty list. Benchmarks report it.
pub fn median(values: &mut [f64]) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    values.sort_by(f64::total_cmp);
    let mid = values.len() / 2;
    if values.len() % 2 == 1 { values[mid] } else { 0.5 * (values[mid - 1] + values[mid]) }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Asserts `|got - expected| <= tol`, naming `what` and both values when it fails.
    #[track_caller]
    fn assert_close(what: impl std::fmt::Display, got: f64, expected: f64, tol: f64) {
        assert!((got - expected).abs() <= tol, "{what}: {got}, expected {expected} within {tol}");
    }

    #[test]
    fn normal_quantiles_match_tables() {
        // (p, Φ⁻¹(p)) from standard tables.
        let known = [
            (0.5, 0.0),
            (0.975, 1.959_963_985),
            (0.995, 2.575_829_304),
            (0.841_344_746, 1.0),
            (0.01, -2.326_347_874),     // lower-tail branch
            (0.999_999, 4.753_424_309), // upper-tail branch
            (1e-10, -6.361_340_902),
        ];
        for (p, x) in known {
            let got = inverse_normal_cdf(p);
            assert_close(format!("Φ⁻¹({p})"), got, x, 1e-6 * x.abs().max(1.0));
        }
        // Symmetry Φ⁻¹(1 - p) = -Φ⁻¹(p) across branches.
        for p in [1e-5, 0.02, 0.03, 0.2, 0.4] {
            assert_close(format!("Φ⁻¹(1 - {p})"), inverse_normal_cdf(1.0 - p), -inverse_normal_cdf(p), 1e-8);
        }
        assert_eq!(inverse_normal_cdf(0.0), f64::NEG_INFINITY);
        assert_eq!(inverse_normal_cdf(1.0), f64::INFINITY);
        assert!(inverse_normal_cdf(f64::NAN).is_nan());
    }

    /// 2x1 images: a = [(1,2,3), (0,0,0)], r = [(1,1,1), (0,0,2)].
    fn pair() -> (RgbImage32, RgbImage32) {
        let a = RgbImage32 { width: 2, height: 1, pixels: vec![[1.0, 2.0, 3.0], [0.0, 0.0, 0.0]] };
        let r = RgbImage32 { width: 2, height: 1, pixels: vec![[1.0, 1.0, 1.0], [0.0, 0.0, 2.0]] };
        (a, r)
    }

    #[test]
    fn rmse_by_hand() {
        let (a, r) = pair();
        // Differences 0, 1, 2, 0, 0, -2: squares sum to 9 over 6 values.
        assert_close("rmse", rmse(&a, &r).unwrap(), 1.5f64.sqrt(), 1e-12);
        assert_eq!(rmse(&r, &r).unwrap(), 0.0);
    }

    #[test]
    fn rel_mse_by_hand() {
        let (a, r) = pair();
        // Non-zero terms: 1/(1 + 0.01), 4/(1 + 0.01), 4/(4 + 0.01); divided by 6 values.
        let expected = (1.0 / 1.01 + 4.0 / 1.01 + 4.0 / 4.01) / 6.0; // = 0.991333...
        assert_close("rel_mse", rel_mse(&a, &r).unwrap(), expected, 1e-12);
        assert_close("the relMSE worked by hand", expected, 0.991_333_6, 1e-6);
        // A black reference pixel: error 0.1 counts as 0.01 / 0.01 = 1.
        let z = RgbImage32::new(1, 1);
        let e = RgbImage32::filled(1, 1, [0.1; 3]);
        assert_close("rel_mse against zero", rel_mse(&e, &z).unwrap(), 1.0, 1e-6);
    }

    #[test]
    fn luminance_bias_by_hand() {
        let (a, r) = pair();
        // mean(a) = (0.5, 1, 1.5): Y = 0.1063 + 0.7152 + 0.1083 = 0.9298
        // mean(r) = (0.5, 0.5, 1.5): Y = 0.1063 + 0.3576 + 0.1083 = 0.5722
        let expected = (0.9298 - 0.5722) / 0.5722;
        assert_close("mean_luminance_bias", mean_luminance_bias(&a, &r).unwrap(), expected, 1e-12);
        let black = RgbImage32::new(2, 1);
        assert_eq!(mean_luminance_bias(&a, &black), Err(MetricsError::DegenerateReference(0.0)));
    }

    #[test]
    fn size_mismatch_and_empty_are_errors() {
        let (a, _) = pair();
        let big = RgbImage32::new(3, 1);
        let err = rmse(&a, &big).unwrap_err();
        assert_eq!(
            err.to_string(),
            "the image is 2x1 but the reference is 3x1; the images must have the same size"
        );
        assert!(rel_mse(&big, &a).is_err());
        assert!(matches!(
            rmse(&RgbImage32::new(0, 4), &RgbImage32::new(0, 4)),
            Err(MetricsError::Empty { .. })
        ));
        let mut broken = a.clone();
        broken.pixels.push([0.0; 3]);
        assert!(matches!(rmse(&broken, &a), Err(MetricsError::Inconsistent { .. })));
        let v = RgbImage32::new(2, 1);
        assert!(matches!(
            z_test_pass_fraction(&a, &v, &a, &big, 0.01),
            Err(MetricsError::SizeMismatch { what: "var_b_of_mean", .. })
        ));
        assert_eq!(z_test_pass_fraction(&a, &v, &a, &v, 1.0), Err(MetricsError::InvalidAlpha(1.0)));
        assert!(z_test_pass_fraction(&a, &v, &a, &v, f64::NAN).is_err());
    }

    #[test]
    fn z_test_by_hand() {
        let one = |v: [f32; 3]| RgbImage32::filled(1, 1, v);
        // alpha = 0.05: per channel |z| <= Φ⁻¹(1 - 0.05/6) = 2.394.
        let frac = |a, va, b, vb| z_test_pass_fraction(&one(a), &one(va), &one(b), &one(vb), 0.05).unwrap();
        // z = 1 / sqrt(0.25) = 2 in the red channel: passes.
        assert_eq!(frac([1.0, 0.0, 0.0], [0.25, 0.0, 0.0], [0.0; 3], [0.0; 3]), 1.0);
        // z = 1 / sqrt(0.16) = 2.5 > 2.394: fails.
        assert_eq!(frac([1.0, 0.0, 0.0], [0.16, 0.0, 0.0], [0.0; 3], [0.0; 3]), 0.0);
        // z = 2.2 / sqrt(0.5 + 0.5) = 2.2 would fail an uncorrected test (> 1.96) but passes
        // the per-channel level alpha/3 (< 2.394).
        assert_eq!(frac([2.2, 0.0, 0.0], [0.5, 0.0, 0.0], [0.0; 3], [0.5, 0.0, 0.0]), 1.0);
        // Zero variance: equal passes, different fails, tiny relative difference passes.
        assert_eq!(frac([3.0; 3], [0.0; 3], [3.0; 3], [0.0; 3]), 1.0);
        assert_eq!(frac([3.0; 3], [0.0; 3], [3.1, 3.0, 3.0], [0.0; 3]), 0.0);
        assert_eq!(frac([1000.0; 3], [0.0; 3], [1000.0001, 1000.0, 1000.0], [0.0; 3]), 1.0);
        // Non-finite means fail.
        assert_eq!(frac([f32::NAN, 0.0, 0.0], [1.0; 3], [0.0; 3], [1.0; 3]), 0.0);
        // One failing channel fails the pixel; 1 of 2 pixels passing gives 0.5.
        let a = RgbImage32 { width: 2, height: 1, pixels: vec![[0.0, 0.0, 10.0], [0.0; 3]] };
        let v = RgbImage32::filled(2, 1, [1.0; 3]);
        let b = RgbImage32::new(2, 1);
        assert_eq!(z_test_pass_fraction(&a, &v, &b, &v, 0.01).unwrap(), 0.5);
    }

    /// A Monte Carlo "render": each pixel channel is the mean of `n` exponential samples
    /// (skewed, like path-tracing radiance) with true mean `truth(x, y) * scale`. Returns the
    /// mean image and the variance-of-the-mean image (sample variance / n).
    fn mc_render(seed: u64, n: usize, scale: f64) -> (RgbImage32, RgbImage32) {
        let mut rng = illum_oracle::Rng::from_state(seed);
        // (mean, variance of the mean) of one channel's n samples of true mean `truth`.
        let mut channel = |truth: f64| {
            let (mut s, mut s2) = (0.0, 0.0);
            for _ in 0..n {
                let sample = -truth * (1.0 - rng.uniform()).ln();
                s += sample;
                s2 += sample * sample;
            }
            let mu = s / n as f64;
            let sample_var = (s2 - n as f64 * mu * mu) / (n as f64 - 1.0);
            (mu as f32, (sample_var / n as f64) as f32)
        };
        let w = 64u32;
        let (mut mean, mut var) = (RgbImage32::new(w, w), RgbImage32::new(w, w));
        // Row-major, as the pixels are stored.
        for (i, (m, v)) in mean.pixels.iter_mut().zip(&mut var.pixels).enumerate() {
            let (x, y) = (i as u32 % w, i as u32 / w);
            for c in 0..3 {
                (m[c], v[c]) = channel(scale * (0.1 + f64::from(x + 2 * y + 7 * c as u32) / 200.0));
            }
        }
        (mean, var)
    }

    #[test]
    fn z_test_separates_same_from_shifted_distributions() {
        let (ma, va) = mc_render(1, 256, 1.0);
        let (mb, vb) = mc_render(2, 256, 1.0);
        let same = z_test_pass_fraction(&ma, &va, &mb, &vb, 0.01).unwrap();
        // Bonferroni makes the nominal pass rate >= 99 %; estimated variances from skewed
        // samples lower it slightly (0.987 to 0.994 over 20 seed pairs; 0.990 for this one).
        assert!(same > 0.98, "independent renders of the same image: only {same} pass");

        // 30 % brighter: z ≈ 0.3 / (sqrt(2) / 16) ≈ 3.4 per channel.
        let (mc, vc) = mc_render(3, 256, 1.3);
        let shifted = z_test_pass_fraction(&ma, &va, &mc, &vc, 0.01).unwrap();
        assert!(shifted < 0.2, "a 30% brighter render passes on {shifted} of the pixels");
    }

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median(&mut []).is_nan());
    }

    #[test]
    fn binomial_critical_counts_match_exact_tails() {
        // Bin(100, 1/2): P(K >= 59) = 0.0443, P(K >= 58) = 0.0666 (tables).
        assert_eq!(binomial_critical_count(100, 0.5, 0.05), 59);
        // Bin(10, 1/2): P(K >= 10) = 1/1024 < 0.001 < P(K >= 9) = 11/1024.
        assert_eq!(binomial_critical_count(10, 0.5, 0.001), 10);
        assert_eq!(binomial_critical_count(10, 0.5, 0.0009), 11);
        // p = 0: no failure is possible, so one failure is already significant.
        assert_eq!(binomial_critical_count(576, 0.0, 0.001), 1);
        // The oracle test's case, against a direct sum of the pmf in f64.
        let (n, p) = (576usize, 0.01f64);
        let k = binomial_critical_count(n, p, 1e-3);
        let mut pmf = vec![(1.0 - p).powi(n as i32)];
        for j in 0..n {
            let next = pmf[j] * (n - j) as f64 / (j + 1) as f64 * p / (1.0 - p);
            pmf.push(next);
        }
        let tail = |from: usize| pmf[from..].iter().sum::<f64>();
        assert!(tail(k) <= 1e-3 && tail(k - 1) > 1e-3, "k = {k}: {} and {}", tail(k), tail(k - 1));
        assert_eq!(k, 15);
        // tests/pathtrace/oracle_agreement.rs: P(K >= 2) = 1.6e-3, P(K >= 3) = 3.0e-5.
        assert_eq!(binomial_critical_count(576, 1e-4, 1e-3), 3);
    }
}
