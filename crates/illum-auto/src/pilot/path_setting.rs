//! A path-tracer setting in the pilot: first its bias and noise at the pilot's size (stopping at
//! each spp where its own estimate or its denoised image is measured), then its throughput where
//! [`super::TimedAt`] says.

use web_time::Instant;

use illum_denoise::{AtrousDenoiser, AtrousSettings, DenoiseInput};
use illum_gpu::GpuContext;
use illum_scene::{DenoiserKind, Sequence};

use super::FILTER_RUNS;
use super::machine::{Pilot, pixels, wait_natively};
use super::pending::Pending;
use super::running::Running;
use crate::measure::{denoised, denoised_spps, low_discrepancy, low_discrepancy_spps};
use crate::plan::Setting;
use crate::settings::{apply, tracer_options};

impl Pilot {
    /// The next step of a path-tracer setting.
    pub(super) fn step_path_tracer(&mut self, gpu: &GpuContext, setting: &Setting) -> Result<(), String> {
        if self.bias.is_none() && self.given().is_none() {
            self.step_bias(gpu, setting)
        } else {
            self.step_throughput(gpu, setting)
        }
    }

    /// Its bias and noise at the pilot's size: run to each stop, measure there, then at the
    /// pilot's spp compare the image with the truth.
    fn step_bias(&mut self, gpu: &GpuContext, setting: &Setting) -> Result<(), String> {
        let &Setting::PathTrace { sequence, adaptive, denoise, .. } = setting else {
            unreachable!("a path-tracer setting")
        };
        let pilot_spp = self.options.pilot_spp;
        let Some(running) = &mut self.running else {
            let mut stops = vec![pilot_spp];
            if denoise.is_some() {
                stops.extend(denoised_spps(pilot_spp));
            }
            if sequence == Sequence::LowDiscrepancy {
                stops.extend(low_discrepancy_spps(pilot_spp));
            }
            stops.sort_unstable();
            stops.dedup();
            self.stops = stops;
            let variant = apply(&self.small, setting);
            self.running =
                Some(Running::start(gpu, &variant, tracer_options(setting), adaptive, self.slice)?);
            return Ok(());
        };
        let stop = self.stops[0];
        if !running.step(stop, self.slice)? {
            return Ok(());
        }
        if sequence == Sequence::LowDiscrepancy
            && low_discrepancy_spps(pilot_spp).contains(&stop)
            && !self.estimates.iter().any(|(n, _)| *n == stop)
        {
            self.estimates.push((stop, running.tracer.accumulator().estimated_rel_mse()));
        }
        if let Some(kind) = denoise
            && denoised_spps(pilot_spp).contains(&stop)
            && !self.denoising.at.iter().any(|(n, _)| *n == stop)
        {
            return self.denoise_at(gpu, kind, stop);
        }
        self.stops.remove(0);
        if !self.stops.is_empty() {
            return Ok(());
        }
        let running = self.running.take().expect("running above");
        let accumulator = running.tracer.accumulator();
        let raw = self.measure(&accumulator.mean_image(), Some(accumulator.estimated_rel_mse()), pilot_spp);
        self.bias = Some(match (sequence, denoise) {
            (_, Some(_)) => denoised(raw, &self.denoising.at),
            (Sequence::LowDiscrepancy, None) => low_discrepancy(raw, &self.estimates),
            (Sequence::Independent, None) => raw,
        });
        Ok(())
    }

    /// The running tracer's accumulation at `spp` denoised by `kind` and measured against the
    /// truth: its guides first (when it has none of the samples `spp` takes), then the filter.
    fn denoise_at(&mut self, gpu: &GpuContext, kind: DenoiserKind, spp: u32) -> Result<(), String> {
        let running = self.running.as_ref().expect("a running tracer is denoised");
        let samples = self.options.denoising.guide_samples(spp);
        let guides = match &self.denoising.guides {
            Some((n, guides)) if *n == samples => guides,
            _ => {
                let submitted = Instant::now();
                let guides = running.tracer.start_guides(samples).map_err(|e| e.to_string())?;
                wait_natively(gpu)?;
                self.pending = Some(Pending::Guides { guides, samples, submitted });
                return Ok(());
            }
        };
        let input = DenoiseInput::from_render(running.tracer.accumulator(), guides);
        match kind {
            DenoiserKind::Atrous => {
                if self.filter.is_none() {
                    self.filter = Some(AtrousDenoiser::new(gpu).map_err(|e| e.to_string())?);
                }
                let filter = self.filter.as_ref().expect("made above");
                let submitted = Instant::now();
                let pending = filter.start(&input, &AtrousSettings::default()).map_err(|e| e.to_string())?;
                wait_natively(gpu)?;
                self.pending = Some(Pending::Denoised { pending, input, spp, submitted });
            }
            DenoiserKind::Oidn => {
                let t = Instant::now();
                let image = oidn(gpu, &input)?;
                self.denoising.filtered(t.elapsed().as_secs_f64());
                self.record_denoised(image, spp);
            }
        }
        Ok(())
    }

    /// Polls a denoised setting's guides or filter run.
    pub(super) fn poll_denoising(&mut self, gpu: &GpuContext, pending: Pending) -> Result<(), String> {
        match pending {
            Pending::Guides { guides, samples, submitted } => match guides.poll(gpu) {
                None => self.pending = Some(Pending::Guides { guides, samples, submitted }),
                Some(result) => {
                    self.denoising.guides = Some((samples, result.map_err(|e| e.to_string())?));
                    self.denoising.guide_seconds = Some(submitted.elapsed().as_secs_f64());
                }
            },
            Pending::Denoised { pending, input, spp, submitted } => match pending.poll(gpu) {
                None => self.pending = Some(Pending::Denoised { pending, input, spp, submitted }),
                Some(result) => {
                    self.denoising.filtered(submitted.elapsed().as_secs_f64());
                    let mut image = result.map_err(|e| e.to_string())?.0;
                    // Finished as every denoised image is (the Denoise toggle's, the CLI's).
                    input.finish(&mut image);
                    self.record_denoised(image, spp);
                }
            },
            _ => unreachable!("a denoised setting's readback"),
        }
        Ok(())
    }

    /// A denoised image at `spp`, measured as a deterministic image: its relMSE less the
    /// truth's noise. In the throughput phase only its filter's time counts.
    fn record_denoised(&mut self, image: illum_image::RgbImage32, spp: u32) {
        if self.bias.is_none() && self.given().is_none() {
            let m = self.measure(&image, None, spp);
            self.denoising.at.push((spp, m));
        }
    }

    /// Its throughput: set-up, then the time per spp over `timing_spp`, where the options say;
    /// a denoised setting's guides and filter run too, when the bias phase did not time them
    /// (its measurements were handed in).
    fn step_throughput(&mut self, gpu: &GpuContext, setting: &Setting) -> Result<(), String> {
        let &Setting::PathTrace { adaptive, denoise, .. } = setting else {
            unreachable!("a path-tracer setting")
        };
        let Some(running) = &mut self.running else {
            let variant = apply(&self.timing_scene, setting);
            self.running =
                Some(Running::start(gpu, &variant, tracer_options(setting), adaptive, self.slice)?);
            // The denoiser's times of the bias phase were taken at the pilot's size.
            self.denoising.pixels = pixels([self.small.camera.width, self.small.camera.height]);
            return Ok(());
        };
        if !running.step(self.options.timing_spp, self.slice)? {
            return Ok(());
        }
        if let Some(kind) = denoise
            && (self.denoising.guide_seconds.is_none() || self.denoising.filter_seconds.is_none())
        {
            let camera = running.tracer.scene().camera;
            self.denoising.pixels = pixels([camera.width, camera.height]);
            let spp = running.tracer.spp_done();
            return self.denoise_at(gpu, kind, spp);
        }
        let running = self.running.take().expect("running above");
        let target = pixels(self.sizes.pathtrace);
        let camera = running.tracer.scene().camera;
        let timed = pixels([camera.width, camera.height]);
        let filtering = match denoise {
            Some(_) => {
                let guides = self.denoising.guide_seconds.unwrap_or(0.0);
                let filter = self.denoising.filter_seconds.unwrap_or(0.0);
                (guides + FILTER_RUNS * filter) * target / self.denoising.pixels
            }
            None => 0.0,
        };
        let setup = running.setup_seconds.unwrap_or(0.0);
        let fixed = setup + running.adaptive_seconds * target / timed + filtering;
        // Timed at the pilot's size, scaled by the pixel counts; the pace's wall time per
        // traced second is 1 but where a window's frames share the device.
        let per_spp = running.seconds_per_spp() * target / timed * self.wall_per_traced_second;
        let bias = self.bias.take();
        self.push(bias, fixed, per_spp);
        Ok(())
    }
}

/// Open Image Denoise on `input` (a CPU library: it waits, native only).
#[cfg(not(target_arch = "wasm32"))]
fn oidn(gpu: &GpuContext, input: &DenoiseInput) -> Result<illum_image::RgbImage32, String> {
    let filter = illum_denoise::Denoiser::new(gpu, DenoiserKind::Oidn).map_err(|e| e.to_string())?;
    filter.denoise(input).map_err(|e| e.to_string())
}

#[cfg(target_arch = "wasm32")]
fn oidn(_: &GpuContext, _: &DenoiseInput) -> Result<illum_image::RgbImage32, String> {
    Err("Open Image Denoise runs on the CPU natively: a web page's Auto cannot measure it".to_owned())
}
