//! The `render` example as a user runs it: the real binary, its exit status, its messages and
//! the files it leaves: stop rules that stop, work that is never lost, and a README whose
//! commands and pictures exist. One module a concern; the helpers they share are here.
//!
//! The example is built by `cargo test` (examples are built with the tests); this finds it next
//! to the test binary, in `target/<profile>/examples/`.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Output, Stdio};

#[path = "../common/binary.rs"]
mod binary;

mod docs;
mod long_renders;
mod outputs;
mod renderers;
mod signals;
mod stop_rules;

use binary::{
    assert_no_panic, assert_refused, example_binary, field, metadata, render, run, statistics_bits, text,
    words,
};

/// Runs the example with `flags` (words separated by spaces) and `-o` for each of `outputs`.
fn run_to(flags: &str, outputs: &[&Path]) -> Output {
    let mut args: Vec<&str> = flags.split_whitespace().collect();
    for output in outputs {
        args.extend(["-o", output.to_str().expect("a UTF-8 path")]);
    }
    run(&args)
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
