//! Stop rules: the error target, the time budget, what the error is measured over, and the
//! values each refuses.

use super::*;

#[test]
fn target_error_takes_the_render_past_the_scenes_spp() {
    let meta = render_16_exr(&["--target-error", "0.05"]);
    assert_eq!(field(&meta, "stopped_by"), "target_error");
    let spp: u32 = field(&meta, "spp").parse().unwrap();
    assert!(spp > 16, "stopped at {spp} spp: the scene's spp = 16 capped the error target");
    let error: f64 = field(&meta, "estimated_relative_error").parse().unwrap();
    assert!(error <= 0.05, "{error}");
    assert_eq!(meta.renderer, "pathtrace");
}

#[test]
fn a_time_budget_finishes_one_pass_and_says_it_stopped_on_time() {
    let meta = render_16_exr(&["--time-budget", "0.001"]);
    assert_eq!(field(&meta, "stopped_by"), "time_budget");
    let spp: u32 = field(&meta, "spp").parse().unwrap();
    assert!(spp >= 1, "a time budget must not stop inside the first pass");
    assert!(field(&meta, "estimated_relative_error").parse::<f64>().is_ok());
}

#[test]
fn bad_stop_rules_and_exposures_are_clear_errors() {
    for (args, expected) in [
        (&["--time-budget", "1e30"][..], "too large"),
        (&["--time-budget", "0"][..], "above 0"),
        (&["--target-error", "0"][..], "above 0"),
        (&["--target-error", "-0.5"][..], "above 0"),
        (&["--exposure", "nan"][..], "neither auto nor a finite number of stops"),
        (&["--exposure", "inf"][..], "neither auto nor a finite number of stops"),
        (&["--exposure", "-inf"][..], "neither auto nor a finite number of stops"),
        (&["--exposure", "1e10"][..], "at most 64 stops"),
        (&["--exposure", "-65"][..], "at most 64 stops"),
    ] {
        let out = run(args);
        assert_no_panic(&out);
        assert_refused(&out, &format!("{args:?}"), &[args[0], expected]);
    }
}

/// `--error-percentile` and `--region` say what `--target-error` is measured over; bad values
/// are refused naming the flag, the value and what is allowed (for a region, the valid names).
#[test]
fn error_percentile_and_region_refuse_bad_values_and_stop_on_their_error() {
    for bad in ["0", "101", "-3", "ninety"] {
        let out = run(&["--target-error", "0.1", "--error-percentile", bad]);
        assert_refused(&out, &format!("--error-percentile {bad}"), &["--error-percentile", bad, "100"]);
        assert_no_panic(&out);
    }
    let out = run(&words(
        "scenes/whitted.toml --renderer pathtrace --width 32 --height 18 --target-error 0.1 --region teapot",
        &[],
    ));
    assert_refused(
        &out,
        "--region teapot",
        &["--region \"teapot\"", "\"glass sphere\"", "\"metal sphere\"", "\"floor\""],
    );
    let out = run(&["--error-percentile", "95"]);
    assert_refused(&out, "--error-percentile without --target-error", &["--target-error"]);
    let out = run(&["--target-error", "0.1", "--error-percentile", "95", "--region", "floor"]);
    assert_refused(&out, "both", &["not both"]);

    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("glass.exr");
    let exr_text = exr.to_str().unwrap();
    let args = words(
        "scenes/whitted.toml --renderer pathtrace --width 32 --height 18 --target-error 0.05 --region",
        &["glass sphere", "-o", exr_text],
    );
    let out = run(&args);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(field(&metadata(&exr), "stopped_by"), "target_error");
    let error = illum::image::load_f32_layer(&exr, "illum.error").unwrap().expect("an illum.error layer");
    assert_eq!(error.channels.len(), 1);
    assert_eq!(error.channels[0].1.len(), 32 * 18);
}

/// Misuse found by trying the command as a new user: each gets an answer that says what is
/// allowed, and nothing is announced, rendered or rewritten for nothing.
#[test]
fn negative_counts_adaptive_without_spp_and_a_resume_with_nothing_to_do_get_clear_answers() {
    for (flag, value, expected) in [
        ("--spp", "-1", "--spp = -1: must be a whole number from 1"),
        ("--seed", "-1", "--seed = -1: must be a whole number from 0"),
        ("--width", "-5", "--width = -5: must be a whole number from 1"),
        ("--bounces", "-1", "\"-1\""),
    ] {
        let out = run(&[flag, value, "-o", "target/never.png"]);
        assert_refused(&out, &format!("{flag} {value}"), &[expected]);
        assert!(!text(&out.stderr).contains("-- -1"), "{flag} {value}: clap's tip: {}", text(&out.stderr));
    }
    let out = run(&["--adaptive", "--width", "8", "--height", "8", "-o", "target/never.png"]);
    assert_refused(&out, "--adaptive without --spp", &["--adaptive needs --spp N"]);
    assert!(!text(&out.stdout).contains("no stop rule given"), "announced: {}", text(&out.stdout));

    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("done.exr");
    let path = exr.to_str().unwrap();
    render_ok(&["--spp", "16", "-o", path]);
    let before = std::fs::read(&exr).unwrap();
    let out = run(&["--resume", path, "--spp", "16"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("nothing to render"), "{}", text(&out.stdout));
    assert!(!text(&out.stdout).contains("Msamples/s"), "a summary of no render: {}", text(&out.stdout));
    assert_eq!(std::fs::read(&exr).unwrap(), before, "the finished file was rewritten");
    // With another output, that one is written from the file's samples.
    let png = dir.path().join("done.png");
    let out = run(&["--resume", path, "--spp", "16", "-o", png.to_str().unwrap()]);
    assert!(out.status.success() && png.exists(), "{}", text(&out.stderr));
    assert_eq!(std::fs::read(&exr).unwrap(), before);
}

/// The summary names the sequence the samples came from, and an error that cannot be estimated
/// yet (a low-discrepancy render's comes from the spread of its replicates, two of which need
/// 8 spp) is said to be unknown, with the spp it needs, never shown as infinite.
#[test]
fn the_summary_names_the_sequence_and_an_error_not_yet_known_says_what_it_needs() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("x.png");
    let out = run_to("--width 8 --height 8 --spp 4 --sequence low-discrepancy", &[&png]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    assert!(stdout.contains("cosine sampling, low-discrepancy samples"), "{stdout}");
    assert!(stdout.contains("estimated relative error unknown until 8 spp"), "{stdout}");
    assert!(!stdout.contains("inf"), "{stdout}");
    let out = run_to("--width 8 --height 8 --spp 8 --sequence low-discrepancy", &[&png]);
    let stdout = text(&out.stdout);
    let error = stdout.split("estimated relative error ").nth(1).and_then(|rest| rest.split('%').next());
    assert!(error.is_some_and(|e| e.parse::<f64>().is_ok_and(f64::is_finite)), "{stdout}");
    let out = run_to("--width 8 --height 8 --spp 2", &[&png]);
    assert!(text(&out.stdout).contains("cosine sampling, independent samples"), "{}", text(&out.stdout));
}
