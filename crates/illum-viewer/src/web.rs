//! The browser side of the viewer: starting eframe's web runner on the page's canvas, the
//! page's "command line" (its URL query), downloads, the browser's file picker, and the status
//! the page shows to scripts. Only built for `wasm32`; see [`crate::platform`] for the seams
//! the rest of the viewer goes through.

use std::cell::RefCell;
use std::path::PathBuf;
use std::rc::Rc;

use wasm_bindgen::JsCast;
use wasm_bindgen::prelude::*;

use crate::app::{Mode, StartOptions, ViewerApp};
use crate::pathtrace_panel::{MAX_SCALE, MIN_SCALE};
use crate::scene_file::DEFAULT_PATHTRACE_SCENE;

/// The canvas the page gives the viewer, and the element it reports to.
const CANVAS_ID: &str = "illum-canvas";
const STATUS_ID: &str = "illum-status";

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
    let mode =
        get("mode").and_then(|m| m.parse::<Mode>().map_err(|e| errors.push(format!("mode: {e}"))).ok());
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
    (StartOptions { scene, mode, screenshot: None }, PathTraceQuery { spp, caustics, scale }, error)
}

/// Publishes the viewer's status as `data-*` attributes of `#illum-status` (for scripts and
/// the browser test), and its text for people.
pub fn publish_status(status: &[(&'static str, String)]) {
    let Some(element) = document().ok().and_then(|d| d.get_element_by_id(STATUS_ID)) else { return };
    for (name, value) in status {
        let _ = element.set_attribute(&format!("data-{name}"), value);
    }
    let _ = element.set_attribute("data-running", "yes");
}

/// The WebGPU adapter as the page's script described it (vendor, architecture, description,
/// from `GPUAdapter.info`): wgpu's adapter info has no name in the browser.
pub fn adapter_description() -> String {
    document()
        .ok()
        .and_then(|d| d.get_element_by_id(STATUS_ID))
        .and_then(|e| e.get_attribute("data-webgpu-adapter"))
        .filter(|name| !name.is_empty())
        .unwrap_or_else(|| "WebGPU adapter".to_owned())
}

/// Starts a download of `bytes` as a file called `name`.
pub fn download(name: &str, bytes: &[u8], mime: &str) -> Result<(), String> {
    let failed = |e: JsValue| format!("the download of {name} could not start: {}", js_text(&e));
    let parts = js_sys::Array::of1(&js_sys::Uint8Array::from(bytes));
    let properties = web_sys::BlobPropertyBag::new();
    properties.set_type(mime);
    let blob = web_sys::Blob::new_with_u8_array_sequence_and_options(&parts, &properties).map_err(failed)?;
    let url = web_sys::Url::create_object_url_with_blob(&blob).map_err(failed)?;
    let link = document()?
        .create_element("a")
        .map_err(failed)?
        .dyn_into::<web_sys::HtmlAnchorElement>()
        .map_err(|_| format!("the download of {name} could not start: no link element"))?;
    link.set_href(&url);
    link.set_download(name);
    link.click();
    // The browser has taken the blob once the click is handled; free it a little later.
    let revoke = Closure::once_into_js(move || {
        let _ = web_sys::Url::revoke_object_url(&url);
    });
    if let Some(window) = web_sys::window() {
        let _ = window.set_timeout_with_callback_and_timeout_and_arguments_0(revoke.unchecked_ref(), 10_000);
    }
    Ok(())
}

/// The browser's file picker for scene files. [`FilePicker::open`] shows it; the chosen
/// file's name and text arrive later and are taken with [`FilePicker::take`].
#[derive(Default)]
pub struct FilePicker {
    inbox: Rc<RefCell<Option<PickedFile>>>,
}

/// A picked or dropped file: its name, and its text or why it could not be read.
pub type PickedFile = (String, Result<String, String>);

impl FilePicker {
    /// Shows the picker; `ctx` is asked to repaint when the file has been read.
    pub fn open(&mut self, ctx: &egui::Context) -> Result<(), String> {
        let failed = |e: JsValue| format!("the file picker could not open: {}", js_text(&e));
        let input = document()?
            .create_element("input")
            .map_err(failed)?
            .dyn_into::<web_sys::HtmlInputElement>()
            .map_err(|_| "the file picker could not open: no input element".to_owned())?;
        input.set_type("file");
        input.set_accept(".toml,text/plain");
        let inbox = self.inbox.clone();
        let ctx = ctx.clone();
        let chosen = input.clone();
        let on_change = Closure::once_into_js(move || {
            let Some(file) = chosen.files().and_then(|files| files.get(0)) else { return };
            wasm_bindgen_futures::spawn_local(async move {
                let name = file.name();
                let text = wasm_bindgen_futures::JsFuture::from(file.text()).await;
                let result = match text {
                    Ok(value) => value.as_string().ok_or_else(|| format!("{name}: not a text file")),
                    Err(e) => Err(format!("{name}: could not be read: {}", js_text(&e))),
                };
                *inbox.borrow_mut() = Some((name, result));
                ctx.request_repaint();
            });
        });
        input.set_onchange(Some(on_change.unchecked_ref()));
        input.click();
        Ok(())
    }

    /// Reads a file dropped on the page into the same inbox as a picked one.
    pub fn read_dropped(&mut self, ctx: &egui::Context, file: egui::DroppedFileHandle) {
        let inbox = self.inbox.clone();
        let ctx = ctx.clone();
        wasm_bindgen_futures::spawn_local(async move {
            let name = file.path().display().to_string();
            let name = if name.is_empty() { "dropped file".to_owned() } else { name };
            let result =
                file.bytes_async().await.map_err(|e| format!("{name}: could not be read: {e}")).and_then(
                    |bytes| {
                        String::from_utf8(bytes)
                            .map_err(|e| format!("{name}: not a text (UTF-8) scene file: {e}"))
                    },
                );
            *inbox.borrow_mut() = Some((name, result));
            ctx.request_repaint();
        });
    }

    /// The file chosen since the last call: its name and text, or why it could not be read.
    pub fn take(&mut self) -> Option<PickedFile> {
        self.inbox.borrow_mut().take()
    }
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

fn document() -> Result<web_sys::Document, String> {
    web_sys::window()
        .and_then(|w| w.document())
        .ok_or_else(|| "no document (not in a browser page)".to_owned())
}

/// A JavaScript error or value as text.
fn js_text(value: &JsValue) -> String {
    value
        .dyn_ref::<js_sys::Error>()
        .map(|e| String::from(e.message()))
        .or_else(|| value.as_string())
        .unwrap_or_else(|| format!("{value:?}"))
}
