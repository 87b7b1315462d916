//! `render --renderer auto` as a user runs it: every bad goal and every flag that sets what auto
//! chooses is refused before anything is measured or rendered, with a message naming the flag,
//! the value and what is allowed, and never a panic. (Its predictions are checked against the
//! truth in crates/illum-lab/tests/auto.rs and by the auto_check example.)

#[path = "common/binary.rs"]
mod binary;

use binary::{render, text};

#[test]
fn bad_goals_and_settings_auto_chooses_are_refused_by_name() {
    let cases: [(&str, &[&str]); 13] = [
        ("--target-error 0", &["--target-error", "0", "above 0"]),
        ("--target-error -0.1", &["--target-error", "-0.1", "above 0"]),
        ("--target-error nan", &["--target-error", "NaN", "finite"]),
        ("--target-error inf", &["--target-error", "finite"]),
        ("--time-budget 0", &["--time-budget", "0", "above 0"]),
        ("--time-budget -5", &["--time-budget", "-5", "above 0"]),
        ("--time-budget 1e12", &["--time-budget", "1000000000000", "30 days"]),
        ("", &["--renderer auto needs a goal", "--target-error", "--time-budget"]),
        ("--target-error 0.1 --time-budget 5", &["one goal", "not both"]),
        (
            "--target-error 0.1 --spp 16 --depth 2",
            &["--spp, --depth", "chooses the renderer and its settings"],
        ),
        ("--target-error 0.1 --caustics on --no-shadows", &["--caustics, --no-shadows"]),
        ("--target-error 0.1 --resume x.exr", &["--resume"]),
        ("--target-error 0.1 --denoise atrous --adaptive", &["--adaptive, --denoise"]),
    ];
    for (flags, expected) in cases {
        let mut args = vec!["scenes/whitted.toml", "--renderer", "auto"];
        args.extend(flags.split_whitespace());
        let out = render(&args).output().expect("the render example starts");
        let stderr = text(&out.stderr);
        assert!(!out.status.success(), "{flags}: accepted: {}", text(&out.stdout));
        assert!(out.status.code() != Some(101) && !stderr.contains("panicked"), "{flags}: {stderr}");
        for part in expected {
            assert!(stderr.contains(part), "{flags}: the refusal lacks {part:?}: {stderr}");
        }
        // Refused before the pilot: nothing measured, nothing printed.
        assert!(!text(&out.stdout).contains("auto: pilot"), "{flags}: {}", text(&out.stdout));
    }
    let out = render(&["scenes/whitted.toml", "--renderer", "automatic"]).output().expect("starts");
    assert!(
        text(&out.stderr).contains("\"automatic\" is not a renderer")
            && text(&out.stderr).contains("\"auto\"")
    );
}
