//! The renderers other than the default path: the rasterizer, the Whitted ray tracer, the
//! caustic's light tracer, adaptive sampling and `--reference`.

use super::*;

#[test]
fn raster_scenes_refuse_path_tracer_flags_and_write_their_own_metadata() {
    let out = run(&["scenes/whitted.toml", "--sequence", "low-discrepancy", "-o", "target/never.png"]);
    assert_refused(&out, "--sequence on a raster scene", &["--sequence applies only to the path tracer"]);

    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("w.exr");
    let out = run_to("scenes/whitted.toml --width 32 --height 18 --no-msaa", &[&exr]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let meta = metadata(&exr);
    assert_eq!(meta.renderer, "raster");
    for key in ["spp", "bounces", "seed", "sampling"] {
        assert!(meta.get(key).is_none(), "a raster EXR carries the path tracer's illum.{key}: {meta:?}");
    }
    assert_eq!(field(&meta, "look"), "figure");
    // --no-msaa is the former name of --no-antialiasing.
    assert_eq!(field(&meta, "antialiasing"), "off, 1 sample per pixel");
}

#[test]
fn the_whitted_ray_tracer_renders_both_scenes_and_refuses_the_other_renderers_flags() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("w.exr");
    let png = dir.path().join("w.png");
    let out = run_to(
        "scenes/whitted.toml --renderer whitted --width 32 --height 18 --depth 3 --aa 1",
        &[&exr, &png],
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(png.exists());
    let meta = metadata(&exr);
    assert_eq!(meta.renderer, "whitted");
    assert_eq!((field(&meta, "depth"), field(&meta, "aa")), ("3".to_owned(), "1".to_owned()));
    // The Cornell box too (its light as a point light).
    let cornell = dir.path().join("c.png");
    let out = run_to("scenes/cornell.toml --renderer whitted --width 16 --height 16", &[&cornell]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    // Flags of the other renderers, and out-of-range values, are refused before rendering.
    for (args, expected) in [
        (vec!["--renderer", "whitted", "--spp", "4"], "--spp applies to the other renderers"),
        (vec!["--renderer", "whitted", "--no-msaa"], "--no-antialiasing applies to the other renderers"),
        (vec!["--renderer", "whitted", "--depth", "65"], "--depth = 65: must be an integer in 0..=64"),
        (vec!["--renderer", "whitted", "--aa", "0"], "--aa = 0: must be an integer in 1..=16"),
        (vec!["--depth", "2"], "--depth applies only to the Whitted ray tracer"),
    ] {
        let never = dir.path().join("never.png");
        let mut all = vec!["scenes/whitted.toml"];
        all.extend(args);
        all.extend(["-o", never.to_str().unwrap()]);
        let out = run(&all);
        assert_eq!(out.status.code(), Some(1), "{all:?}");
        assert!(text(&out.stderr).contains(expected), "{all:?}: {}", text(&out.stderr));
        assert!(!never.exists());
    }
}

#[test]
fn caustics_on_off_is_recorded_and_a_checkpoint_of_the_other_setting_is_refused() {
    let whitted = ["scenes/whitted.toml", "--renderer", "pathtrace", "--spp", "16"];
    let on = render_16_exr(&whitted);
    assert_eq!(field(&on, "caustics"), "on", "scenes/whitted.toml turns it on");
    let mut off_flags = whitted.to_vec();
    off_flags.extend(["--caustics", "off"]);
    assert_eq!(field(&render_16_exr(&off_flags), "caustics"), "off");
    // The Cornell box has neither a sun nor glass: nothing to light-trace, so asking for it is
    // refused like any other flag that does not apply (and `off` is what it renders anyway).
    let out = run(&["--spp", "16", "--caustics", "on", "-o", "target/never.exr"]);
    assert_refused(
        &out,
        "--caustics on on the Cornell box",
        &["cornell.toml", "--caustics on", "no caustic"],
    );
    assert_eq!(field(&render_16_exr(&["--spp", "16", "--caustics", "off"]), "caustics"), "off");

    // A render with the caustic cannot be continued without it.
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("w.exr");
    let mut args = whitted.to_vec();
    args.extend(["--width", "16", "--height", "16", "-o", exr.to_str().unwrap()]);
    assert!(run(&args).status.success());
    let out = run(&words(
        "scenes/whitted.toml --renderer pathtrace --width 16 --height 16 --caustics off --resume",
        &[exr.to_str().unwrap(), "--spp", "32"],
    ));
    assert_refused(&out, "--caustics off on a resume", &["caustics: on in the file, off now"]);
    // Files name their estimators by a versioned token list (illum.estimators). A file of the
    // sentence that came before it (illum.caustic_estimators), or of no key, is refused on resume
    // and merge with that reason; one whose tokens differ (the gather's first radius rule, or no
    // glint) with the tokens that differ.
    let rendered = illum::pathtrace::checkpoint::load_checkpoint(&exr).unwrap();
    let today = field(&metadata(&exr), "estimators");
    assert_eq!(today, "estimators.v1 camera-paths light-tracer photon-gather.r2 glint-solve");
    let part = dir.path().join("part.exr");
    let args = words(
        "scenes/whitted.toml --renderer pathtrace --width 16 --height 16 --sample-range 16..32 -o",
        &[part.to_str().unwrap()],
    );
    let out = run(&args);
    assert!(out.status.success(), "{}", text(&out.stderr));
    // The glint is the image's exact part, in a layer of its own (illum.exact); the metadata
    // holds its digest, which parts to be merged must share.
    assert_eq!(field(&metadata(&exr), "glint_hash").len(), 16);
    assert!(!rendered.accumulator.exact().is_empty(), "no glint read back from its layer");
    let sentence = "light tracer and photon gather at every diffuse vertex but the camera's own hit (r_1 = 0.02 x the \
                    largest specular radius, r_k = r_1 (k + 1)^(-1/6)); glint solved";
    let first_rule = today.replace("photon-gather.r2", "photon-gather.r1");
    let without_glint = today.replace(" glint-solve", "");
    for (case, estimators, legacy, refusal) in [
        (
            "sentence",
            None,
            Some(sentence),
            vec!["illum.estimators", "older form", "caustic_estimators", "render it again"],
        ),
        ("no-key", None, None, vec!["illum.estimators", "no illum.estimators field", "render it again"]),
        ("first-radius-rule", Some(first_rule.as_str()), None, vec!["photon-gather.r1 in the file only"]),
        ("before-glint", Some(without_glint.as_str()), None, vec!["glint-solve in this render only"]),
    ] {
        let mut older = rendered.clone();
        older.metadata.fields.retain(|(k, _)| k != "estimators" && k != "caustic_estimators");
        if case == "before-glint" {
            older.metadata.fields.retain(|(k, _)| k != "glint_hash");
            older.accumulator.set_exact(Default::default());
        }
        if let Some(value) = estimators {
            older.metadata.fields.push(("estimators".to_owned(), value.to_owned()));
        }
        if let Some(value) = legacy {
            older.metadata.fields.push(("caustic_estimators".to_owned(), value.to_owned()));
        }
        let old = dir.path().join(format!("{case}.exr"));
        illum::pathtrace::checkpoint::save_loaded(&old, &older).unwrap();
        let out = run(&words(
            "scenes/whitted.toml --renderer pathtrace --width 16 --height 16 --resume",
            &[old.to_str().unwrap(), "--spp", "32"],
        ));
        assert_refused(&out, &format!("resuming a file {case}"), &refusal);
        let merged = dir.path().join("never.exr");
        let out = merge(&[old.to_str().unwrap(), part.to_str().unwrap(), "-o", merged.to_str().unwrap()]);
        assert_refused(&out, &format!("merging a file {case}"), &["estimators"]);
        assert!(!merged.exists());
    }

    // A file that keeps its glint as metadata text (illum.glint, the form before its layer) is
    // refused on resume and merge with that reason.
    let mut older = rendered.clone();
    older.metadata.fields.push(("glint".to_owned(), "3:0.5,0.5,0.5".to_owned()));
    let old = dir.path().join("glint-text.exr");
    illum::pathtrace::checkpoint::save_loaded(&old, &older).unwrap();
    let out = run(&words(
        "scenes/whitted.toml --renderer pathtrace --width 16 --height 16 --resume",
        &[old.to_str().unwrap(), "--spp", "32"],
    ));
    let reason = ["illum.glint", "metadata text", "own layer", "render it again"];
    assert_refused(&out, "resuming a file with the glint as text", &reason);
    let merged = dir.path().join("never.exr");
    let out = merge(&[old.to_str().unwrap(), part.to_str().unwrap(), "-o", merged.to_str().unwrap()]);
    assert_refused(&out, "merging a file with the glint as text", &reason);
    assert!(!merged.exists());

    // A bad value and the raster renderer are refused by name.
    let out = run(&["scenes/whitted.toml", "--renderer", "pathtrace", "--caustics", "maybe"]);
    assert_refused(&out, "--caustics maybe", &["neither on nor off"]);
    let out = run(&["scenes/whitted.toml", "--caustics", "on", "-o", "target/never.png"]);
    assert_refused(&out, "--caustics on a raster scene", &["--caustics applies only to the path tracer"]);
}

/// `--adaptive`: the EXR records its allocation (and a uniform render `off`), and what cannot
/// combine with uneven sample counts is refused by name: no budget, a resume or a sample range,
/// the caustic's light tracer, and continuing or merging an adaptive file.
#[test]
fn adaptive_renders_record_their_allocation_and_refuse_what_cannot_combine() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("adaptive.exr");
    let path = exr.to_str().unwrap();
    let out = render_ok(&["--spp", "64", "--adaptive", "-o", path]);
    assert!(text(&out.stdout).contains("adaptive sampling: 8x8 blocks"), "{}", text(&out.stdout));
    assert!(text(&out.stdout).contains("spp on average (adaptive)"), "{}", text(&out.stdout));
    let adaptive = field(&metadata(&exr), "adaptive");
    assert!(adaptive.starts_with("8x8 blocks, ") && adaptive.contains("mean 6"), "{adaptive}");
    assert_eq!(field(&render_16_exr(&["--spp", "16"]), "adaptive"), "off");

    let small = |extra: &[&str]| {
        let mut args = SMALL.to_vec();
        args.extend(extra);
        run(&args)
    };
    assert_refused(&small(&["--adaptive"]), "no budget", &["--adaptive needs --spp N"]);
    assert_refused(
        &small(&["--adaptive", "--sample-range", "0..32"]),
        "a sample range",
        &["--adaptive", "--sample-range", "same samples in every pixel"],
    );
    let uniform = dir.path().join("uniform.exr");
    render_ok(&["--spp", "16", "-o", uniform.to_str().unwrap()]);
    assert_refused(
        &small(&["--adaptive", "--spp", "32", "--resume", uniform.to_str().unwrap()]),
        "a resume",
        &["--adaptive", "--resume"],
    );
    assert_refused(
        &run(&["--resume", path, "--spp", "128"]),
        "continuing an adaptive file",
        &["adaptive.exr", "illum.adaptive", "cannot be continued"],
    );
    let merged = dir.path().join("merged.exr");
    let out = merge(&[path, uniform.to_str().unwrap(), "-o", merged.to_str().unwrap()]);
    assert_refused(&out, "merging an adaptive file", &["illum.adaptive"]);
    assert!(!merged.exists());
    assert_refused(
        &run(&words(
            "scenes/whitted.toml --renderer pathtrace --caustics on --adaptive --spp 16 --width 32 --height 18",
            &[],
        )),
        "the caustic",
        &["adaptive sampling is not available with the caustic"],
    );
    assert_no_panic(&small(&["--adaptive", "--spp", "0"]));
}

/// `--reference FILE.exr`: the rasterizer's and the Whitted tracer's EXRs get the signed
/// difference from a path-traced truth (image minus reference, exactly), and a reference of
/// another scene or size is refused naming both sides, before anything is rendered.
#[test]
fn raster_and_whitted_write_their_signed_difference_from_a_reference() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_owned();
    let size = ["--width", "32", "--height", "18"];
    let with = |extra: &[&str]| {
        let mut args = vec!["scenes/whitted.toml"];
        args.extend(size);
        args.extend(extra);
        run(&args)
    };
    let out = with(&["--renderer", "pathtrace", "--spp", "64", "-o", &p("truth.exr")]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (truth, _) = illum::image::load_exr(p("truth.exr")).unwrap();
    for renderer in ["raster", "whitted"] {
        let exr = p(&format!("{renderer}.exr"));
        let out = with(&["--renderer", renderer, "--reference", &p("truth.exr"), "-o", &exr]);
        assert!(out.status.success(), "{renderer}: {}", text(&out.stderr));
        assert!(text(&out.stdout).contains("against the reference: relMSE"), "{}", text(&out.stdout));
        let (image, _) = illum::image::load_exr(&exr).unwrap();
        let layer =
            illum::image::load_f32_layer(&exr, "illum.difference").unwrap().expect("a difference layer");
        for (c, name) in ["R", "G", "B"].iter().enumerate() {
            let (_, values) = layer.channels.iter().find(|(n, _)| n == name).expect("channel");
            for (i, v) in values.iter().enumerate() {
                assert_eq!(
                    *v,
                    image.pixels[i][c] - truth.pixels[i][c],
                    "{renderer}: pixel {i} channel {name}"
                );
            }
        }
    }
    // Another scene: the Cornell box's truth for the Whitted scene.
    let out = run(&["--width", "32", "--height", "18", "--spp", "2", "-o", &p("cornell.exr")]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let cornell_hash = field(&metadata(Path::new(&p("cornell.exr"))), "scene_hash");
    let whitted_hash = field(&metadata(Path::new(&p("truth.exr"))), "scene_hash");
    let out = with(&["--renderer", "whitted", "--reference", &p("cornell.exr"), "-o", &p("x.exr")]);
    assert_refused(
        &out,
        "a reference of another scene",
        &["--reference", "\"cornell\"", &cornell_hash, "\"whitted\"", &whitted_hash],
    );
    // Another size.
    let out = run(&words(
        "scenes/whitted.toml --renderer raster --width 16 --height 9 --reference",
        &[&p("truth.exr"), "-o", &p("y.exr")],
    ));
    assert_refused(&out, "a reference of another size", &["32 x 18", "16 x 9"]);
    assert!(
        !Path::new(&p("x.exr")).exists() && !Path::new(&p("y.exr")).exists(),
        "a refused render wrote a file"
    );
    let out = with(&["--renderer", "pathtrace", "--reference", &p("truth.exr")]);
    assert_refused(&out, "--reference with the path tracer", &["--reference", "raster", "whitted"]);
}

/// `convergence --reference` refuses an EXR of another scene, naming both, before rendering.
#[test]
fn a_reference_of_another_scene_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("whitted.exr");
    let out = run(&words(
        "scenes/whitted.toml --renderer pathtrace --width 8 --height 8 --spp 1 -o",
        &[exr.to_str().unwrap()],
    ));
    assert!(out.status.success(), "{}", text(&out.stderr));
    let out = Command::new(example_binary("convergence"))
        .args(["scenes/cornell.toml", "--width", "8", "--height", "8", "--spp-list", "1", "--reference"])
        .arg(&exr)
        .arg("--out")
        .arg(dir.path().join("convergence"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the convergence example starts");
    assert_refused(
        &out,
        "a reference of the Whitted scene for the Cornell box",
        &["\"whitted\"", "\"cornell\"", "illum.scene_hash"],
    );
    assert!(!text(&out.stdout).contains("reference mean luminance"), "{}", text(&out.stdout));
}

/// The ladder's `truth.exr` carries the metadata of the render it is, as every EXR does.
#[test]
fn the_ladders_truth_exr_says_what_it_is() {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(example_binary("ladder"))
        .args(["scenes/whitted.toml", "--width", "32", "--height", "18", "--truth-spp", "64"])
        .args(["--spp-list", "1", "--depths", "1", "--bounce-spp", "0", "--frames", "1", "--out"])
        .arg(dir.path())
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the ladder example starts");
    assert!(out.status.success(), "{}{}", text(&out.stdout), text(&out.stderr));
    let meta = metadata(&dir.path().join("truth.exr"));
    assert_eq!(meta.renderer, "pathtrace");
    assert_eq!(meta.scene, "whitted");
    assert!(meta.render_seconds > 0.0, "render_seconds = {}", meta.render_seconds);
    assert_eq!(field(&meta, "spp"), "64");
    assert_eq!(field(&meta, "caustics"), "on");
}
