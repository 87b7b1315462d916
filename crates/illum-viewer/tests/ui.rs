//! egui_kittest tests that drive the real viewer UI on lavapipe: the mode switch, the path
//! tracer's controls, saving, opening a bad file, that the path tracer's window shows what Save
//! PNG writes, and snapshots of both modes.
//!
//! Both renderers repaint continuously while they work, so the tests step a fixed number of
//! frames (`run_steps`) instead of waiting for the UI to settle.
//!
//! All harnesses share one device, as the real window has one (a device per harness would
//! compile every pipeline again: the pipeline caches belong to each device's `GpuContext`).

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use illum_scene::{Bounces, RendererKind};
use illum_viewer::ViewerApp;

mod common;
use common::{drag_across_the_image, harness_sized, shared_device};

fn harness(mode: RendererKind) -> Harness<'static, ViewerApp> {
    harness_with("scenes/cornell.toml", mode)
}

fn harness_with(scene: &'static str, mode: RendererKind) -> Harness<'static, ViewerApp> {
    harness_sized(scene, mode, egui::vec2(900.0, 560.0))
}

/// Clicks the widget labelled `label` and runs the frame that reacts to it.
fn click(harness: &mut Harness<'_, ViewerApp>, label: &str) {
    harness.get_by_label(label).click();
    harness.run_steps(1);
}

fn spp(harness: &Harness<'_, ViewerApp>) -> u32 {
    harness.state().pathtrace().expect("path tracer loaded").stats().spp
}

#[test]
fn switching_modes_keeps_each_modes_settings() {
    let mut harness = harness(RendererKind::PathTrace);
    harness.run_steps(2);
    click(&mut harness, "Uniform");

    harness.get_by_label("Raster").click();
    harness.run_steps(2);
    assert_eq!(harness.state().mode(), RendererKind::Raster);
    harness.get_by_label("enhanced").click();
    harness.get_by_label("Anti-aliasing").click();
    harness.run_steps(2);

    harness.get_by_label("Path tracer").click();
    harness.run_steps(2);
    assert_eq!(harness.state().mode(), RendererKind::PathTrace);
    let settings = harness.state().pathtrace().unwrap().settings;
    assert_eq!(settings.sampling, illum_scene::Sampling::Uniform);

    harness.get_by_label("Raster").click();
    harness.run_steps(2);
    let options = harness.state().raster().unwrap().options;
    assert_eq!(options.look, illum_raster::Look::Enhanced);
    assert!(!options.effects.antialiasing);
}

#[test]
fn changing_bounces_restarts_the_accumulation() {
    let mut harness = harness(RendererKind::PathTrace);
    // A pass may take several of the pacer's slices when other tests load the machine.
    for _ in 0..100 {
        harness.run_steps(1);
        if spp(&harness) > 0 {
            break;
        }
    }
    let before = spp(&harness);
    assert!(before > 0, "the path tracer rendered nothing in 100 frames");
    harness.get_by_role_and_label(egui::accesskit::Role::Slider, "Bounces").set_value_accesskit(5.0);
    harness.run_steps(1);
    assert_eq!(harness.state().pathtrace().unwrap().settings.bounces, Bounces::Fixed(5));
    click(&mut harness, "Unbounded");
    assert_eq!(harness.state().pathtrace().unwrap().settings.bounces, Bounces::Unbounded);
    assert!(spp(&harness) < before.max(2), "a bounce change must restart: {} >= {before}", spp(&harness));
}

#[test]
fn pause_and_reset() {
    let mut harness = harness(RendererKind::PathTrace);
    harness.run_steps(6);
    click(&mut harness, "Pause");
    assert!(harness.state().pathtrace().unwrap().paused());
    harness.get_by_label("Reset").click();
    harness.run_steps(2);
    assert_eq!(spp(&harness), 0, "reset while paused leaves no samples");
    harness.get_by_label("Resume").click();
    harness.run_steps(4);
    assert!(!harness.state().pathtrace().unwrap().paused());
    assert!(harness.state().pathtrace().unwrap().stats().elapsed_seconds > 0.0);
}

/// With the view still, every frame carries its share of samples: each frame's submission is
/// a whole pass over the image, and what the frames accumulated is exactly what the planner
/// scheduled for them. (A planner that took the window's drawing for the cost of its samples
/// once shrank each frame's share to a row or two of one pass.)
#[test]
fn every_frame_with_the_view_still_carries_a_whole_pass() {
    let mut harness = harness(RendererKind::PathTrace);
    // The first submission is the planner's probe, which measures what a sample costs.
    harness.run_steps(3);
    click(&mut harness, "Reset");
    harness.run_steps(10);
    let mode = harness.state().pathtrace().expect("path tracer loaded");
    let (work, stats) = (mode.work(), mode.stats());
    let pixels = u64::from(stats.width) * u64::from(stats.height);
    println!("{work:?} over {} x {} pixels: {}", stats.width, stats.height, mode.summary());
    assert!(work.submissions >= 10, "{work:?}: a frame without its submission");
    assert_eq!(mode.total_samples(), work.scheduled_samples, "{work:?}: samples scheduled but not folded");
    assert!(
        work.smallest_submission >= pixels,
        "{work:?}: a frame carried less than one pass over the {pixels} pixels"
    );
    assert_eq!(work.passes, work.submissions, "{work:?}: a submission that did not complete a pass");
}

#[test]
fn saves_png_and_exr_into_a_directory() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("nested").join("render.png");
    let mut harness = harness(RendererKind::PathTrace);
    harness.run_steps(4);
    harness.state_mut().pathtrace_mut().unwrap().save_path = target.display().to_string();
    harness.run_steps(1);
    click(&mut harness, "Save PNG");
    click(&mut harness, "Save EXR");

    let png = image::open(&target).unwrap_or_else(|e| panic!("{}: {e}", target.display()));
    let (w, h) = (png.width(), png.height());
    assert!(w > 0 && h > 0);
    let exr = target.with_extension("exr");
    let (image, attributes) =
        illum_image::load_exr(&exr).unwrap_or_else(|e| panic!("{}: {e}", exr.display()));
    assert_eq!((image.width, image.height), (w, h));
    // One metadata builder with the render example: the same keys, the error and the stop rule.
    let metadata = illum_image::ExrMetadata::from_attributes(&exr, &attributes).unwrap().unwrap();
    assert_eq!(metadata.renderer, "pathtrace");
    assert_eq!(metadata.scene, "cornell", "illum.scene is the scene's name, as the render example writes it");
    for key in ["spp", "bounces", "estimated_relative_error", "dropped_samples", "stopped_by", "sequence"] {
        assert!(metadata.get(key).is_some(), "no illum.{key}: {metadata:?}");
    }
    assert_eq!(metadata.get("source"), Some("illum-viewer"));
    // It is a checkpoint too: the render example can continue it with --resume.
    let checkpoint = illum_pathtrace::checkpoint::load_checkpoint(&exr).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((checkpoint.accumulator.width, checkpoint.accumulator.height), (w, h));
    assert!(checkpoint.spp_done > 0);
    let message = harness.state().pathtrace().unwrap().message.clone().unwrap_or_default();
    assert!(message.starts_with("saved"), "{message}");
}

#[test]
fn a_bad_scene_file_shows_its_error_and_keeps_the_scene() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("broken.toml");
    std::fs::write(&bad, "[camera]\nvfov = \"wide\"\n").unwrap();
    let mut harness = harness(RendererKind::PathTrace);
    harness.run_steps(2);
    harness.state_mut().scene_field = bad.display().to_string();
    harness.run_steps(1);
    harness.get_by_label("Open").click();
    harness.run_steps(2);
    let error = harness.state().open_error.clone().expect("an error is shown");
    assert!(error.contains("broken.toml"), "{error}");
    harness.get_by_label_contains("Could not open the scene");
    assert_eq!(harness.state().mode(), RendererKind::PathTrace);
    assert!(harness.state().pathtrace().unwrap().scene_path().ends_with("scenes/cornell.toml"));
    // A good file of the other kind then opens in its own mode.
    harness.state_mut().scene_field = "scenes/whitted.toml".to_owned();
    harness.run_steps(1);
    harness.get_by_label("Open").click();
    harness.run_steps(2);
    assert_eq!(harness.state().mode(), RendererKind::Raster);
    assert!(harness.state().open_error.is_none());
}

/// The path-tracer window run until its spp target stops it (within 200 frames).
fn stopped_at(spp_target: u32) -> Harness<'static, ViewerApp> {
    let mut harness = harness(RendererKind::PathTrace);
    harness.state_mut().pathtrace_mut().unwrap().settings.stop.spp = Some(spp_target);
    for _ in 0..200 {
        harness.run_steps(1);
        if harness.state().pathtrace().unwrap().stop_reason().is_some() {
            break;
        }
    }
    harness
}

#[test]
fn snapshot_path_tracer() {
    // A fixed spp target makes the image deterministic; the run stops there.
    let mut harness = stopped_at(4);
    assert_eq!(spp(&harness), 4);
    harness.run_steps(2);
    harness.snapshot("viewer_pathtrace");
}

/// The path tracer's image as the window shows it (read back from the display texture).
fn shown(harness: &Harness<'_, ViewerApp>) -> image::RgbaImage {
    let setup = shared_device();
    let gpu = illum_gpu::GpuContext::from_device(setup.device, setup.queue, setup.adapter.get_info());
    let display = harness.state().pathtrace().unwrap().display().expect("an image was shown");
    display.read_shown(&gpu).unwrap_or_else(|e| panic!("{e}")).expect("an image was shown")
}

#[test]
fn the_window_shows_what_save_png_writes() {
    // The window draws the GPU display sum (f32); Save PNG writes the f64 mean. Both encode the
    // same samples with gamma 2.2, so they may differ only where f32 rounding tips a value over
    // a rounding boundary: by one level at most.
    let dir = tempfile::tempdir().unwrap();
    let mut harness = stopped_at(3);
    assert_eq!(spp(&harness), 3);
    let mode = harness.state_mut().pathtrace_mut().unwrap();
    mode.save_path = dir.path().join("shown.png").display().to_string();
    let saved = mode.save("png").unwrap_or_else(|e| panic!("{e}"));
    let png = image::open(&saved).unwrap_or_else(|e| panic!("{}: {e}", saved.display())).to_rgba8();
    let window = shown(&harness);
    assert_eq!(window.dimensions(), png.dimensions());
    let differences: Vec<u8> =
        window.as_raw().iter().zip(png.as_raw()).map(|(a, b)| a.abs_diff(*b)).filter(|&d| d > 0).collect();
    println!("{} of {} channel values differ by one level", differences.len(), png.as_raw().len());
    assert!(differences.iter().all(|&d| d <= 1), "the window differs from the PNG by more than one level");

    // One stop of exposure redraws the same samples twice as bright: level v becomes about
    // 255 (2 (v / 255)^2.2)^(1 / 2.2) = v 2^(1 / 2.2), clamped (the 8-bit v is itself within half
    // a level of the exact value, so allow 2 levels).
    harness.state_mut().pathtrace_mut().unwrap().settings.exposure = 1.0;
    harness.run_steps(2);
    let brighter = shown(&harness);
    for (b, v) in brighter.pixels().zip(window.pixels()) {
        for c in 0..3 {
            let expected = (f64::from(v[c]) * 2f64.powf(1.0 / 2.2)).min(255.0);
            assert!((f64::from(b[c]) - expected).abs() <= 2.0, "{v:?} at +1 stop became {b:?}");
        }
    }
}

/// "Error view" shows the heat map of the estimated error of every pixel, of the samples taken
/// so far, and switching it off shows the image again. On the Cornell box the ceiling, lit only
/// by light from the walls, is noisier than the directly lit floor: its colours are brighter.
#[test]
fn the_error_view_shows_where_the_error_is() {
    let mut harness = stopped_at(16);
    let image_texture = harness.state().pathtrace().unwrap().texture();
    click(&mut harness, "Error view");
    harness.run_steps(2);
    let mode = harness.state().pathtrace().unwrap();
    let (map, samples) = mode.error_view().expect("the error view is on");
    let accumulator = mode.accumulator().expect("a tracer");
    assert_eq!(samples, accumulator.total_samples());
    assert_eq!(map.size, [accumulator.width as usize, accumulator.height as usize]);
    assert_ne!(mode.texture(), image_texture, "the window still shows the image");
    // Mean brightness of a band of rows, in the middle third of the columns.
    let band = |rows: std::ops::Range<usize>| {
        let [w, h] = map.size;
        let (x0, x1) = (w / 3, 2 * w / 3);
        let rows = rows.start * h / 100..rows.end * h / 100;
        let n = (rows.len() * (x1 - x0)) as f64;
        rows.flat_map(|y| (x0..x1).map(move |x| map.pixels[y * w + x]))
            .map(|c| f64::from(c.r()) + f64::from(c.g()) + f64::from(c.b()))
            .sum::<f64>()
            / n
    };
    let (ceiling, floor) = (band(3..10), band(88..97));
    println!("heat-map brightness: ceiling {ceiling:.1}, floor {floor:.1}");
    assert!(ceiling > floor, "ceiling {ceiling:.1} not above floor {floor:.1}");
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("error_view.png");
    let rgba: Vec<u8> = map.pixels.iter().flat_map(|c| c.to_array()).collect();
    image::RgbaImage::from_raw(map.size[0] as u32, map.size[1] as u32, rgba).unwrap().save(&path).unwrap();
    println!("saved {}", path.display());

    click(&mut harness, "Error view");
    harness.run_steps(1);
    let mode = harness.state().pathtrace().unwrap();
    assert!(mode.error_view().is_none());
    assert_eq!(mode.texture(), image_texture);
}

#[test]
fn snapshot_raster() {
    let mut harness = harness_with("scenes/whitted.toml", RendererKind::Raster);
    harness.run_steps(4);
    harness.snapshot("viewer_raster");
}

#[test]
fn dragging_orbits_the_camera_and_reset_camera_restores_it() {
    let mut harness = harness(RendererKind::PathTrace);
    harness.run_steps(4);
    assert!(spp(&harness) > 0);
    // Paused, so that the restart caused by the camera change stays visible as 0 spp.
    click(&mut harness, "Pause");
    drag_across_the_image(&mut harness);
    assert!(!harness.state().pathtrace().unwrap().camera.is_home(), "the drag did not move the camera");
    assert_eq!(spp(&harness), 0, "a camera change restarts the accumulation");
    harness.get_by_label("Reset camera").click();
    harness.run_steps(2);
    assert!(harness.state().pathtrace().unwrap().camera.is_home());
}

/// The view flips between the three renderers: a camera moved in one mode is the camera of
/// the next mode shown, when both show the same scene file; a mode showing another file keeps
/// its own.
#[test]
fn switching_modes_keeps_the_camera_on_the_same_scene() {
    let mut harness = harness_with("scenes/whitted.toml", RendererKind::Whitted);
    harness.run_steps(2);
    drag_across_the_image(&mut harness);
    let moved = harness.state().whitted().unwrap().camera;
    assert!(!moved.is_home(), "the drag did not move the camera");
    click(&mut harness, "Path tracer");
    harness.run_steps(1);
    assert_eq!(harness.state().mode(), RendererKind::PathTrace);
    assert_eq!(harness.state().pathtrace().unwrap().camera, moved);
    click(&mut harness, "Raster");
    harness.run_steps(1);
    assert_eq!(harness.state().raster().unwrap().camera, moved);

    // The Cornell box opened in the path tracer only (the rasterizer cannot draw it): the
    // raster keeps the Whitted scene and its camera, and the box starts from its own.
    harness.state_mut().open(std::path::Path::new("scenes/cornell.toml")).unwrap();
    click(&mut harness, "Path tracer");
    assert!(harness.state().pathtrace().unwrap().camera.is_home());
    assert_eq!(harness.state().raster().unwrap().camera, moved);
}

#[test]
fn the_path_tracer_follows_the_window_size() {
    let mut harness = harness(RendererKind::PathTrace);
    harness.run_steps(3);
    let small = harness.state().pathtrace().unwrap().stats();
    harness.set_size(egui::vec2(1000.0, 700.0));
    harness.run_steps(3);
    let large = harness.state().pathtrace().unwrap().stats();
    assert!(large.width > small.width && large.height > small.height, "{small:?} -> {large:?}");
    harness.state_mut().pathtrace_mut().unwrap().settings.resolution_scale = 0.25;
    harness.run_steps(3);
    let scaled = harness.state().pathtrace().unwrap().stats();
    assert!(scaled.width * 2 <= large.width + 1, "{large:?} -> {scaled:?}");
}

#[test]
fn the_scene_field_follows_the_mode() {
    // Started on the Cornell box but shown in raster mode: the field names the raster's scene.
    let mut harness = harness(RendererKind::Raster);
    harness.run_steps(1);
    assert_eq!(harness.state().scene_field, "scenes/whitted.toml");
    click(&mut harness, "Path tracer");
    assert_eq!(harness.state().scene_field, "scenes/cornell.toml");
}

#[test]
fn a_mode_that_cannot_render_the_opened_scene_says_why() {
    // The Cornell box has boxes and an area light: the rasterizer keeps its own scene and says so.
    let mut harness = harness(RendererKind::Raster);
    harness.run_steps(1);
    let refusal = harness.state().refusal_of(RendererKind::Raster).expect("a refusal for the raster");
    assert!(
        refusal.contains("cornell.toml: objects[0]")
            && refusal.contains("cannot render")
            && refusal.ends_with("showing scenes/whitted.toml"),
        "{refusal}"
    );
    harness.get_by_label_contains("cannot render");
    assert_eq!(harness.state().refusal_of(RendererKind::PathTrace), None);
    // A scene every mode renders clears it.
    harness.state_mut().scene_field = "scenes/whitted.toml".into();
    harness.run_steps(1);
    click(&mut harness, "Open");
    assert_eq!(harness.state().refusal_of(RendererKind::Raster), None);
}

#[test]
fn a_small_window_still_shows_the_image_and_the_panel_hides() {
    let mut harness = harness_sized("scenes/cornell.toml", RendererKind::PathTrace, egui::vec2(200.0, 150.0));
    harness.run_steps(3);
    // A window that starts narrow starts with the settings hidden: the image has the window
    // below a compact, two-line top bar (x 0.5 render scale).
    assert!(!harness.state().show_panel);
    let without = harness.state().pathtrace().unwrap().stats();
    assert!(without.width * 2 >= 180 && without.height * 2 >= 80, "the image is too small: {without:?}");
    // The compact bar's toggle shows them; the panel takes at most half the width.
    harness.get_by_label("Settings").click();
    harness.run_steps(3);
    assert!(harness.state().show_panel);
    let with_panel = harness.state().pathtrace().unwrap().stats();
    assert!(with_panel.width >= 40, "the settings panel covers the image: {with_panel:?}");
    assert!(without.width > with_panel.width, "{with_panel:?} -> {without:?}");
    click(&mut harness, "Settings");
    assert!(!harness.state().show_panel);
    // A wide window has the full bar again.
    harness.set_size(egui::vec2(900.0, 560.0));
    harness.run_steps(1);
    click(&mut harness, "Show settings");
    assert!(harness.state().show_panel);
}

#[test]
fn the_path_tracers_clock_stands_still_while_the_raster_is_shown() {
    let mut harness = harness(RendererKind::PathTrace);
    harness.run_steps(3);
    harness.get_by_label("Raster").click();
    harness.run_steps(2);
    let before = harness.state().pathtrace().unwrap().render_seconds();
    assert!(before > 0.0);
    harness.run_steps(3);
    assert_eq!(harness.state().pathtrace().unwrap().render_seconds(), before);
    harness.get_by_label("Path tracer").click();
    harness.run_steps(3);
    assert!(harness.state().pathtrace().unwrap().render_seconds() > before);
}

#[test]
fn the_whitted_mode_renders_on_change_and_keeps_its_camera() {
    let mut harness = harness(RendererKind::Whitted);
    harness.run_steps(3);
    // The viewer starts the Whitted mode on the Whitted scene (its default scene).
    let first = harness.state().whitted().expect("Whitted mode loaded").frames;
    assert!(first >= 1, "no frame rendered");
    assert!(
        harness.state().whitted().unwrap().message.is_none(),
        "{:?}",
        harness.state().whitted().unwrap().message
    );
    // Nothing changed: no new frame (Whitted is deterministic).
    harness.run_steps(3);
    assert_eq!(harness.state().whitted().unwrap().frames, first);
    // A new depth renders again.
    harness.state_mut().whitted_mut().unwrap().depth = 2;
    harness.run_steps(2);
    assert_eq!(harness.state().whitted().unwrap().frames, first + 1);
    // The mode button shows it, and the other modes keep theirs.
    harness.get_by_label("Path tracer").click();
    harness.run_steps(2);
    assert_eq!(harness.state().mode(), RendererKind::PathTrace);
    harness.get_by_label("Whitted").click();
    harness.run_steps(2);
    assert_eq!(harness.state().whitted().unwrap().depth, 2);
}
