//! What a pilot's measurement of one setting means for the planner: its bias, its noise curve
//! and its worst region, from its image compared with the pilot's truth.

use crate::plan::NoiseCurve;
use crate::regions::{Comparison, Regions};

/// One setting's bias and noise as a pilot measured them.
#[derive(Clone, Debug, PartialEq)]
pub struct Measured {
    /// relMSE against the truth that no number of samples removes (>= 0).
    pub bias_rel_mse: f64,
    /// How the relMSE from noise falls with the spp (the path tracer's; `None` otherwise).
    pub noise: Option<NoiseCurve>,
    /// The region whose mean brightness is furthest from the truth's, and that brightness
    /// relative to the truth's.
    pub worst_region: Option<(String, f64)>,
}

/// The measurement of a setting whose image compares with the truth as `errors` does.
/// `truth_rel_mse` is the truth's own estimated relMSE from its noise; `own_noise` the
/// setting's (a path tracer's estimated relMSE at `spp` samples per pixel, `None` for a
/// deterministic renderer). Expected relMSE against a noisy truth = bias² + own noise + the
/// truth's noise (the three are independent), so the bias² is the measured relMSE less both
/// noises, never below 0; the noise curve is the own noise at `spp` falling as 1/N (independent
/// samples; a pilot that measures another law replaces it).
pub fn measured(
    errors: &Comparison,
    regions: &Regions,
    truth_rel_mse: f64,
    own_noise: Option<f64>,
    spp: u32,
) -> Measured {
    let bias_rel_mse = (errors.overall.rel_mse - truth_rel_mse - own_noise.unwrap_or(0.0)).max(0.0);
    let worst_region = regions
        .names
        .iter()
        .zip(&errors.regions)
        .filter(|(_, e)| e.pixels > 0 && e.luminance_ratio.is_finite())
        .max_by(|a, b| (a.1.luminance_ratio - 1.0).abs().total_cmp(&(b.1.luminance_ratio - 1.0).abs()))
        .map(|(name, e)| (name.clone(), e.luminance_ratio));
    let noise = own_noise.and_then(|n| NoiseCurve::independent(n, f64::from(spp)));
    Measured { bias_rel_mse, noise, worst_region }
}

/// The measurement of a denoised render: `raw`, the raw render's at the last spp of `at`; `at`,
/// the denoised image's at each spp, measured as a deterministic image's (its relMSE less the
/// truth's noise). The denoised relMSE beyond the raw render's bias is its noise curve, held
/// flat beyond the last spp (the denoiser's own bias stays in it), and its worst region the
/// denoised image's at the last spp. What `render --renderer auto`'s pilot and the viewer's
/// both use.
pub fn denoised(raw: Measured, at: &[(u32, Measured)]) -> Measured {
    let points = at.iter().map(|(n, m)| (f64::from(*n), m.bias_rel_mse - raw.bias_rel_mse)).collect();
    let worst_region = at.last().map_or(raw.worst_region.clone(), |(_, m)| m.worst_region.clone());
    Measured { noise: NoiseCurve::new(points, 0.0), worst_region, ..raw }
}

/// The spp at which a pilot measures a denoised render, from one render continued: 4, 16 and
/// 64 where below the pilot's `pilot_spp`, and `pilot_spp` (what the CLI's pilot and the viewer's
/// both run).
pub fn denoised_spps(pilot_spp: u32) -> Vec<u32> {
    [4, 16, 64].into_iter().filter(|&n| n < pilot_spp).chain([pilot_spp]).collect()
}

/// The spp at which a pilot reads a low-discrepancy render's own estimate: a sixteenth, a
/// quarter and all of `pilot_spp`, three points a factor 4 apart, so that the curve's law
/// beyond them ([`NoiseCurve::with_measured_law`]) sees how its exponent changes.
pub fn low_discrepancy_spps(pilot_spp: u32) -> Vec<u32> {
    let mut spps: Vec<u32> =
        [pilot_spp / 16, pilot_spp / 4, pilot_spp].into_iter().filter(|&n| n > 0).collect();
    spps.dedup();
    spps
}

/// The measurement of a low-discrepancy render: `raw`, the render's at its last spp;
/// `estimates`, its own estimated relMSE (from its replicates) at each spp of
/// [`low_discrepancy_spps`]. The noise curve goes through the estimates, with the law beyond
/// them of [`NoiseCurve::with_measured_law`].
pub fn low_discrepancy(raw: Measured, estimates: &[(u32, f64)]) -> Measured {
    let points = estimates.iter().map(|(n, v)| (f64::from(*n), *v)).collect();
    Measured { noise: NoiseCurve::with_measured_law(points).or(raw.noise.clone()), ..raw }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::noise_rel_mse;

    fn m(bias_rel_mse: f64, region: &str) -> Measured {
        Measured { bias_rel_mse, noise: None, worst_region: Some((region.to_owned(), 0.9)) }
    }

    /// A low-discrepancy curve goes through its estimates at a sixteenth, a quarter and all of
    /// the pilot's spp, and beyond them follows the measured law, not the raw 1/N.
    #[test]
    fn a_low_discrepancy_curve_is_its_estimates_with_the_measured_law_beyond() {
        assert_eq!(low_discrepancy_spps(256), vec![16, 64, 256]);
        assert_eq!(low_discrepancy_spps(8), vec![2, 8]);
        let mut raw = m(2e-4, "raw");
        raw.noise = NoiseCurve::independent(1e-3, 256.0);
        let estimates = [(16, 0.064), (64, 0.064 / 8.0), (256, 0.064 / 8.0 / 4f64.powf(1.4))];
        let ld = low_discrepancy(raw, &estimates);
        assert_eq!(ld.bias_rel_mse, 2e-4);
        let curve = ld.noise.expect("a curve");
        assert_eq!(curve.points().len(), 3);
        assert!((curve.exponent() - 1.3).abs() < 1e-12, "{curve:?}");
        assert!((noise_rel_mse(&curve, 32.0) - 0.064 / 2f64.powf(1.5)).abs() < 1e-12);
    }

    /// The denoised curve is the denoised relMSE less the raw bias at each spp, flat beyond the
    /// last, with the raw bias kept and the denoised image's worst region.
    #[test]
    fn a_denoised_curve_is_its_error_beyond_the_raw_bias() {
        let raw = m(1e-4, "raw");
        let at = [(4, m(8e-3, "a")), (16, m(3e-3, "b")), (64, m(1.1e-3, "c"))];
        let d = denoised(raw, &at);
        assert_eq!(d.bias_rel_mse, 1e-4);
        assert_eq!(d.worst_region, Some(("c".to_owned(), 0.9)));
        let curve = d.noise.expect("a curve");
        for (n, want) in [(4.0, 7.9e-3), (16.0, 2.9e-3), (64.0, 1e-3), (1024.0, 1e-3)] {
            let got = noise_rel_mse(&curve, n);
            assert!((got - want).abs() < 1e-12 * want.max(1.0) + 1e-15, "{n} spp: {got}, want {want}");
        }
    }
}
