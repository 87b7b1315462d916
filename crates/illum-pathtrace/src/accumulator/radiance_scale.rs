//! The power-of-two scale between the radiance the GPU traces and the true radiance, for scenes
//! whose lights are bright enough that f32 squares of their samples would overflow.

/// Largest emitted radiance the GPU traces unscaled: 2^16. Above it the scene's emission is
/// divided by a power of two 2^k on upload (so that the brightest light is below 2^17) and the
/// fold multiplies the sums back by 2^k and the sums of squares by 2^(2k), in f64.
///
/// Why: a sample is at most about the brightest emission times a geometric factor of the
/// next-event estimator (light area / distance^2), and the GPU squares it in f32 and sums 16 such
/// squares. Unscaled, `emission = 1e30` would give squares of 1e60, past f32's 3.4e38: an
/// infinite variance while the image is still finite. Scaled, a sample squares in range unless that
/// geometric factor exceeds about 1e13, so every radiance the validator accepts (up to f32::MAX)
/// keeps a finite error estimate. Multiplying by a power of two is exact in binary floating point
/// (short of subnormal numbers), so the scaled render is the unscaled one, bit for bit, times 2^-k;
/// and scenes whose lights are below 2^16 (every scene in scenes/) are not scaled at all.
pub const UNSCALED_RADIANCE_LIMIT: f32 = 65536.0;

/// The exponent k by which the GPU's radiance is scaled down (2^-k) for a scene whose brightest
/// emission component is `max_emission` (0 for every emission up to [`UNSCALED_RADIANCE_LIMIT`]).
pub fn radiance_exponent(max_emission: f32) -> i32 {
    if max_emission.is_nan() || max_emission <= UNSCALED_RADIANCE_LIMIT {
        return 0;
    }
    // max_emission in [2^e, 2^(e+1)), e >= 16; after scaling by 2^-(e - 16) it is below 2^17.
    let e = ((max_emission.to_bits() >> 23) & 0xff) as i32 - 127;
    e - 16
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Accumulator;

    #[test]
    fn radiance_is_scaled_only_above_the_limit_and_by_a_power_of_two() {
        assert_eq!(radiance_exponent(30.0), 0);
        assert_eq!(radiance_exponent(UNSCALED_RADIANCE_LIMIT), 0);
        assert_eq!(radiance_exponent(f32::NAN), 0);
        for m in [65536.5f32, 1e20, 1e30, f32::MAX] {
            let k = radiance_exponent(m);
            let scaled = m as f64 * 2f64.powi(-k);
            assert!((65536.0..131072.0).contains(&scaled), "{m}: k = {k}, scaled {scaled}");
        }
        // The fold undoes the scale exactly: a sample of f32::MAX, traced as f32::MAX / 2^k.
        let k = radiance_exponent(f32::MAX);
        let traced = f32::MAX * 2f32.powi(-k);
        let mut acc = Accumulator::new(1, 1);
        acc.set_radiance_exponent(k);
        for _ in 0..2 {
            acc.fold(0, &[[traced, 1.0, 1.0, 1.0]], &[[traced * traced, 1.0, 1.0, 0.0]]);
        }
        assert_eq!(acc.pixel_mean(0)[0], f32::MAX as f64);
        assert!(acc.estimated_relative_error().is_finite());
    }
}
