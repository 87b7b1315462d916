//! Starts the real viewer binary under Xvfb in each mode with `--screenshot FILE --frames N`,
//! and checks that each screenshot shows a picture (not one flat colour), that the modes draw
//! different pictures, and that each run printed its mode's statistics (the path tracer's spp,
//! sample rate, elapsed time, error estimate, and the window's frame rate).

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Window size of the smoke runs (small: lavapipe draws every pixel on the CPU).
const WIDTH: &str = "640";
const HEIGHT: &str = "420";

fn xvfb_run() -> &'static str {
    let found =
        Command::new("sh").args(["-c", "command -v xvfb-run"]).output().is_ok_and(|o| o.status.success());
    assert!(
        found,
        "xvfb-run is missing: the viewer's smoke test needs a virtual X display. \
         Install it with `apt-get install xvfb xauth` (Debian/Ubuntu)."
    );
    "xvfb-run"
}

/// egui's dark theme's panel fill, which the viewer's window clears to.
const PANEL_GREY: u8 = 27;

/// Longest a screenshot run may take before it counts as hung (it takes seconds on lavapipe).
const RUN_TIMEOUT: Duration = Duration::from_secs(180);

/// The screenshot a run in `mode` saved, and the statistics line it printed.
fn screenshot(mode: &str, path: &Path) -> (image::RgbaImage, String) {
    let (log_out, log_err) = (path.with_extension("stdout.txt"), path.with_extension("stderr.txt"));
    let mut child = Command::new(xvfb_run())
        .args(["-a", "-s", "-screen 0 1024x768x24"])
        .arg(env!("CARGO_BIN_EXE_illum-viewer"))
        .args(["--mode", mode, "--frames", "8", "--width", WIDTH, "--height", HEIGHT, "--screenshot"])
        .arg(path)
        // Files, not pipes: a full pipe would block the child while the test polls it.
        .stdout(Stdio::from(std::fs::File::create(&log_out).expect("creating the stdout log")))
        .stderr(Stdio::from(std::fs::File::create(&log_err).expect("creating the stderr log")))
        .spawn()
        .expect("starting xvfb-run");
    let started = Instant::now();
    // Poll rather than wait, so a hung window fails the test instead of hanging it.
    while child.try_wait().expect("polling the viewer").is_none() {
        if started.elapsed() > RUN_TIMEOUT {
            let _ = child.kill();
            panic!("the viewer did not exit within {RUN_TIMEOUT:?} in {mode} mode");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let status = child.wait().expect("collecting the viewer's exit status");
    let read = |p: &Path| std::fs::read_to_string(p).unwrap_or_default();
    assert!(
        status.success(),
        "the viewer failed in {mode} mode ({status}):\nstdout:\n{}\nstderr:\n{}",
        read(&log_out),
        read(&log_err)
    );
    let stdout = read(&log_out);
    let statistics = stdout
        .lines()
        .find_map(|line| line.strip_prefix("statistics: "))
        .unwrap_or_else(|| panic!("{mode}: no statistics line in the output:\n{stdout}"))
        .to_owned();
    println!("{mode}: {statistics}");
    let image = image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgba8();
    (image, statistics)
}

/// The number after `name ` in a statistics line ("spp done 12, ...").
fn figure(statistics: &str, name: &str) -> f64 {
    let rest =
        statistics.split(&format!("{name} ")).nth(1).unwrap_or_else(|| panic!("no {name:?} in {statistics}"));
    let number: String = rest.chars().take_while(|c| c.is_ascii_digit() || *c == '.').collect();
    number.parse().unwrap_or_else(|_| panic!("{name:?} is not followed by a number in {statistics}"))
}

/// Standard deviation of the pixels' grey level, 0..255.
fn spread(image: &image::RgbaImage) -> f64 {
    let grey: Vec<f64> =
        image.pixels().map(|p| (f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2])) / 3.0).collect();
    let mean = grey.iter().sum::<f64>() / grey.len() as f64;
    (grey.iter().map(|g| (g - mean).powi(2)).sum::<f64>() / grey.len() as f64).sqrt()
}

/// Mean absolute difference per channel, 0..255.
fn difference(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    assert_eq!(a.dimensions(), b.dimensions());
    let total: u64 = a.as_raw().iter().zip(b.as_raw()).map(|(x, y)| u64::from(x.abs_diff(*y))).sum();
    total as f64 / a.as_raw().len() as f64
}

#[test]
fn all_three_modes_draw_under_xvfb() {
    let dir = tempfile::tempdir().unwrap();
    let (raster, raster_statistics) = screenshot("raster", &dir.path().join("raster.png"));
    let (pathtrace, statistics) = screenshot("pathtrace", &dir.path().join("pathtrace.png"));
    let (whitted, whitted_statistics) = screenshot("whitted", &dir.path().join("whitted.png"));
    // Each run names its mode, and the path tracer's says what it accumulated.
    assert!(raster_statistics.starts_with("raster:"), "{raster_statistics}");
    assert!(whitted_statistics.starts_with("whitted:") && figure(&whitted_statistics, "whitted:") >= 1.0);
    assert!(statistics.starts_with("pathtrace:"), "{statistics}");
    assert!(figure(&statistics, "spp done") >= 1.0, "{statistics}");
    assert!(figure(&statistics, "samples/s (wall)") > 0.0, "{statistics}");
    assert!(figure(&statistics, "elapsed") > 0.0, "{statistics}");
    assert!(statistics.contains("estimated error") && statistics.contains("fps"), "{statistics}");
    let shots = [("raster", &raster), ("pathtrace", &pathtrace), ("whitted", &whitted)];
    for (name, image) in shots {
        assert!(image.width() >= 200 && image.height() >= 200, "{name}: {:?}", image.dimensions());
        let s = spread(image);
        assert!(s > 10.0, "{name} screenshot looks blank (grey-level spread {s:.1})");
        // The window's clear paints the panels (they have no fill of their own): the settings
        // panel's empty bottom corner and the image's right margin show the panel colour.
        let (w, h) = image.dimensions();
        for (x, y) in [(4, h - 4), (w - 3, h / 2)] {
            let p = image.get_pixel(x, y);
            assert!(
                p.0[..3].iter().all(|&c| c.abs_diff(PANEL_GREY) <= 1),
                "{name}: pixel ({x}, {y}) is {p:?}, not the panel grey {PANEL_GREY}"
            );
        }
    }
    // Each mode shows its own renderer's picture (the path tracer starts on the Cornell box;
    // raster and Whitted on the Whitted scene, where the ray tracer's glass and mirror differ
    // from the fake's).
    for (a, b) in [(0, 1), (0, 2), (1, 2)] {
        let d = difference(shots[a].1, shots[b].1);
        assert!(
            d > 2.0,
            "{} and {} screenshots barely differ (mean difference {d:.2})",
            shots[a].0,
            shots[b].0
        );
    }
}

/// A screenshot run is a check: a scene that does not open fails it (before any window opens,
/// so this needs no X display).
#[test]
fn a_screenshot_run_with_a_missing_scene_fails() {
    let dir = tempfile::tempdir().expect("temp dir");
    let shot = dir.path().join("never.png");
    let output = Command::new(env!("CARGO_BIN_EXE_illum-viewer"))
        .args(["no/such/scene.toml", "--frames", "1", "--screenshot"])
        .arg(&shot)
        .output()
        .expect("starting the viewer");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("no/such/scene.toml"), "{stderr}");
    assert!(!shot.exists());
}
