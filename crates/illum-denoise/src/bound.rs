//! What any denoiser may do to a pixel: its denoised value stays, channel by channel, within
//! [`BOUND_Z`] standard errors of the pixel's own noisy mean. Applied once to the output of
//! every denoiser by [`DenoiseInput::finish`] (called by [`crate::Denoiser::denoise`] and by the
//! viewer's polled à-trous runs), so that a denoiser cannot move a converged image beyond its
//! noise (docs/denoising.md, "A converged image").
//!
//! Derivation of the width: the ideal denoiser returns each pixel's expected value mu. A
//! pixel's mean x over n samples is, by the central limit theorem, about normal around mu with
//! standard deviation sigma (its standard error, sqrt of the variance of the mean), so
//! P(|mu - x| > z sigma) = 2 (1 - Phi(z)), which is 1e-3 at z = Phi^-1(1 - 5e-4) = 3.2905. The
//! bound therefore alters the ideal denoiser's output in 0.1% of pixels (two-sided), while any
//! change larger than the pixel's own samples can explain at that level is cut back to it. As
//! the samples grow, sigma shrinks as 1/sqrt(n) and the bound closes on the converged value.
//!
//! sigma is the sample estimate: a pixel whose samples were all equal (the black outside a
//! box, a light seen directly, or a few samples that all missed the light) has sigma = 0 and
//! keeps its noisy value; a pixel with fewer than 2 samples has an unknown variance
//! ([`crate::input::UNKNOWN_VARIANCE`]) and is, in effect, not bounded.

use illum_image::RgbImage32;

use crate::input::DenoiseInput;

/// The bound's half-width in standard errors: two-sided 0.1% of the normal distribution.
pub const BOUND_Z: f64 = 3.2905;

/// Clamps each channel of `denoised` to x +- [`BOUND_Z`] sigma, with x the pixel's noisy value
/// in `input.image` and sigma^2 its variance of the mean in `input.variance`. A NaN denoised
/// value stays NaN (a denoiser's failure is not hidden).
pub fn bound(input: &DenoiseInput, denoised: &mut RgbImage32) {
    assert_eq!(denoised.pixels.len(), input.image.pixels.len(), "a denoised image of another size");
    for ((d, x), v) in denoised.pixels.iter_mut().zip(&input.image.pixels).zip(&input.variance) {
        for c in 0..3 {
            let (x, radius) = (f64::from(x[c]), BOUND_Z * f64::from(v[c]).max(0.0).sqrt());
            let value = f64::from(d[c]);
            if value.is_finite() {
                d[c] = value.clamp(x - radius, x + radius) as f32;
            }
        }
    }
}

impl DenoiseInput {
    /// What every denoiser's output goes through (`Denoiser::denoise`, the viewer's polled
    /// filter): the bound to the noisy image ([`bound`]), then the exact radiance added
    /// back.
    pub fn finish(&self, denoised: &mut RgbImage32) {
        bound(self, denoised);
        self.exact.add_to(denoised);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::input::UNKNOWN_VARIANCE;

    fn input(pixels: Vec<[f32; 3]>, variance: Vec<[f32; 3]>) -> DenoiseInput {
        let n = pixels.len();
        DenoiseInput {
            image: RgbImage32 { width: n as u32, height: 1, pixels },
            variance,
            albedo: vec![[0.5; 3]; n],
            normal: vec![[0.0, 0.0, 1.0]; n],
            exact: Default::default(),
        }
    }

    /// Inside the bound nothing changes; outside, each channel stops at x +- 3.29 sigma on its
    /// own side; a zero variance pins the noisy value; an unknown one lets anything through.
    #[test]
    fn each_channel_is_clamped_to_its_own_noise() {
        let input = input(
            vec![[1.0, 1.0, 1.0], [0.5, 0.2, 0.0], [2.0, 2.0, 2.0]],
            vec![[0.01, 0.04, 1.0], [0.0, 0.0, 0.0], [UNKNOWN_VARIANCE; 3]],
        );
        let mut denoised = RgbImage32 {
            width: 3,
            height: 1,
            pixels: vec![[1.2, 0.1, 5.0], [0.6, 0.2, 0.1], [-5.0, 9.0, 2.0]],
        };
        bound(&input, &mut denoised);
        let expected =
            [[1.2, (1.0 - BOUND_Z * 0.2) as f32, (1.0 + BOUND_Z) as f32], [0.5, 0.2, 0.0], [-5.0, 9.0, 2.0]];
        for (got, want) in denoised.pixels.iter().zip(expected) {
            for c in 0..3 {
                assert!((got[c] - want[c]).abs() <= 1e-6 * want[c].abs().max(1.0), "{got:?} != {want:?}");
            }
        }
    }

    /// The width is the two-sided 0.1% point of the normal distribution.
    #[test]
    fn the_width_is_the_two_sided_one_in_a_thousand_point() {
        let z = illum_image::inverse_normal_cdf(1.0 - 0.5e-3);
        assert!((z - BOUND_Z).abs() < 1e-4, "Phi^-1(1 - 5e-4) = {z}");
    }

    /// An ideal denoiser (it returns the expected value) on pixels of 256 uniform samples per
    /// channel: the bound moves it in about 0.1% of the channels (a little more, as sigma is
    /// estimated from the samples: Student's t with 255 degrees of freedom gives 0.11%). Of
    /// 60000 independent channels (expected count 69) the test asks for 30 to 120; a Poisson
    /// count of mean 69 leaves that range with probability below 1e-6, the false-alarm rate.
    /// A bound of 2.58 sigma (1%) or 3.89 sigma (0.01%) fails it.
    #[test]
    fn an_ideal_denoiser_is_moved_in_one_channel_in_a_thousand() {
        let (pixels, samples) = (20_000usize, 256usize);
        // A 64-bit LCG (Knuth's MMIX constants): enough for test noise.
        let mut state = 17u64;
        let mut uniform = move || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut means, mut variances) = (Vec::new(), Vec::new());
        for _ in 0..pixels {
            let (mut mean, mut variance) = ([0.0f32; 3], [0.0f32; 3]);
            for c in 0..3 {
                let xs: Vec<f64> = (0..samples).map(|_| uniform()).collect();
                let m = xs.iter().sum::<f64>() / samples as f64;
                let s2 = xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (samples - 1) as f64;
                (mean[c], variance[c]) = (m as f32, (s2 / samples as f64) as f32);
            }
            means.push(mean);
            variances.push(variance);
        }
        let input = input(means, variances);
        let mut ideal = RgbImage32 { width: pixels as u32, height: 1, pixels: vec![[0.5; 3]; pixels] };
        bound(&input, &mut ideal);
        let moved = ideal.pixels.iter().flatten().filter(|&&v| v != 0.5).count();
        println!("the bound moved {moved} of {} channels of an ideal denoiser", 3 * pixels);
        assert!((30..=120).contains(&moved), "{moved} of {} channels moved", 3 * pixels);
    }

    #[test]
    fn a_nan_stays_nan() {
        let input = input(vec![[1.0; 3]], vec![[0.01; 3]]);
        let mut denoised = RgbImage32 { width: 1, height: 1, pixels: vec![[f32::NAN, 1.0, 1.0]] };
        bound(&input, &mut denoised);
        assert!(denoised.pixels[0][0].is_nan());
    }
}
