//! The page's services the viewer uses while it runs in a browser: its status for scripts, the
//! WebGPU adapter's description, downloads and the file picker. Only built for `wasm32`;
//! [`crate::web`] starts the viewer, and [`crate::platform`] names what differs from the desktop.

use std::cell::RefCell;
use std::rc::Rc;

use wasm_bindgen::JsCast;
use wasm_bindgen::prelude::*;

use crate::scene_file::GivenFile;

/// The element the viewer reports its status to (the page's script reads it).
pub(crate) const STATUS_ID: &str = "illum-status";

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

/// The browser's file picker for scene files and the mesh files they name, picked together.
/// [`FilePicker::open`] shows it; the chosen files' names and bytes arrive later and are taken
/// with [`FilePicker::take`].
#[derive(Default)]
pub struct FilePicker {
    inbox: Rc<RefCell<Option<Vec<GivenFile>>>>,
}

impl FilePicker {
    /// Shows the picker; `ctx` is asked to repaint when the files have been read.
    pub fn open(&mut self, ctx: &egui::Context) -> Result<(), String> {
        let failed = |e: JsValue| format!("the file picker could not open: {}", js_text(&e));
        let input = document()?
            .create_element("input")
            .map_err(failed)?
            .dyn_into::<web_sys::HtmlInputElement>()
            .map_err(|_| "the file picker could not open: no input element".to_owned())?;
        input.set_type("file");
        input.set_multiple(true);
        input.set_accept(".toml,.obj,.ply,text/plain");
        let inbox = self.inbox.clone();
        let ctx = ctx.clone();
        let chosen = input.clone();
        let on_change = Closure::once_into_js(move || {
            let Some(list) = chosen.files() else { return };
            let files: Vec<web_sys::File> = (0..list.length()).filter_map(|i| list.get(i)).collect();
            wasm_bindgen_futures::spawn_local(async move {
                let mut given = Vec::with_capacity(files.len());
                for file in files {
                    let name = file.name();
                    let bytes = wasm_bindgen_futures::JsFuture::from(file.array_buffer())
                        .await
                        .map(|buffer| js_sys::Uint8Array::new(&buffer).to_vec())
                        .map_err(|e| format!("{name}: could not be read: {}", js_text(&e)));
                    given.push((name, bytes));
                }
                *inbox.borrow_mut() = Some(given);
                ctx.request_repaint();
            });
        });
        input.set_onchange(Some(on_change.unchecked_ref()));
        input.click();
        Ok(())
    }

    /// Reads files dropped on the page together into the same inbox as picked ones.
    pub fn read_dropped(&mut self, ctx: &egui::Context, files: Vec<egui::DroppedFileHandle>) {
        let inbox = self.inbox.clone();
        let ctx = ctx.clone();
        wasm_bindgen_futures::spawn_local(async move {
            let mut given = Vec::with_capacity(files.len());
            for file in files {
                let name = file.path().display().to_string();
                let name = if name.is_empty() { "dropped file".to_owned() } else { name };
                let bytes = file.bytes_async().await.map_err(|e| format!("{name}: could not be read: {e}"));
                given.push((name, bytes));
            }
            *inbox.borrow_mut() = Some(given);
            ctx.request_repaint();
        });
    }

    /// The files chosen together since the last call: each one's name and bytes, or why it
    /// could not be read.
    pub fn take(&mut self) -> Option<Vec<GivenFile>> {
        self.inbox.borrow_mut().take()
    }
}

pub(crate) fn document() -> Result<web_sys::Document, String> {
    web_sys::window()
        .and_then(|w| w.document())
        .ok_or_else(|| "no document (not in a browser page)".to_owned())
}

/// A JavaScript error or value as text.
pub(crate) fn js_text(value: &JsValue) -> String {
    value
        .dyn_ref::<js_sys::Error>()
        .map(|e| String::from(e.message()))
        .or_else(|| value.as_string())
        .unwrap_or_else(|| format!("{value:?}"))
}
