//! The noise model: how a path tracer's relMSE beyond its bias falls with the samples per pixel
//! ([`NoiseCurve`]), and [`noise_rel_mse`], the one place the curve is read.

/// A path tracer's relMSE beyond its bias against the spp, as measured: log-log linear between
/// the measured points, and falling as N^-exponent beyond the last (before the first, as the
/// first segment falls, or as N^-exponent with one point).
#[derive(Clone, Debug, PartialEq)]
pub struct NoiseCurve {
    /// (spp, relMSE), spp increasing and relMSE not increasing, every value above 0.
    points: Vec<(f64, f64)>,
    exponent: f64,
}

impl NoiseCurve {
    /// A curve through `points` (any order) with `exponent` beyond them. Each relMSE is kept
    /// at least 1e-12 and at most the one before it, and the exponent at least 0, so that the
    /// curve never rises with the spp (the planner's search for the fewest spp relies on it:
    /// more samples never predict a larger error). `None` without a finite point.
    pub fn new(mut points: Vec<(f64, f64)>, exponent: f64) -> Option<Self> {
        points.retain(|(n, v)| *n > 0.0 && n.is_finite() && v.is_finite());
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        points.dedup_by(|b, a| a.0 == b.0);
        let mut lowest = f64::INFINITY;
        for point in &mut points {
            lowest = lowest.min(point.1.max(1e-12));
            point.1 = lowest;
        }
        let exponent = if exponent.is_finite() { exponent.max(0.0) } else { 1.0 };
        (!points.is_empty()).then_some(NoiseCurve { points, exponent })
    }

    /// A curve through relMSE measured at three or more spp (any order), whose law beyond the
    /// last point is an exponent derived from the points themselves, kept from being optimistic
    /// where it was not measured (with two points, the exponent between them).
    ///
    /// Derivation: let e1 and e2 be the exponents (slopes of log relMSE against log spp) of the
    /// last two segments. How the exponent changes from one segment to the next, |e2 - e1|,
    /// is what the curve is measured to bend by (the sequence's advantage growing or fading
    /// with the spp), plus the statistical error of the two slopes. Beyond the last point the
    /// exponent is e2 - |e2 - e1|:
    /// - if it fell from e1 to e2, 2 e2 - e1. With segments of equal width in log spp (the
    ///   pilot's 16, 64, 256) and a fall linear in log spp, that is the exponent at the middle
    ///   of a next segment as wide, which is at most the mean exponent from the last point to
    ///   any spp up to the end of that segment (4 times the last): held flat, it predicts no less
    ///   noise than the fall would give there. Further on it assumes the fall has stopped.
    /// - if it rose, the lower e1: the rise is not relied on.
    ///
    /// A curve whose exponent stays the same keeps it. [`Self::new`]'s floor of 0 applies.
    pub fn with_measured_law(points: Vec<(f64, f64)>) -> Option<Self> {
        let curve = Self::new(points, 1.0)?;
        let slope = |(n0, v0): (f64, f64), (n1, v1): (f64, f64)| (v0 / v1).ln() / (n1 / n0).ln();
        let exponent = match curve.points.as_slice() {
            [.., a, b, c] => {
                let (e1, e2) = (slope(*a, *b), slope(*b, *c));
                e2 - (e2 - e1).abs()
            }
            [a, b] => slope(*a, *b),
            _ => 1.0,
        };
        Self::new(curve.points, exponent)
    }

    /// The 1/N law of independent samples, from the relMSE `rel_mse` measured at `spp`.
    pub fn independent(rel_mse: f64, spp: f64) -> Option<Self> {
        Self::new(vec![(spp, rel_mse)], 1.0)
    }

    pub fn points(&self) -> &[(f64, f64)] {
        &self.points
    }

    pub fn exponent(&self) -> f64 {
        self.exponent
    }
}

/// The relMSE beyond the bias after `spp` samples per pixel, read off the measured curve (see
/// [`NoiseCurve`]). This is the one place the noise model is written (see the module's comment).
pub fn noise_rel_mse(curve: &NoiseCurve, spp: f64) -> f64 {
    let points = &curve.points;
    let at = |(n0, v0): (f64, f64), slope: f64| v0 * (n0 / spp).powf(slope);
    let first = points[0];
    let last = points[points.len() - 1];
    let slope = |(n0, v0): (f64, f64), (n1, v1): (f64, f64)| (v0 / v1).ln() / (n1 / n0).ln();
    if spp >= last.0 {
        return at(last, curve.exponent);
    }
    if spp <= first.0 {
        return at(first, if points.len() > 1 { slope(first, points[1]) } else { curve.exponent });
    }
    let i = points.iter().position(|p| p.0 > spp).expect("spp is below the last point");
    at(points[i - 1], slope(points[i - 1], points[i]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_noise_curve_is_log_log_linear_between_its_points_and_follows_its_law_beyond() {
        // Two points a quarter apart with relMSE falling 8 times: exponent 1.5 between them.
        let ld = NoiseCurve::new(vec![(256.0, 1e-3), (64.0, 8e-3)], 1.5).unwrap();
        assert!((noise_rel_mse(&ld, 128.0) - 8e-3 / 2f64.powf(1.5)).abs() < 1e-15);
        assert!((noise_rel_mse(&ld, 1024.0) - 1e-3 / 8.0).abs() < 1e-15);
        assert!((noise_rel_mse(&ld, 16.0) - 8e-3 * 8.0).abs() < 1e-12);
        // One point and the 1/N law: the independent model, rel_mse x spp / N.
        let independent = NoiseCurve::independent(0.02, 256.0).unwrap();
        assert!((noise_rel_mse(&independent, 64.0) - 0.08).abs() < 1e-15);
        // A denoised curve is held flat beyond its last point, and never rises: a point above
        // the one before is lowered to it; an exponent below 0 is taken as 0.
        let denoised = NoiseCurve::new(vec![(4.0, 0.01), (16.0, 0.004), (64.0, 0.005)], -0.5).unwrap();
        assert_eq!(denoised.points()[2], (64.0, 0.004));
        assert_eq!(noise_rel_mse(&denoised, 1e6), 0.004);
        assert!((noise_rel_mse(&denoised, 8.0) - (0.01f64 * 0.004).sqrt()).abs() < 1e-15);
        assert_eq!(NoiseCurve::new(vec![(64.0, f64::NAN)], 1.0), None);
    }

    /// The low-discrepancy law beyond the measured points is the last segment's exponent less
    /// how much it changed from the segment before, never the last exponent alone where the
    /// exponent fell.
    #[test]
    fn beyond_its_points_a_measured_curve_falls_no_faster_than_its_bend_allows() {
        // Exponents 1.5 (16 to 64) then 1.4 (64 to 256): beyond, 1.4 - 0.1 = 1.3.
        let v64 = 1e-2 / 4f64.powf(1.5);
        let v256 = v64 / 4f64.powf(1.4);
        let falling = NoiseCurve::with_measured_law(vec![(16.0, 1e-2), (64.0, v64), (256.0, v256)]).unwrap();
        assert!((falling.exponent() - 1.3).abs() < 1e-12, "{falling:?}");
        let at_512 = noise_rel_mse(&falling, 512.0);
        assert!((at_512 - v256 / 2f64.powf(1.3)).abs() < 1e-15 * at_512.max(1.0));
        // The last exponent alone (the rule this replaces) predicts less noise at 512 spp.
        assert!(at_512 > v256 / 2f64.powf(1.4) * 1.06, "{at_512}");
        // Between the points, the measured segments.
        assert!((noise_rel_mse(&falling, 32.0) - 1e-2 / 2f64.powf(1.5)).abs() < 1e-15);
        // Rising from 1.2 to 1.4: beyond, the lower 1.2.
        let v64 = 1e-2 / 4f64.powf(1.2);
        let rising =
            NoiseCurve::with_measured_law(vec![(256.0, v64 / 4f64.powf(1.4)), (64.0, v64), (16.0, 1e-2)]);
        assert!((rising.unwrap().exponent() - 1.2).abs() < 1e-12);
        // A straight line keeps its exponent; two points give theirs; a steep bend stops at 0.
        let straight = NoiseCurve::with_measured_law(vec![(16.0, 1.0), (64.0, 0.125), (256.0, 0.125 / 8.0)]);
        assert!((straight.unwrap().exponent() - 1.5).abs() < 1e-12);
        let two = NoiseCurve::with_measured_law(vec![(64.0, 8e-3), (256.0, 1e-3)]).unwrap();
        assert!((two.exponent() - 1.5).abs() < 1e-12);
        let bend =
            NoiseCurve::with_measured_law(vec![(16.0, 1.0), (64.0, 1.0 / 4096.0), (256.0, 1.0 / 8192.0)]);
        assert_eq!(bend.unwrap().exponent(), 0.0);
    }
}
