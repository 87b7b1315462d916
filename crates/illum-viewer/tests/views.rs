//! egui_kittest tests of the views that show an image other than the renderer's own: the path
//! tracer's Denoise toggle (`denoise_view.rs`) and the Difference view of the rasterizer and
//! the Whitted tracer (`difference_view.rs`), driven through the real UI on lavapipe.

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use illum_denoise::input::DenoiseInput;
use illum_denoise::{AtrousSettings, bound, reference};
use illum_scene::RendererKind;
use illum_viewer::ViewerApp;

mod common;
use common::{drag_across_the_image, harness_sized};

fn harness(scene: &'static str, mode: RendererKind) -> Harness<'static, ViewerApp> {
    harness_sized(scene, mode, egui::vec2(900.0, 560.0))
}

/// Runs frames until `done` holds (at most `frames`); returns whether it did.
fn run_until(harness: &mut Harness<'_, ViewerApp>, frames: u32, done: impl Fn(&ViewerApp) -> bool) -> bool {
    for _ in 0..frames {
        if done(harness.state()) {
            return true;
        }
        harness.run_steps(1);
    }
    done(harness.state())
}

/// Mean absolute difference between horizontal neighbours' luminance: what noise raises.
fn roughness(image: &illum_image::RgbImage32) -> f64 {
    let w = image.width as usize;
    let lum = |p: [f32; 3]| 0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2]);
    let mut total = 0.0;
    let mut n = 0usize;
    for (i, pair) in image.pixels.windows(2).enumerate() {
        if (i + 1) % w != 0 {
            total += (lum(pair[0]) - lum(pair[1])).abs();
            n += 1;
        }
    }
    total / n as f64
}

/// Denoise on, to 64 spp on the Cornell box: the window shows the à-trous filter of the whole
/// accumulation with the guides it read back (checked against the filter's f64 copy), denoised
/// again as the spp doubles and once more at the end, with the halves' estimate from the
/// accumulation at the previous refresh and the samples after it; the panel shows both errors;
/// Save PNG writes the denoised image; Denoise off shows the noisy one again.
#[test]
fn denoise_shows_the_filtered_accumulation_and_its_estimated_error() {
    let mut harness = harness("scenes/cornell.toml", RendererKind::PathTrace);
    harness.state_mut().pathtrace_mut().unwrap().settings.stop.spp = Some(64);
    harness.run_steps(1);
    let noisy_texture = harness.state().pathtrace().unwrap().texture();
    harness.get_by_label("Denoise").click();
    let finished = run_until(&mut harness, 600, |app| {
        let mode = app.pathtrace().unwrap();
        mode.stop_reason().is_some() && mode.denoise.estimate().is_some_and(|e| e.spp == 64)
    });
    assert!(finished, "no denoised image at 64 spp: {}", harness.state().pathtrace().unwrap().summary());
    harness.run_steps(2);
    let mode = harness.state().pathtrace().unwrap();
    let view = &mode.denoise;
    let estimate = view.estimate().unwrap();
    println!("{}", mode.summary());
    let (a, b) = estimate.halves.expect("halves at the last refresh");
    assert_eq!(a + b, 64, "the halves {a} + {b} are not the whole");
    assert!(a >= 2 && b >= 2, "halves {a}, {b}");
    assert!(view.refreshes >= 2, "{} refreshes", view.refreshes);
    let (noisy, denoised) =
        (estimate.noisy.expect("noisy estimate"), estimate.denoised.expect("denoised estimate"));
    assert!(noisy > 0.0 && denoised > 0.0, "noisy {noisy}, denoised {denoised}");
    assert_ne!(mode.texture(), noisy_texture, "the window still shows the noisy image");
    assert_eq!(mode.texture(), view.texture());

    // The image shown is the filter of this accumulation with these guides, bounded (f32 GPU
    // against f64: docs/denoising.md states 1e-4 relative; the tolerance here adds 1e-6
    // absolute).
    let accumulator = mode.accumulator().unwrap();
    let input = DenoiseInput::from_render(accumulator, view.guides().expect("guides"));
    let (mut expected, _) = reference::denoise(&input, &AtrousSettings::default());
    bound(&input, &mut expected);
    let shown = view.image().unwrap();
    assert_eq!((shown.width, shown.height), (accumulator.width, accumulator.height));
    for (p, (g, c)) in shown.pixels.iter().zip(&expected.pixels).enumerate() {
        for k in 0..3 {
            let (g, c) = (f64::from(g[k]), f64::from(c[k]));
            assert!(
                (g - c).abs() <= 1e-6 + 1e-4 * c.abs(),
                "pixel {p} channel {k}: shown {g}, f64 filter {c}"
            );
        }
    }
    let (raw, smooth) = (roughness(&accumulator.mean_image()), roughness(shown));
    println!("neighbour luminance difference: noisy {raw:.4}, denoised {smooth:.4}");
    // At 64 spp the filter leaves the well-converged pixels alone (measured: 0.74 of the noisy
    // image's neighbour differences); an unfiltered image would be at 1.
    assert!(smooth < 0.9 * raw, "denoised {smooth:.4} not under 0.9 x the noisy {raw:.4}");
    let panel = format!("noisy {:.2}%, denoised {:.2}%", 100.0 * noisy, 100.0 * denoised);
    assert!(harness.query_by_label_contains(&panel).is_some(), "the panel does not show {panel:?}");

    // Save PNG writes what is shown: the denoised image, gamma 2.2.
    let dir = tempfile::tempdir().unwrap();
    let mode = harness.state_mut().pathtrace_mut().unwrap();
    mode.save_path = dir.path().join("denoised.png").display().to_string();
    let saved = mode.save("png").unwrap_or_else(|e| panic!("{e}"));
    let png = image::open(&saved).unwrap().to_rgba8();
    let expected_png =
        illum_image::to_rgba8(mode.denoise.image().unwrap(), 0.0, illum_image::Encoding::Gamma22);
    assert!(png == expected_png, "the saved PNG is not the denoised image");
    // Save EXR stays the raw samples' checkpoint and records the denoised image's estimate.
    let exr = mode.save("exr").unwrap_or_else(|e| panic!("{e}"));
    let (raw, attributes) = illum_image::load_exr(&exr).unwrap();
    let metadata = illum_image::ExrMetadata::from_attributes(&exr, &attributes).unwrap().expect("metadata");
    assert!(raw == mode.accumulator().unwrap().mean_image(), "the EXR is not the raw mean");
    assert_eq!(metadata.get("denoised_spp"), Some("64"));
    let recorded: f64 = metadata.get("denoised_estimated_relative_error").expect("recorded").parse().unwrap();
    assert_eq!(recorded, denoised);
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("denoised.png");
    std::fs::copy(&saved, &path).unwrap();
    println!("saved {}", path.display());

    harness.get_by_label("Denoise").click();
    harness.run_steps(2);
    let mode = harness.state().pathtrace().unwrap();
    assert_eq!(mode.texture(), noisy_texture, "Denoise off does not show the noisy image");
    assert!(mode.denoise.estimate().is_none());
}

/// A drag restarts the accumulation: the denoised image of the old view is dropped at once and
/// a new one, of a few spp, follows within a few frames. Reset drops it too.
#[test]
fn a_drag_gives_a_fresh_denoised_image_at_low_spp() {
    let mut harness = harness("scenes/cornell.toml", RendererKind::PathTrace);
    let mode = harness.state_mut().pathtrace_mut().unwrap();
    mode.settings.denoise = true;
    mode.settings.stop.spp = Some(32);
    let denoised_at_32 = run_until(&mut harness, 400, |app| {
        app.pathtrace().unwrap().denoise.estimate().is_some_and(|e| e.spp == 32)
    });
    assert!(denoised_at_32, "{}", harness.state().pathtrace().unwrap().summary());
    let before = harness.state().pathtrace().unwrap().denoise.refreshes;
    drag_across_the_image(&mut harness);
    let mode = harness.state().pathtrace().unwrap();
    assert!(
        mode.denoise.estimate().is_none_or(|e| e.spp < 32),
        "the old view's denoised image is still shown after the drag"
    );
    let fresh = run_until(&mut harness, 40, |app| app.pathtrace().unwrap().denoise.estimate().is_some());
    let mode = harness.state().pathtrace().unwrap();
    let estimate = mode.denoise.estimate();
    println!("after the drag: {:?}, {}", estimate, mode.summary());
    assert!(fresh, "no denoised image within 40 frames of the drag");
    assert!(
        estimate.unwrap().spp <= 4,
        "the first denoised image after the drag has {} spp",
        estimate.unwrap().spp
    );
    assert!(mode.denoise.refreshes > before);

    // Reset discards the samples, and the denoised image and halves made of them.
    harness.get_by_label("Reset").click();
    harness.run_steps(1);
    let mode = harness.state().pathtrace().unwrap();
    assert!(mode.denoise.estimate().is_none() && mode.denoise.image().is_none(), "{}", mode.summary());
}

/// The path tracer's accumulation of the Whitted scene at 8 spp, then the Whitted mode with the
/// Difference view on (its image is half the view's size, as the path tracer's at scale 0.5).
fn whitted_beside_the_path_tracer() -> Harness<'static, ViewerApp> {
    let mut harness = harness("scenes/whitted.toml", RendererKind::PathTrace);
    let mode = harness.state_mut().pathtrace_mut().unwrap();
    mode.settings.stop.spp = Some(8);
    mode.settings.resolution_scale = 0.5;
    let stopped = run_until(&mut harness, 400, |app| app.pathtrace().unwrap().stop_reason().is_some());
    assert!(stopped, "{}", harness.state().pathtrace().unwrap().summary());
    harness.state_mut().switch_to(RendererKind::Whitted);
    harness.run_steps(2);
    harness.get_by_label("Difference").click();
    run_until(&mut harness, 20, |app| app.whitted().unwrap().difference.summary().is_some());
    // The panel is drawn before the image: one more frame shows the new summary in it.
    harness.run_steps(1);
    harness
}

fn luminance(p: [f32; 3]) -> f64 {
    p.iter().zip(illum_image::rgb_image::REC709_LUMINANCE).map(|(&c, w)| f64::from(c) * w).sum()
}

/// The Whitted image's signed difference from the path tracer's accumulation of the same view,
/// pixel by pixel, with its scale and how converged the truth is; moving the camera in the
/// Whitted mode alone leaves no truth for the new view, which the panel says, and the image is
/// shown again.
#[test]
fn the_whitted_difference_from_the_path_tracers_accumulation() {
    let mut harness = whitted_beside_the_path_tracer();
    let app = harness.state();
    let whitted = app.whitted().unwrap();
    let summary = whitted
        .difference
        .summary()
        .unwrap_or_else(|| panic!("no difference: {:?}", whitted.difference.refusal));
    let (image, _) = whitted.image().unwrap();
    let truth = app.pathtrace().unwrap().accumulator().unwrap().mean_image();
    assert_eq!((image.width, image.height), (truth.width, truth.height));
    for (p, ((a, t), d)) in image.pixels.iter().zip(&truth.pixels).zip(&summary.values).enumerate() {
        let expected = luminance(*a) - luminance(*t);
        // The map holds f32 (6e-8 relative rounding) of differences that may be large.
        assert!(
            (f64::from(*d) - expected).abs() <= 1e-6 * (1.0 + expected.abs()),
            "pixel {p}: {d} against {expected}"
        );
    }
    let beyond = summary.values.iter().filter(|v| f64::from(v.abs()) > summary.scale).count();
    println!(
        "scale {}, mean difference {:+.4} of truth mean {:.4}, {beyond} of {} pixels beyond the scale; {}",
        summary.scale,
        summary.mean_difference,
        summary.truth_mean,
        summary.values.len(),
        summary.truth
    );
    assert!(beyond <= summary.values.len() / 100 + 1, "{beyond} pixels beyond the scale");
    assert!(summary.truth.contains("8 spp"), "{}", summary.truth);
    let panel = format!("+{}", summary.scale);
    assert!(harness.query_by_label(&panel).is_some(), "the panel does not show the scale {panel}");
    assert_eq!(whitted.difference.texture(), harness.state().whitted().unwrap().difference.texture());
    let shown_difference = whitted.difference.texture();
    assert!(shown_difference.is_some());
    save_difference_map("whitted_difference.png", &summary.values, summary.scale, image.width, image.height);

    // Orbit the Whitted camera only: the path tracer's image is of the old view.
    harness.state_mut().whitted_mut().unwrap().camera.orbit(0.2, 0.0);
    run_until(&mut harness, 20, |app| app.whitted().unwrap().difference.summary().is_none());
    let whitted = harness.state().whitted().unwrap();
    let refusal = whitted.difference.refusal.clone().expect("a refusal");
    println!("{refusal}");
    assert!(refusal.contains("another camera"), "{refusal}");
    assert!(whitted.difference.texture().is_none());
}

/// The rasterizer's frame, read back without waiting, and its signed difference from the path
/// tracer's accumulation of the same view (at scale 1: the raster draws the whole view), pixel by
/// pixel; another look is read back again and changes the difference.
#[test]
fn the_raster_difference_from_the_path_tracers_accumulation() {
    let mut harness = harness("scenes/whitted.toml", RendererKind::PathTrace);
    let mode = harness.state_mut().pathtrace_mut().unwrap();
    mode.settings.stop.spp = Some(2);
    mode.settings.resolution_scale = 1.0;
    let stopped = run_until(&mut harness, 400, |app| app.pathtrace().unwrap().stop_reason().is_some());
    assert!(stopped, "{}", harness.state().pathtrace().unwrap().summary());
    harness.state_mut().switch_to(RendererKind::Raster);
    harness.run_steps(2);
    harness.get_by_label("Difference").click();
    let shown = run_until(&mut harness, 40, |app| app.raster().unwrap().difference.summary().is_some());
    let raster = harness.state().raster().unwrap();
    assert!(shown, "no difference: {:?}", raster.difference.refusal);
    let summary = raster.difference.summary().unwrap().clone();
    let (image, scene) = raster.image().unwrap();
    let truth = harness.state().pathtrace().unwrap().accumulator().unwrap().mean_image();
    assert_eq!((image.width, image.height), (truth.width, truth.height));
    assert_eq!((scene.camera.width, scene.camera.height), (image.width, image.height));
    // The frame read back is the raster's 8-bit output: every value a level k / 255.
    assert!(
        image.pixels.iter().flatten().all(|&v| ((v * 255.0).round() - v * 255.0).abs() < 1e-3),
        "a value off the 8-bit levels"
    );
    for (p, ((a, t), d)) in image.pixels.iter().zip(&truth.pixels).zip(&summary.values).enumerate() {
        let expected = luminance(*a) - luminance(*t);
        assert!(
            (f64::from(*d) - expected).abs() <= 1e-6 * (1.0 + expected.abs()),
            "pixel {p}: {d} against {expected}"
        );
    }
    println!(
        "raster: scale {}, mean difference {:+.4} of truth mean {:.4}; {}",
        summary.scale, summary.mean_difference, summary.truth_mean, summary.truth
    );
    assert!(summary.truth.contains("2 spp"), "{}", summary.truth);
    assert!(raster.difference.texture().is_some());
    save_difference_map("raster_difference.png", &summary.values, summary.scale, image.width, image.height);

    // Another look: read back again, another difference.
    let before = image.clone();
    let mode = harness.state_mut().raster_mut().unwrap();
    mode.options.look = match mode.options.look {
        illum_raster::Look::Figure => illum_raster::Look::Enhanced,
        _ => illum_raster::Look::Figure,
    };
    let read_again =
        run_until(&mut harness, 40, |app| app.raster().unwrap().image().is_some_and(|(i, _)| *i != before));
    assert!(read_again, "the new look was not read back");
    harness.run_steps(1);
    let raster = harness.state().raster().unwrap();
    let (image, _) = raster.image().unwrap();
    let again = raster.difference.summary().unwrap();
    let expected = luminance(image.pixels[0]) - luminance(truth.pixels[0]);
    assert!((f64::from(again.values[0]) - expected).abs() <= 1e-6 * (1.0 + expected.abs()));
    assert_ne!(again.values, summary.values);
}

/// `--reference`: an EXR of the same view is the truth (the same difference as from the path
/// tracer it was saved from); one of another scene is refused naming both scenes.
#[test]
fn a_reference_file_is_the_truth_or_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let mut harness = whitted_beside_the_path_tracer();
    let from_path_tracer =
        harness.state().whitted().unwrap().difference.summary().cloned().expect("a difference");
    let mode = harness.state_mut().pathtrace_mut().unwrap();
    mode.save_path = dir.path().join("truth.exr").display().to_string();
    let truth = mode.save("exr").unwrap_or_else(|e| panic!("{e}"));
    harness.state_mut().whitted_mut().unwrap().difference.load_reference(&truth).unwrap();
    harness.run_steps(2);
    let summary = harness.state().whitted().unwrap().difference.summary().cloned().expect("a difference");
    assert!(summary.truth.contains("truth.exr") && summary.truth.contains("8 spp"), "{}", summary.truth);
    assert_eq!(summary.values, from_path_tracer.values);

    // The Cornell box saved at the same size is of another scene.
    let mut cornell = harness_sized_cornell();
    let mode = cornell.state_mut().pathtrace_mut().unwrap();
    mode.save_path = dir.path().join("cornell.exr").display().to_string();
    let other = mode.save("exr").unwrap_or_else(|e| panic!("{e}"));
    harness.state_mut().whitted_mut().unwrap().difference.load_reference(&other).unwrap();
    harness.run_steps(2);
    let whitted = harness.state().whitted().unwrap();
    let refusal = whitted.difference.refusal.clone().expect("a refusal");
    println!("{refusal}");
    for part in ["cornell.exr", "\"cornell\"", "\"whitted\"", "illum.scene_hash"] {
        assert!(refusal.contains(part), "{part:?} not in {refusal}");
    }
    assert!(whitted.difference.summary().is_none() && whitted.difference.texture().is_none());
}

/// A Cornell box path-traced at 2 spp.
fn harness_sized_cornell() -> Harness<'static, ViewerApp> {
    let mut harness = harness("scenes/cornell.toml", RendererKind::PathTrace);
    harness.state_mut().pathtrace_mut().unwrap().settings.stop.spp = Some(2);
    let stopped = run_until(&mut harness, 200, |app| app.pathtrace().unwrap().stop_reason().is_some());
    assert!(stopped);
    harness
}

/// Saves a signed difference map (`values`, one per pixel) in the viewer's diverging colours to
/// `name` in the test's temporary folder, for a person to look at.
fn save_difference_map(name: &str, values: &[f32], scale: f64, width: u32, height: u32) {
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let map: Vec<u8> = values
        .iter()
        .flat_map(|&d| {
            let [r, g, b] = illum_viewer::difference_view::diverging_colour(d, scale as f32);
            [r, g, b, 255]
        })
        .collect();
    image::RgbaImage::from_raw(width, height, map).unwrap().save(&path).unwrap();
    println!("saved {}", path.display());
}
