//! What the window reports about itself: the status the web page publishes for scripts and
//! browser tests (`#illum-status`), and the summary line a `--screenshot` run prints.

use super::ViewerApp;
use crate::pathtrace_mode::PathTraceMode;

impl ViewerApp {
    /// What the window shows, as (name, value) pairs: the mode, the scene, the last open
    /// error, the adapter, and each mode's progress. The web page publishes them on the page
    /// (`data-*` attributes of `#illum-status`) for scripts and browser tests.
    pub fn status(&self) -> Vec<(&'static str, String)> {
        // Every name every time (empty when it does not apply), so that a value never outlives
        // what it describes.
        let text = |value: Option<String>| value.unwrap_or_default();
        let pathtrace = self.pathtrace();
        let stats = pathtrace.map(PathTraceMode::stats);
        let image = pathtrace.and_then(PathTraceMode::image_mean);
        let seconds = pathtrace.and_then(PathTraceMode::submission_seconds);
        let whitted_image = self.whitted().and_then(|w| w.image_mean);
        let on_off = |on: bool| if on { "on" } else { "off" };
        vec![
            ("mode", self.mode.to_string()),
            ("scene", text(self.current_scene_path())),
            ("open-error", text(self.open_error.clone())),
            ("mode-refusal", text(self.refusal_of(self.mode))),
            ("window-fps", text(self.frame_rate.fps().map(|f| format!("{f:.1}")))),
            (
                "adapter",
                text(
                    self.gpu.as_ref().ok().map(|(gpu, _)| {
                        format!("{} ({:?})", gpu.adapter_info.name, gpu.adapter_info.backend)
                    }),
                ),
            ),
            ("pathtrace-spp", text(stats.map(|s| s.spp.to_string()))),
            ("pathtrace-samples-per-second", text(stats.map(|s| format!("{:.0}", s.samples_per_second)))),
            ("pathtrace-stopped", text(pathtrace.and_then(|p| p.stop_reason()).map(|r| r.name().to_owned()))),
            ("pathtrace-size", text(image.map(|(_, [w, h])| format!("{w}x{h}")))),
            ("pathtrace-mean", text(image.map(|(m, _)| format!("{} {} {}", m[0], m[1], m[2])))),
            ("pathtrace-submission-seconds", text(seconds.map(|(wall, _)| format!("{wall:.3}")))),
            ("pathtrace-gpu-seconds", text(seconds.map(|(_, gpu)| format!("{gpu:.3}")))),
            ("pathtrace-message", text(pathtrace.and_then(|p| p.message.clone()))),
            (
                "pathtrace-caustics",
                text(pathtrace.and_then(PathTraceMode::caustics_running).map(|on| on_off(on).to_owned())),
            ),
            (
                "pathtrace-denoise",
                text(pathtrace.filter(|p| p.settings.denoise).map(|p| p.denoise.summary())),
            ),
            ("raster-message", text(self.raster().and_then(|r| r.message.clone()))),
            ("view-rect", text(self.view_rect.map(|[x, y, w, h]| format!("{x} {y} {w} {h}")))),
            ("whitted-frames", text(self.whitted().map(|w| w.frames.to_string()))),
            ("whitted-size", text(whitted_image.map(|(_, [w, h])| format!("{w}x{h}")))),
            ("whitted-mean", text(whitted_image.map(|(m, _)| format!("{} {} {}", m[0], m[1], m[2])))),
            ("whitted-ms", text(self.whitted().and_then(|w| w.frame_ms).map(|ms| format!("{ms:.0}")))),
            ("whitted-message", text(self.whitted().and_then(|w| w.message.clone()))),
        ]
    }

    /// One line of the shown mode's statistics and the window's frame rate, as a
    /// `--screenshot` run prints them on exit (the smoke test and `bench --viewer` read it).
    pub fn summary(&self) -> String {
        let mode = self.mode_ref(self.mode).ok().map(|m| m.summary());
        let fps = self.frame_rate.fps().map_or("n/a".to_owned(), |f| format!("{f:.1} fps"));
        let auto = if self.auto_shown { format!("{}; ", self.auto.summary()) } else { String::new() };
        format!("{auto}{}, window {fps}", mode.unwrap_or_else(|| format!("{}: no scene", self.mode)))
    }
}
