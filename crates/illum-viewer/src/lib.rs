//! illum-viewer: one eframe window that shows either renderer of illum on eframe's own wgpu
//! device.
//!
//! - [`app`]: the application state, the mode switch and the scene field;
//! - [`pathtrace_mode`] / [`pathtrace_panel`]: the path tracer's mode (settings, renderer,
//!   statistics, saving) and its panel;
//! - [`raster_mode`] / [`raster_panel`], [`whitted_mode`] / [`whitted_panel`]: each of the
//!   other modes' state (settings, renderer) and its panel;
//! - [`mode`]: what the window asks of every mode ([`mode::ViewMode`]);
//! - [`auto_panel`]: the Auto mode (the accuracy slider and the choice), its pilot
//!   (`illum_auto::pilot`) stepped once per frame;
//! - [`camera`]: orbit / pan / zoom with the mouse, shared by both modes;
//! - [`denoise_view`]: the path tracer's Denoise toggle (the denoised image and its estimated
//!   error);
//! - [`difference_view`]: the raster and Whitted modes' signed difference from a truth;
//! - [`display`]: the path tracer's GPU tone-mapping pass from its display sum (a GPU buffer)
//!   into the texture egui shows;
//! - [`gpu_setup`]: how eframe creates the device the renderers share;
//! - [`frame_rate`]: frames per second over recent frames;
//! - [`pacer`]: how much of each frame the path tracer gets;
//! - [`scene_file`]: opening scene files of either kind, with errors as text;
//! - [`cli`] and [`screenshot`]: the desktop's command line, and `--screenshot FILE --frames N`;
//!   [`start_mode`]: the first mode as `--mode` and the page's `?mode=` name it;
//! - [`plural`]: counts in words ("1 frame", "2 frames");
//! - [`platform`]: what differs between the desktop and the browser (readback, scene files,
//!   saving); `web` (wasm32 only): the viewer's start on a page, which builds the app; and
//!   `browser` (wasm32 only): the page's services the app uses (downloads, the file picker,
//!   the status for scripts).
//!
//! The modes are the renderers, [`illum_scene::RendererKind`]. Modules depend on each other in
//! one direction only: `web` and `cli` on `app`, `app` on the panels, `scene_file`, `platform`
//! and `browser`, none of which depends back.

pub mod app;
pub mod auto_panel;
#[cfg(target_arch = "wasm32")]
pub mod browser;
pub mod camera;
#[cfg(not(target_arch = "wasm32"))]
pub mod cli;
pub mod denoise_view;
pub mod difference_view;
pub mod display;
pub mod error_view;
pub mod frame_rate;
pub mod gpu_setup;
pub mod mode;
pub mod pacer;
pub mod pathtrace_mode;
pub mod pathtrace_panel;
pub mod platform;
pub mod plural;
pub mod raster_mode;
pub mod raster_panel;
pub mod scene_file;
pub mod screenshot;
pub mod start_mode;
#[cfg(target_arch = "wasm32")]
pub mod web;
pub mod whitted_mode;
pub mod whitted_panel;

pub use app::{StartOptions, ViewerApp};
