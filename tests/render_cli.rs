//! The `render` example as a user runs it: the real binary, its exit status, its messages and
//! the files it leaves: stop rules that stop, work that is never lost, and a README whose
//! commands and pictures exist.
//!
//! The example is built by `cargo test` (examples are built with the tests); this finds it next
//! to the test binary, in `target/<profile>/examples/`.
//!
//! Over 450 lines: every test runs the binary as a user would, through the helpers at the top.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Output, Stdio};

#[path = "common/binary.rs"]
mod binary;

use binary::{example_binary, field, metadata, render, statistics_bits, text};

fn run(args: &[&str]) -> Output {
    render(args).output().expect("the render example starts")
}

/// Runs the example with `flags` (words separated by spaces) and `-o` for each of `outputs`.
fn run_to(flags: &str, outputs: &[&Path]) -> Output {
    let mut args: Vec<&str> = flags.split_whitespace().collect();
    for output in outputs {
        args.extend(["-o", output.to_str().expect("a UTF-8 path")]);
    }
    run(&args)
}

/// Asserts that a run of `case` (what the test tried, for the failure message) failed and that
/// its message names every one of `expected`; the message is shown when either does not hold.
fn assert_refused(out: &Output, case: &str, expected: &[&str]) {
    let stderr = text(&out.stderr);
    assert!(!out.status.success(), "{case}: accepted, expected a refusal naming {expected:?}: {stderr}");
    for part in expected {
        assert!(stderr.contains(part), "{case}: the refusal lacks {part:?}: {stderr}");
    }
}

fn assert_no_panic(output: &Output) {
    let stderr = text(&output.stderr);
    assert!(!stderr.contains("panicked") && output.status.code() != Some(101), "{stderr}");
}

/// Renders 16 x 16 with `flags` to an EXR, which must succeed, and returns its metadata.
fn render_16_exr(flags: &[&str]) -> illum::image::ExrMetadata {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("out.exr");
    let mut args = vec!["--width", "16", "--height", "16"];
    args.extend(flags);
    args.extend(["-o", exr.to_str().unwrap()]);
    let out = run(&args);
    assert!(out.status.success(), "{}", text(&out.stderr));
    metadata(&exr)
}

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
    let out = run(&[
        scene.to_str().unwrap(),
        "--width",
        "24",
        "--height",
        "24",
        "--spp",
        "8",
        "--exposure",
        "auto",
        "-o",
        png.to_str().unwrap(),
    ]);
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

/// Starts a long render with pass logging on, and waits until `passes` passes are complete
/// (0: until the render has started, its signal handlers installed). Returns the rest of its
/// standard error, line by line.
#[cfg(unix)]
fn start_long_render(
    size: &str,
    spp: &str,
    output: &Path,
    passes: u32,
) -> (Child, std::io::Lines<BufReader<std::process::ChildStderr>>) {
    let mut child =
        render(&["--width", size, "--height", size, "--spp", spp, "-o", output.to_str().unwrap()])
            .env("RUST_LOG", "illum_pathtrace=debug")
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("the render example starts");
    let mut lines = BufReader::new(child.stderr.take().expect("piped")).lines();
    let wanted = if passes == 0 { "render started" } else { "pass complete" };
    let mut seen = 0;
    while seen < passes.max(1) {
        let line =
            lines.next().unwrap_or_else(|| panic!("the render ended before {wanted:?}")).expect("utf-8");
        seen += u32::from(line.contains(wanted));
    }
    (child, lines)
}

#[cfg(unix)]
fn signal(child: &Child, name: &str) {
    let status = Command::new("kill")
        .args([&format!("-{name}"), &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(status.success());
}

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

/// Every example of `examples/`: a `NAME.rs` file or a `NAME/main.rs` folder.
fn example_names() -> Vec<String> {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let mut names: Vec<String> = std::fs::read_dir(&folder)
        .expect("the examples folder")
        .map(|entry| entry.expect("an entry").path())
        .filter_map(|path| match path.extension() {
            Some(ext) if ext == "rs" => path.file_stem().map(|s| s.to_string_lossy().into_owned()),
            None if path.join("main.rs").exists() => {
                path.file_name().map(|s| s.to_string_lossy().into_owned())
            }
            _ => None,
        })
        .collect();
    names.sort();
    names
}

#[test]
fn every_examples_help_says_what_it_does_and_documents_each_flag() {
    let names = example_names();
    assert!(names.len() >= 8 && names.iter().any(|n| n == "ladder"), "{names:?}");
    for name in &names {
        let binary = example_binary(name);
        assert!(binary.exists(), "{} is missing (cargo test builds the examples)", binary.display());
        let out = Command::new(&binary).arg("--help").output().expect("runs");
        assert!(out.status.success(), "{name} --help failed");
        let help = text(&out.stdout);
        let first = help.lines().next().unwrap_or_default();
        assert!(!first.starts_with("Usage"), "{name} --help has no description line:\n{help}");
        // Every flag and argument has a description: after its name on the same line, or (when
        // clap wraps a long help) on the next, more indented line.
        let lines: Vec<&str> = help.lines().collect();
        let mut section = "";
        for (i, line) in lines.iter().enumerate() {
            if line.ends_with(':') && !line.starts_with(' ') {
                section = line;
                continue;
            }
            let is_entry = line.starts_with("  ") && line.trim_start().starts_with(['-', '[', '<']);
            if (section == "Options:" || section == "Arguments:") && is_entry {
                let same_line = line.trim().split("  ").filter(|part| !part.trim().is_empty()).count() >= 2;
                let next = lines.get(i + 1).copied().unwrap_or_default();
                let indent = |l: &str| l.len() - l.trim_start().len();
                let next_line = !next.trim().is_empty()
                    && indent(next) > indent(line)
                    && !next.trim_start().starts_with('-');
                assert!(same_line || next_line, "{name}: undocumented: {line:?}\n{help}");
            }
        }
    }
    // The convergence tool sets spp (--spp-list) and sampling (it measures both) itself: its
    // help must not offer flags it would refuse.
    let out = Command::new(example_binary("convergence")).arg("--help").output().expect("runs");
    let help = text(&out.stdout);
    for flag in ["--spp ", "--sampling"] {
        assert!(!help.contains(flag), "convergence --help offers {flag}:\n{help}");
    }
    assert!(help.contains("--spp-list") && help.contains("--bounces"), "{help}");
}

/// The benchmarks refuse repetition counts that measure nothing (0) or would run for days, with
/// the flag, the value and the range, before touching the GPU.
#[test]
fn benchmarks_refuse_absurd_repetition_counts() {
    let ranges = [("--runs", "1..=1000"), ("--frames", "1..=100000"), ("--warmup", "0..=10000")];
    let cases = [
        "bench --runs 0",
        "bench --runs 1000000",
        "raster_bench --frames 0",
        "raster_bench --frames 100000000",
        "raster_bench --warmup 20000",
    ];
    for case in cases {
        let words: Vec<&str> = case.split(' ').collect();
        let out = Command::new(example_binary(words[0])).args(&words[1..]).output().expect("runs");
        let range = ranges.iter().find(|(flag, _)| *flag == words[1]).map(|(_, range)| *range);
        assert_refused(&out, case, &[words[1], words[2], range.expect("a range per flag")]);
    }
}

/// Every picture the README and the docs show exists, every `--example NAME` they name is an
/// example, and every flag on a line that runs an example is one that example's `--help` lists.
/// (The numbers they quote are re-measured by `scripts/readme-figures.sh`; timings cannot be
/// asserted.)
#[test]
fn the_readme_shows_only_pictures_examples_and_flags_that_exist() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut pages = vec![(root.join("README.md"), "](docs/images/", "docs/images/")];
    for entry in std::fs::read_dir(root.join("docs")).expect("docs/") {
        let path = entry.expect("an entry").path();
        if path.extension().is_some_and(|e| e == "md") {
            pages.push((path, "](images/", "docs/images/"));
        }
    }
    let mut text_of_all = String::new();
    for (page, link, folder) in &pages {
        let content = std::fs::read_to_string(page).expect("a page");
        for (i, _) in content.match_indices(link) {
            let rest = &content[i + link.len()..];
            let name = &rest[..rest.find(')').expect("closing parenthesis")];
            assert!(
                root.join(folder).join(name).exists(),
                "{} shows {name}, which does not exist",
                page.display()
            );
        }
        text_of_all.push_str(&content);
        text_of_all.push('\n');
    }
    let readme = text_of_all;
    let facade_examples = example_names();
    let mut checked = 0;
    for line in readme.lines() {
        let Some(at) = line.find("--example ") else { continue };
        let name: String = line[at + "--example ".len()..]
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        if !facade_examples.contains(&name) {
            // Another crate's example (`-p illum-oracle --example NAME`): it must exist.
            let elsewhere = std::fs::read_dir(root.join("crates"))
                .expect("crates/")
                .any(|c| c.expect("an entry").path().join("examples").join(format!("{name}.rs")).exists());
            assert!(elsewhere, "the docs name --example {name}, which is no example");
            continue;
        }
        let help = Command::new(example_binary(&name)).arg("--help").output().expect("the example starts");
        assert!(help.status.success(), "README names --example {name}, which has no working --help");
        let help = text(&help.stdout);
        // The flags after the example's name, as the line spells them (`--spp N`, `[--look ...]`).
        for word in line[at..].split(|c: char| c.is_whitespace() || "[]`|=,()".contains(c)).skip(2) {
            if let Some(flag) =
                word.strip_prefix("--").filter(|f| f.chars().all(|c| c.is_ascii_lowercase() || c == '-'))
            {
                if flag.is_empty() || flag == "release" || flag == "example" {
                    continue;
                }
                assert!(
                    help.contains(&format!("--{flag}")),
                    "README runs `{name}` with --{flag}, which its --help lacks"
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 20, "only {checked} flags found in the example lines of the README and docs");
}

/// The README's set-up line installs exactly the packages `scripts/setup.sh` (what `.ci/run`
/// runs) installs for the default test run, so that the two cannot drift apart.
#[test]
fn the_readmes_setup_line_is_the_setup_scripts_list() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).expect("README.md");
    let script = std::fs::read_to_string(root.join("scripts/setup.sh")).expect("scripts/setup.sh");
    let base = script
        .lines()
        .find_map(|l| l.strip_prefix("BASE_PACKAGES=\""))
        .and_then(|l| l.strip_suffix('"'))
        .expect("BASE_PACKAGES in scripts/setup.sh");
    let line = format!("sudo apt-get install -y {base}");
    assert!(readme.contains(&format!("```sh\n{line}\n```")), "the README's set-up line is not `{line}`");
    let ci = std::fs::read_to_string(root.join(".ci/run")).expect(".ci/run");
    assert!(ci.contains("scripts/setup.sh"), ".ci/run does not install through scripts/setup.sh");
}

// ---- Long renders: checkpoints, resume, sample ranges and merge ----

/// The merge example's executable.
fn merge(args: &[&str]) -> Output {
    Command::new(example_binary("merge"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the merge example starts")
}

fn checkpoint(path: &Path) -> illum::pathtrace::checkpoint::Checkpoint {
    illum::pathtrace::checkpoint::load_checkpoint(path).unwrap_or_else(|e| panic!("{e}"))
}

/// The largest relative difference between two checkpoints' per-pixel sums and sums of squares
/// (their counts must be equal).
fn max_relative_difference(a: &Path, b: &Path) -> f64 {
    let (a, b) = (checkpoint(a), checkpoint(b));
    let (sa, sb) = (a.accumulator.state(), b.accumulator.state());
    assert_eq!(sa.count, sb.count, "different sample counts");
    let pairs = sa.sum.iter().zip(sb.sum).chain(sa.sum_sq.iter().zip(sb.sum_sq));
    pairs
        .flat_map(|(x, y)| (0..3).map(move |c| (x[c], y[c])))
        .map(|(x, y)| if x == y { 0.0 } else { (x - y).abs() / x.abs().max(y.abs()) })
        .fold(0.0, f64::max)
}

const SMALL: [&str; 4] = ["--width", "32", "--height", "32"];

fn render_ok(extra: &[&str]) -> Output {
    let mut args = SMALL.to_vec();
    args.extend(extra);
    let out = run(&args);
    assert!(out.status.success(), "{args:?}: {}", text(&out.stderr));
    out
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
/// so its error estimate, through a resume and a merge: resumed from 41 spp (inside a chunk and a
/// replicate run) to 96 its replicate sums are a straight render's bit for bit, and merged from
/// the ranges 0..48 and 48..96 within 1e-12.
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

/// `--error-percentile` and `--region` say what `--target-error` is measured over; bad values
/// are refused naming the flag, the value and what is allowed (for a region, the valid names).
#[test]
fn error_percentile_and_region_refuse_bad_values_and_stop_on_their_error() {
    for bad in ["0", "101", "-3", "ninety"] {
        let out = run(&["--target-error", "0.1", "--error-percentile", bad]);
        assert_refused(&out, &format!("--error-percentile {bad}"), &["--error-percentile", bad, "100"]);
        assert_no_panic(&out);
    }
    let out = run(&[
        "scenes/whitted.toml",
        "--renderer",
        "pathtrace",
        "--width",
        "32",
        "--height",
        "18",
        "--target-error",
        "0.1",
        "--region",
        "teapot",
    ]);
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
    let args = [
        "scenes/whitted.toml",
        "--renderer",
        "pathtrace",
        "--width",
        "32",
        "--height",
        "18",
        "--target-error",
        "0.05",
        "--region",
        "glass sphere",
        "-o",
        exr_text,
    ];
    let out = run(&args);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(field(&metadata(&exr), "stopped_by"), "target_error");
    let error = illum::image::load_f32_layer(&exr, "illum.error").unwrap().expect("an illum.error layer");
    assert_eq!(error.channels.len(), 1);
    assert_eq!(error.channels[0].1.len(), 32 * 18);
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
    let out = run(&[
        "scenes/whitted.toml",
        "--renderer",
        "raster",
        "--width",
        "16",
        "--height",
        "9",
        "--reference",
        &p("truth.exr"),
        "-o",
        &p("y.exr"),
    ]);
    assert_refused(&out, "a reference of another size", &["32 x 18", "16 x 9"]);
    assert!(
        !Path::new(&p("x.exr")).exists() && !Path::new(&p("y.exr")).exists(),
        "a refused render wrote a file"
    );
    let out = with(&["--renderer", "pathtrace", "--reference", &p("truth.exr")]);
    assert_refused(&out, "--reference with the path tracer", &["--reference", "raster", "whitted"]);
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
    let out = run(&[
        "scenes/whitted.toml",
        "--renderer",
        "pathtrace",
        "--width",
        "16",
        "--height",
        "16",
        "--caustics",
        "off",
        "--resume",
        exr.to_str().unwrap(),
        "--spp",
        "32",
    ]);
    assert_refused(&out, "--caustics off on a resume", &["caustics: on in the file, off now"]);
    // A file rendered before the photon gather (the light tracer alone, no estimators key)
    // holds other light in the metal sphere, and one rendered with the gather at the first
    // diffuse vertex alone lacks E (S|D)* D S* D S+ L: resuming either with today's estimators
    // is refused, and so is merging it with a part rendered today.
    let rendered = illum::pathtrace::checkpoint::load_checkpoint(&exr).unwrap();
    assert!(
        field(&metadata(&exr), "caustic_estimators")
            .starts_with("light tracer and photon gather at every diffuse")
    );
    let first_vertex =
        "light tracer and photon gather (r_1 = 0.02 x the largest specular radius, r_k = r_1 (k + 1)^(-1/6))";
    let part = dir.path().join("part.exr");
    let args = [
        "scenes/whitted.toml",
        "--renderer",
        "pathtrace",
        "--width",
        "16",
        "--height",
        "16",
        "--sample-range",
        "16..32",
        "-o",
        part.to_str().unwrap(),
    ];
    let out = run(&args);
    assert!(out.status.success(), "{}", text(&out.stderr));
    // A file rendered without the sun's glint (`illum.glint`, and its estimators without it)
    // lacks the sun's image in the balls: it is refused by name too.
    assert_ne!(field(&metadata(&exr), "glint"), "none");
    let today = field(&metadata(&exr), "caustic_estimators");
    let without_glint = today.replace("; glint solved", "");
    assert_ne!(without_glint, today, "the estimators name the glint");
    for (case, estimators, refusal) in [
        ("before-gather", None, "caustic_estimators: light tracer in the file".to_owned()),
        (
            "first-vertex-gather",
            Some(first_vertex.to_owned()),
            format!("caustic_estimators: {first_vertex} in the file"),
        ),
        (
            "before-glint",
            Some(without_glint.clone()),
            format!("caustic_estimators: {without_glint} in the file"),
        ),
    ] {
        let mut older = rendered.clone();
        older.metadata.fields.retain(|(k, _)| k != "caustic_estimators" && k != "glint");
        if let Some(value) = estimators {
            older.metadata.fields.push(("caustic_estimators".to_owned(), value));
        }
        let old = dir.path().join(format!("{case}.exr"));
        illum::pathtrace::checkpoint::save_loaded(&old, &older).unwrap();
        let out = run(&[
            "scenes/whitted.toml",
            "--renderer",
            "pathtrace",
            "--width",
            "16",
            "--height",
            "16",
            "--resume",
            old.to_str().unwrap(),
            "--spp",
            "32",
        ]);
        assert_refused(&out, &format!("resuming a file {case}"), &[&refusal]);
        let merged = dir.path().join("never.exr");
        let out = merge(&[old.to_str().unwrap(), part.to_str().unwrap(), "-o", merged.to_str().unwrap()]);
        assert_refused(&out, &format!("merging a file {case}"), &["caustic_estimators"]);
        assert!(!merged.exists());
    }

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
        &run(&[
            "scenes/whitted.toml",
            "--renderer",
            "pathtrace",
            "--caustics",
            "on",
            "--adaptive",
            "--spp",
            "16",
            "--width",
            "32",
            "--height",
            "18",
        ]),
        "the caustic",
        &["adaptive sampling is not available with the caustic"],
    );
    assert_no_panic(&small(&["--adaptive", "--spp", "0"]));
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

/// `convergence --reference` refuses an EXR of another scene, naming both, before rendering.
#[test]
fn a_reference_of_another_scene_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("whitted.exr");
    let out = run(&[
        "scenes/whitted.toml",
        "--renderer",
        "pathtrace",
        "--width",
        "8",
        "--height",
        "8",
        "--spp",
        "1",
        "-o",
        exr.to_str().unwrap(),
    ]);
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
        &["\"whitted\"", "\"cornell\"", "another scene"],
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
