//! A render run as a job, through the real `render` binary: stopped the ways schedulers stop
//! jobs, and logging its progress where no terminal shows a bar.
//!
//! The stop cases: `timeout -s TERM` and `timeout -s INT` (which signal the child and then its
//! whole process group, so the render receives the signal twice within microseconds),
//! `kill -TERM -- -PGID` (the group), two signals 1 ms apart, and SIGKILL after a checkpoint.
//! Every run must leave a file that `--resume` continues to the straight render bit for bit, or,
//! stopped before the first complete pass, say that nothing was written. The double delivery
//! is a race (a render that takes the repeat for a second request loses its image), so each case
//! runs [`RUNS`] times, at varying moments of the render. How a repeat is told from a second
//! request is unit-tested without processes (`illum_cli::interrupt`); these runs check that the
//! real signals, at real moments, reach that rule.

#![cfg(unix)]

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, ChildStderr, Command, ExitStatus, Stdio};
use std::sync::OnceLock;
use std::time::Duration;

#[path = "common/binary.rs"]
mod binary;

use binary::{example_binary, field, metadata, render, statistics_bits, text};

/// Runs of each stop case: each of the 10 moments `timeout_case` cycles through once, and the
/// other cases' 2 or 3 moments 3 to 5 times each. A fault at one moment fails its run every
/// time; one that strikes at random in a fraction p of runs escapes a case with probability
/// (1 - p)^10: 11% for p = 0.2, 2.8% for p = 0.3, and escapes all five cases (1 - p)^50, under
/// 1.5e-5 for p = 0.2.
const RUNS: usize = 10;
/// The image: tiny, so that the runs stay cheap; the race is in the signals, not the pixels.
const SIZE: &str = "32";
/// Every run renders toward this spp and is resumed to it; a multiple of the 16-sample chunk.
const TARGET: u32 = 1024;

/// The straight render's statistics at [`TARGET`] spp, made once for every case.
fn straight() -> &'static [u64] {
    static STRAIGHT: OnceLock<Vec<u64>> = OnceLock::new();
    STRAIGHT.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let exr = dir.path().join("straight.exr");
        let out = render(&["--width", SIZE, "--height", SIZE, "--spp", &TARGET.to_string(), "-o"])
            .arg(&exr)
            .output()
            .expect("the render example starts");
        assert!(out.status.success(), "the straight render: {}", text(&out.stderr));
        statistics_bits(&exr)
    })
}

/// The arguments of a stopped run writing `exr`.
fn job_args(exr: &Path) -> Vec<String> {
    let mut args: Vec<String> =
        ["--width", SIZE, "--height", SIZE, "--spp", &TARGET.to_string()].map(String::from).to_vec();
    args.extend(["-o".to_owned(), exr.to_str().expect("a UTF-8 path").to_owned()]);
    args
}

/// Starts a render with pass and checkpoint logging on, in a process group of its own (as a
/// job's processes are), reading its standard error.
fn start(exr: &Path, extra: &[&str]) -> (Child, std::io::Lines<BufReader<ChildStderr>>) {
    use std::os::unix::process::CommandExt;
    let mut child = render(&[])
        .args(job_args(exr))
        .args(extra)
        .env("RUST_LOG", "illum_pathtrace=debug,render=info")
        .process_group(0)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the render example starts");
    let lines = BufReader::new(child.stderr.take().expect("piped")).lines();
    (child, lines)
}

/// Reads standard error until `count` lines containing `wanted` went by; the lines read.
fn wait_for(lines: &mut std::io::Lines<BufReader<ChildStderr>>, wanted: &str, count: usize) -> Vec<String> {
    let mut read = Vec::new();
    let mut seen = 0;
    while seen < count {
        let Some(line) = lines.next() else { break };
        let line = line.expect("utf-8");
        seen += usize::from(line.contains(wanted));
        read.push(line);
    }
    read
}

fn send(pid: i32, signal: i32) {
    // SAFETY: kill(2) with a live child's pid (or a negated process group id).
    let result = unsafe { libc::kill(pid, signal) };
    assert_eq!(result, 0, "kill({pid}, {signal}): {}", std::io::Error::last_os_error());
}

/// What a run that was sent a stop left.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Outcome {
    /// A checkpoint marked as cancelled, which resumes to the straight render.
    Written,
    /// Stopped before the first complete pass: nothing written, and said so.
    Nothing,
    /// The render reached its spp before the signal came (a fast device): nothing to stop.
    Completed,
}

/// What a stopped run left, checked: the exit status of the first signal (`signal`, e.g.
/// "SIGTERM"), and either a checkpoint marked as cancelled with the message saying so, which
/// resumes to the straight render bit for bit, or no file and the message that nothing was
/// written; never a temporary file. A render that ended before the signal came must have
/// finished normally.
fn check_stopped(case: &str, status: ExitStatus, stderr: &str, exr: &Path, signal: &str) -> Outcome {
    let leftovers: Vec<_> = std::fs::read_dir(exr.parent().unwrap())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "{case}: temporary files left: {leftovers:?}");
    if status.success() {
        assert_eq!(
            field(&metadata(exr), "stopped_by"),
            "spp",
            "{case}: status 0 without finishing:\n{stderr}"
        );
        return Outcome::Completed;
    }
    let code = if signal == "SIGINT" { 130 } else { 143 };
    assert_eq!(status.code(), Some(code), "{case}: exit status {status}; standard error:\n{stderr}");
    if exr.exists() {
        assert!(stderr.contains(&format!("stopped by {signal}")), "{case}: wrote a file silently:\n{stderr}");
        if field(&metadata(exr), "stopped_by") == "spp" {
            // The signal came after the last pass: the complete render was written.
            assert!(statistics_bits(exr) == straight(), "{case}: the complete render differs");
            return Outcome::Completed;
        }
        assert_eq!(field(&metadata(exr), "stopped_by"), "cancelled", "{case}");
        check_resumes(case, exr);
        Outcome::Written
    } else {
        assert!(
            stderr.contains(&format!("error: {signal} ")) && stderr.contains("nothing was written"),
            "{case}: wrote nothing and did not say so:\n{stderr}"
        );
        Outcome::Nothing
    }
}

/// Resumes `exr` to [`TARGET`] and checks it against the straight render, bit for bit.
fn check_resumes(case: &str, exr: &Path) {
    let spp: u32 = field(&metadata(exr), "spp").parse().unwrap();
    assert!((1..TARGET).contains(&spp), "{case}: {spp} spp of {TARGET}");
    let out = render(&["--resume", exr.to_str().unwrap(), "--spp", &TARGET.to_string()])
        .output()
        .expect("the render example starts");
    assert!(out.status.success(), "{case}: the resume failed: {}", text(&out.stderr));
    assert!(
        statistics_bits(exr) == straight(),
        "{case}: resumed from {spp} spp, differs from the straight render"
    );
}

/// How many runs of a case ended each way (printed with `--nocapture`).
#[derive(Debug, Default)]
struct Tally {
    written_and_resumed: usize,
    nothing_written: usize,
    completed_first: usize,
}

impl Tally {
    fn add(&mut self, outcome: Outcome) {
        match outcome {
            Outcome::Written => self.written_and_resumed += 1,
            Outcome::Nothing => self.nothing_written += 1,
            Outcome::Completed => self.completed_first += 1,
        }
    }
}

/// `timeout -s SIGNAL`: GNU timeout sends the signal to the render, then to its own process
/// group, which the render is in. `--preserve-status` exits with the render's status. Each run
/// waits a different time, so the signals land at different moments: during the setup, the
/// first pass, or later passes.
fn timeout_case(signal: &str) {
    let mut tally = Tally::default();
    for run in 0..RUNS {
        let dir = tempfile::tempdir().unwrap();
        let exr = dir.path().join("t.exr");
        // From before the first pass to near the end of a render on lavapipe.
        let seconds = format!("{:.2}", 0.25 + 0.05 * (run % 10) as f64);
        let out = Command::new("timeout")
            .args(["--preserve-status", "-s", signal, &seconds])
            .arg(example_binary("render"))
            .args(job_args(&exr))
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .output()
            .expect("timeout (GNU coreutils) runs");
        let case = format!("timeout -s {signal} {seconds}, run {run}");
        tally.add(check_stopped(&case, out.status, &text(&out.stderr), &exr, &format!("SIG{signal}")));
    }
    eprintln!("timeout -s {signal}: {tally:?} of {RUNS} runs");
}

#[test]
fn timeout_with_sigterm_leaves_a_resumable_file_or_says_nothing_was_written() {
    timeout_case("TERM");
}

#[test]
fn timeout_with_sigint_leaves_a_resumable_file_or_says_nothing_was_written() {
    timeout_case("INT");
}

/// Waits for the moment of run `run`: the render's start (its handlers are installed and the
/// first pass is under way) or the end of its first or second pass.
fn wait_for_moment(lines: &mut std::io::Lines<BufReader<ChildStderr>>, run: usize) -> Vec<String> {
    match run % 3 {
        0 => wait_for(lines, "render started", 1),
        passes => wait_for(lines, "pass complete", passes),
    }
}

#[test]
fn sigterm_to_the_process_group_leaves_a_resumable_file_or_says_nothing_was_written() {
    let mut tally = Tally::default();
    for run in 0..RUNS {
        let dir = tempfile::tempdir().unwrap();
        let exr = dir.path().join("g.exr");
        let (mut child, mut lines) = start(&exr, &[]);
        let mut stderr = wait_for_moment(&mut lines, run);
        let group = format!("-{}", child.id());
        let kill = Command::new("kill").args(["-TERM", "--", &group]).status().expect("kill runs");
        assert!(kill.success(), "kill -TERM -- {group}");
        stderr.extend(lines.map_while(Result::ok));
        let status = child.wait().expect("the render ends");
        let case = format!("kill -TERM -- -PGID, run {run}");
        tally.add(check_stopped(&case, status, &stderr.join("\n"), &exr, "SIGTERM"));
    }
    eprintln!("kill -TERM -- -PGID: {tally:?} of {RUNS} runs");
}

#[test]
fn two_signals_1_ms_apart_are_one_request() {
    let mut tally = Tally::default();
    for run in 0..RUNS {
        let dir = tempfile::tempdir().unwrap();
        let exr = dir.path().join("two.exr");
        let (mut child, mut lines) = start(&exr, &[]);
        let mut stderr = wait_for_moment(&mut lines, run);
        let pid = child.id() as i32;
        // The same signal twice, or Ctrl-C and then SIGTERM: either way one request, whose
        // status is the first signal's.
        let (first, second, name) = if run % 2 == 0 {
            (libc::SIGTERM, libc::SIGTERM, "SIGTERM")
        } else {
            (libc::SIGINT, libc::SIGTERM, "SIGINT")
        };
        send(pid, first);
        std::thread::sleep(Duration::from_millis(1));
        send(pid, second);
        stderr.extend(lines.map_while(Result::ok));
        let status = child.wait().expect("the render ends");
        let case = format!("{name} then SIGTERM 1 ms later, run {run}");
        // Two different signals that are both pending when the render next runs (a loaded
        // machine may not run it within the millisecond) are handled by two of its threads at
        // once, in either order: either one is the request, never both.
        let name = match (name, status.code()) {
            ("SIGINT", Some(143)) => "SIGTERM",
            _ => name,
        };
        tally.add(check_stopped(&case, status, &stderr.join("\n"), &exr, name));
    }
    eprintln!("two signals 1 ms apart: {tally:?} of {RUNS} runs");
}

#[test]
fn sigkill_after_a_checkpoint_leaves_the_checkpoint_which_resumes() {
    let mut tally = Tally::default();
    for run in 0..RUNS {
        let dir = tempfile::tempdir().unwrap();
        let exr = dir.path().join("k.exr");
        let (mut child, mut lines) = start(&exr, &["--checkpoint-seconds", "0.1"]);
        // After the first or second checkpoint; the next may be being written.
        let read = wait_for(&mut lines, "checkpoint written", 1 + run % 2);
        child.kill().expect("SIGKILL");
        let _: Vec<String> = lines.map_while(Result::ok).collect();
        let status = child.wait().expect("the render ends");
        let case = format!("SIGKILL after a checkpoint, run {run}");
        if status.success() {
            // It finished before the kill (a fast device).
            assert_eq!(field(&metadata(&exr), "stopped_by"), "spp", "{case}:\n{}", read.join("\n"));
            tally.add(Outcome::Completed);
            continue;
        }
        use std::os::unix::process::ExitStatusExt;
        assert_eq!(status.signal(), Some(libc::SIGKILL), "{case}: {status}");
        // The checkpoint is whole (written to a temporary file, then renamed), and resumes.
        check_resumes(&case, &exr);
        tally.add(Outcome::Written);
    }
    eprintln!("SIGKILL after a checkpoint: {tally:?} of {RUNS} runs");
}

// ---- Job logs: progress lines where standard error is not a terminal ----

/// The lines of `stderr` that start with `progress: `.
fn progress_lines(stderr: &str) -> Vec<&str> {
    stderr.lines().filter(|l| l.starts_with("progress: ")).collect()
}

/// A path-traced render logged to a pipe: lines with its spp, error, sample rate and time left,
/// one at each tenth of the way when the period is longer than the render (never more than
/// ten); the final summary on standard output as before.
#[test]
fn a_logged_path_traced_render_prints_progress_lines_at_each_tenth() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("log.exr");
    // A time budget: the fraction moves with every submission (a fraction of a second each).
    let out = render(&[
        "--width",
        SIZE,
        "--height",
        SIZE,
        "--time-budget",
        "1",
        "--progress-seconds",
        "86400",
        "-o",
    ])
    .arg(&exr)
    .output()
    .expect("the render example starts");
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert!(out.status.success(), "{stderr}");
    let lines = progress_lines(&stderr);
    assert!((1..=10).contains(&lines.len()), "{} progress lines:\n{stderr}", lines.len());
    for line in &lines {
        for part in [" spp", "Msamples/s", "error", "toward time budget", "ETA"] {
            assert!(line.contains(part), "a progress line without {part:?}: {line}");
        }
    }
    assert!(stdout.contains("stopped by the time budget") && stdout.contains("wrote "), "{stdout}");
}

#[test]
fn progress_seconds_refuses_zero_negative_nan_and_absurd_periods() {
    for bad in ["0", "-1", "nan", "inf", "1e9", "0.001", "soon"] {
        let out =
            render(&["--progress-seconds", bad, "--width", "8", "--height", "8", "-o", "target/never.png"])
                .output()
                .expect("the render example starts");
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "--progress-seconds {bad} was accepted: {stderr}");
        for part in ["--progress-seconds", bad, "from 0.1 to 86400"] {
            assert!(stderr.contains(part), "--progress-seconds {bad}: the refusal lacks {part:?}: {stderr}");
        }
    }
}

/// The Whitted ray tracer renders in parts of about 65,536 camera rays: 64 x 64 pixels with
/// 8 x 8 rays each makes four bands of 1024 pixels (16 rows), each reported in the log.
#[test]
fn a_logged_whitted_render_reports_each_part() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("w.png");
    let out = render(&["scenes/whitted.toml", "--renderer", "whitted", "--width", "64", "--height", "64"])
        .args(["--aa", "8", "--progress-seconds", "86400", "-o"])
        .arg(&png)
        .output()
        .expect("the render example starts");
    let stderr = text(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let lines = progress_lines(&stderr);
    let parts: Vec<&str> = lines.iter().copied().filter(|l| l.contains("  pixels ")).collect();
    let pixels: Vec<&str> =
        parts.iter().filter_map(|l| l.split("  pixels ").nth(1).and_then(|r| r.split(" (").next())).collect();
    assert_eq!(pixels, ["1024 of 4096", "2048 of 4096", "3072 of 4096", "4096 of 4096"], "{stderr}");
    assert!(parts.iter().all(|l| l.contains("M camera rays/s")), "{stderr}");
    // Then what follows the render, and the summary as before.
    assert!(lines.last().is_some_and(|l| l.contains("writing ")), "{stderr}");
    assert!(text(&out.stdout).contains("Whitted ray tracer, depth"), "{}", text(&out.stdout));
    assert!(png.exists());
}

/// Starts `args` with standard error piped, waits for its first progress line, sends SIGTERM and
/// returns the exit status and the whole of standard error.
fn terminate_after_first_progress_line(args: &[&str]) -> (ExitStatus, String) {
    let mut child = render(args).stdout(Stdio::null()).stderr(Stdio::piped()).spawn().expect("starts");
    let mut lines = BufReader::new(child.stderr.take().expect("piped")).lines();
    let mut stderr = wait_for(&mut lines, "progress: ", 1);
    send(child.id() as i32, libc::SIGTERM);
    stderr.extend(lines.map_while(Result::ok));
    (child.wait().expect("the render ends"), stderr.join("\n"))
}

/// Ctrl-C / SIGTERM stops the Whitted ray tracer between parts: nothing written (its image is
/// deterministic), said so, status 143.
#[test]
fn sigterm_stops_a_whitted_render_between_parts_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("w.png");
    // 128 parts of 1024 pixels; the signal comes after the first part's line.
    let (status, stderr) = terminate_after_first_progress_line(&[
        "scenes/whitted.toml",
        "--renderer",
        "whitted",
        "--width",
        "64",
        "--height",
        "2048",
        "--aa",
        "8",
        "--progress-seconds",
        "0.1",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert_eq!(status.code(), Some(143), "{stderr}");
    assert!(!png.exists(), "an interrupted Whitted render wrote its file");
    assert!(
        stderr.contains("error: SIGTERM after")
            && stderr.contains("of 131072 pixels")
            && stderr.contains("nothing was written"),
        "{stderr}"
    );
}

/// The rasterizer draws a frame above 4 Mpixels in bands (of 1024 rows at 4096 wide) and stops
/// between them the same way.
#[test]
fn sigterm_stops_a_large_raster_frame_between_bands_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("r.png");
    let (status, stderr) = terminate_after_first_progress_line(&[
        "scenes/whitted.toml",
        "--renderer",
        "raster",
        "--width",
        "4096",
        "--height",
        "4096",
        "--progress-seconds",
        "0.1",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert_eq!(status.code(), Some(143), "{stderr}");
    assert!(!png.exists(), "an interrupted raster render wrote its file");
    assert!(
        stderr.contains("error: SIGTERM after")
            && stderr.contains("of 4096 rows")
            && stderr.contains("nothing was written"),
        "{stderr}"
    );
}
