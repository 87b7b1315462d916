//! The error a user is shown (estimated from the per-pixel variance, without a reference) tracks
//! the true error against a converged reference within a factor of 1.5, from 8 to 1024 spp, and
//! the error falls at Monte Carlo's 1/sqrt(N) rate.
//!
//! Both are relMSE with the same epsilon: the estimate is mean(Var[mean] / (mean^2 + 0.01)), the
//! truth mean((mean - ref)^2 / (ref^2 + 0.01)). The reference (tests/reference, 16384 spp) has
//! its own variance, 1/16 of the test's at 1024 spp; it is subtracted from the measured error.
//!
//! With two estimators (camera paths plus the caustic's light tracer, whose variances add) the
//! same check runs against an exact closed form in `caustic.rs`
//! (`an_index_1_ball_vanishes_and_the_error_estimate_of_both_estimators_is_honest`).

use illum_image::{load_exr, rel_mse};
use illum_pathtrace::PathTracer;
use illum_scene::{Bounces, Overrides};

use crate::common;

#[test]
fn estimated_relative_error_tracks_the_true_error_within_a_factor_of_1_5() {
    let (reference, _) =
        load_exr(common::crate_path("tests/reference/cornell-64-b2-mean.exr")).expect("reference mean");
    let (reference_variance, _) = load_exr(common::crate_path("tests/reference/cornell-64-b2-variance.exr"))
        .expect("reference variance");
    // The reference's own contribution to the measured relMSE.
    let reference_noise = reference
        .pixels
        .iter()
        .zip(&reference_variance.pixels)
        .map(|(r, v)| (0..3).map(|c| v[c] as f64 / ((r[c] as f64).powi(2) + 1e-2)).sum::<f64>())
        .sum::<f64>()
        / (3.0 * reference.pixels.len() as f64);

    let scene = common::scene(
        "cornell",
        Overrides {
            width: Some(64),
            height: Some(64),
            bounces: Some(Bounces::Fixed(2)),
            seed: Some(4242),
            ..Default::default()
        },
    );
    let mut tracer = PathTracer::new(common::gpu(), &scene).expect("builds");
    let mut log_points = Vec::new();
    for spp in [8, 32, 128, 512, 1024] {
        tracer.render_to_spp(spp).expect("renders");
        let estimated = tracer.accumulator().estimated_rel_mse();
        let measured =
            rel_mse(&tracer.accumulator().mean_image(), &reference).expect("same size") - reference_noise;
        let ratio = estimated / measured;
        println!("{spp:5} spp: estimated relMSE {estimated:.3e}, measured {measured:.3e}, ratio {ratio:.3}");
        log_points.push(((spp as f64).ln(), measured.ln()));
        assert!(
            (1.0 / 1.5..=1.5).contains(&ratio),
            "{spp} spp: estimated relMSE {estimated:.3e} vs measured {measured:.3e} (ratio {ratio:.3})"
        );
    }
    // Monte Carlo converges at O(1/sqrt(N)) in error, so relMSE ~ 1/N: the least-squares slope
    // of log relMSE against log spp must be -1.
    let n = log_points.len() as f64;
    let (mx, my) =
        (log_points.iter().map(|p| p.0).sum::<f64>() / n, log_points.iter().map(|p| p.1).sum::<f64>() / n);
    let slope = log_points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>()
        / log_points.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>();
    println!("slope of log relMSE against log spp: {slope:.3}");
    assert!((slope + 1.0).abs() < 0.1, "relMSE falls as spp^{slope:.3}, not spp^-1");
}
