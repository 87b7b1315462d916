//! Long renders: checkpoints, resume, sample ranges and merge, and the files each refuses.

use super::*;

#[test]
fn three_sample_ranges_merged_equal_one_render() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_owned();
    for (range, name) in [("0..48", "a.exr"), ("48..80", "b.exr"), ("80..160", "c.exr")] {
        render_ok(&["--sample-range", range, "-o", &p(name)]);
        assert_eq!(field(&metadata(Path::new(&p(name))), "sample_start"), range.split("..").next().unwrap());
    }
    render_ok(&["--spp", "160", "-o", &p("straight.exr")]);
    // Inputs in any order.
    let out = merge(&[&p("c.exr"), &p("a.exr"), &p("b.exr"), "-o", &p("merged.exr")]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("samples 0..160 (160 spp)"), "{}", text(&out.stdout));
    let difference = max_relative_difference(Path::new(&p("merged.exr")), Path::new(&p("straight.exr")));
    assert!(difference <= 1e-12, "merged differs from one render by {difference:e} relative");
    assert_eq!(field(&metadata(Path::new(&p("merged.exr"))), "spp"), "160");
}

/// What `parallel render ... --sample-range {} ::: 0..64 64..128` runs: two processes at once.
#[test]
fn two_concurrent_processes_like_gnu_parallel_then_merge_equal_one_render() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_owned();
    let children: Vec<(Child, String)> = [("0..64", "r0.exr"), ("64..128", "r1.exr")]
        .into_iter()
        .map(|(range, name)| {
            let mut args = SMALL.to_vec();
            args.extend(["--sample-range", range, "-o"]);
            let path = p(name);
            let child =
                render(&args).arg(&path).stdout(Stdio::null()).stderr(Stdio::piped()).spawn().unwrap();
            (child, path)
        })
        .collect();
    for (child, path) in children {
        let out = child.wait_with_output().unwrap();
        assert!(out.status.success(), "{path}: {}", text(&out.stderr));
    }
    render_ok(&["--spp", "128", "-o", &p("straight.exr")]);
    let out = merge(&[&p("r0.exr"), &p("r1.exr"), "-o", &p("merged.exr")]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let difference = max_relative_difference(Path::new(&p("merged.exr")), Path::new(&p("straight.exr")));
    assert!(difference <= 1e-12, "{difference:e}");
}

/// A low-discrepancy render keeps its replicates (crates/illum-pathtrace/src/replicates.rs), and
/// so its error estimate, through a resume and a merge: resumed from 41 spp (inside a chunk of 4)
/// to 96 its replicate sums are a straight render's bit for bit, and merged from the ranges 0..48
/// and 48..96 within 1e-12.
#[test]
fn a_low_discrepancy_render_keeps_its_replicates_through_resume_and_merge() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_owned();
    let with = |extra: &[&str]| {
        let mut args = vec!["--sequence", "low-discrepancy"];
        args.extend(extra);
        render_ok(&args)
    };
    with(&["--spp", "96", "-o", &p("straight.exr")]);
    with(&["--spp", "41", "-o", &p("resumed.exr")]);
    with(&["--resume", &p("resumed.exr"), "--spp", "96"]);
    with(&["--sample-range", "0..48", "-o", &p("a.exr")]);
    with(&["--sample-range", "48..96", "-o", &p("b.exr")]);
    let out = merge(&[&p("a.exr"), &p("b.exr"), "-o", &p("merged.exr")]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let load = |name: &str| checkpoint(Path::new(&p(name))).accumulator;
    let (straight, resumed, merged) = (load("straight.exr"), load("resumed.exr"), load("merged.exr"));
    let replicates = |a: &illum::pathtrace::Accumulator| a.replicates().expect("replicates kept").clone();
    assert!(replicates(&resumed) == replicates(&straight), "the resumed render's replicates differ");
    let (m, s) = (replicates(&merged), replicates(&straight));
    assert_eq!(m.count, s.count);
    let worst =
        m.sum.iter().flatten().zip(s.sum.iter().flatten()).map(|(a, b)| (a - b).abs() / a.abs().max(1e-300));
    let worst = worst.fold(0.0, f64::max);
    assert!(worst <= 1e-12, "merged replicate sums differ by {worst:e} relative");
    let (e_merged, e_straight) = (merged.estimated_rel_mse(), straight.estimated_rel_mse());
    assert!(
        e_straight.is_finite() && (e_merged / e_straight - 1.0).abs() < 1e-9,
        "{e_merged} vs {e_straight}"
    );
}

/// One randomisation of the low-discrepancy sequence (`--replicates off`): the summary names it
/// and says its error is not estimated; resumed from 41 spp without the flag (the file gives
/// it) its statistics are a straight render's bit for bit, and merged from two ranges within
/// 1e-12, with no replicates and no estimate in the merged file. Continuing it with replicates,
/// and every rule that reads the estimate, is refused by name.
#[test]
fn one_randomisation_resumes_and_merges_like_one_render_and_claims_no_error() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_owned();
    let with = |extra: &[&str]| {
        let mut args = vec!["--sequence", "low-discrepancy", "--replicates", "off"];
        args.extend(extra);
        render_ok(&args)
    };
    let out = with(&["--spp", "96", "-o", &p("straight.exr")]);
    let stdout = text(&out.stdout);
    assert!(stdout.contains("low-discrepancy (one randomisation) samples"), "{stdout}");
    assert!(
        stdout.contains("estimated relative error none (low-discrepancy without replicates)"),
        "{stdout}"
    );
    with(&["--spp", "41", "-o", &p("resumed.exr")]);
    render_ok(&["--resume", &p("resumed.exr"), "--spp", "96"]);
    assert!(
        statistics_bits(Path::new(&p("resumed.exr"))) == statistics_bits(Path::new(&p("straight.exr"))),
        "41 spp resumed to 96 differs from a straight 96 spp render"
    );
    with(&["--sample-range", "0..48", "-o", &p("a.exr")]);
    with(&["--sample-range", "48..96", "-o", &p("b.exr")]);
    let out = merge(&[&p("a.exr"), &p("b.exr"), "-o", &p("merged.exr")]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let difference = max_relative_difference(Path::new(&p("merged.exr")), Path::new(&p("straight.exr")));
    assert!(difference <= 1e-12, "merged differs from one render by {difference:e} relative");
    let merged = checkpoint(Path::new(&p("merged.exr"))).accumulator;
    assert!(merged.replicates().is_none() && !merged.estimates_error());
    assert!(merged.estimated_rel_mse().is_infinite());

    let out = run(&["--resume", &p("straight.exr"), "--spp", "128", "--replicates", "on"]);
    assert_refused(&out, "--resume with --replicates on", &["sequence", "(one randomisation)"]);
    // The file's setting holds without the flag: a rule that reads the estimate is refused.
    let out = run(&["--resume", &p("straight.exr"), "--spp", "128", "--target-error", "0.01"]);
    assert_refused(
        &out,
        "--resume of one randomisation with --target-error",
        &["--replicates off", "--target-error needs one"],
    );
    for (flags, expected) in [
        (&["--sequence", "low-discrepancy", "--replicates", "off"][..], "the default stop rule"),
        (&["--replicates", "off", "--spp", "8"][..], "the independent sequence has no replicates"),
        (
            &["--sequence", "low-discrepancy", "--replicates", "off", "--spp", "8", "--target-error", "0.1"]
                [..],
            "--target-error needs one",
        ),
        (
            &["--sequence", "low-discrepancy", "--replicates", "off", "--spp", "8", "--adaptive"][..],
            "--adaptive needs one",
        ),
    ] {
        let mut args = SMALL.to_vec();
        args.extend(flags);
        let never = p("never.png");
        args.extend(["-o", &never]);
        assert_refused(&run(&args), &format!("{flags:?}"), &[expected]);
    }
    assert!(!Path::new(&p("never.png")).exists());
}

/// A render whose spp is not a multiple of the chunk (16) ends inside a chunk. Resumed, it goes
/// on from its last chunk boundary and equals a straight render bit for bit; split into ranges
/// (each starting on a chunk), merged and resumed, it equals one render within 1e-12.
#[test]
fn a_render_ending_inside_a_chunk_resumes_and_merges_like_one_render() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_owned();
    render_ok(&["--spp", "50", "-o", &p("fifty.exr")]);
    assert_eq!(field(&metadata(Path::new(&p("fifty.exr"))), "aligned_spp"), "48");
    // Nothing to continue (the scene file's 16 spp), or a target the file already meets: the
    // file keeps all of its 50 spp (going back to the chunk boundary would drop 2).
    let before = statistics_bits(Path::new(&p("fifty.exr")));
    let out = run(&["--resume", &p("fifty.exr")]);
    assert_refused(&out, "--resume fifty.exr", &["already holds 50 spp, more than the 16 of the scene file"]);
    render_ok(&["--resume", &p("fifty.exr"), "--target-error", "0.9"]);
    assert_eq!(field(&metadata(Path::new(&p("fifty.exr"))), "spp"), "50");
    assert!(
        statistics_bits(Path::new(&p("fifty.exr"))) == before,
        "a resume that had nothing to do changed the file"
    );
    let resumed = render_ok(&["--resume", &p("fifty.exr"), "--spp", "100"]);
    assert!(text(&resumed.stdout).contains("going on from 48 spp"), "{}", text(&resumed.stdout));
    render_ok(&["--spp", "100", "-o", &p("straight.exr")]);
    assert!(
        statistics_bits(Path::new(&p("fifty.exr"))) == statistics_bits(Path::new(&p("straight.exr"))),
        "50 spp resumed to 100 differs from a straight 100 spp render"
    );

    render_ok(&["--sample-range", "0..48", "-o", &p("a.exr")]);
    render_ok(&["--sample-range", "48..100", "-o", &p("b.exr")]);
    let out = merge(&[&p("b.exr"), &p("a.exr"), "-o", &p("merged.exr")]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let difference = max_relative_difference(Path::new(&p("merged.exr")), Path::new(&p("straight.exr")));
    assert!(difference <= 1e-12, "merged differs from one render by {difference:e} relative");
    render_ok(&["--resume", &p("merged.exr"), "--spp", "130"]);
    render_ok(&["--spp", "130", "-o", &p("straight130.exr")]);
    let difference = max_relative_difference(Path::new(&p("merged.exr")), Path::new(&p("straight130.exr")));
    assert!(difference <= 1e-12, "merged and resumed differs from one render by {difference:e} relative");

    // A range that starts inside a chunk could not merge exactly: refused, with a start that can.
    let out = run(&["--sample-range", "50..100", "-o", &p("never.exr")]);
    assert_refused(&out, "--sample-range 50..100", &["must be a multiple of 16", "48..100"]);
    assert!(!Path::new(&p("never.exr")).exists());
}

/// A checkpoint that decodes but whose statistics do not add up (a count edited, the spp in the
/// metadata edited) is refused, and merge refuses a part that was stopped early.
#[test]
fn checkpoints_whose_counts_do_not_add_up_and_parts_stopped_early_are_refused() {
    use illum::pathtrace::Accumulator;
    use illum::pathtrace::checkpoint::{CheckpointError, load_checkpoint, merge_checkpoints, save_loaded};
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("part.exr");
    render_ok(&["--sample-range", "0..32", "-o", path.to_str().unwrap()]);
    let original = checkpoint(&path);
    let rebuilt = |edit: &dyn Fn(&mut Vec<u64>)| {
        let state = original.accumulator.state();
        let mut count = state.count.to_vec();
        edit(&mut count);
        let (w, h) = (original.accumulator.width, original.accumulator.height);
        Accumulator::from_state(w, h, state.sum.to_vec(), state.sum_sq.to_vec(), count, state.dropped)
            .unwrap()
    };
    let refused = |c: &illum::pathtrace::checkpoint::Checkpoint, name: &str, expected: &str| {
        let file = dir.path().join(name);
        save_loaded(&file, c).unwrap();
        let error = load_checkpoint(&file).expect_err("an inconsistent checkpoint was accepted");
        assert!(matches!(error, CheckpointError::Corrupt { .. }), "{error:?}");
        let error = error.to_string();
        assert!(error.contains(name) && error.contains(expected), "{error}");
    };
    let mut more = original.clone();
    more.accumulator = rebuilt(&|count| count[37] += 5);
    refused(&more, "more.exr", "has 37 samples, more than the 32");
    let mut fewer = original.clone();
    fewer.accumulator = rebuilt(&|count| count[0] -= 1);
    refused(&fewer, "fewer.exr", "1 samples fewer than illum.spp = 32");
    let mut claims = original.clone();
    claims.metadata.fields.iter_mut().find(|(k, _)| k == "spp").unwrap().1 = "999".into();
    refused(&claims, "claims.exr", "fewer than illum.spp = 999");

    let mut cancelled = original.clone();
    cancelled.metadata.fields.iter_mut().find(|(k, _)| k == "stopped_by").unwrap().1 = "cancelled".into();
    let error = merge_checkpoints(vec![(path.clone(), cancelled)]).expect_err("a cancelled part was merged");
    assert!(matches!(error, CheckpointError::Unfinished { .. }), "{error:?}");
    let error = error.to_string();
    assert!(error.contains("stopped early") && error.contains("--resume"), "{error}");
    // The part recorded its range, so the command to finish it is exact.
    assert_eq!(field(&metadata(&path), "sample_end"), "32");
    assert!(error.contains("--sample-range 0..32`") && !error.contains("END"), "{error}");
}

#[test]
fn mismatched_corrupt_and_overlapping_inputs_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_owned();
    render_ok(&["--sample-range", "0..16", "-o", &p("a.exr")]);
    render_ok(&["--sample-range", "0..32", "-o", &p("overlap.exr")]);
    render_ok(&["--sample-range", "16..32", "--seed", "7", "-o", &p("seed7.exr")]);
    render_ok(&["--sample-range", "32..48", "-o", &p("gap.exr")]);
    let original = std::fs::read(p("a.exr")).unwrap();

    for (inputs, expected) in [
        (vec![p("a.exr"), p("overlap.exr")], "overlap"),
        (vec![p("a.exr"), p("seed7.exr")], "seed: 0 in"),
        (vec![p("a.exr"), p("gap.exr")], "samples 16..32 are missing"),
    ] {
        let mut args: Vec<&str> = inputs.iter().map(String::as_str).collect();
        let out_path = p("never.exr");
        args.extend(["-o", &out_path]);
        let out = merge(&args);
        assert_no_panic(&out);
        assert_refused(&out, &format!("{args:?}"), &[expected]);
        assert!(!Path::new(&out_path).exists());
    }

    // Resuming with another setting, another resolution or an edited scene names what differs.
    let a = p("a.exr");
    for (flags, expected) in [
        (&["--seed", "3"][..], "seed: 0 in the file, 3 now"),
        (&["--bounces", "5"][..], "bounces: 2 in the file, 5 now"),
        (&["--width", "16"][..], "width: 32 in the file, 16 now"),
    ] {
        let width = if flags[0] == "--width" { flags[1] } else { "32" };
        let mut args = vec!["--width", width, "--height", "32"];
        let flags = if flags[0] == "--width" { &[][..] } else { flags };
        args.extend(["--resume", &a, "--spp", "64"]);
        args.extend(flags);
        let out = run(&args);
        assert_refused(&out, &format!("{flags:?}"), &[expected]);
    }
    let edited = dir.path().join("edited.toml");
    let scene =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.toml")).unwrap();
    std::fs::write(&edited, scene.replace("vfov = 45.0", "vfov = 46.0")).unwrap();
    let mut args = vec![edited.to_str().unwrap()];
    args.extend(SMALL);
    args.extend(["--resume", &a, "--spp", "64"]);
    let out = run(&args);
    assert!(text(&out.stderr).contains("scene content"), "{}", text(&out.stderr));
    assert_eq!(std::fs::read(p("a.exr")).unwrap(), original, "a refused resume changed the file");

    // A truncated file and a file without statistics: refused, nothing written.
    std::fs::write(p("truncated.exr"), &original[..original.len() / 2]).unwrap();
    let out = run(&["--resume", &p("truncated.exr"), "--spp", "64", "-o", &p("t.exr")]);
    assert_refused(&out, "--resume truncated.exr", &["truncated.exr"]);
    assert!(!Path::new(&p("t.exr")).exists());
    let plain = illum::image::ExrMetadata { renderer: "pathtrace".into(), ..Default::default() };
    illum::image::save_exr(p("plain.exr"), &illum::image::RgbImage32::new(2, 2), &plain).unwrap();
    let out = run(&["--resume", &p("plain.exr"), "--spp", "64"]);
    assert_refused(&out, "--resume plain.exr", &["plain.exr"]);
}

/// Files that are not checkpoints are named for what they are: a PNG, a denoised EXR; a part
/// of a split render must be an EXR (the only file `merge` reads), so a range written only to
/// a PNG is refused before rendering.
#[test]
fn a_png_a_denoised_image_and_a_part_without_an_exr_are_refused_for_what_they_are() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_owned();
    render_ok(&["--spp", "2", "-o", &p("image.png")]);
    let out = run(&["--resume", &p("image.png"), "--spp", "4"]);
    assert_refused(&out, "--resume image.png", &["image.png", "a PNG image, not an OpenEXR file"]);

    render_ok(&["--spp", "2", "--denoise", "atrous", "-o", &p("denoised.exr")]);
    let out = run(&["--resume", &p("denoised.exr"), "--spp", "4"]);
    assert_refused(
        &out,
        "--resume denoised.exr",
        &["denoised.exr", "illum.denoiser = atrous", "a denoised image is not a checkpoint"],
    );

    let out = run(&words("--sample-range 0..16 -o", &[&p("part.png")]));
    assert_refused(&out, "--sample-range to a PNG", &["--sample-range 0..16", "part.png", "EXR", "merge"]);
    assert!(!Path::new(&p("part.png")).exists());
}

/// The scene is known by its content: after its `name` is changed, a render resumes; a merge
/// of parts of two scenes names only what differs, briefly (the sun's glint by its digest).
#[test]
fn a_renamed_scene_resumes_and_a_merge_of_two_scenes_names_what_differs_briefly() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_owned();
    render_ok(&["--spp", "16", "-o", &p("long.exr")]);
    let cornell =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.toml")).unwrap();
    let renamed = cornell.replace("name = \"cornell\"", "name = \"cornell-renamed\"");
    assert_ne!(renamed, cornell, "the Cornell box's name line moved");
    std::fs::write(p("renamed.toml"), renamed).unwrap();
    render_ok(&[&p("renamed.toml"), "--resume", &p("long.exr"), "--spp", "32"]);
    assert_eq!(field(&metadata(Path::new(&p("long.exr"))), "spp"), "32");

    let whitted = "scenes/whitted.toml --renderer pathtrace --sample-range 16..32 -o";
    render_ok(&words(whitted, &[&p("whitted.exr")]));
    assert_eq!(field(&metadata(Path::new(&p("whitted.exr"))), "glint_hash").len(), 16, "a glint");
    render_ok(&["--sample-range", "0..16", "-o", &p("cornell.exr")]);
    let out = merge(&[&p("cornell.exr"), &p("whitted.exr"), "-o", &p("never.exr")]);
    assert_refused(
        &out,
        "merging two scenes",
        &["scene_hash: ", "\"cornell\"", "\"whitted\"", "glint_hash: none in"],
    );
    let stderr = text(&out.stderr);
    assert!(stderr.len() < 1500, "{} characters: {stderr}", stderr.len());
    assert!(!stderr.contains("seed:"), "a key that agrees: {stderr}");
}
