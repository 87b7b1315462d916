//! The viewer's start in a browser: eframe's web runner on the page's canvas, and the page's
//! "command line" (its URL query). Only built for `wasm32`; the page's services the running
//! app uses are [`crate::browser`], and [`crate::platform`] names the seams the rest of the
//! viewer goes through.

use std::path::PathBuf;

use wasm_bindgen::JsCast;

use crate::app::{StartOptions, ViewerApp};
use crate::browser::{STATUS_ID, document, js_text};
use crate::pathtrace_mode::{MAX_SCALE, MIN_SCALE};
use crate::scene_file::DEFAULT_PATHTRACE_SCENE;
use crate::start_mode::{StartMode, parse_start_mode};

/// The canvas the page gives the viewer.
const CANVAS_ID: &str = "illum-canvas";

/// Starts the viewer on the page's canvas. The page has already checked that the browser has
/// a WebGPU adapter (index.html); a failure to start is shown on the page.
pub fn start() {
    // Errors and warnings go to the browser console.
    let _ = eframe::WebLogger::init(log::LevelFilter::Warn);
    wasm_bindgen_futures::spawn_local(async {
        if let Err(message) = run().await {
            log::error!("{message}");
            show_failure(&message);
        }
    });
}

async fn run() -> Result<(), String> {
    let document = document()?;
    let canvas = document
        .get_element_by_id(CANVAS_ID)
        .ok_or_else(|| format!("the page has no element #{CANVAS_ID}"))?
        .dyn_into::<web_sys::HtmlCanvasElement>()
        .map_err(|_| format!("#{CANVAS_ID} is not a canvas"))?;
    let (options, pathtrace, url_error) = start_options_from_url();
    let mut web_options = eframe::WebOptions::default();
    web_options.wgpu_options.wgpu_setup = crate::gpu_setup::wgpu_setup(false);
    eframe::WebRunner::new()
        .start(
            canvas,
            web_options,
            Box::new(move |cc| {
                let mut app = ViewerApp::new(cc, options);
                if let Some(mode) = app.pathtrace_mut() {
                    let settings = &mut mode.settings;
                    settings.stop.spp = pathtrace.spp.or(settings.stop.spp);
                    settings.caustics = pathtrace.caustics.unwrap_or(settings.caustics);
                    settings.resolution_scale = pathtrace.scale.unwrap_or(settings.resolution_scale);
                }
                if let Some(error) = url_error {
                    app.open_error = Some(error);
                }
                if pathtrace.auto {
                    app.show_auto();
                }
                Ok(Box::new(app))
            }),
        )
        .await
        .map_err(|e| format!("the viewer could not start: {}", js_text(&e)))
}

/// The path tracer's settings the page's address may give.
#[derive(Default)]
struct PathTraceQuery {
    /// `spp=N`: the spp target.
    spp: Option<u32>,
    /// `caustics=on|off`: the caustic's light tracer, whatever the scene file says.
    caustics: Option<bool>,
    /// `scale=S`: the resolution scale (the panel's slider, 0.1 to 1).
    scale: Option<f32>,
    /// `mode=auto`: the Auto mode shown first.
    auto: bool,
}

/// The page's URL query as the desktop's command line:
/// `?scene=scenes/whitted.toml&mode=pathtrace&spp=16&caustics=off&scale=0.25` (a built-in scene,
/// the first mode, and the path tracer's spp target, light tracer and resolution scale). A bad
/// value is returned as an error to show.
fn start_options_from_url() -> (StartOptions, PathTraceQuery, Option<String>) {
    let search = web_sys::window().and_then(|w| w.location().search().ok()).unwrap_or_default();
    let params = web_sys::UrlSearchParams::new_with_str(&search).ok();
    let get = |key: &str| params.as_ref().and_then(|p| p.get(key)).filter(|v| !v.is_empty());
    let scene = PathBuf::from(get("scene").unwrap_or_else(|| DEFAULT_PATHTRACE_SCENE.to_owned()));
    let mut errors = Vec::new();
    let start_mode =
        get("mode").and_then(|m| parse_start_mode(&m).map_err(|e| errors.push(format!("mode: {e}"))).ok());
    let mode = start_mode.and_then(StartMode::renderer);
    let spp = get("spp").and_then(|text| match text.parse::<u32>() {
        Ok(spp) if spp >= 1 => Some(spp),
        _ => {
            errors.push(format!("spp = {text:?}: must be a whole number of at least 1"));
            None
        }
    });
    let caustics = get("caustics").and_then(|text| match text.as_str() {
        "on" => Some(true),
        "off" => Some(false),
        _ => {
            errors.push(format!("caustics = {text:?}: must be on or off"));
            None
        }
    });
    let (min, max) = (MIN_SCALE, MAX_SCALE);
    let scale = get("scale").and_then(|text| match text.parse::<f32>() {
        Ok(scale) if (min..=max).contains(&scale) => Some(scale),
        _ => {
            errors.push(format!("scale = {text:?}: must be a number from {min} to {max}"));
            None
        }
    });
    let error = (!errors.is_empty()).then(|| format!("in the page address: {}", errors.join("; ")));
    (
        StartOptions { scene, mode, screenshot: None, clear_is_backdrop: true },
        PathTraceQuery { spp, caustics, scale, auto: start_mode == Some(StartMode::Auto) },
        error,
    )
}

/// Replaces the canvas with a message (the viewer could not start).
fn show_failure(message: &str) {
    let Ok(document) = document() else { return };
    if let Some(element) = document.get_element_by_id("illum-failure") {
        element.set_text_content(Some(message));
        let _ = element.set_attribute("data-shown", "yes");
    }
    if let Some(status) = document.get_element_by_id(STATUS_ID) {
        let _ = status.set_attribute("data-failure", message);
    }
}
