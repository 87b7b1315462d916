//! Where the error of an accumulation is: its estimated relative error per pixel, and summed over
//! the whole image, over a set of pixels (a region), or at a percentile of the pixels.
//!
//! A pixel's relative variance is the mean over its channels of Var(mean_c) / (mean_c^2 + eps),
//! the terms of [`Accumulator::estimated_rel_mse`]: the image's estimated relMSE is the mean of
//! the pixels' relative variances, and a pixel's relative standard error (the EXR layer
//! `illum.error`, the viewer's error view) is the square root of its own. The variance is the
//! accumulator's: from replicates for the low-discrepancy sequence, s^2 / n otherwise.
//!
//! A percentile of the per-pixel errors reads each pixel's own noisy estimate (3 degrees of
//! freedom with replicates, n - 1 otherwise), and the noise of an estimate spreads the
//! distribution: a high percentile of estimates lies somewhat above that of the true errors, so a
//! percentile stop rule errs toward stopping late.

use illum_image::metrics::REL_MSE_EPSILON;

use crate::Accumulator;

/// The per-pixel relative variance of an accumulation's mean image.
#[derive(Clone, Debug)]
pub struct ErrorMap {
    pub width: u32,
    pub height: u32,
    /// Per pixel, row-major from the top-left: the estimated relative variance of its mean
    /// (infinite where it has fewer than two samples or replicates).
    pub relative_variance: Vec<f64>,
}

/// What a stop rule measures the error over.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum ErrorScope {
    /// The whole image: sqrt(estimated relMSE), `--target-error` alone.
    #[default]
    Image,
    /// The pixels at or below this percentile of the per-pixel errors (0 < p <= 100):
    /// `--error-percentile P`.
    Percentile(f64),
    /// sqrt of the mean relative variance over the pixels where the mask is true: `--region NAME`.
    Region { name: String, mask: Vec<bool> },
}

impl ErrorScope {
    /// What the error is measured over, in words ("the 95th percentile of the pixels").
    pub fn describe(&self) -> String {
        match self {
            ErrorScope::Image => "the image".to_owned(),
            ErrorScope::Percentile(p) => format!("the {p}th percentile of the pixels"),
            ErrorScope::Region { name, mask } => {
                format!("region {name:?} ({} pixels)", mask.iter().filter(|m| **m).count())
            }
        }
    }
}

impl ErrorMap {
    pub fn of(accumulator: &Accumulator) -> ErrorMap {
        let pixels = accumulator.width as usize * accumulator.height as usize;
        let relative_variance = (0..pixels)
            .map(|p| {
                let mean = accumulator.pixel_mean(p);
                let var = accumulator.pixel_variance_of_mean(p);
                (0..3).map(|c| var[c] / (mean[c] * mean[c] + REL_MSE_EPSILON)).sum::<f64>() / 3.0
            })
            .collect();
        ErrorMap { width: accumulator.width, height: accumulator.height, relative_variance }
    }

    /// Per pixel, the relative standard error (f32, infinite where unknown): the `illum.error` layer.
    pub fn relative_error(&self) -> Vec<f32> {
        self.relative_variance.iter().map(|&v| v.sqrt() as f32).collect()
    }

    /// The relative error over `scope` (see [`ErrorScope`]); infinite while any pixel it reads is
    /// unknown, NaN never.
    pub fn error(&self, scope: &ErrorScope) -> f64 {
        match scope {
            ErrorScope::Image => mean(self.relative_variance.iter().copied()).sqrt(),
            ErrorScope::Region { mask, .. } => {
                mean(self.relative_variance.iter().zip(mask).filter(|(_, inside)| **inside).map(|(v, _)| *v))
                    .sqrt()
            }
            ErrorScope::Percentile(p) => self.percentile(*p),
        }
    }

    /// The per-pixel relative error that `percentile` per cent of the pixels are at or under
    /// (the nearest-rank definition: the ceil(p N / 100)-th smallest).
    pub fn percentile(&self, percentile: f64) -> f64 {
        let mut values: Vec<f64> = self.relative_variance.clone();
        if values.is_empty() {
            return f64::INFINITY;
        }
        let rank = ((percentile / 100.0 * values.len() as f64).ceil() as usize).clamp(1, values.len());
        let (_, nth, _) = values.select_nth_unstable_by(rank - 1, |a, b| a.total_cmp(b));
        nth.sqrt()
    }
}

/// The mean of `values`; infinite for none (nothing measured yet).
fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    if n == 0 { f64::INFINITY } else { sum / n as f64 }
}

/// Checks a `--error-percentile` value: a number above 0 and at most 100.
pub fn parse_error_percentile(flag: &str, text: &str) -> Result<f64, String> {
    let value: f64 = text.trim().parse().map_err(|_| {
        format!("{flag} = {text:?} is not a number: give a percentage above 0 and at most 100, e.g. 95")
    })?;
    if !(value > 0.0 && value <= 100.0) {
        return Err(format!("{flag} = {text}: a percentile must be above 0 and at most 100, e.g. 95"));
    }
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(values: &[f64]) -> ErrorMap {
        ErrorMap { width: values.len() as u32, height: 1, relative_variance: values.to_vec() }
    }

    #[test]
    fn the_image_error_is_the_square_root_of_the_estimated_rel_mse() {
        let mut acc = Accumulator::new(2, 1);
        acc.fold(
            0,
            &[[1.0, 1.0, 1.0, 2.0], [4.0, 4.0, 4.0, 2.0]],
            &[[1.0, 1.0, 1.0, 0.0], [10.0, 10.0, 10.0, 0.0]],
        );
        let m = ErrorMap::of(&acc);
        let image = m.error(&ErrorScope::Image);
        assert!((image - acc.estimated_relative_error()).abs() < 1e-12, "{image}");
        let per_pixel = m.relative_error();
        assert!((f64::from(per_pixel[0]) - m.relative_variance[0].sqrt()).abs() < 1e-6);
    }

    #[test]
    fn percentiles_take_the_nearest_rank() {
        let m = map(&[0.01, 0.04, 0.09, 0.16, 0.25, 0.36, 0.49, 0.64, 0.81, 1.0]);
        assert!((m.error(&ErrorScope::Percentile(100.0)) - 1.0).abs() < 1e-12);
        assert!((m.error(&ErrorScope::Percentile(50.0)) - 0.5).abs() < 1e-12);
        assert!((m.error(&ErrorScope::Percentile(95.0)) - 1.0).abs() < 1e-12);
        assert!((m.error(&ErrorScope::Percentile(90.0)) - 0.9).abs() < 1e-12);
        assert!((m.error(&ErrorScope::Percentile(0.1)) - 0.1).abs() < 1e-12);
    }

    #[test]
    fn a_region_reads_only_its_pixels_and_an_unknown_pixel_makes_it_unknown() {
        let m = map(&[0.04, f64::INFINITY, 0.16]);
        let region = |mask: Vec<bool>| ErrorScope::Region { name: "r".into(), mask };
        assert!((m.error(&region(vec![true, false, true])) - 0.1f64.sqrt()).abs() < 1e-12);
        assert!(m.error(&region(vec![true, true, false])).is_infinite());
        assert!(m.error(&region(vec![false; 3])).is_infinite());
        assert!(m.error(&ErrorScope::Image).is_infinite());
    }

    #[test]
    fn bad_percentiles_are_refused_naming_the_flag_and_the_range() {
        for bad in ["0", "101", "-5", "nan", "abc", "inf"] {
            let e = parse_error_percentile("--error-percentile", bad).unwrap_err();
            assert!(e.contains("--error-percentile") && e.contains(bad) && e.contains("100"), "{e}");
        }
        assert_eq!(parse_error_percentile("--error-percentile", "95").unwrap(), 95.0);
        assert_eq!(parse_error_percentile("--error-percentile", "100").unwrap(), 100.0);
    }
}
