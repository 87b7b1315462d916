//! `--renderer auto`'s predictions against measurement on a small case: the Whitted scene at
//! 96x54, planned from a pilot at 48x27 (so the scaling from the pilot's size to the render's
//! is checked too), each choice rendered and compared with a path-traced truth at 96x54.
//! The predicted relative error must be within a factor 1.5 of the measured one.

use illum_auto::plan::{Goal, plan};
use illum_auto::settings::{apply, truth_scene};
use illum_cli::auto::pilot::{PilotOptions, measure};
use illum_gpu::testing::{gpu, workspace_path};
use illum_image::rel_mse;
use illum_lab::auto::render;
use illum_lab::reference::cached_reference;
use illum_scene::{Bounces, Overrides, Scene};

#[test]
fn predicted_errors_are_within_a_factor_1_5_of_the_measured_ones() {
    let mut scene = Scene::load(&workspace_path("scenes/whitted.toml")).unwrap();
    scene
        .apply_overrides(&Overrides { width: Some(96), height: Some(54), ..Default::default() }, "test")
        .unwrap();
    let folder = std::env::temp_dir().join(format!("illum-auto-test-{}", std::process::id()));
    let pilot = illum_auto::pilot::PilotOptions {
        longer_side: 48,
        truth_spp: 2048,
        pilot_spp: 256,
        timing_spp: 16,
        ..illum_auto::pilot::PilotOptions::COMMAND_LINE
    };
    let options = PilotOptions { pilot, folder: folder.clone() };
    let pilot = measure(gpu(), &scene, 0.0, &options, &mut |_, _| {}).unwrap();
    assert_eq!(pilot.size, (48, 27));

    let truth_scene = truth_scene(&scene, Bounces::Unbounded);
    let truth = cached_reference(gpu(), &truth_scene, 2048, &folder, "test truth", &mut |_, _| {}).unwrap();

    let mut renderers = Vec::new();
    for target in [0.3, 0.1, 0.03] {
        let choice = plan(&pilot.candidates, Goal::Error(target)).unwrap().choice;
        let setting = &choice.candidate.setting;
        let (image, _) = render(gpu(), &apply(&scene, setting), setting, choice.spp.unwrap_or(1)).unwrap();
        // The truth's own noise is not the image's error.
        let measured = (rel_mse(&image, &truth.image).unwrap() - truth.estimated_rel_mse).max(0.0).sqrt();
        let ratio = measured / choice.predicted_error;
        println!(
            "target {target}: {}: predicted {:.4}, measured {measured:.4} (x{ratio:.2})",
            choice.describe(),
            choice.predicted_error
        );
        assert!(choice.predicted_error <= target, "{choice:?}");
        assert!((1.0 / 1.5..=1.5).contains(&ratio), "target {target}: {choice:?}: measured {measured}");
        renderers.push(setting.renderer());
    }
    // The cheapest render for 3% needs the caustic's light tracer (without it the glass's
    // shadow alone is half as bright as the truth's).
    let choice = plan(&pilot.candidates, Goal::Error(0.03)).unwrap().choice;
    assert!(
        matches!(choice.candidate.setting, illum_auto::plan::Setting::PathTrace { caustics: true, .. }),
        "{choice:?}"
    );
    // 1% is beyond every deterministic setting: refused by them, met by the path tracer alone.
    let raster_and_whitted: Vec<_> = pilot.candidates.iter().filter(|c| c.noise.is_none()).cloned().collect();
    let why = plan(&raster_and_whitted, Goal::Error(0.01)).unwrap_err();
    assert!(why.contains("rasterizer") && why.contains("Whitted ray tracer"), "{why}");
    println!("renderers chosen: {renderers:?}\n{why}");
    std::fs::remove_dir_all(&folder).unwrap();
}
