//! The solve's unit tests: the glints do not depend on the thread count, and the exact
//! Jacobian agrees with central differences.

mod threads {
    use super::super::*;

    /// The Whitted scene with a row of small glass and mirror balls before it, at 320 x 180.
    pub(super) fn whitted_row() -> Scene {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/whitted.toml");
        let mut text = std::fs::read_to_string(&path).expect("scenes/whitted.toml");
        for k in 0..6 {
            let material = if k % 2 == 0 { "glass" } else { "metal" };
            let z = -6.0 + 1.2 * f64::from(k);
            text += &format!(
                "\n[[objects]]\nmaterial = \"{material}\"\nsphere = {{ center = [1.0, 0.35, {z:?}], radius = 0.35 }}\n"
            );
        }
        let mut scene = Scene::from_toml_str(&text, "whitted-row.toml").unwrap_or_else(|e| panic!("{e}"));
        scene.camera.width = 320;
        scene.camera.height = 180;
        scene
    }

    #[test]
    fn the_glints_do_not_depend_on_how_many_threads_share_the_solve() {
        // Hundreds of chains, whose starts come from shares of the seeds cut where the thread
        // count says.
        let mut solver = Solver::new(&whitted_row());
        solver.threads = 1;
        let one = solver.solve(&|| false);
        assert!(one.len() > 40, "{} glints", one.len());
        for threads in [2, 3, 7] {
            solver.threads = threads;
            assert_eq!(solver.solve(&|| false), one, "{threads} threads against 1");
        }
    }
}

mod jacobian {
    use super::super::*;

    /// dg/ds by central differences of step h and h / 2, extrapolated (Richardson, error O(h^4)).
    fn differences(solver: &Solver, s: [f64; 2], chain: &[Step], h: f64) -> Option<[[f64; 2]; 2]> {
        let central = |h: f64| -> Option<[[f64; 2]; 2]> {
            let mut j = [[0.0; 2]; 2];
            for c in 0..2 {
                let (mut plus, mut minus) = (s, s);
                plus[c] += h;
                minus[c] -= h;
                let (gp, gm) = (
                    solver.residual(plus, chain, Blockers::Checked)?.g,
                    solver.residual(minus, chain, Blockers::Checked)?.g,
                );
                for r in 0..2 {
                    j[r][c] = (gp[r] - gm[r]) / (2.0 * h);
                }
            }
            Some(j)
        };
        let (a, b) = (central(h)?, central(0.5 * h)?);
        Some([0, 1].map(|r| [0, 1].map(|c| (4.0 * b[r][c] - a[r][c]) / 3.0)))
    }

    #[test]
    fn the_forward_jacobian_matches_differences_along_every_kind_of_chain() {
        let solver = Solver::new(&super::threads::whitted_row());
        let points = solver.solve(&|| false);
        let (mut checked, mut refractions, mut long) = (0, 0, 0);
        for p in &points {
            // At the root and off it, where Newton's method steers.
            for offset in [[0.0, 0.0], [0.37, -0.21], [-1.3, 0.8]] {
                let s = [p.film[0] + offset[0], p.film[1] + offset[1]];
                let Some(at) = solver.residual(s, &p.chain, Blockers::Checked) else { continue };
                // Differences err by truncation (large steps near a caustic) or by the residual's
                // rounding (small steps along long chains): the forward Jacobian must match them
                // at one of the steps, to 1e-4 of its largest entry.
                let errors: Vec<f64> = [1e-2, 1e-3, 1e-4, 1e-5]
                    .into_iter()
                    .filter_map(|h| differences(&solver, s, &p.chain, h))
                    .map(|want| {
                        let size = want.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
                        (0..4).map(|k| (at.j[k / 2][k % 2] - want[k / 2][k % 2]).abs()).fold(0.0, f64::max)
                            / size
                    })
                    .collect();
                if errors.is_empty() {
                    continue;
                }
                let best = errors.iter().copied().fold(f64::INFINITY, f64::min);
                assert!(
                    best < 1e-4,
                    "chain {:?} at {s:?}: forward {:?}, relative errors {errors:?}",
                    p.chain,
                    at.j
                );
                checked += 1;
                refractions += usize::from(p.chain.iter().any(|&(_, e)| e == Event::Refract));
                long += usize::from(p.chain.len() >= 3);
            }
        }
        assert!(
            checked > 100 && refractions > 20 && long > 20,
            "{checked} checked, {refractions} refracting, {long} long"
        );
    }
}
