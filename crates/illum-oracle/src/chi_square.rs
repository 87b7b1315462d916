//! Pearson's chi-square goodness-of-fit test, for the statistical tests of sampling routines
//! (the way Mitsuba ships its `chi2` test as library code).
//!
//! Observed counts per cell are compared with `total x p_i` for cell probabilities `p_i`
//! integrated from the routine's pdf. Cells expecting fewer than 5 samples are pooled into one,
//! as the test requires; the statistic is compared with the chi-square critical value of the
//! remaining degrees of freedom (Wilson-Hilferty approximation, accurate to <1% above a few
//! degrees of freedom).

use illum_image::inverse_normal_cdf;

/// The outcome of [`pearson`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChiSquare {
    /// Pearson's statistic, sum over cells of (observed - expected)^2 / expected.
    pub statistic: f64,
    /// The critical value at the test's alpha for `cells - 1` degrees of freedom.
    pub critical: f64,
    /// Cells after pooling.
    pub cells: usize,
}

impl ChiSquare {
    /// True when the counts are consistent with the probabilities at the test's alpha.
    pub fn passes(&self) -> bool {
        self.statistic < self.critical
    }
}

/// Chi-square critical value for `dof` degrees of freedom at upper-tail probability `alpha`.
pub fn critical_value(dof: usize, alpha: f64) -> f64 {
    let k = dof as f64;
    let z = inverse_normal_cdf(1.0 - alpha);
    k * (1.0 - 2.0 / (9.0 * k) + z * (2.0 / (9.0 * k)).sqrt()).powi(3)
}

/// Pearson's test of `observed` counts against cell `probability` (which must sum to 1) at
/// significance `alpha`, pooling the cells that expect fewer than 5 samples.
///
/// # Panics
/// If the probabilities do not sum to 1 (within 1e-9) or fewer than two cells remain.
pub fn pearson(observed: &[u64], probability: &[f64], alpha: f64) -> ChiSquare {
    let total: u64 = observed.iter().sum();
    let p_sum: f64 = probability.iter().sum();
    assert!((p_sum - 1.0).abs() < 1e-9, "cell probabilities sum to {p_sum}");
    let mut cells: Vec<(f64, f64)> = Vec::new();
    let (mut pool_o, mut pool_e) = (0.0, 0.0);
    for (&o, &p) in observed.iter().zip(probability) {
        let e = p * total as f64;
        if e < 5.0 {
            pool_o += o as f64;
            pool_e += e;
        } else {
            cells.push((o as f64, e));
        }
    }
    if pool_e > 0.0 {
        cells.push((pool_o, pool_e));
    }
    assert!(cells.len() >= 2, "{} cell(s) after pooling: nothing to test", cells.len());
    let statistic: f64 = cells.iter().map(|(o, e)| (o - e) * (o - e) / e).sum();
    ChiSquare { statistic, critical: critical_value(cells.len() - 1, alpha), cells: cells.len() }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn critical_values_match_the_tables() {
        // Upper 1% points of chi-square: 10 dof 23.209, 100 dof 135.807.
        assert!((critical_value(10, 0.01) - 23.209).abs() < 0.1);
        assert!((critical_value(100, 0.01) - 135.807).abs() < 0.2);
    }

    #[test]
    fn exact_counts_pass_and_lopsided_counts_fail() {
        let p = [0.25; 4];
        assert!(pearson(&[250, 250, 250, 250], &p, 0.01).passes());
        assert!(!pearson(&[400, 200, 200, 200], &p, 0.01).passes());
    }

    #[test]
    fn small_cells_are_pooled() {
        let outcome = pearson(&[500, 497, 1, 2], &[0.5, 0.497, 0.001, 0.002], 0.01);
        assert_eq!(outcome.cells, 3);
        assert!(outcome.passes());
    }
}
