//! The web viewer in a real browser: builds it (`scripts/build-web.sh`), serves `web/dist/` on
//! 127.0.0.1, drives headless Chromium on WebGPU (SwiftShader) with `web/tests/browser.mjs`
//! (Playwright), and checks what the page showed and reported:
//!
//! - a browser without WebGPU (no adapter, or no API at all) gets the page that says so and how
//!   to enable it;
//! - a WebGPU adapter was found (which one is printed);
//! - the matrix: every built-in scene in every mode ([`matrix`]), the path tracer with its light
//!   tracer on and off where the scene has a caustic. Each path-traced cell has the image mean
//!   of a native render of the same scene, size, seed, spp and light tracer (the samples depend
//!   only on seed, pixel and sample index); each Whitted cell the image mean of a native Whitted
//!   render of the same size; the raster's cell the native raster's pixels, and the figure look's
//!   exact colours; a mode that cannot render a scene shows the desktop's refusal, and its own
//!   scene rather than a blank canvas;
//! - "Open file..." opens a scene through the browser's file picker;
//! - Save EXR downloads a checkpoint of the Cornell box's 8 spp that the desktop's loader reads;
//! - a bad scene file dropped on the page shows the desktop's error and keeps the scene.
//!
//! Prerequisites (`.ci/run` installs them): `rustup target add wasm32-unknown-unknown`,
//! `cargo install wasm-bindgen-cli --version <Cargo.lock's wasm-bindgen>`, chromium, node and
//! `npm ci --prefix web/tests`. Without them the test fails under CI (`CI` set) naming the
//! missing piece, and elsewhere says loudly that it did not run.

use std::collections::HashMap;
use std::io::{BufRead, BufReader, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::Command;

use illum_gpu::GpuContext;
use illum_pathtrace::PathTracer;
use illum_scene::{RendererKind, Scene};
use illum_viewer::platform::BUILT_IN_SCENES;

/// The path tracer's samples per pixel in the browser (the page's `?spp=`).
const SPP: u32 = 8;
/// The path tracer's resolution scale in the browser (the page's `?scale=`): a quarter of the
/// view each way, about 160 x 140 pixels in browser.mjs's 960 x 600 page, so that the matrix's
/// path-traced cells take seconds each on SwiftShader.
const SCALE: &str = "0.25";
/// The largest relative difference of an image mean (per channel) between the page and the
/// native render of the same samples, path-traced or Whitted: the same samples on two drivers
/// differ only by f32 rounding (measured 4e-10 to 3e-5 over the matrix), while another seed at
/// these spp and sizes differs by 7e-4 to 8e-3 (printed beside each cell), so a page that drew
/// other samples fails.
const MEAN_TOLERANCE: f64 = 2e-4;
/// The same for the raster's image, whose edges, shadow-map texels and anti-aliasing each driver
/// rasterises its own way (measured 5e-4).
const RASTER_MEAN_TOLERANCE: f64 = 1e-3;

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().expect("the workspace root")
}

fn chromium() -> String {
    std::env::var("CHROMIUM").unwrap_or_else(|_| "/usr/bin/chromium".to_owned())
}

/// What is missing to run the browser test, with the command that installs each piece.
fn missing_prerequisites(root: &Path) -> Vec<String> {
    let runs = |program: &str, args: &[&str]| {
        Command::new(program).args(args).output().is_ok_and(|o| o.status.success())
    };
    let mut missing = Vec::new();
    let lock = std::fs::read_to_string(root.join("Cargo.lock")).expect("Cargo.lock");
    let wanted = lock
        .split("[[package]]")
        .find(|p| p.contains("\nname = \"wasm-bindgen\"\n"))
        .and_then(|p| p.lines().find_map(|l| l.strip_prefix("version = \"")))
        .map(|v| v.trim_end_matches('"').to_owned())
        .expect("wasm-bindgen in Cargo.lock");
    let have = Command::new("wasm-bindgen")
        .arg("--version")
        .output()
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).into_owned());
    if have.as_deref().is_none_or(|v| !v.contains(&wanted)) {
        missing.push(format!("wasm-bindgen {wanted} (cargo install wasm-bindgen-cli --version {wanted})"));
    }
    let targets = Command::new("rustup").args(["target", "list", "--installed"]).output();
    if targets
        .is_ok_and(|o| !String::from_utf8_lossy(&o.stdout).lines().any(|l| l == "wasm32-unknown-unknown"))
    {
        missing.push("the wasm32 target (rustup target add wasm32-unknown-unknown)".to_owned());
    }
    if !runs(&chromium(), &["--version"]) {
        missing.push(format!("chromium at {} (apt-get install chromium; or set CHROMIUM)", chromium()));
    }
    if !runs("node", &["--version"]) {
        missing.push("node (apt-get install nodejs npm)".to_owned());
    }
    if !root.join("web/tests/node_modules/playwright-core").is_dir() {
        missing.push("playwright-core (npm ci --prefix web/tests)".to_owned());
    }
    missing
}

/// Serves `dir` over HTTP on 127.0.0.1 (a free port) from a background thread; returns the URL.
fn serve(dir: PathBuf) -> String {
    let listener = TcpListener::bind("127.0.0.1:0").expect("binding a local port");
    let url = format!("http://{}/", listener.local_addr().expect("the bound address"));
    std::thread::spawn(move || {
        for stream in listener.incoming().flatten() {
            let dir = dir.clone();
            std::thread::spawn(move || respond(&dir, stream));
        }
    });
    url
}

fn respond(dir: &Path, mut stream: TcpStream) {
    let mut request_line = String::new();
    let mut reader = BufReader::new(stream.try_clone().expect("cloning the socket"));
    if reader.read_line(&mut request_line).is_err() {
        return;
    }
    // Skip the headers.
    let mut header = String::new();
    while reader.read_line(&mut header).is_ok_and(|n| n > 2) {
        header.clear();
    }
    let target = request_line.split_whitespace().nth(1).unwrap_or("/");
    let path = target.split(['?', '#']).next().unwrap_or("/").trim_start_matches('/');
    let path = if path.is_empty() { "index.html" } else { path };
    let file = dir.join(path);
    let (status, body, kind) = match (path.contains(".."), std::fs::read(&file)) {
        (false, Ok(body)) => {
            let kind = match file.extension().and_then(|e| e.to_str()) {
                Some("html") => "text/html; charset=utf-8",
                Some("js") => "text/javascript",
                Some("wasm") => "application/wasm",
                _ => "application/octet-stream",
            };
            ("200 OK", body, kind)
        }
        _ => ("404 Not Found", b"not found".to_vec(), "text/plain"),
    };
    let head = format!(
        "HTTP/1.1 {status}\r\nContent-Type: {kind}\r\nContent-Length: {}\r\nConnection: close\r\n\r\n",
        body.len()
    );
    let _ = stream.write_all(head.as_bytes()).and_then(|()| stream.write_all(&body));
}

fn status(out: &Path, case: &str) -> HashMap<String, String> {
    let path = out.join(format!("{case}.status"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.lines().filter_map(|l| l.split_once('=')).map(|(k, v)| (k.to_owned(), v.to_owned())).collect()
}

fn get<'a>(status: &'a HashMap<String, String>, key: &str) -> &'a str {
    status.get(key).map_or("", String::as_str)
}

fn screenshot(out: &Path, case: &str) -> image::RgbaImage {
    let path = out.join(format!("{case}.png"));
    image::open(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgba8()
}

/// Pixels of `image` within one level of `rgb` in each channel.
fn count(image: &image::RgbaImage, rgb: [u8; 3]) -> usize {
    image.pixels().filter(|p| (0..3).all(|c| p.0[c].abs_diff(rgb[c]) <= 1)).count()
}

/// Distinct colours: a blank or flat canvas has a handful, a rendered picture thousands.
fn distinct_colours(image: &image::RgbaImage) -> usize {
    let mut colours: Vec<[u8; 3]> = image.pixels().map(|p| [p.0[0], p.0[1], p.0[2]]).collect();
    colours.sort_unstable();
    colours.dedup();
    colours.len()
}

/// One cell of the browser matrix: a built-in scene in one mode (with the path tracer's light
/// tracer on or off where it applies), or the refusal of a mode that cannot render it.
struct Cell {
    name: String,
    scene: &'static str,
    mode: RendererKind,
    /// The light tracer, for the path tracer on a scene where it can add a caustic.
    caustics: Option<bool>,
    /// Why `mode` cannot render the scene (the desktop's message), if it cannot.
    refusal: Option<String>,
}

impl Cell {
    /// The page's address for the cell.
    fn query(&self) -> String {
        let mut query = format!("?scene={}&mode={}", self.scene, self.mode);
        if self.mode == RendererKind::PathTrace {
            query += &format!("&spp={SPP}&scale={SCALE}");
        }
        if let Some(on) = self.caustics {
            query += if on { "&caustics=on" } else { "&caustics=off" };
        }
        query
    }

    /// What browser.mjs waits for before its screenshot.
    fn expect(&self) -> String {
        if self.refusal.is_some() { "refusal".to_owned() } else { self.mode.to_string() }
    }
}

/// Every built-in scene in every mode, as the desktop's loader sees them: a cell that renders
/// where the mode can (the path tracer twice, light tracer on and off, where the scene has a
/// sun and a mirror or glass object), a refusal where it cannot.
fn matrix() -> Vec<Cell> {
    let mut cells = Vec::new();
    for (scene, text) in BUILT_IN_SCENES {
        let loaded = illum_viewer::scene_file::load_text(scene, text).unwrap_or_else(|e| panic!("{e}"));
        let stem = scene.trim_start_matches("scenes/").trim_end_matches(".toml");
        for mode in [RendererKind::PathTrace, RendererKind::Raster, RendererKind::Whitted] {
            let refusal = match mode {
                RendererKind::PathTrace => loaded.pathtrace.as_ref().err().cloned(),
                RendererKind::Raster => loaded.raster.as_ref().err().cloned(),
                RendererKind::Whitted => loaded.whitted.as_ref().err().cloned(),
            };
            let caustic_applies = loaded.pathtrace.as_ref().is_ok_and(|s| {
                let mut on = s.clone();
                on.pathtrace.caustics = true;
                illum_pathtrace::Estimators::of(&on).caustics()
            });
            let variants: &[Option<bool>] = if mode == RendererKind::PathTrace && caustic_applies {
                &[Some(true), Some(false)]
            } else {
                &[None]
            };
            for &caustics in variants {
                let suffix = match caustics {
                    Some(true) => "-caustics-on",
                    Some(false) => "-caustics-off",
                    None => "",
                };
                let name = format!("{stem}-{mode}{suffix}");
                cells.push(Cell { name, scene, mode, caustics, refusal: refusal.clone() });
            }
        }
    }
    cells
}

/// The built-in scene at `path` at `width` x `height` (its own camera otherwise, as the page's
/// camera before any drag).
fn sized_scene(root: &Path, path: &str, width: u32, height: u32) -> Scene {
    let mut scene = Scene::load(&root.join(path)).unwrap_or_else(|e| panic!("{e}"));
    scene.camera.width = width;
    scene.camera.height = height;
    scene
}

/// The image mean of a native path-traced render of `scene` with `seed`.
fn native_pathtrace_mean(gpu: &GpuContext, scene: &Scene, seed: u32) -> [f64; 3] {
    let mut scene = scene.clone();
    scene.pathtrace.seed = seed;
    let mut tracer = PathTracer::new(gpu, &scene).unwrap_or_else(|e| panic!("{e}"));
    tracer.render_to_spp(SPP).unwrap_or_else(|e| panic!("{e}"));
    tracer.accumulator().mean_image().mean()
}

/// "WxH" as numbers.
fn size_of(text: &str) -> (u32, u32) {
    let (w, h) = text.split_once('x').unwrap_or_else(|| panic!("{text:?} is not WxH"));
    (w.parse().unwrap(), h.parse().unwrap())
}

/// Three numbers separated by spaces.
fn mean_of(text: &str) -> [f64; 3] {
    let values: Vec<f64> = text.split(' ').map(|v| v.parse().unwrap_or(f64::NAN)).collect();
    assert_eq!(values.len(), 3, "{text:?} is not three numbers");
    [values[0], values[1], values[2]]
}

/// The largest relative difference over the channels of two image means.
fn relative_difference(web: [f64; 3], native: [f64; 3]) -> f64 {
    (0..3).map(|c| (web[c] - native[c]).abs() / native[c].abs().max(1e-12)).fold(0.0, f64::max)
}

/// The path tracer's cell: the page's image mean against the native render's.
fn check_pathtrace_cell(root: &Path, gpu: &GpuContext, cell: &Cell, status: &HashMap<String, String>) -> f64 {
    let name = &cell.name;
    assert_eq!(get(status, "pathtraceSpp"), SPP.to_string(), "{name}: {status:?}");
    let expected = cell.caustics.map_or("off", |on| if on { "on" } else { "off" });
    assert_eq!(get(status, "pathtraceCaustics"), expected, "{name}: the light tracer: {status:?}");
    let (width, height) = size_of(get(status, "pathtraceSize"));
    let web = mean_of(get(status, "pathtraceMean"));
    let mut scene = sized_scene(root, cell.scene, width, height);
    if let Some(on) = cell.caustics {
        scene.pathtrace.caustics = on;
    }
    let seed = scene.pathtrace.seed;
    let native = native_pathtrace_mean(gpu, &scene, seed);
    let other_seed = native_pathtrace_mean(gpu, &scene, seed + 1);
    let relative = relative_difference(web, native);
    println!(
        "{name} ({width}x{height}, {SPP} spp): web {web:.6?}, native {native:.6?}: relative difference {relative:.2e} \
         (another seed: {:.2e})",
        relative_difference(other_seed, native)
    );
    assert!(
        relative < MEAN_TOLERANCE,
        "{name}: web {web:?} vs native {native:?} ({width}x{height}, {SPP} spp)"
    );
    relative
}

/// The Whitted cell: the page's image mean against a native Whitted render of the same size.
fn check_whitted_cell(root: &Path, gpu: &GpuContext, cell: &Cell, status: &HashMap<String, String>) -> f64 {
    let name = &cell.name;
    let (width, height) = size_of(get(status, "whittedSize"));
    let web = mean_of(get(status, "whittedMean"));
    let scene = sized_scene(root, cell.scene, width, height);
    let tracer = illum_whitted::WhittedTracer::new(gpu, &scene).unwrap_or_else(|e| panic!("{e}"));
    let native = tracer.render().unwrap_or_else(|e| panic!("{e}")).mean();
    let relative = relative_difference(web, native);
    println!(
        "{name} ({width}x{height}): web {web:.6?}, native {native:.6?}: relative difference {relative:.2e}"
    );
    // Deterministic: the two drivers differ by f32 rounding, which may move a ray across an
    // object's edge in a few pixels.
    assert!(relative < MEAN_TOLERANCE, "{name}: web {web:?} vs native {native:?} ({width}x{height})");
    relative
}

/// The raster's cell: the image in the page's screenshot (cropped to where the page says it
/// drew it) against a native raster render of the same size, pixel by pixel; returns the
/// relative difference of the image means.
fn check_raster_cell(
    root: &Path,
    gpu: &GpuContext,
    cell: &Cell,
    status: &HashMap<String, String>,
    shot: &image::RgbaImage,
) -> f64 {
    let name = &cell.name;
    let rect: Vec<u32> = get(status, "viewRect").split(' ').map(|v| v.parse().unwrap()).collect();
    let [x, y, width, height] = rect[..] else { panic!("{name}: view-rect {rect:?}") };
    let shown = image::imageops::crop_imm(shot, x, y, width, height).to_image();
    let scene = sized_scene(root, cell.scene, width, height);
    let raster = illum_raster::RasterScene::from_scene(&scene).unwrap_or_else(|e| panic!("{e}"));
    let mut renderer =
        illum_raster::RasterRenderer::new(gpu, &raster, width, height).unwrap_or_else(|e| panic!("{e}"));
    let native =
        renderer.render(&illum_raster::Options::from_scene(&raster)).unwrap_or_else(|e| panic!("{e}"));
    // The native image's 8-bit levels (exactly the output's bytes, see RasterRenderer::render).
    let level = |v: f32| (v * 255.0).round() as i32;
    let (mut web_sum, mut native_sum, mut off) = ([0f64; 3], [0f64; 3], 0usize);
    for (i, p) in shown.pixels().enumerate() {
        let q = native.pixels[i];
        let mut differs = false;
        for c in 0..3 {
            web_sum[c] += f64::from(p.0[c]);
            native_sum[c] += f64::from(level(q[c]));
            differs |= (i32::from(p.0[c]) - level(q[c])).abs() > 2;
        }
        off += usize::from(differs);
    }
    let pixels = f64::from(width * height);
    let relative = relative_difference(web_sum.map(|s| s / pixels), native_sum.map(|s| s / pixels));
    let fraction = off as f64 / pixels;
    println!(
        "{name} ({width}x{height}): image mean relative difference {relative:.2e}; {off} pixels ({:.3}%) differ by more than 2 levels",
        100.0 * fraction
    );
    // The picture is the same when the means agree and all but a sliver of edge pixels do
    // (measured 0.86% of the pixels beyond 2 levels).
    assert!(relative < RASTER_MEAN_TOLERANCE, "{name}: image means differ by {relative:.2e}");
    assert!(fraction < 0.02, "{name}: {off} of {pixels} pixels differ by more than 2 levels");
    relative
}

#[test]
fn the_web_viewer_works_in_headless_chromium() {
    let root = workspace();
    let missing = missing_prerequisites(&root);
    if !missing.is_empty() {
        let message = format!(
            "the browser test cannot run; missing: {}. .ci/run installs all of them.",
            missing.join("; ")
        );
        assert!(std::env::var_os("CI").is_none(), "{message}");
        // Straight to stderr, past the test harness's capture: a skip must be seen.
        let _ = writeln!(std::io::stderr(), "\n*** SKIPPED (not under CI): {message} ***\n");
        return;
    }

    let build = Command::new("bash").arg(root.join("scripts/build-web.sh")).current_dir(&root).status();
    assert!(build.is_ok_and(|s| s.success()), "scripts/build-web.sh failed (its output is above)");
    let url = serve(root.join("web/dist"));
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("web-test");
    let _ = std::fs::remove_dir_all(&out);
    std::fs::create_dir_all(&out).expect("the output folder");
    let cells = matrix();
    let tsv: String = cells.iter().map(|c| format!("{}\t{}\t{}\n", c.name, c.query(), c.expect())).collect();
    std::fs::write(out.join("matrix.tsv"), tsv).expect("writing the matrix");
    let started = web_time::Instant::now();
    let run = Command::new("node")
        .arg(root.join("web/tests/browser.mjs"))
        .arg(&url)
        .arg(&out)
        .env("CHROMIUM", chromium())
        .status()
        .expect("starting node");
    let browser_seconds = started.elapsed().as_secs_f64();
    assert!(run.success(), "the browser run failed (its output is above; screenshots in {})", out.display());
    println!("the browser run took {browser_seconds:.0} s ({} matrix cells)", cells.len());

    // No WebGPU: the explanation, not a blank canvas.
    let none = status(&out, "no-webgpu");
    assert_eq!(get(&none, "webgpu"), "missing", "{none:?}");
    assert_eq!(get(&none, "messageVisible"), "true", "{none:?}");
    let text = get(&none, "messageText");
    assert!(text.contains("illum needs WebGPU") && text.contains("enable-unsafe-webgpu"), "{text}");
    let no_api = status(&out, "no-webgpu-api");
    assert_eq!((get(&no_api, "webgpu"), get(&no_api, "messageVisible")), ("missing", "true"), "{no_api:?}");
    assert!(get(&no_api, "webgpuReason").contains("navigator.gpu is missing"), "{no_api:?}");

    // The matrix.
    let gpu = GpuContext::new().unwrap_or_else(|e| panic!("{e}"));
    let mut summary = Vec::new();
    for cell in &cells {
        let name = &cell.name;
        let st = status(&out, name);
        // Every page found the adapter, and shows the cell's scene in the cell's mode.
        let described = get(&st, "webgpuAdapter");
        assert!(!described.is_empty(), "{name}: the page found no adapter: {st:?}");
        assert_eq!(get(&st, "adapter"), format!("{described} (BrowserWebGpu)"), "{name}: {st:?}");
        assert_eq!(get(&st, "mode"), cell.mode.to_string(), "{name}: {st:?}");
        assert_eq!(get(&st, "openError"), "", "{name}: {st:?}");
        let shot = screenshot(&out, name);
        // A picture, never a blank canvas: a rendered image has thousands of colours.
        let colours = distinct_colours(&shot);
        assert!(colours > 500, "{name}: the canvas looks blank: {colours} colours");
        let outcome = match &cell.refusal {
            Some(reason) => {
                // The desktop's reason, in the top bar, and the mode's own scene meanwhile.
                let shown = get(&st, "modeRefusal");
                assert!(shown.contains(reason.as_str()), "{name}: the refusal {shown:?} lacks {reason:?}");
                assert_ne!(get(&st, "scene"), cell.scene, "{name}: {st:?}");
                assert!(shown.contains(&format!("showing {}", get(&st, "scene"))), "{name}: {shown:?}");
                "refused".to_owned()
            }
            None => {
                assert_eq!(get(&st, "modeRefusal"), "", "{name}: {st:?}");
                assert_eq!(get(&st, "scene"), cell.scene, "{name}: {st:?}");
                let relative = match cell.mode {
                    RendererKind::PathTrace => check_pathtrace_cell(&root, &gpu, cell, &st),
                    RendererKind::Whitted => check_whitted_cell(&root, &gpu, cell, &st),
                    RendererKind::Raster => check_raster_cell(&root, &gpu, cell, &st, &shot),
                };
                format!("image mean within {relative:.1e} of native")
            }
        };
        summary.push(format!("{name}: {outcome}"));
    }
    println!("WebGPU adapter: {}", get(&status(&out, &cells[0].name), "adapter"));
    println!("matrix:\n  {}", summary.join("\n  "));

    // The path tracer's speed in the page, for docs/performance.md.
    if let Some(cell) = cells.iter().find(|c| c.name == "cornell-pathtrace") {
        let pt = status(&out, &cell.name);
        let (width, height) = size_of(get(&pt, "pathtraceSize"));
        let gpu_seconds: f64 = get(&pt, "pathtraceGpuSeconds").parse().unwrap_or(0.0);
        let submission_seconds: f64 = get(&pt, "pathtraceSubmissionSeconds").parse().unwrap_or(0.0);
        let samples = f64::from(width) * f64::from(height) * f64::from(SPP);
        println!(
            "path tracer in the browser (Cornell box): {} samples/s (wall clock, the panel's), {:.0} over the submissions' wall time, {:.0} over their GPU time; window {} frames/s",
            get(&pt, "pathtraceSamplesPerSecond"),
            samples / submission_seconds.max(1e-9),
            samples / gpu_seconds.max(1e-9),
            get(&pt, "windowFps")
        );
    }

    // Save EXR on the Cornell box's page downloads the checkpoint the desktop writes: the same
    // f64 statistics, 8 spp.
    let web = mean_of(get(&status(&out, "cornell-pathtrace"), "pathtraceMean"));
    let described = get(&status(&out, "cornell-pathtrace"), "webgpuAdapter").to_owned();
    let name = std::fs::read_to_string(out.join("download.name")).expect("the download's name");
    assert_eq!(name, "viewer-cornell.exr");
    let saved = illum_pathtrace::checkpoint::load_checkpoint(&out.join("download.exr"))
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(saved.spp_done, SPP);
    assert_eq!(saved.metadata.get("spp"), Some(SPP.to_string().as_str()), "{:?}", saved.metadata);
    assert_eq!(saved.metadata.get("adapter"), Some(described.as_str()), "{:?}", saved.metadata);
    let saved_mean = saved.accumulator.mean_image().mean();
    for c in 0..3 {
        assert!(
            (saved_mean[c] - web[c]).abs() <= 1e-6 * web[c],
            "the saved EXR's mean {saved_mean:?} vs the page's {web:?}"
        );
    }

    // A bad file dropped on the page: the desktop's message; the Cornell box stays.
    let bad = status(&out, "bad-scene");
    let expected =
        illum_viewer::scene_file::load_text("bad.toml", "[camera]\nvfov = \"wide\"\n").unwrap_err();
    assert_eq!(get(&bad, "openError"), expected.replace('\n', " "), "{bad:?}");
    assert_eq!(get(&bad, "scene"), "scenes/cornell.toml", "{bad:?}");
    assert_eq!(get(&bad, "mode"), "pathtrace", "{bad:?}");
    // A scene the page does not have: an error naming it; the default scene stays.
    let missing_scene = status(&out, "missing-scene");
    let error = get(&missing_scene, "openError");
    assert!(error.contains("scenes/nope.toml") && error.contains("built into this page"), "{error}");
    assert_eq!(get(&missing_scene, "scene"), "scenes/cornell.toml", "{missing_scene:?}");
    // "Open file...": the browser's file picker, given the Whitted scene as picked.toml; it
    // opens in its file's mode and the error goes.
    let picked = status(&out, "picked-scene");
    assert_eq!(
        (get(&picked, "scene"), get(&picked, "mode"), get(&picked, "openError")),
        ("picked.toml", "raster", ""),
        "{picked:?}"
    );

    // The raster's figure look: the assignment's exact colours (docs/scenes.md).
    let raster = screenshot(&out, "whitted-raster");
    for (what, rgb, least) in [
        ("background", [76, 128, 229], 5000),
        ("lit yellow tile", [207, 207, 0], 500),
        ("lit red tile", [207, 0, 0], 500),
        ("shadowed yellow tile", [47, 47, 0], 20),
        ("shadowed red tile", [47, 0, 0], 20),
    ] {
        let n = count(&raster, rgb);
        assert!(n >= least, "raster: only {n} pixels of the {what} {rgb:?} (at least {least} expected)");
    }
    println!(
        "raster in the browser: the window at {} frames/s",
        get(&status(&out, "whitted-raster"), "windowFps")
    );

    // The Whitted ray tracer: the scene's sky (76, 128, 229 in its linear PNG).
    let whitted = screenshot(&out, "whitted-whitted");
    assert!(count(&whitted, [76, 128, 229]) > 5000, "no sky in the Whitted picture");
    println!("Whitted in the browser: {} ms per frame", get(&status(&out, "whitted-whitted"), "whittedMs"));
}
