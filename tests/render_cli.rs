//! The `render` example as a user runs it: the real binary, its exit status, its messages and
//! the files it leaves: stop rules that stop, work that is never lost, and a README whose
//! commands and pictures exist.
//!
//! The example is built by `cargo test` (examples are built with the tests); this finds it next
//! to the test binary, in `target/<profile>/examples/`.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};

/// The render example's executable.
fn render_binary() -> PathBuf {
    let exe = std::env::current_exe().expect("test binary path");
    // target/<profile>/deps/render_cli-HASH -> target/<profile>/examples/render
    let profile_dir = exe.parent().and_then(Path::parent).expect("target/<profile>");
    let binary = profile_dir.join("examples").join(format!("render{}", std::env::consts::EXE_SUFFIX));
    assert!(
        binary.exists(),
        "{} is missing: `cargo test` builds it; alone, run `cargo build --example render`",
        binary.display()
    );
    binary
}

fn render(args: &[&str]) -> Command {
    let mut command = Command::new(render_binary());
    command.args(args).current_dir(env!("CARGO_MANIFEST_DIR"));
    command
}

fn run(args: &[&str]) -> Output {
    render(args).output().expect("the render example starts")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// The `illum.*` metadata of an EXR the example wrote.
fn metadata(path: &Path) -> illum::image::ExrMetadata {
    let (_, attributes) = illum::image::load_exr(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    illum::image::ExrMetadata::from_attributes(path, &attributes).expect("parses").expect("illum metadata")
}

fn field(meta: &illum::image::ExrMetadata, key: &str) -> String {
    meta.get(key).unwrap_or_else(|| panic!("no illum.{key} in {meta:?}")).to_owned()
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
        (&["--exposure", "nan"][..], "not a finite number of stops"),
        (&["--exposure", "inf"][..], "not a finite number of stops"),
    ] {
        let out = run(args);
        assert_no_panic(&out);
        assert!(!out.status.success(), "{args:?} was accepted");
        let stderr = text(&out.stderr);
        assert!(stderr.contains(args[0]) && stderr.contains(expected), "{args:?}: {stderr}");
    }
}

#[test]
fn a_negative_exposure_is_accepted_as_typed() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("dark.png");
    let out = run(&[
        "--width",
        "8",
        "--height",
        "8",
        "--spp",
        "1",
        "--exposure",
        "-1",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(png.exists());
}

#[test]
fn png_only_flags_without_a_png_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("x.exr");
    for flags in [&["--encoding", "srgb"][..], &["--exposure", "1"][..]] {
        let mut args = vec!["--width", "8", "--height", "8", "--spp", "1", "-o", exr.to_str().unwrap()];
        args.extend(flags);
        let out = run(&args);
        assert!(!out.status.success(), "{flags:?} with only an EXR output was accepted");
        let stderr = text(&out.stderr);
        assert!(stderr.contains(flags[0]) && stderr.contains("only to PNG output"), "{stderr}");
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
        let out = run(&[
            "--width",
            "8",
            "--height",
            "8",
            "--spp",
            "1",
            "-o",
            good.to_str().unwrap(),
            "-o",
            bad.to_str().unwrap(),
        ]);
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
    let out = run(&["--width", "8", "--height", "8", "--spp", "1", "-o", png.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("read-only"), "{}", text(&out.stderr));
    assert_eq!(std::fs::read(&png).unwrap(), b"precious");
    assert_eq!(std::fs::metadata(&png).unwrap().permissions().mode() & 0o777, 0o444);
}

#[test]
fn raster_scenes_refuse_path_tracer_flags_and_write_their_own_metadata() {
    let out = run(&["scenes/whitted.toml", "--sequence", "low-discrepancy", "-o", "target/never.png"]);
    assert!(!out.status.success());
    assert!(
        text(&out.stderr).contains("--sequence applies only to the path tracer"),
        "{}",
        text(&out.stderr)
    );

    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("w.exr");
    let out = run(&[
        "scenes/whitted.toml",
        "--width",
        "32",
        "--height",
        "18",
        "--no-msaa",
        "-o",
        exr.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let meta = metadata(&exr);
    assert_eq!(meta.renderer, "raster");
    for key in ["spp", "bounces", "seed", "sampling"] {
        assert!(meta.get(key).is_none(), "a raster EXR carries the path tracer's illum.{key}: {meta:?}");
    }
    assert_eq!(field(&meta, "look"), "figure");
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

/// The examples' executables, found like [`render_binary`].
fn example_binary(name: &str) -> PathBuf {
    render_binary().with_file_name(format!("{name}{}", std::env::consts::EXE_SUFFIX))
}

#[test]
fn every_examples_help_says_what_it_does_and_documents_each_flag() {
    for name in ["render", "figures", "convergence", "bench", "raster_bench", "raster_figures"] {
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

/// Every picture the README shows exists, every `--example NAME` it names is an example, and
/// every flag on a line that runs an example is one that example's `--help` lists. (The numbers
/// it quotes are re-measured by `scripts/readme-figures.sh`; timings cannot be asserted.)
#[test]
fn the_readme_shows_only_pictures_examples_and_flags_that_exist() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).expect("README.md");
    for (i, _) in readme.match_indices("](docs/images/") {
        let rest = &readme[i + 2..];
        let path = &rest[..rest.find(')').expect("closing parenthesis")];
        assert!(root.join(path).exists(), "README shows {path}, which does not exist");
    }
    let mut checked = 0;
    for line in readme.lines() {
        let Some(at) = line.find("--example ") else { continue };
        let name: String = line[at + "--example ".len()..]
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
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
    assert!(checked > 20, "only {checked} flags found in the README's example lines");
}
