//! The GPU Whitted ray tracer against the independent f64 copy of the algorithm
//! (`illum_oracle::whitted`), pixel by pixel, on both scenes at depths 0, 1, 2 and 8, by the
//! criterion of `illum_oracle::whitted_agreement` (a per-pixel tolerance from f32 rounding, and
//! differences beyond it only at edges that f32 can flip, at most 0.5% of the pixels).
//!
//! - **Power.** The same comparison must fail the GPU image with a 4 x 4 patch of smooth
//!   pixels made 3% brighter, or one pixel made 1% brighter.

use illum_gpu::testing::gpu;
use illum_image::RgbImage32;
use illum_oracle::WhittedOracle;
use illum_oracle::whitted_agreement::{compare, edge_change, tolerance};
use illum_scene::Scene;
use illum_whitted::WhittedTracer;

fn render(scene: &Scene) -> (RgbImage32, WhittedOracle, Vec<[f64; 3]>) {
    let image = WhittedTracer::new(gpu(), scene).unwrap_or_else(|e| panic!("{e}")).render().unwrap();
    let oracle = WhittedOracle::new(scene).unwrap_or_else(|e| panic!("{e}"));
    let reference = oracle.render(2);
    (image, oracle, reference)
}

/// The top-left corner of a 4 x 4 block of pixels whose rays change by at most 1e-3 of a pixel
/// when they move (no edge in it, so a 1% error there is not explained by one) and are not
/// black, nearest the image's centre.
fn smooth_block(oracle: &WhittedOracle, reference: &[[f64; 3]], width: u32, height: u32) -> (u32, u32) {
    let smooth = |x: u32, y: u32| {
        reference[(y * width + x) as usize].iter().any(|&c| c > 0.05) && edge_change(oracle, x, y) <= 1e-3
    };
    let mut blocks: Vec<(u32, u32)> =
        (0..height - 3).step_by(4).flat_map(|y| (0..width - 3).step_by(4).map(move |x| (x, y))).collect();
    blocks.sort_by_key(|&(x, y)| (2 * x + 4).abs_diff(width) + (2 * y + 4).abs_diff(height));
    blocks
        .into_iter()
        .find(|&(x0, y0)| (y0..y0 + 4).all(|y| (x0..x0 + 4).all(|x| smooth(x, y))))
        .expect("a smooth 4 x 4 block")
}

/// The comparison passes the GPU's image and fails it with a small local error: a 4 x 4 patch
/// of smooth pixels 3% too bright, or one of them 1% too bright.
fn check(name: &str, scene: &Scene) {
    let depth = scene.whitted.depth;
    let (image, oracle, reference) = render(scene);
    let comparison = compare(&image, &reference, &oracle, depth);
    println!(
        "{name}, depth {depth}: {} of {} pixels at edges beyond {:.1e}; largest difference within it {:.2e}",
        comparison.edges,
        comparison.pixels,
        tolerance(depth),
        comparison.worst_within
    );
    assert!(comparison.passes(), "{name}, depth {depth}: {comparison:?}");

    let (x0, y0) = smooth_block(&oracle, &reference, image.width, image.height);
    let brighten = |pixels: &[(u32, u32)], factor: f32| {
        let mut wrong = image.clone();
        for &(x, y) in pixels {
            let p = &mut wrong.pixels[(y * image.width + x) as usize];
            *p = p.map(|c| c * factor);
        }
        compare(&wrong, &reference, &oracle, depth)
    };
    let patch: Vec<(u32, u32)> = (y0..y0 + 4).flat_map(|y| (x0..x0 + 4).map(move |x| (x, y))).collect();
    for (what, pixels, factor) in
        [("a 4 x 4 patch 3% too bright", &patch[..], 1.03), ("one pixel 1% too bright", &patch[5..6], 1.01)]
    {
        let wrong = brighten(pixels, factor);
        assert!(!wrong.passes(), "{name}, depth {depth}: {what} at ({x0}, {y0}) passes: {wrong:?}");
    }
}

#[test]
fn the_whitted_scene_matches_the_f64_copy() {
    for depth in [0, 1, 2, 8] {
        let mut scene = illum_scene::testing::shipped_scene("whitted.toml", 160, 90);
        scene.whitted.depth = depth;
        check("whitted", &scene);
    }
}

#[test]
fn the_cornell_box_matches_the_f64_copy() {
    for depth in [0, 1, 2, 8] {
        let mut scene = illum_scene::testing::shipped_scene("cornell.toml", 64, 64);
        scene.whitted.depth = depth;
        check("cornell", &scene);
    }
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
        let (image, oracle, reference) = render(&scene);
        assert!(
            image.pixels.iter().flatten().all(|c| c.is_finite() && *c >= 0.0),
            "ior {ior}, depth {depth}"
        );
        let comparison = compare(&image, &reference, &oracle, depth);
        println!("ior {ior}, depth {depth}: {comparison:?}");
        assert!(comparison.passes(), "ior {ior}, depth {depth}: {comparison:?}");
    }
}
