//! `--screenshot FILE --frames N`: draw N frames, capture the window through eframe's own
//! screenshot command, save it as PNG (atomically, via illum-image) and close the window.

use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use egui::{ColorImage, ViewportCommand};

/// What happened to a screenshot request, read by `main` after the window closed.
pub type Outcome = Arc<Mutex<Option<Result<PathBuf, String>>>>;

/// A pending screenshot.
pub struct ScreenshotJob {
    path: PathBuf,
    frames_left: u32,
    requested: bool,
    /// Filled by eframe's callback once the frame has been read back.
    captured: Arc<Mutex<Option<Arc<ColorImage>>>>,
    outcome: Outcome,
}

impl ScreenshotJob {
    pub fn new(path: PathBuf, frames: u32, outcome: Outcome) -> Self {
        ScreenshotJob { path, frames_left: frames, requested: false, captured: Arc::default(), outcome }
    }

    /// Called once per frame. Counts frames, then asks for the capture, then saves it and closes
    /// the window. Keeps the window repainting until done. `summary` gives the shown mode's
    /// statistics and the frame rate, printed with the result.
    pub fn tick(&mut self, ctx: &egui::Context, summary: impl FnOnce() -> String) {
        ctx.request_repaint();
        if self.frames_left > 0 {
            self.frames_left -= 1;
            return;
        }
        if !self.requested {
            self.requested = true;
            let captured = self.captured.clone();
            let repaint = ctx.clone();
            ctx.send_viewport_cmd(ViewportCommand::Screenshot(egui::ScreenshotCallback::new(move |image| {
                *captured.lock().unwrap_or_else(|p| p.into_inner()) = Some(image);
                repaint.request_repaint();
            })));
            return;
        }
        let Some(image) = self.captured.lock().unwrap_or_else(|p| p.into_inner()).take() else { return };
        let result = save(&self.path, &image).map(|()| self.path.clone());
        println!("statistics: {}", summary());
        if let Err(e) = &result {
            log::error!("{e}");
        }
        *self.outcome.lock().unwrap_or_else(|p| p.into_inner()) = Some(result);
        ctx.send_viewport_cmd(ViewportCommand::Close);
    }
}

/// Writes the captured window (egui gives sRGB-encoded RGBA bytes, as shown) as PNG.
fn save(path: &std::path::Path, image: &ColorImage) -> Result<(), String> {
    let [width, height] = image.size;
    let bytes: Vec<u8> = image.pixels.iter().flat_map(|c| c.to_array()).collect();
    let rgba = image::RgbaImage::from_raw(width as u32, height as u32, bytes)
        .ok_or_else(|| format!("the captured window ({width} x {height}) has the wrong number of pixels"))?;
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).map_err(|e| format!("creating {}: {e}", parent.display()))?;
    }
    illum_image::save_rgba8_png(path, &rgba).map_err(|e| format!("saving the screenshot: {e}"))
}
