//! The web viewer in a real browser: builds it, or uses the page already built from the same
//! sources (`scripts/build-web.sh --if-stale`; `.ci/run` builds it beside the tests, and this
//! waits for that build), serves `web/dist/` on 127.0.0.1, drives headless Chromium on WebGPU
//! (SwiftShader) with `web/tests/browser.mjs` (Playwright), and checks what the page showed and reported:
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

mod matrix;
mod native;
mod page;
mod prerequisites;
mod server;

use std::io::Write;
use std::path::Path;
use std::process::Command;

use illum_gpu::GpuContext;
use illum_scene::RendererKind;

use matrix::{SPP, matrix};
use native::{check_pathtrace_cell, check_raster_cell, check_whitted_cell, mean_of, size_of};
use page::{count, distinct_colours, get, screenshot, status};
use prerequisites::{chromium, missing_prerequisites, workspace};
use server::serve;

/// The scene the page is given with "Open file...", with its mesh file: the Whitted scene shown
/// by the Whitted ray tracer with a mirror icosahedron (20 triangles) added, written into `out`
/// (`mesh.toml`, `models/icosphere-0.obj`) for browser.mjs, and checked to load from there.
fn write_mesh_scene(root: &Path, out: &Path) {
    let text = std::fs::read_to_string(root.join("scenes/whitted.toml")).expect("the Whitted scene");
    assert!(text.contains("renderer = \"raster\""), "the Whitted scene's renderer line moved");
    let text = text.replace("renderer = \"raster\"", "renderer = \"whitted\"")
        + "\n[[objects]]\nname = \"ball\"\nmaterial = \"metal\"\n\
           mesh = { file = \"models/icosphere-0.obj\", translate = [1.0, 1.0, -6.0], scale = 1.0 }\n";
    std::fs::create_dir_all(out.join("models")).expect("the models folder");
    std::fs::copy(root.join("scenes/models/icosphere-0.obj"), out.join("models/icosphere-0.obj"))
        .expect("copying the mesh");
    std::fs::write(out.join("mesh.toml"), text).expect("writing the mesh scene");
    illum_scene::Scene::load(&out.join("mesh.toml")).unwrap_or_else(|e| panic!("{e}"));
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

    // The page as built from these sources: the one in web/dist when its fingerprint is theirs.
    let build = Command::new("bash")
        .arg(root.join("scripts/build-web.sh"))
        .arg("--if-stale")
        .current_dir(&root)
        .status();
    assert!(build.is_ok_and(|s| s.success()), "scripts/build-web.sh --if-stale failed (its output is above)");
    let url = serve(root.join("web/dist"));
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("web-test");
    let _ = std::fs::remove_dir_all(&out);
    std::fs::create_dir_all(&out).expect("the output folder");
    let cells = matrix();
    let tsv: String = cells.iter().map(|c| format!("{}\t{}\t{}\n", c.name, c.query(), c.expect())).collect();
    std::fs::write(out.join("matrix.tsv"), tsv).expect("writing the matrix");
    write_mesh_scene(&root, &out);
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
    // A scene naming a mesh file, picked without it: refused, naming the file to pick with it;
    // the scene before stays.
    let alone = status(&out, "mesh-alone");
    let error = get(&alone, "openError");
    assert!(
        error.contains("cannot read models/icosphere-0.obj")
            && error.contains("open icosphere-0.obj together with mesh.toml"),
        "{error}"
    );
    assert_eq!(get(&alone, "scene"), "picked.toml", "{alone:?}");
    // Picked with its mesh file: it opens in its file's mode. Its frame is not awaited
    // (browser.mjs: SwiftShader does not finish the pipeline).
    let meshed = status(&out, "mesh-scene");
    assert_eq!(
        (get(&meshed, "scene"), get(&meshed, "mode"), get(&meshed, "openError")),
        ("mesh.toml", "whitted", ""),
        "{meshed:?}"
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
