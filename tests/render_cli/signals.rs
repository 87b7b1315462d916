//! Ctrl-C and SIGTERM: what an interrupted render keeps, and a resume that continues it bit
//! for bit.

use super::*;

#[cfg(unix)]
#[test]
fn sigterm_and_sigint_write_what_has_accumulated_and_exit_143_and_130() {
    let dir = tempfile::tempdir().unwrap();
    for (name, code) in [("TERM", 143), ("INT", 130)] {
        let exr = dir.path().join(format!("{name}.exr"));
        let (mut child, lines) = start_long_render("32", "100000000", &exr, 1);
        signal(&child, name);
        let rest: Vec<String> = lines.map_while(Result::ok).collect();
        let status = child.wait().expect("the render ends");
        assert!(rest.iter().any(|l| l.contains(&format!("stopped by SIG{name}"))), "{rest:?}");
        assert_eq!(status.code(), Some(code), "SIG{name}");
        let meta = metadata(&exr);
        assert_eq!(field(&meta, "stopped_by"), "cancelled");
        assert!(field(&meta, "spp").parse::<u32>().unwrap() >= 1);
    }
}

#[cfg(unix)]
#[test]
fn a_signal_before_the_first_complete_pass_writes_nothing_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("none.exr");
    // 4096 x 4096 at 1 spp: the first pass takes seconds on lavapipe; the signal comes at once.
    let (mut child, lines) = start_long_render("4096", "1", &exr, 0);
    signal(&child, "TERM");
    let stderr = lines.map_while(Result::ok).collect::<Vec<_>>().join("\n");
    let status = child.wait().expect("the render ends");
    assert_eq!(status.code(), Some(143), "{stderr}");
    if stderr.contains("pass complete") {
        // The signal arrived after all (a fast device): the render must then have been kept.
        assert!(exr.exists());
    } else {
        assert!(!exr.exists(), "wrote an image with no complete pass");
        assert!(
            stderr.contains("SIGTERM before the first complete pass")
                && stderr.contains("nothing was written"),
            "{stderr}"
        );
    }
}

#[cfg(unix)]
#[test]
fn sigint_mid_render_then_resume_equals_a_straight_render_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let (partial, straight) = (dir.path().join("partial.exr"), dir.path().join("straight.exr"));
    let target = 8192;
    let (mut child, lines) = start_long_render("32", &target.to_string(), &partial, 1);
    signal(&child, "INT");
    let _: Vec<String> = lines.map_while(Result::ok).collect();
    assert_eq!(child.wait().expect("the render ends").code(), Some(130));

    // The partial file: valid, below the target, no NaN, marked as cancelled.
    let meta = metadata(&partial);
    assert_eq!(field(&meta, "stopped_by"), "cancelled");
    let spp: u32 = field(&meta, "spp").parse().unwrap();
    assert!((1..target).contains(&spp), "interrupted at {spp} spp of {target}");
    let (image, _) = illum::image::load_exr(&partial).unwrap();
    assert!(image.pixels.iter().flatten().all(|v| v.is_finite()), "NaN or Inf in the partial image");

    let resumed = render_ok(&["--resume", partial.to_str().unwrap(), "--spp", &target.to_string()]);
    assert!(text(&resumed.stdout).contains(&format!("resuming {}: {spp} spp done", partial.display())));
    render_ok(&["--spp", &target.to_string(), "-o", straight.to_str().unwrap()]);
    assert_eq!(field(&metadata(&partial), "spp"), target.to_string());
    assert!(
        statistics_bits(&partial) == statistics_bits(&straight),
        "the resumed render differs from the straight one"
    );
    let ((a, _), (b, _)) =
        (illum::image::load_exr(&partial).unwrap(), illum::image::load_exr(&straight).unwrap());
    assert_eq!(a, b, "mean images differ");
}
