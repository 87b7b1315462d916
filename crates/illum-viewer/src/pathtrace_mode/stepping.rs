//! A frame of the path-tracer mode: the tracer brought in line with the settings, camera and
//! view size, this frame's slice of samples, and the texture shown (the tone-mapped sum, its
//! error view or the denoised image).

use illum_gpu::GpuContext;
use illum_pathtrace::{ExactPart, PathTracer};
use illum_scene::Scene;

use super::{PathTraceMode, WHOLE_PASS_SAMPLES, WorkLog};
use crate::display::Display;

impl PathTraceMode {
    /// Brings the tracer in line with the settings, camera and `view_pixels` size, runs this
    /// frame's slice of work and refreshes the displayed texture.
    pub(crate) fn step_frame(
        &mut self,
        gpu: &GpuContext,
        ctx: &egui::Context,
        render_state: &egui_wgpu::RenderState,
        view_pixels: [u32; 2],
    ) {
        let [width, height] = self.render_size(view_pixels);
        let wanted = self.desired_scene(width, height);
        if self.failed.as_ref() == Some(&wanted) {
            return;
        }
        let restarted = match self.sync_tracer(gpu, &wanted) {
            Ok(restarted) => restarted,
            Err(message) => {
                self.message = Some(format!("path tracer: {message}"));
                self.tracer = None;
                self.failed = Some(wanted);
                return;
            }
        };
        self.failed = None;
        let Some(tracer) = self.tracer.as_mut() else { return };
        // The rules follow the panel (a changed spp target restarts the accumulation through
        // the scene; a changed error target or budget applies from now on).
        self.progressive.rules = self.settings.stop;
        if !self.paused {
            // The web page never waits for a band (each comes back a frame or more later), so
            // there the submission keeps its fixed size; natively the frame waits for it.
            if !crate::platform::POLLED_READBACK {
                tracer.set_target_seconds(self.pacer.submission_seconds(restarted));
            }
            let started = web_time::Instant::now();
            let stepped = self.progressive.step(tracer);
            let step_seconds = started.elapsed().as_secs_f64();
            self.pacer.stepped(started, step_seconds);
            self.work.step_seconds += step_seconds;
            if let Err(e) = stepped {
                self.message = Some(format!("path tracer: {e}"));
                self.set_paused(true);
                return;
            }
            let report = tracer.last_step();
            if report.scheduled_samples > 0 {
                let work = &mut self.work;
                work.submissions += 1;
                work.scheduled_samples += report.scheduled_samples;
                work.smallest_submission = work.smallest_submission.min(report.scheduled_samples);
                work.passes += u64::from(report.pass_completed);
            }
        }
        let total = tracer.accumulator().total_samples();
        let solved = tracer.accumulator().exact_solved();
        let display = self.display.get_or_insert_with(|| Display::new(gpu));
        // The display sum holds radiance scaled by 2^-k for very bright lights (k = 0 below
        // 2^16): k more stops give the radiance back.
        let stops = self.settings.exposure + tracer.display_scale().log2();
        if total != self.shown_samples || solved != self.shown_exact {
            self.shown_samples = total;
            self.shown_exact = solved;
            self.stats = Self::measure(tracer, &self.progressive);
            let camera = tracer.scene().camera;
            if let Some(display_sum) = tracer.display_sum_buffer() {
                let mut renderer = render_state.renderer.write();
                // The exact part is radiance; the display sum holds radiance / display_scale.
                let exact_scale = 1.0 / tracer.display_scale();
                let unsolved = ExactPart::default();
                let exact = if solved { tracer.accumulator().exact() } else { &unsolved };
                display.show(
                    gpu,
                    &mut renderer,
                    display_sum,
                    [camera.width, camera.height],
                    stops,
                    exact,
                    exact_scale,
                );
            }
            self.shown_exposure = self.settings.exposure;
        } else if self.shown_exposure != self.settings.exposure {
            display.redraw(gpu, stops);
            self.shown_exposure = self.settings.exposure;
        }
        // The error view and the denoiser read the whole image, exact part included: they
        // wait for its solve to end rather than hold a frame for it.
        if !solved {
            return;
        }
        self.refresh_error_view(ctx);
        if self.settings.denoise
            && let Some(tracer) = &self.tracer
        {
            let stopped = self.paused || self.progressive.stopped().is_some();
            self.denoise.frame(gpu, ctx, tracer, self.settings.exposure, stopped);
        } else {
            self.denoise.clear();
        }
    }

    /// Computes the error view's heat map again when it is on and new samples arrived.
    fn refresh_error_view(&mut self, ctx: &egui::Context) {
        let Some(tracer) = self.tracer.as_ref().filter(|_| self.settings.error_view) else {
            self.error_texture = None;
            return;
        };
        let accumulator = tracer.accumulator();
        let total = accumulator.total_samples();
        if self.error_texture.as_ref().is_some_and(|(_, _, shown)| *shown == total) {
            return;
        }
        let errors = illum_pathtrace::error_map::ErrorMap::of(accumulator).relative_error();
        let image = crate::error_view::heat_map(&errors, accumulator.width, accumulator.height);
        // Nearest: each pixel's own error, not a blend of neighbours.
        let options = egui::TextureOptions::NEAREST;
        match &mut self.error_texture {
            Some((handle, shown_image, shown)) => {
                handle.set(image.clone(), options);
                *shown_image = image;
                *shown = total;
            }
            None => {
                let handle = ctx.load_texture("path tracer error view", image.clone(), options);
                self.error_texture = Some((handle, image, total));
            }
        }
    }
    /// Creates the tracer, or hands it the new scene when anything changed (which restarts the
    /// accumulation). Returns whether it restarted. Errors are the renderer's messages.
    fn sync_tracer(&mut self, gpu: &GpuContext, wanted: &Scene) -> Result<bool, String> {
        match &mut self.tracer {
            Some(tracer) if tracer.scene() == wanted => return Ok(false),
            Some(tracer) => tracer.update_scene(wanted).map_err(|e| e.to_string())?,
            None => {
                let mut tracer = PathTracer::new(gpu, wanted).map_err(|e| e.to_string())?;
                tracer.set_target_seconds(crate::platform::submission_seconds(crate::pacer::MOVING_SECONDS));
                tracer.set_whole_passes_up_to(Some(WHOLE_PASS_SAMPLES));
                // Natively the device's default (mapped, or a staging copy), waited for.
                if crate::platform::POLLED_READBACK {
                    tracer.set_readback(illum_pathtrace::Readback::Polled);
                }
                // The window shows the GPU-resident sum; it follows resets and resizes itself.
                tracer.enable_display_sum().map_err(|e| e.to_string())?;
                self.tracer = Some(tracer);
            }
        }
        // A fresh accumulation: the stop rules, the clock and the denoised image start over too.
        self.denoise.clear();
        self.progressive.restart();
        self.sync_clock();
        self.shown_samples = u64::MAX;
        self.work = WorkLog { smallest_submission: u64::MAX, ..WorkLog::default() };
        Ok(true)
    }
}
