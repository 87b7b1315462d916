//! The viewer's Auto mode, driven through the real UI with egui_kittest on lavapipe: its pilot
//! runs across frames with the viewer's renderers and measures every path-tracer setting raw
//! and denoised by à-trous, the planner's choice is shown in its own mode with its settings
//! (a denoised one through the Denoise toggle), the path tracer stops at the planned spp, and
//! a target no renderer can meet is refused in the panel with each renderer's reason.
//!
//! The pilot here is smaller than the window's default (32 pixels on the longer side, a 512 spp
//! truth) and the path tracer renders at a tenth of the view's size each way, so that a test
//! takes seconds; the rules are the same.

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use illum_auto::pilot::PilotOptions;
use illum_auto::plan::{Candidate, Goal, Plan, Planned, Setting, noise_rel_mse, plan};
use illum_scene::{DenoiserKind, RendererKind};
use illum_viewer::ViewerApp;

mod common;
use common::harness_sized;

/// Most frames a pilot may take here (each runs a slice of it).
const PILOT_FRAMES: usize = 2000;

fn harness(scene: &'static str) -> Harness<'static, ViewerApp> {
    let mut harness = harness_sized(scene, RendererKind::PathTrace, egui::vec2(900.0, 560.0));
    let app = harness.state_mut();
    app.pathtrace_mut().expect("path tracer loaded").settings.resolution_scale = 0.1;
    app.auto_mut().pilot_options = PilotOptions {
        longer_side: 32,
        truth_spp: 512,
        pilot_spp: 32,
        timing_spp: 2,
        ..PilotOptions::VIEWER
    };
    harness
}

/// Clicks Auto and runs frames until its pilot is done; returns the frames it took.
fn run_pilot(harness: &mut Harness<'_, ViewerApp>) -> usize {
    harness.get_by_label("Auto").click();
    for frame in 1..=PILOT_FRAMES {
        harness.step();
        let auto = harness.state().auto();
        if !auto.measuring() && auto.plan().is_some() {
            // The plan is made in the view, after the panel was drawn: one more frame shows it.
            harness.step();
            return frame;
        }
    }
    panic!("the pilot did not finish in {PILOT_FRAMES} frames");
}

/// The plan shown for `target`, checked against what the plan for an error target is, not
/// against the planner that made it (the panel runs that same planner on these candidates).
fn shown_plan(harness: &Harness<'_, ViewerApp>, target: f64) -> Plan {
    let auto = harness.state().auto();
    let shown = auto.plan().expect("planned").clone().expect("a choice");
    check_cheapest_to_meet(auto.candidates().expect("measured"), &shown.choice, target);
    shown
}

/// `choice` is the plan for the error `target` over `candidates` by its definition: one of them,
/// predicted by the error model (relMSE = bias² + the noise curve at the spp; seconds = fixed +
/// spp x seconds per spp) to meet the target, with the fewest samples that do so (in steps of
/// its spp multiple), and no candidate at any spp predicted to meet it in less time. The
/// search scans every spp of every candidate up to the choice's time: it shares nothing with
/// the planner's bisection, sort or tie rule, only the noise curve's reading ([`noise_rel_mse`],
/// unit-tested in illum-auto).
fn check_cheapest_to_meet(candidates: &[Candidate], choice: &Planned, target: f64) {
    let budget = target * target;
    let rel_mse = |c: &Candidate, spp: u32| {
        c.bias_rel_mse + c.noise.as_ref().map_or(0.0, |n| noise_rel_mse(n, f64::from(spp)))
    };
    let seconds = |c: &Candidate, spp: u32| c.fixed_seconds + f64::from(spp) * c.seconds_per_spp;
    let chosen = &choice.candidate;
    assert!(candidates.contains(chosen), "the choice is not a measured candidate: {choice:?}");
    let step = chosen.spp_multiple.max(1);
    match (choice.spp, &chosen.noise) {
        (Some(spp), Some(_)) => {
            assert!(spp > 0 && spp % step == 0, "{spp} spp in steps of {step}");
            assert!(rel_mse(chosen, spp) <= budget, "{choice:?} does not meet {target}");
            assert!(
                spp == step || rel_mse(chosen, spp - step) > budget,
                "{choice:?}: fewer spp meet {target}"
            );
            let predicted = seconds(chosen, spp);
            assert!(
                (choice.predicted_seconds - predicted).abs() <= 1e-9 * predicted,
                "{choice:?}: {predicted} s"
            );
        }
        (None, None) => {
            assert!(chosen.bias_rel_mse <= budget, "{choice:?} does not meet {target}");
            assert_eq!(choice.predicted_seconds, chosen.fixed_seconds, "{choice:?}");
        }
        _ => panic!("an spp for a deterministic renderer, or none for the path tracer: {choice:?}"),
    }
    let cheaper = |s: f64| s < choice.predicted_seconds * (1.0 - 1e-9);
    for c in candidates {
        if c.noise.is_none() {
            assert!(
                !(cheaper(c.fixed_seconds) && c.bias_rel_mse <= budget),
                "{} is cheaper: {choice:?}",
                c.setting
            );
            continue;
        }
        let step = c.spp_multiple.max(1);
        let mut spp = step;
        while cheaper(seconds(c, spp)) && spp <= 1 << 24 {
            assert!(
                rel_mse(c, spp) > budget,
                "{} at {spp} spp meets {target} sooner than {choice:?}",
                c.setting
            );
            spp += step;
        }
    }
}

#[test]
fn a_tighter_target_takes_the_path_tracer_at_the_planned_spp_and_a_loose_one_something_faster() {
    let mut harness = harness("scenes/cornell.toml");
    harness.state_mut().auto_mut().target = 0.1;
    let frames = run_pilot(&mut harness);
    let candidates = harness.state().auto().candidates().unwrap().to_vec();
    eprintln!("pilot: {frames} frames, {} candidates", candidates.len());
    // The Cornell box has no caustic and the rasterizer cannot draw it: Whitted and the path
    // tracer's bounces.
    assert!(candidates.iter().all(|c| c.setting.renderer() != "raster"), "{candidates:?}");
    // Whitted misses the indirect light: its measured bias is far above 10%.
    let whitted_floor = candidates
        .iter()
        .filter(|c| c.setting.renderer() == "whitted")
        .map(|c| c.bias_rel_mse.sqrt())
        .fold(f64::INFINITY, f64::min);
    assert!(whitted_floor > 0.15, "Whitted's smallest bias {whitted_floor}");

    let tight = shown_plan(&harness, 0.1);
    let Setting::PathTrace { bounces, caustics, .. } = tight.choice.candidate.setting.clone() else {
        panic!("10% on the Cornell box is the path tracer's: {:?}", tight.choice)
    };
    let spp = tight.choice.spp.expect("the path tracer's plan has an spp");
    assert!(tight.choice.predicted_error <= 0.1, "{:?}", tight.choice);
    assert_eq!(harness.state().mode(), RendererKind::PathTrace);
    let settings = harness.state().pathtrace().unwrap().settings;
    assert_eq!((settings.bounces, settings.caustics, settings.stop.spp), (bounces, caustics, Some(spp)));
    // The panel names the choice and why Whitted was not picked.
    harness.get_by_label_contains(&format!("Choice: {}", tight.choice.describe()));
    harness.get_by_label_contains("whatever the settings allow it");
    // The path tracer renders the plan and stops at its spp.
    for _ in 0..PILOT_FRAMES {
        harness.step();
        if harness.state().pathtrace().unwrap().stop_reason().is_some() {
            break;
        }
    }
    let pathtrace = harness.state().pathtrace().unwrap();
    assert_eq!(pathtrace.stop_reason(), Some(illum_pathtrace::StopReason::SppReached));
    assert_eq!(pathtrace.stats().spp, spp);
    let reached = pathtrace.stats().relative_error.unwrap();
    eprintln!("planned {spp} spp for 10%: the path tracer's own noise estimate {reached:.4}");

    check_denoised_candidates(&candidates);
    // A denoised choice is shown denoised: the path tracer's Denoise toggle on, stopping at its
    // spp with the denoised image of that spp.
    let denoised: Vec<Candidate> = candidates.iter().filter(|c| is_denoised(&c.setting)).cloned().collect();
    let choice = plan(&denoised, Goal::Error(0.1)).expect("a denoised plan for 10%").choice;
    let spp = choice.spp.expect("an spp");
    let kind =
        illum_viewer::auto_panel::apply_choice(&choice, None, None, harness.state_mut().pathtrace_mut());
    assert_eq!(kind, RendererKind::PathTrace);
    assert!(harness.state().pathtrace().unwrap().settings.denoise);
    for _ in 0..PILOT_FRAMES {
        harness.step();
        let pathtrace = harness.state().pathtrace().unwrap();
        if pathtrace.stop_reason().is_some() && pathtrace.denoise.estimate().is_some_and(|e| e.spp == spp) {
            break;
        }
    }
    let pathtrace = harness.state().pathtrace().unwrap();
    assert_eq!(pathtrace.stop_reason(), Some(illum_pathtrace::StopReason::SppReached));
    assert_eq!(pathtrace.stats().spp, spp);
    assert_eq!(pathtrace.denoise.estimate().map(|e| e.spp), Some(spp), "{}", pathtrace.denoise.summary());
    assert!(pathtrace.denoise.image().is_some() && pathtrace.denoise.texture().is_some());
    eprintln!("{}: {}", choice.describe(), pathtrace.denoise.summary());

    // A loose target: the planner's cheapest choice, faster than the tight one, in its mode.
    harness.state_mut().auto_mut().target = 0.5;
    harness.run_steps(2);
    let loose = shown_plan(&harness, 0.5);
    assert!(loose.choice.predicted_seconds < tight.choice.predicted_seconds, "{loose:?} {tight:?}");
    let shown: RendererKind = loose.choice.candidate.setting.renderer().parse().unwrap();
    assert_eq!(harness.state().mode(), shown);
    match loose.choice.candidate.setting {
        Setting::Whitted { depth, aa } => {
            let whitted = harness.state().whitted().unwrap();
            assert_eq!((whitted.depth, whitted.aa), (depth, aa));
        }
        Setting::PathTrace { bounces, .. } => {
            let settings = harness.state().pathtrace().unwrap().settings;
            assert_eq!((settings.bounces, settings.stop.spp), (bounces, loose.choice.spp));
        }
        Setting::Raster { .. } => panic!("the rasterizer cannot draw the Cornell box"),
    }
    eprintln!(
        "0.5: {} ({:.2} s); 0.1: {} ({:.2} s)",
        loose.choice.describe(),
        loose.choice.predicted_seconds,
        tight.choice.describe(),
        tight.choice.predicted_seconds
    );
}

fn is_denoised(setting: &Setting) -> bool {
    matches!(setting, Setting::PathTrace { denoise: Some(DenoiserKind::Atrous), .. })
}

/// Every raw path-tracer setting has its à-trous variant among the candidates (as the CLI's
/// pilot measures it), with a curve measured at the spp of `denoised_spps`, below the raw
/// setting's noise at 4 spp (the filter ran on that setting's samples).
fn check_denoised_candidates(candidates: &[Candidate]) {
    let raw: Vec<&Candidate> =
        candidates.iter().filter(|c| matches!(c.setting, Setting::PathTrace { denoise: None, .. })).collect();
    let denoised: Vec<&Candidate> = candidates.iter().filter(|c| is_denoised(&c.setting)).collect();
    assert_eq!(raw.len(), 5, "the Cornell box's path tracer: bounces 1, 2, 4, 8, unbounded");
    assert_eq!(denoised.len(), raw.len(), "{candidates:#?}");
    let spps: Vec<f64> = illum_auto::measure::denoised_spps(32).into_iter().map(f64::from).collect();
    for r in raw {
        let Setting::PathTrace { bounces, caustics, .. } = r.setting else { unreachable!() };
        let d = denoised
            .iter()
            .find(|d| matches!(d.setting, Setting::PathTrace { bounces: b, caustics: c, .. } if b == bounces && c == caustics))
            .unwrap_or_else(|| panic!("no denoised variant of {}", r.setting));
        let curve = d.noise.as_ref().expect("a denoised setting has a noise curve");
        assert_eq!(curve.points().iter().map(|p| p.0).collect::<Vec<_>>(), spps, "{}", d.setting);
        let (raw_4, denoised_4) = (noise_rel_mse(r.noise.as_ref().unwrap(), 4.0), noise_rel_mse(curve, 4.0));
        eprintln!(
            "{}: relMSE beyond the bias at 4 spp {raw_4:.2e} raw, {denoised_4:.2e} denoised",
            r.setting
        );
        assert!(denoised_4 < raw_4, "{}: denoised {denoised_4} against raw {raw_4}", r.setting);
        assert!(d.fixed_seconds > 0.0 && d.seconds_per_spp > 0.0, "{d:?}");
    }
}

#[test]
fn a_target_no_renderer_can_meet_is_refused_in_the_panel_with_each_renderers_reason() {
    let mut harness = harness("scenes/whitted.toml");
    harness.state_mut().auto_mut().target = illum_viewer::auto_panel::MIN_TARGET;
    run_pilot(&mut harness);
    let why = harness.state().auto().plan().unwrap().clone().unwrap_err();
    assert!(why.contains("no renderer is predicted to reach a relative error of 0.00001"), "{why}");
    // Each renderer's closest setting and what holds it back: the deterministic ones their
    // bias (the glass's shadow), the path tracer the samples it would need.
    assert!(why.contains("rasterizer") && why.contains("Whitted ray tracer"), "{why}");
    assert!(why.contains("glass sphere's shadow"), "{why}");
    assert!(why.contains("path tracer") && why.contains("samples per pixel"), "{why}");
    harness.get_by_label_contains("no renderer is predicted to reach");
    // The mode shown stays as it was: nothing was applied.
    assert_eq!(harness.state().mode(), RendererKind::PathTrace);
}
