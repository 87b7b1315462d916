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
