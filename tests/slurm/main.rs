//! The README's split-and-merge recipes run for real: on a Slurm cluster (a job array and a
//! dependent merge) and with GNU parallel, each merged image compared with one straight render
//! of the same samples (within the README's 1e-12 relative per pixel).
//!
//! Slurm: the test uses a cluster that is already up (`scontrol ping` answers with the caller's
//! `SLURM_CONF` or `/etc/slurm/slurm.conf`); otherwise it starts a one-node cluster of its own,
//! all in a temporary folder (munged on a private socket and key, slurmctld and slurmd on free
//! ports, `SLURM_CONF` pointing at its configuration, so nothing of the system's is touched), and
//! stops those daemons by their pid files when it ends. On that cluster it runs:
//! - the README's `render.sbatch` and its two submission commands, as written (the README's 16
//!   tasks cut to 4 by `SBATCH_ARRAY_INX`, which overrides the file's `--array`), in a folder
//!   whose `scenes/cornell.toml` is the Cornell box at 64 x 64;
//! - `scripts/slurm-render.sh` with a sample count that is not a multiple of the chunk, one task
//!   stopped by `scancel --signal=TERM` after its first checkpoint (what the time limit sends);
//!   `merge` then refuses its part and names the `--resume` command; the two commands the
//!   script printed finish that task from its checkpoint and merge.
//!
//! Prerequisites (`.ci/run` installs them): `apt-get install slurm-wlm munge parallel`, and root
//! to start slurmd when no cluster is up. Without them each test fails under CI (`CI` set)
//! naming the install command, and elsewhere says loudly that it did not run.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

#[path = "../common/binary.rs"]
mod binary;

use binary::{example_binary, text};

mod cluster;

use cluster::{Cluster, missing_for_slurm, read_logs, start_cluster};

/// How long a job may take before the test gives up and shows the queue and the logs: a guard
/// against a cluster that never runs the job, far above what any job here needs.
const JOB_DEADLINE: Duration = Duration::from_secs(900);

/// The README's recipes render the Cornell box; the tests render it this small.
const SIZE: u32 = 64;

/// The samples of the README's recipes: Slurm's 4 tasks (of its 16) and GNU parallel's 4
/// ranges, 1024 spp each.
const README_SPP: u32 = 4096;

/// `scripts/slurm-render.sh`'s run: not a multiple of 16, so the last range ends inside a
/// chunk, and enough samples per task (9002) that a task is still rendering after its first
/// checkpoint (a quarter second in) when the test stops it, on a fast host too.
const SCRIPT_SPP: u32 = 36008;
const SCRIPT_TASKS: u32 = 4;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn runs(program: &str, args: &[&str]) -> bool {
    Command::new(program).args(args).output().is_ok_and(|o| o.status.success())
}

/// Whether `program` is an executable file in a folder of PATH.
fn on_path(program: &str) -> bool {
    use std::os::unix::fs::PermissionsExt;
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path).any(|dir| {
        std::fs::metadata(dir.join(program)).is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
    })
}

/// Fails under CI, naming what is missing; elsewhere says loudly that the test did not run.
/// Returns whether the test may go on.
fn prerequisites_met(test: &str, missing: &[String]) -> bool {
    if missing.is_empty() {
        return true;
    }
    let message =
        format!("{test} cannot run; missing: {}. .ci/run installs all of them.", missing.join("; "));
    assert!(std::env::var_os("CI").is_none(), "{message}");
    // Straight to stderr, past the test harness's capture: a skip must be seen.
    let _ = writeln!(std::io::stderr(), "\n*** SKIPPED (not under CI): {message} ***\n");
    false
}

/// A private runtime folder for lavapipe (it warns without one), shared by every child.
fn runtime_dir() -> PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| match std::env::var_os("XDG_RUNTIME_DIR") {
        Some(dir) => PathBuf::from(dir),
        None => {
            let dir =
                tempfile::Builder::new().prefix("illum-farm-xdg").tempdir().expect("a temporary folder");
            dir.keep()
        }
    })
    .clone()
}

/// A fresh folder under the target directory (on a cluster, a file system every node sees),
/// with `scenes/cornell.toml` the Cornell box at SIZE x SIZE: the README's commands, which name
/// that file, run there as written.
fn work_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("farm").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("scenes")).expect("creating the work folder");
    let scene = std::fs::read_to_string(root().join("scenes/cornell.toml")).expect("scenes/cornell.toml");
    let small = scene
        .replace("\nwidth = 512\n", &format!("\nwidth = {SIZE}\n"))
        .replace("\nheight = 512\n", &format!("\nheight = {SIZE}\n"));
    assert!(
        small.contains(&format!("\nwidth = {SIZE}\n")),
        "scenes/cornell.toml's width is not 512 any more"
    );
    std::fs::write(dir.join("scenes/cornell.toml"), small).expect("writing the small scene");
    dir
}

/// PATH with the examples' folder first, so that `render` and `merge` are the built examples.
fn path_with_examples() -> std::ffi::OsString {
    let examples = example_binary("render").parent().expect("examples/").to_path_buf();
    let rest = std::env::var_os("PATH").unwrap_or_default();
    std::env::join_paths(std::iter::once(examples).chain(std::env::split_paths(&rest))).expect("a valid PATH")
}

/// A straight render of the small scene at `spp`, made once per spp and test binary.
fn straight_render(spp: u32) -> PathBuf {
    static RENDERS: std::sync::Mutex<Vec<(u32, PathBuf)>> = std::sync::Mutex::new(Vec::new());
    let mut renders = RENDERS.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, path)) = renders.iter().find(|(s, _)| *s == spp) {
        return path.clone();
    }
    let dir = work_dir(&format!("straight-{spp}"));
    let out = Command::new(example_binary("render"))
        .args(["scenes/cornell.toml", "--spp", &spp.to_string(), "-o", "straight.exr"])
        .current_dir(&dir)
        .env("XDG_RUNTIME_DIR", runtime_dir())
        .output()
        .expect("the render example starts");
    assert!(out.status.success(), "the straight render failed: {}", text(&out.stderr));
    renders.push((spp, dir.join("straight.exr")));
    dir.join("straight.exr")
}

fn checkpoint(path: &Path) -> illum::pathtrace::checkpoint::Checkpoint {
    illum::pathtrace::checkpoint::load_checkpoint(path).unwrap_or_else(|e| panic!("{e}"))
}

/// Asserts that `merged` holds the samples of `straight` (the same counts per pixel) and that
/// their per-pixel sums and sums of squares differ by at most 1e-12 relative (the README's
/// bound: a merge adds whole partial sums, so only the f64 rounding of those additions differs).
fn assert_equals_straight(merged: &Path, straight: &Path) {
    let (a, b) = (checkpoint(merged), checkpoint(straight));
    let (sa, sb) = (a.accumulator.state(), b.accumulator.state());
    assert_eq!(a.spp_done, b.spp_done, "{} against {}", merged.display(), straight.display());
    assert!(sa.count == sb.count, "{}: other sample counts than the straight render", merged.display());
    let pairs = sa.sum.iter().zip(sb.sum).chain(sa.sum_sq.iter().zip(sb.sum_sq));
    let difference = pairs
        .flat_map(|(x, y)| (0..3).map(move |c| (x[c], y[c])))
        .map(|(x, y)| if x == y { 0.0 } else { (x - y).abs() / x.abs().max(y.abs()) })
        .fold(0.0, f64::max);
    println!("{}: largest relative difference from the straight render {difference:e}", merged.display());
    assert!(difference <= 1e-12, "{} differs from one render by {difference:e} relative", merged.display());
}

/// The page with the recipes: README.md, or docs/long-renders.md where the README sends the
/// long renders' details.
fn recipes_page() -> String {
    ["README.md", "docs/long-renders.md"]
        .iter()
        .filter_map(|page| std::fs::read_to_string(root().join(page)).ok())
        .find(|text| text.contains("sbatch --parsable render.sbatch"))
        .expect("no page (README.md, docs/long-renders.md) has the Slurm recipe")
}

/// The README's Slurm recipe: the `render.sbatch` code block (the one with `#SBATCH --array`)
/// and the block that submits it.
fn readme_slurm_recipe() -> (String, String) {
    let readme = recipes_page();
    let blocks: Vec<&str> = readme.split("```sh\n").skip(1).filter_map(|b| b.split("\n```").next()).collect();
    let job = blocks.iter().find(|b| b.contains("#SBATCH --array")).expect("README: no render.sbatch block");
    let submit = blocks
        .iter()
        .find(|b| b.contains("sbatch --parsable render.sbatch"))
        .expect("README: no submission block");
    (format!("{job}\n"), format!("{submit}\n"))
}

#[test]
fn slurm_array_and_dependent_merge_equal_one_render_and_a_stopped_task_resumes() {
    if !prerequisites_met("the Slurm test", &missing_for_slurm()) {
        return;
    }
    let cluster = start_cluster();
    readme_recipe_on_slurm(&cluster);
    script_with_a_stopped_task(&cluster);
}

/// The README's recipe as written, in a folder where `scenes/cornell.toml` is small.
fn readme_recipe_on_slurm(cluster: &Cluster) {
    let dir = work_dir("slurm-readme");
    let (job, submit) = readme_slurm_recipe();
    std::fs::write(dir.join("render.sbatch"), &job).expect("writing render.sbatch");
    // The README's commands, then one line of the test's: the array job's id, to wait for.
    let script = format!("set -euo pipefail\n{submit}echo \"array job: $jobid\"\n");
    let out = cluster
        .command("bash")
        .args(["-c", &script])
        .current_dir(&dir)
        .env("SBATCH_ARRAY_INX", "0-3")
        .output()
        .expect("bash runs");
    let stdout = text(&out.stdout);
    assert!(out.status.success(), "the README's commands failed: {stdout}{}", text(&out.stderr));
    let array = stdout.lines().find_map(|l| l.strip_prefix("array job: ")).expect("the array's id").trim();
    let merge = stdout
        .lines()
        .find_map(|l| l.strip_prefix("Submitted batch job "))
        .expect("sbatch --wrap says `Submitted batch job N`")
        .trim();
    cluster.wait_completed(&[array, merge], &dir.join("logs"));
    let merged = std::fs::read_dir(&dir)
        .expect("the work folder")
        .flatten()
        .map(|e| e.path())
        .find(|p| p.extension().is_some_and(|e| e == "exr"))
        .unwrap_or_else(|| panic!("the merge wrote no EXR in {}", dir.display()));
    assert_equals_straight(&merged, &straight_render(README_SPP));
    // Every task's log: the render's summary and its progress lines.
    let logs = read_logs(&dir.join("logs"));
    assert_eq!(logs.matches("spp target reached").count(), 4, "four tasks' summaries in the logs:\n{logs}");
    assert!(logs.contains("progress: "), "no progress lines in the task logs:\n{logs}");
}

/// `scripts/slurm-render.sh`, one task stopped by SIGTERM after its first checkpoint, the merge
/// refused, the task finished from its checkpoint with the commands the script printed.
fn script_with_a_stopped_task(cluster: &Cluster) {
    let dir = work_dir("slurm-script");
    let render_options = ["--checkpoint-seconds", "0.25", "--progress-seconds", "1"];
    let out = cluster
        .command("bash")
        .arg(root().join("scripts/slurm-render.sh"))
        .args(["scenes/cornell.toml", "--spp", &SCRIPT_SPP.to_string(), "--tasks", &SCRIPT_TASKS.to_string()])
        .args(["-o", "out/cornell.exr", "--"])
        .args(render_options)
        .current_dir(&dir)
        .env("ILLUM_RENDER", example_binary("render"))
        .env("ILLUM_MERGE", example_binary("merge"))
        .output()
        .expect("bash runs");
    let stdout = text(&out.stdout);
    assert!(out.status.success(), "slurm-render.sh failed: {stdout}{}", text(&out.stderr));
    println!("slurm-render.sh said:\n{stdout}");
    let id = |prefix: &str| -> String {
        let line = stdout
            .lines()
            .find(|l| l.starts_with(prefix))
            .unwrap_or_else(|| panic!("no {prefix:?} in {stdout}"));
        line[prefix.len()..].split(':').next().expect("an id").to_owned()
    };
    let (array, merge) = (id("render job "), id("merge job "));
    // The ranges: consecutive from 0 to the spp, each starting on a multiple of 16.
    let ranges: Vec<(u32, u32)> = stdout
        .lines()
        .find_map(|l| l.split_once("samples ").filter(|_| l.starts_with("render job ")))
        .expect("the ranges")
        .1
        .split_whitespace()
        .map(|r| {
            let (a, b) = r.split_once("..").expect("A..B");
            (a.parse().expect("a start"), b.parse().expect("an end"))
        })
        .collect();
    assert_eq!(ranges.len(), SCRIPT_TASKS as usize, "{ranges:?}");
    assert_eq!((ranges[0].0, ranges[ranges.len() - 1].1), (0, SCRIPT_SPP), "{ranges:?}");
    for pair in ranges.windows(2) {
        assert_eq!(pair[0].1, pair[1].0, "{ranges:?}");
    }
    assert!(ranges.iter().all(|(a, _)| a % 16 == 0), "a range starts inside a chunk: {ranges:?}");

    // Task 0 is stopped as its time limit would stop it, once its first checkpoint is written:
    // SIGTERM, once, to the task's process (the job script execs the render).
    let farm = dir.join("out/cornell.farm");
    let part = farm.join("parts/0.exr");
    let start = Instant::now();
    while !part.exists() {
        assert!(
            start.elapsed() < JOB_DEADLINE,
            "no checkpoint {} appeared:\n{}",
            part.display(),
            cluster.diagnostics()
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    let task = format!("{array}_0");
    // Sent once, whatever scancel answers: Slurm 22.05 has answered "Job can not be altered now,
    // try again later" (status 1) for a running array task and delivered the signal all the
    // same, so a retry could deliver it twice. What the task did is checked below.
    let cancel = cluster.run("scancel", &["--signal=TERM", "--batch", &task]);
    let scancel_said = format!("scancel exit status {}: {}", cancel.status, text(&cancel.stderr).trim());
    println!("{scancel_said}");
    let states = cluster.wait(&[&array, &merge]);
    let logs = farm.join("logs");
    let state = |id: &str| states.iter().find(|(t, _)| t == id).map_or("?", |(_, s)| s.as_str());
    assert_eq!(
        state(&task),
        "FAILED",
        "the stopped task (exit status 143) should have failed: {states:?} ({scancel_said})\n{}",
        read_logs(&logs)
    );
    assert_eq!(state(&merge), "CANCELLED", "the merge should have been cancelled: {states:?}");
    let task_log = std::fs::read_to_string(logs.join(format!("render-{array}_0.log"))).unwrap_or_default();
    assert!(
        task_log.contains("interrupted; kept what had accumulated")
            && task_log.contains("stopped by SIGTERM"),
        "the stopped task's log lacks its summary (did the signal end it without writing? it must come once):\n{task_log}"
    );
    let stopped = checkpoint(&part);
    assert_eq!(stopped.metadata.get("stopped_by"), Some("cancelled"));
    let range = ranges[0].1 - ranges[0].0;
    assert!(
        stopped.spp_done < range,
        "task 0 finished ({} spp) before the signal came ({scancel_said})",
        stopped.spp_done
    );
    println!("task 0 stopped at {} of {range} spp", stopped.spp_done);

    // The merge refuses the stopped part and names the command that finishes it.
    let parts: Vec<String> =
        ranges.iter().map(|(a, _)| farm.join(format!("parts/{a}.exr")).display().to_string()).collect();
    let mut args: Vec<&str> = parts.iter().map(String::as_str).collect();
    args.extend(["-o", "refused.exr"]);
    let refused =
        Command::new(example_binary("merge")).args(&args).current_dir(&dir).output().expect("merge runs");
    let message = text(&refused.stderr);
    assert!(!refused.status.success(), "merge accepted a stopped part");
    for expected in [part.display().to_string(), "--resume".to_owned(), "--sample-range 0..".to_owned()] {
        assert!(message.contains(&expected), "merge's refusal lacks {expected:?}: {message}");
    }
    assert!(!dir.join("refused.exr").exists());

    // The two commands the script printed, for task I = 0.
    let fix: Vec<&str> = stdout
        .lines()
        .map(str::trim)
        .filter(|l| l.starts_with("fix=") || l.starts_with("sbatch --dependency=afterok:$fix"))
        .collect();
    assert_eq!(fix.len(), 2, "the script's follow-up commands: {stdout}");
    let script =
        format!("set -euo pipefail\n{}\necho \"fix: $fix\"\n{}\n", fix[0].replace("=I ", "=0 "), fix[1]);
    let out = cluster.command("bash").args(["-c", &script]).current_dir(&dir).output().expect("bash runs");
    let said = text(&out.stdout);
    assert!(out.status.success(), "the follow-up commands failed: {said}{}", text(&out.stderr));
    let fix_job =
        said.lines().find_map(|l| l.strip_prefix("fix: ")).expect("the follow-up job's id").to_owned();
    let merge_again = said
        .lines()
        .find_map(|l| l.strip_prefix("Submitted batch job "))
        .expect("sbatch says `Submitted batch job N`")
        .trim()
        .to_owned();
    cluster.wait_completed(&[&fix_job, &merge_again], &logs);
    let resumed_log =
        std::fs::read_to_string(logs.join(format!("render-{fix_job}_0.log"))).unwrap_or_default();
    assert!(resumed_log.contains("resuming"), "the follow-up task did not resume: {resumed_log}");
    assert_equals_straight(&dir.join("out/cornell.exr"), &straight_render(SCRIPT_SPP));
    let all_logs = read_logs(&logs);
    assert_eq!(
        all_logs.matches("spp target reached").count(),
        SCRIPT_TASKS as usize,
        "every range's summary in the logs:\n{all_logs}"
    );
    assert!(all_logs.contains("progress: "), "no progress lines in the task logs:\n{all_logs}");
}

// ---- GNU parallel ----

#[test]
fn gnu_parallel_recipe_merges_to_one_render() {
    let gnu = Command::new("parallel").arg("--version").output();
    let missing = if gnu.is_ok_and(|o| text(&o.stdout).contains("GNU parallel")) {
        vec![]
    } else {
        vec!["GNU parallel (apt-get install parallel)".to_owned()]
    };
    if !prerequisites_met("the GNU parallel test", &missing) {
        return;
    }
    // The README's lines after its `cargo build`, as written; `target/release/examples/` in
    // the work folder links to the examples this test was built with.
    let readme = recipes_page();
    let block = readme
        .split("```sh\n")
        .filter_map(|b| b.split("\n```").next())
        .find(|b| b.contains("parallel target/release/examples/render"))
        .expect("README: no GNU parallel block");
    let commands: String =
        block.lines().filter(|l| !l.starts_with("cargo build")).map(|l| format!("{l}\n")).collect();
    let dir = work_dir("parallel");
    let examples = dir.join("target/release/examples");
    std::fs::create_dir_all(&examples).expect("creating target/release/examples");
    for name in ["render", "merge"] {
        std::os::unix::fs::symlink(example_binary(name), examples.join(name)).expect("linking an example");
    }
    std::fs::create_dir_all(dir.join("out")).expect("creating out/");
    let out = Command::new("bash")
        .args(["-c", &format!("set -euo pipefail\n{commands}")])
        .current_dir(&dir)
        .env("XDG_RUNTIME_DIR", runtime_dir())
        .output()
        .expect("bash runs");
    assert!(
        out.status.success(),
        "the README's GNU parallel lines failed: {}{}",
        text(&out.stdout),
        text(&out.stderr)
    );
    let merged = dir.join("out").join(format!("cornell-{README_SPP}.exr"));
    assert!(merged.exists(), "the README's merge wrote no {}: {}", merged.display(), text(&out.stdout));
    assert_equals_straight(&merged, &straight_render(README_SPP));
}
