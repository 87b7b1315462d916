//! Radiance at the top of the f32 range. Validation accepts any finite emission up to f32::MAX;
//! the GPU squares samples in f32 for the variance, so an unscaled `emission = 1e30` would give
//! an infinite error estimate while the image stayed finite. The tracer therefore uploads very bright
//! lights scaled by a power of two 2^-k and the f64 fold scales back
//! (`illum_pathtrace::accumulator::radiance_exponent`). These tests check the image, the error
//! estimate, the EXR metadata and the viewer's display sum at the largest accepted value, and
//! that the scaling is exact.

use illum_pathtrace::PathTracer;
use illum_pathtrace::accumulator::radiance_exponent;
use illum_scene::{MaterialKind, Scene};

use crate::common;

fn cornell_with_emission(scale: impl Fn(glam::Vec3) -> glam::Vec3) -> Scene {
    let mut scene = common::scene("cornell", common::small(16, 16, 32));
    for m in &mut scene.materials {
        if let MaterialKind::Emitter { radiance } = &mut m.kind {
            *radiance = scale(*radiance);
        }
    }
    scene
}

#[test]
fn the_largest_accepted_emission_keeps_image_error_and_metadata_finite() {
    // The scene file form: the validator accepts it (it is the largest finite f32).
    let text = std::fs::read_to_string(common::workspace_path("scenes/cornell.toml")).unwrap();
    let light = text.lines().find(|l| l.starts_with("emission = ")).expect("an emission line").to_owned();
    let edited = text.replace(&light, "emission = [3.4028235e38, 30.0, 30.0]");
    let mut scene = Scene::from_toml_str(&edited, "max-emission.toml").expect("f32::MAX is accepted");
    scene.apply_overrides(&common::small(16, 16, 32), "test").unwrap();
    assert!(radiance_exponent(f32::MAX) > 0);

    let mut tracer = PathTracer::new(common::gpu(), &scene).expect("builds");
    tracer.enable_display_sum().unwrap();
    tracer.add_samples_in_one_pass(32).unwrap();
    let acc = tracer.accumulator();
    assert_eq!(acc.dropped_samples(), 0);
    common::assert_all_finite(&acc.mean_image(), "emission f32::MAX");
    let error = acc.estimated_relative_error();
    assert!(error.is_finite() && error > 0.0, "estimated relative error {error}");
    let meta = illum_pathtrace::metadata::exr_metadata(&tracer, 0.0, None, "test");
    let stored: f64 = meta.get("estimated_relative_error").unwrap().parse().unwrap();
    assert!(stored.is_finite(), "illum.estimated_relative_error = {stored}");
    println!(
        "emission f32::MAX: estimated relative error {error:.4}, largest pixel mean {:e}",
        acc.mean_image().pixels.iter().flatten().fold(0.0f32, |m, &v| m.max(v))
    );

    // The display sum holds radiance x 2^-k, finite; x display_scale it is the image.
    let display = crate::display_sum::read_display_sum(&tracer);
    let mean = acc.mean_image();
    let scale = f64::from(tracer.display_scale());
    for (sum, exact) in display.iter().zip(&mean.pixels) {
        assert!(sum.iter().all(|v| v.is_finite()), "display sum {sum:?}");
        for c in 0..3 {
            let shown = f64::from(sum[c]) / f64::from(sum[3]) * scale;
            let exact = f64::from(exact[c]);
            assert!((shown - exact).abs() <= 1e-4 * exact.abs() + 1e-30, "display {shown:e} vs {exact:e}");
        }
    }
}

#[test]
fn a_power_of_two_brighter_light_gives_the_same_image_times_that_power_exactly() {
    // 2^100 puts the light far above 2^16, so it is traced scaled; 2^0 is traced as it is.
    let base = common::render(&cornell_with_emission(|e| e));
    let bright = common::render(&cornell_with_emission(|e| e * 2f32.powi(100)));
    let (a, b) = (base.accumulator(), bright.accumulator());
    let (sa, sb) = (a.state(), b.state());
    for p in 0..sa.count.len() {
        for c in 0..3 {
            assert_eq!(sb.sum[p][c], sa.sum[p][c] * 2f64.powi(100), "pixel {p} channel {c}");
            assert_eq!(sb.sum_sq[p][c], sa.sum_sq[p][c] * 2f64.powi(200), "pixel {p} channel {c}");
        }
    }
    assert!(b.estimated_relative_error().is_finite());
}
