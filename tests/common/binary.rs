//! Running the `render` example's executable as a user does, and reading what it wrote. For the
//! test binaries that run it and the other examples (`tests/render_cli/`, `tests/denoise_cli.rs`, `tests/jobs.rs`,
//! `tests/slurm/main.rs`).
#![allow(dead_code)] // each test binary uses a different subset

use std::path::{Path, PathBuf};
use std::process::Command;

/// An example's executable. `cargo test` builds the examples next to the test binary, in
/// `target/<profile>/examples/`.
pub fn example_binary(name: &str) -> PathBuf {
    let exe = std::env::current_exe().expect("test binary path");
    // target/<profile>/deps/TEST-HASH -> target/<profile>/examples/NAME
    let profile_dir = exe.parent().and_then(Path::parent).expect("target/<profile>");
    let binary = profile_dir.join("examples").join(format!("{name}{}", std::env::consts::EXE_SUFFIX));
    assert!(
        binary.exists(),
        "{} is missing: `cargo test` builds it; alone, run `cargo build --example {name}`",
        binary.display()
    );
    binary
}

/// The render example with `args`, run from the workspace root.
pub fn render(args: &[&str]) -> Command {
    let mut command = Command::new(example_binary("render"));
    command.args(args).current_dir(env!("CARGO_MANIFEST_DIR"));
    command
}

/// Runs the render example with `args` to its end.
pub fn run(args: &[&str]) -> std::process::Output {
    render(args).output().expect("the render example starts")
}

/// A command line written as one line: `line`'s words (split at spaces), then `more` as given
/// (paths, names with spaces).
pub fn words<'a>(line: &'a str, more: &[&'a str]) -> Vec<&'a str> {
    line.split_whitespace().chain(more.iter().copied()).collect()
}

/// Asserts that a run of `case` (what the test tried, for the failure message) failed without a
/// panic and that its message names every one of `expected`; the message is shown when either
/// does not hold.
pub fn assert_refused(out: &std::process::Output, case: &str, expected: &[&str]) {
    let stderr = text(&out.stderr);
    assert!(!out.status.success(), "{case}: accepted, expected a refusal naming {expected:?}: {stderr}");
    assert_no_panic(out);
    for part in expected {
        assert!(stderr.contains(part), "{case}: the refusal lacks {part:?}: {stderr}");
    }
}

/// Asserts that a run ended without a panic (which exits with status 101).
pub fn assert_no_panic(output: &std::process::Output) {
    let stderr = text(&output.stderr);
    assert!(!stderr.contains("panicked") && output.status.code() != Some(101), "{stderr}");
}

pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// The `illum.*` metadata of an EXR the example wrote.
pub fn metadata(path: &Path) -> illum::image::ExrMetadata {
    let (_, attributes) = illum::image::load_exr(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    illum::image::ExrMetadata::from_attributes(path, &attributes).expect("parses").expect("illum metadata")
}

pub fn field(meta: &illum::image::ExrMetadata, key: &str) -> String {
    meta.get(key).unwrap_or_else(|| panic!("no illum.{key} in {meta:?}")).to_owned()
}

/// Every pixel's f64 sum, sum of squares and count in a checkpoint, as bits (for exact
/// comparisons).
pub fn statistics_bits(path: &Path) -> Vec<u64> {
    let c = illum::pathtrace::checkpoint::load_checkpoint(path).unwrap_or_else(|e| panic!("{e}"));
    let state = c.accumulator.state();
    let floats = state.sum.iter().chain(state.sum_sq).flatten().map(|v| v.to_bits());
    floats.chain(state.count.iter().copied()).collect()
}
