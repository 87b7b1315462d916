//! The Auto mode: an accuracy slider, the pilot's progress, and the renderer and settings the
//! planner (`illum_auto::plan`) picks for the target, with its prediction, the runners-up and
//! why the other renderers were not picked. The choice is then shown by its own mode (the
//! rasterizer, Whitted or the path tracer, with their panels below this one; a denoised choice
//! with the path tracer's Denoise toggle on); the path tracer stops at the planned spp, so that the time and error it reaches can be set against the
//! prediction (its panel's spp target can be raised or set to Unlimited to go on).
//!
//! The pilot ([`illum_auto::pilot`], with the viewer's options and the window's frame pacing)
//! runs once per scene file and view size, when Auto is
//! first shown; **Measure again** runs it again (after the camera or the window changed).

use std::path::{Path, PathBuf};

use illum_auto::plan::{Candidate, Goal, Plan, Planned, Setting, error_floor, plan};
use illum_pathtrace::StopRules;
use illum_scene::RendererKind;

use illum_auto::pilot::{Pilot, PilotOptions, Progress, Sizes};

use crate::pacer::FramePacer;
use crate::pathtrace_mode::PathTraceMode;
use crate::raster_mode::RasterMode;
use crate::whitted_mode::WhittedMode;

/// The slider's range of target relative errors (log scale): 1e-5 is beyond what any renderer
/// reaches in 30 days on the shipped scenes, so the slider can show a refusal.
pub const MIN_TARGET: f64 = 1e-5;
pub const MAX_TARGET: f64 = 1.0;
pub const DEFAULT_TARGET: f64 = 0.05;

/// The Auto mode's state.
pub struct AutoMode {
    /// The target relative error (the slider).
    pub target: f64,
    /// How the next pilot measures (tests make it smaller).
    pub pilot_options: PilotOptions,
    pilot: Option<Pilot>,
    /// Paces the pilot's path tracing as the path-tracer mode's frames are, and measures the
    /// rest of each frame.
    pacer: FramePacer,
    /// The scene file the pilot measured.
    measured_path: Option<PathBuf>,
    /// Set by **Measure again**.
    remeasure: bool,
    /// The plan for `planned_for` (a target), once the pilot is done.
    plan: Option<Result<Plan, String>>,
    planned_for: Option<f64>,
    /// The choice last handed to its mode.
    applied: Option<Planned>,
}

impl Default for AutoMode {
    fn default() -> Self {
        AutoMode {
            target: DEFAULT_TARGET,
            pilot_options: PilotOptions::VIEWER,
            pilot: None,
            pacer: FramePacer::default(),
            measured_path: None,
            remeasure: false,
            plan: None,
            planned_for: None,
            applied: None,
        }
    }
}

impl AutoMode {
    /// The plan for the current target, once the pilot is done: the choice, or why there is none.
    pub fn plan(&self) -> Option<&Result<Plan, String>> {
        self.plan.as_ref()
    }

    /// The candidates the pilot measured, once it is done.
    pub fn candidates(&self) -> Option<&[Candidate]> {
        self.pilot.as_ref().and_then(Pilot::candidates)
    }

    /// Whether the pilot is still measuring (the window keeps repainting, and shows its progress).
    pub fn measuring(&self) -> bool {
        self.pilot.as_ref().is_some_and(|p| p.error().is_none() && p.candidates().is_none())
    }

    /// The pilot's progress (share done, what it measures now) while it measures.
    pub fn progress(&self) -> Option<(f32, String)> {
        match self.pilot.as_ref()?.progress() {
            Progress::Working { done, what } => Some((done, what)),
            Progress::Done | Progress::Failed(_) => None,
        }
    }

    /// Starts a pilot of `scene` (the file at `path`, its camera at the raster's size `sizes`)
    /// when none has measured this file yet or **Measure again** was pressed; then runs a slice
    /// of it, and once it is done plans for the target. Returns a choice to hand to its mode
    /// when the plan's choice changed.
    pub fn frame(
        &mut self,
        gpu: &illum_gpu::GpuContext,
        path: &Path,
        scene: &illum_scene::Scene,
        sizes: Sizes,
    ) -> Option<Planned> {
        if self.remeasure || self.measured_path.as_deref() != Some(path) {
            self.remeasure = false;
            self.measured_path = Some(path.to_path_buf());
            self.plan = None;
            self.planned_for = None;
            self.applied = None;
            match Pilot::new(scene, sizes, self.pilot_options) {
                Ok(pilot) => {
                    self.pilot = Some(pilot);
                    self.pacer = FramePacer::default();
                }
                Err(e) => {
                    self.pilot = None;
                    self.plan = Some(Err(format!("the pilot could not start: {e}")));
                    return None;
                }
            }
        }
        let pilot = self.pilot.as_mut()?;
        if let Progress::Failed(e) = pilot.step(gpu, &mut self.pacer) {
            self.plan = Some(Err(format!("the pilot failed: {e}")));
            return None;
        }
        self.replan()
    }

    /// Plans again when the target changed; returns the choice when it differs from the one
    /// last applied.
    fn replan(&mut self) -> Option<Planned> {
        let candidates = self.candidates()?;
        if self.planned_for != Some(self.target) {
            let result = plan(candidates, Goal::Error(self.target));
            self.plan = Some(result);
            self.planned_for = Some(self.target);
        }
        let choice = self.plan.as_ref()?.as_ref().ok()?.choice.clone();
        if self.applied.as_ref() == Some(&choice) {
            return None;
        }
        self.applied = Some(choice.clone());
        Some(choice)
    }

    /// One line for `--screenshot` runs: the target and the choice with its prediction, the
    /// pilot's progress, or the refusal.
    pub fn summary(&self) -> String {
        let target = percent(self.target);
        if let Some((done, what)) = self.progress() {
            return format!("auto: target {target}, pilot {:.0}% ({what})", done * 100.0);
        }
        match &self.plan {
            None => format!("auto: target {target}, no plan"),
            Some(Err(why)) => format!("auto: target {target}, refused: {}", why.replace('\n', " ")),
            Some(Ok(plan)) => format!(
                "auto: target {target}, choice {} (predicted error {}, {:.2} s){}",
                plan.choice.describe(),
                percent(plan.choice.predicted_error),
                plan.choice.predicted_seconds,
                self.pilot_summary()
            ),
        }
    }

    /// ", pilot N s wall, longest frame step M s", once the pilot is done.
    fn pilot_summary(&self) -> String {
        if let Some(pilot) = &self.pilot {
            return format!(
                ", pilot {:.1} s wall, longest frame step {:.2} s",
                pilot.seconds(),
                pilot.longest_step()
            );
        }
        String::new()
    }

    /// The panel: the slider, the pilot's state, the choice and why.
    pub fn panel(&mut self, ui: &mut egui::Ui) {
        ui.heading("Auto");
        ui.label("The fastest renderer and settings predicted to reach the target error against the converged image.");
        ui.horizontal(|ui| {
            let label = ui.label("Target relative error");
            ui.add(
                egui::Slider::new(&mut self.target, MIN_TARGET..=MAX_TARGET)
                    .logarithmic(true)
                    .custom_formatter(|v, _| format!("{}%", significant(v * 100.0)))
                    .custom_parser(|text| {
                        text.trim().trim_end_matches('%').trim().parse::<f64>().ok().map(|p| p / 100.0)
                    }),
            )
            .labelled_by(label.id);
        });
        if let Some((done, what)) = self.progress() {
            ui.add(egui::ProgressBar::new(done).show_percentage());
            ui.label(format!("Pilot: {what}"));
            return;
        }
        if let Some(pilot) = &self.pilot {
            let (w, h) = pilot.size();
            let options = pilot.options();
            ui.weak(format!(
                "Pilot: {} settings at {w} x {h} against a {} spp truth, {:.1} s (longest frame step {:.2} s)",
                pilot.candidates().map_or(0, <[Candidate]>::len),
                options.truth_spp,
                pilot.seconds(),
                pilot.longest_step()
            ));
        }
        if ui.button("Measure again").on_hover_text("Run the pilot again for the current view").clicked() {
            self.remeasure = true;
        }
        ui.separator();
        match &self.plan {
            None => {}
            Some(Err(why)) => {
                ui.colored_label(ui.visuals().error_fg_color, why);
            }
            Some(Ok(plan)) => {
                let c = &plan.choice;
                ui.label(egui::RichText::new(format!("Choice: {}", c.describe())).strong());
                ui.label(format!(
                    "predicted relative error {} in {:.2} s (bias {}{})",
                    percent(c.predicted_error),
                    c.predicted_seconds,
                    percent(error_floor(&c.candidate)),
                    if c.spp.is_some() { ", the rest noise" } else { ", no noise" }
                ));
                let why = self.why_not_others(&c.candidate.setting);
                if !why.is_empty() {
                    ui.label("Why not the others:");
                    for line in why {
                        ui.small(line);
                    }
                }
                if !plan.runners_up.is_empty() {
                    ui.label("Runners-up:");
                    for p in &plan.runners_up {
                        ui.small(format!(
                            "{}: {} in {:.2} s",
                            p.describe(),
                            percent(p.predicted_error),
                            p.predicted_seconds
                        ));
                    }
                }
            }
        }
    }

    /// For each renderer other than the choice's: the planner's own answer for its settings
    /// alone, either why none of them meets the target (its error floor and worst region) or
    /// that its best is slower.
    pub fn why_not_others(&self, chosen: &Setting) -> Vec<String> {
        let Some(candidates) = self.candidates() else { return Vec::new() };
        let mut lines = Vec::new();
        for renderer in ["raster", "whitted", "pathtrace"] {
            if renderer == chosen.renderer() {
                continue;
            }
            let own: Vec<Candidate> =
                candidates.iter().filter(|c| c.setting.renderer() == renderer).cloned().collect();
            if own.is_empty() {
                lines.push(format!("{renderer}: cannot render this scene"));
                continue;
            }
            match plan(&own, Goal::Error(self.target)) {
                Ok(p) => lines.push(format!(
                    "{}: meets it, but predicted {:.2} s",
                    p.choice.describe(),
                    p.choice.predicted_seconds
                )),
                // The refusal's first line names the target; the rest is one line per renderer.
                Err(why) => lines.extend(why.lines().skip(1).map(|l| l.trim().to_owned())),
            }
        }
        lines
    }
}

/// Hands `choice` to its mode: the rasterizer's look and effects, Whitted's depth and rays per
/// pixel, or the path tracer's bounces, light tracer, spp (as its stop rule, the only one) and
/// Denoise toggle (on for a denoised choice, which then shows the denoised image; off
/// otherwise, so that the image shown is the one predicted). Returns the mode to show.
pub fn apply_choice(
    choice: &Planned,
    raster: Option<&mut RasterMode>,
    whitted: Option<&mut WhittedMode>,
    pathtrace: Option<&mut PathTraceMode>,
) -> RendererKind {
    match &choice.candidate.setting {
        Setting::Raster { look, effects } => {
            if let Some(mode) = raster {
                mode.options.look = *look;
                mode.options.effects = *effects;
            }
            RendererKind::Raster
        }
        Setting::Whitted { depth, aa } => {
            if let Some(mode) = whitted {
                mode.depth = *depth;
                mode.aa = *aa;
            }
            RendererKind::Whitted
        }
        // The viewer's pilot measures independent samples, raw or denoised by à-trous
        // (illum_auto::pilot::PilotOptions::VIEWER), never the sequence or adaptive sampling.
        Setting::PathTrace { bounces, caustics, denoise, .. } => {
            if let Some(mode) = pathtrace {
                mode.settings.bounces = *bounces;
                mode.settings.caustics = *caustics;
                mode.settings.denoise = denoise.is_some();
                mode.settings.stop = StopRules { spp: choice.spp, ..StopRules::default() };
                mode.set_paused(false);
            }
            RendererKind::PathTrace
        }
    }
}

/// A relative error as a percentage with two significant digits.
fn percent(value: f64) -> String {
    format!("{}%", significant(value * 100.0))
}

/// Two significant digits, without an exponent for the slider's range.
fn significant(value: f64) -> String {
    if value <= 0.0 || !value.is_finite() {
        return format!("{value}");
    }
    let decimals = (1 - value.log10().floor() as i32).max(0) as usize;
    format!("{value:.decimals$}")
}
