//! Output files: exposures, PNG-only flags, and outputs checked before anything is rendered.

use super::*;

#[test]
fn a_negative_exposure_is_accepted_as_typed() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("dark.png");
    let out = run_to("--width 8 --height 8 --spp 1 --exposure -1", &[&png]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(png.exists());
}

/// A light of 1e30 is valid, and `--exposure auto` brings its image into view (a fixed
/// exposure stops at 64 stops, far short of the 100 it needs).
#[test]
fn auto_exposure_shows_a_scene_lit_by_a_light_of_1e30() {
    let dir = tempfile::tempdir().unwrap();
    let cornell =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.toml")).unwrap();
    let bright = cornell.replace("emission = [30.0, 30.0, 30.0]", "emission = [1e30, 1e30, 1e30]");
    assert_ne!(bright, cornell, "the Cornell box's emission line moved");
    let scene = dir.path().join("bright.toml");
    std::fs::write(&scene, bright).unwrap();
    let png = dir.path().join("bright.png");
    let out = run(&words(
        "--width 24 --height 24 --spp 8 --exposure auto",
        &[scene.to_str().unwrap(), "-o", png.to_str().unwrap()],
    ));
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("--exposure auto: -9"), "{}", text(&out.stdout));
    let image = image::open(&png).unwrap().to_luma8();
    let mut levels: Vec<u8> = image.pixels().map(|p| p[0]).collect();
    levels.sort_unstable();
    let median = levels[levels.len() / 2];
    assert!((40..=220).contains(&median), "the median grey level is {median}: not brought into view");
}

#[test]
fn png_only_flags_without_a_png_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("x.exr");
    for flags in [&["--encoding", "srgb"][..], &["--exposure", "1"][..]] {
        let mut args = vec!["--width", "8", "--height", "8", "--spp", "1", "-o", exr.to_str().unwrap()];
        args.extend(flags);
        let out = run(&args);
        assert_refused(
            &out,
            &format!("{flags:?} with only an EXR output"),
            &[flags[0], "only to PNG output"],
        );
        assert!(!exr.exists());
    }
}

#[test]
fn outputs_are_checked_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.png");
    // An existing directory as output, and a folder that cannot be created (its parent is a file).
    let directory = dir.path().join("folder.png");
    std::fs::create_dir(&directory).unwrap();
    let plain = dir.path().join("plain");
    std::fs::write(&plain, b"x").unwrap();
    for bad in [directory, plain.join("x.png")] {
        let out = run_to("--width 8 --height 8 --spp 1", &[&good, &bad]);
        assert_no_panic(&out);
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{} was accepted: {stderr}", bad.display());
        assert!(stderr.contains(bad.file_name().unwrap().to_str().unwrap()), "{stderr}");
        assert!(!good.exists(), "rendered and wrote {} before refusing {}", good.display(), bad.display());
    }
}

#[cfg(unix)]
#[test]
fn a_read_only_output_is_refused_and_left_as_it_was() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("keep.png");
    std::fs::write(&png, b"precious").unwrap();
    std::fs::set_permissions(&png, std::fs::Permissions::from_mode(0o444)).unwrap();
    let out = run_to("--width 8 --height 8 --spp 1", &[&png]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("read-only"), "{}", text(&out.stderr));
    assert_eq!(std::fs::read(&png).unwrap(), b"precious");
    assert_eq!(std::fs::metadata(&png).unwrap().permissions().mode() & 0o777, 0o444);
}
