//! Tests of MNEE's root search (`manifold.rs`) where a sign-change scan alone fails: the pairs
//! of roots born at a fold.

use glam::DVec2;

use crate::manifold::ChainTable;
use crate::manifold_chain::Chain;

/// The point of the unit sphere's plane on the fold of `chain` at incidence `theta1`: g = 0 and
/// dg/dtheta1 = 0. With A = z sin f - r cos f and B = z cos f + r sin f (a rotation of (r, z)),
/// g = A + sin theta1 and g' = f' B + cos theta1, so A = -sin theta1, B = -cos theta1 / f'.
fn fold_point(chain: Chain, n: f64, theta1: f64) -> DVec2 {
    let e = chain.exit(n, theta1).unwrap();
    let (sf, cf) = (e.u.x, e.u.y);
    let (a, b) = (-theta1.sin(), -theta1.cos() / e.turn_rate);
    DVec2::new(-a * cf + b * sf, a * sf + b * cf)
}

/// Guards the search for hidden pairs: 1e-9 off a fold, on its lit side, the two roots lie
/// ~1e-4 apart, well inside one of the 4096 intervals (no sign change at its ends), and both
/// must be found, each refined to g = 0.
#[test]
fn a_pair_of_roots_within_one_interval_is_found() {
    let h = std::f64::consts::PI / 4096.0;
    for (chain, n, theta1) in
        [(Chain::TRT, 1.33, 1.0), (Chain::TRT, 1.5, -0.8), (Chain::TT, 1.5, 1.2), (Chain::R, 1.0, 0.6)]
    {
        let fold = fold_point(chain, n, theta1);
        let (g, dg) = chain.miss(n, theta1, fold).unwrap();
        assert!(g.abs() < 1e-12 && dg.abs() < 1e-12, "{chain:?}: not a fold: g {g}, g' {dg}");
        // g'' by central differences of g'; step off the fold along grad_x g = (-cos f, sin f)
        // (a unit vector, so g changes by the step) to the side where g and g'' differ in sign.
        let d = 1e-5;
        let curvature = (chain.miss(n, theta1 + d, fold).unwrap().1
            - chain.miss(n, theta1 - d, fold).unwrap().1)
            / (2.0 * d);
        let u = chain.exit(n, theta1).unwrap().u;
        let x = fold - 1e-9 * curvature.signum() * DVec2::new(-u.y, u.x);
        let mut roots = Vec::new();
        ChainTable::new(chain, n, 4096).roots(x, &mut roots);
        let near: Vec<f64> = roots.into_iter().filter(|r| (r - theta1).abs() < h).collect();
        assert_eq!(near.len(), 2, "{chain:?} n {n} theta1 {theta1}: {near:?}");
        assert!((near[1] - near[0]).abs() < 0.5 * h, "{near:?}");
        for r in near {
            assert!(chain.miss(n, r, x).unwrap().0.abs() < 1e-12, "{chain:?}: g({r}) not 0");
        }
    }
}
