//! The GPU Whitted ray tracer against the independent f64 copy of the algorithm
//! (`illum_oracle::whitted`), pixel by pixel, on both scenes at depths 0, 1, 2 and 8.
//!
//! Tolerance: a pixel agrees when its channels differ by at most 1e-3 (relative to the larger
//! of 1 and the oracle's value): f32 against f64 arithmetic along a few bounces stays far
//! below that. A ray that grazes an edge (a silhouette, a shadow boundary, a tile border) can
//! fall on the other side in f32, which changes that ray's whole colour; such pixels are
//! allowed, up to 1% of the image. At least 90% of the pixels must also agree within 1e-5.

use illum_gpu::testing::gpu;
use illum_oracle::WhittedOracle;
use illum_scene::Scene;
use illum_whitted::WhittedTracer;

/// The fraction of pixels that agree within 1e-3, the fraction within 1e-5, and the count.
fn agreement(scene: &Scene) -> (f64, f64, usize) {
    let gpu_image = WhittedTracer::new(gpu(), scene).unwrap_or_else(|e| panic!("{e}")).render().unwrap();
    let oracle = WhittedOracle::new(scene).unwrap_or_else(|e| panic!("{e}")).render(2);
    let (mut agree, mut close) = (0usize, 0usize);
    for (g, o) in gpu_image.pixels.iter().zip(&oracle) {
        let diff = (0..3).map(|c| (f64::from(g[c]) - o[c]).abs() / o[c].max(1.0)).fold(0.0, f64::max);
        agree += usize::from(diff <= 1e-3);
        close += usize::from(diff <= 1e-5);
    }
    let n = oracle.len() as f64;
    (agree as f64 / n, close as f64 / n, oracle.len())
}

fn check(name: &str, width: u32, height: u32) {
    for depth in [0, 1, 2, 8] {
        let mut scene = illum_scene::testing::shipped_scene(name, width, height);
        scene.whitted.depth = depth;
        let (agree, close, pixels) = agreement(&scene);
        assert!(agree >= 0.99, "{name}, depth {depth}: only {:.2}% of {pixels} pixels agree", 100.0 * agree);
        // Most pixels agree to f32 rounding, not just within the tolerance.
        assert!(close >= 0.9, "{name}, depth {depth}: only {:.2}% of pixels within 1e-5", 100.0 * close);
    }
}

#[test]
fn the_whitted_scene_matches_the_f64_copy() {
    check("whitted.toml", 160, 90);
}

#[test]
fn the_cornell_box_matches_the_f64_copy() {
    check("cornell.toml", 64, 64);
}

#[test]
fn a_sun_of_finite_size_is_refused_by_name() {
    let mut scene = illum_scene::testing::shipped_scene("whitted.toml", 8, 8);
    if let Some(sun) = &mut scene.directional_light {
        sun.angular_radius_deg = 0.5;
    }
    let err = WhittedTracer::new(gpu(), &scene).err().expect("refused").to_string();
    assert!(err.contains("Whitted ray tracer cannot render") && err.contains("sun disc"), "{err}");
}

#[test]
fn extremes_agree_with_the_f64_copy_and_stay_finite() {
    // Depth 64 and total-internal-reflection chains (index 4), a glass barely denser than air
    // (1.0001) and one that vanishes (1), on the Whitted scene.
    for (ior, depth) in [(4.0f32, 64u32), (1.0001, 8), (1.0, 8), (1.4285715, 64)] {
        let mut scene = illum_scene::testing::shipped_scene("whitted.toml", 96, 54);
        for m in &mut scene.materials {
            if let illum_scene::MaterialKind::Dielectric { ior: value } = &mut m.kind {
                *value = ior;
            }
        }
        scene.whitted.depth = depth;
        let image = WhittedTracer::new(gpu(), &scene).unwrap().render().unwrap();
        assert!(
            image.pixels.iter().flatten().all(|c| c.is_finite() && *c >= 0.0),
            "ior {ior}, depth {depth}"
        );
        let (agree, _, pixels) = agreement(&scene);
        assert!(
            agree >= 0.99,
            "ior {ior}, depth {depth}: only {:.2}% of {pixels} pixels agree",
            100.0 * agree
        );
    }
}
