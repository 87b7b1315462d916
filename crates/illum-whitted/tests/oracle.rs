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
use illum_oracle::whitted_agreement::{compare, power};
use illum_scene::Scene;
use illum_whitted::WhittedTracer;

fn render(scene: &Scene) -> (RgbImage32, WhittedOracle, Vec<[f64; 3]>) {
    let image = WhittedTracer::new(gpu(), scene).unwrap_or_else(|e| panic!("{e}")).render().unwrap();
    let oracle = WhittedOracle::new(scene).unwrap_or_else(|e| panic!("{e}"));
    let reference = oracle.render(2);
    (image, oracle, reference)
}

/// The comparison passes the GPU's image and fails it with a small local error: a 4 x 4 patch
/// of smooth pixels 3% too bright, or one of them 1% too bright.
fn check(name: &str, scene: &Scene) {
    let depth = scene.whitted.depth;
    let (image, oracle, reference) = render(scene);
    let comparison = compare(&image, &reference, &oracle, depth);
    println!("{name}, depth {depth}: {}", comparison.summary(depth));
    assert!(comparison.passes(), "{name}, depth {depth}: {comparison:?}");

    match power(&image, &reference, &oracle, depth) {
        Ok(Some(_)) => {}
        Ok(None) => panic!("{name}, depth {depth}: no smooth block to check the criterion's power on"),
        Err(passed) => panic!("{name}, depth {depth}: {passed}"),
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

/// Small objects past the traversal's literal limit, spheres, quads and boxes of both kinds, go
/// under one BVH (illum-rtcore's analytic_bvh.rs) while the floor stays a literal; the f64 copy
/// tests every object by brute force.
#[test]
fn many_objects_under_the_bvh_match_the_f64_copy() {
    let count = illum_rtcore::analytic_bvh::LITERAL_OBJECTS + 24;
    for depth in [1, 8] {
        let mut scene = illum_scene::testing::with_small_objects(
            illum_scene::testing::shipped_scene("whitted.toml", 96, 54),
            count,
        );
        let bvh = illum_rtcore::Geometry::new(&scene).analytic.expect("a BVH");
        assert_eq!((bvh.objects.len(), bvh.kinds().len()), (count + 2, 4));
        scene.whitted.depth = depth;
        check(&format!("whitted + {count} objects (BVH)"), &scene);
    }
}

/// Past the most objects the hierarchy holds the tracer refuses the scene by count and limit
/// (illum-rtcore's analytic_bvh::check_count), before compiling anything: as literals the
/// traversal would take minutes to compile.
#[test]
fn more_objects_than_the_bvh_holds_are_refused_by_count() {
    use illum_rtcore::analytic_bvh::MAX_BVH_OBJECTS;
    let scene = illum_scene::testing::with_small_objects(
        illum_scene::testing::shipped_scene("whitted.toml", 8, 8),
        MAX_BVH_OBJECTS + 1,
    );
    let err = WhittedTracer::new(gpu(), &scene).err().expect("refused").to_string();
    // The Whitted scene's own two spheres make MAX_BVH_OBJECTS + 3; its floor is not counted.
    let count = format!("{} non-emitting spheres, quads and boxes", MAX_BVH_OBJECTS + 3);
    assert!(err.contains(&count) && err.contains(&format!("at most {MAX_BVH_OBJECTS}")), "{err}");
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
