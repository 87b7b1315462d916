//! `render --renderer auto` (the planner of `illum_auto::plan`, on the pilot's measurements,
//! chooses the renderer and its settings): what `auto` refuses, the command itself ([`run`]:
//! the [`pilot`] with its caches, the plan, the render and what it reached, [`text`]), and how
//! the flags follow its choice. The `--renderer` value, [`RendererChoice`], is parsed beside the
//! other flags (`render_args.rs`) and re-exported here.

mod cache;
pub mod pilot;
pub mod text;

use illum_auto::plan::{Goal, Planned, Setting};
use illum_scene::{RendererKind, Scene};

use crate::render_args::RenderArgs;
pub use crate::render_args::RendererChoice;

/// `render --renderer auto`: checks the flags, runs the pilot, prints the plan, then renders it
/// as the flags naming its renderer and settings would, and compares what it reached with what
/// was predicted.
pub fn run(mut args: RenderArgs) -> anyhow::Result<()> {
    let goal = args.auto_goal()?;
    let scene = crate::load_scene(&args.scene, &args.settings)?;
    crate::check_outputs(&args.outputs, &args.png_flags())?;
    let started = std::time::Instant::now();
    let gpu = crate::gpu()?;
    let device_seconds = started.elapsed().as_secs_f64();
    let progress = crate::progress::RenderProgress::new();
    let on_step = &mut |t: &_, p: &_| progress.update(t, p);
    let options = pilot::PilotOptions::default();
    let pilot = pilot::measure(&gpu, &scene, device_seconds, &options, on_step)?;
    progress.finish();
    drop(gpu);
    let pilot_seconds = started.elapsed().as_secs_f64();
    let left = goal_left(goal, pilot_seconds).map_err(anyhow::Error::msg)?;
    let plan = illum_auto::plan::plan(&pilot.candidates, left)
        .map_err(|why| anyhow::anyhow!("{}: {why}", args.scene.display()))?;
    if let (Goal::Seconds(budget), Goal::Seconds(rest)) = (goal, left) {
        println!(
            "auto: the pilot took {pilot_seconds:.1} s of the {budget} s budget; the render gets the {rest:.1} s left"
        );
    }
    print!("{}", text::describe(&scene, &pilot, left, &plan));
    args.follow(&plan.choice, &scene, left);
    let rendering = std::time::Instant::now();
    let noise = crate::render::render(&args)?;
    println!("{}", text::reached(&plan.choice, noise, rendering.elapsed().as_secs_f64()));
    if let Goal::Seconds(budget) = goal {
        println!(
            "auto: the whole command took {:.1} s of its {budget} s budget (the device and the pilot {pilot_seconds:.1} s)",
            started.elapsed().as_secs_f64()
        );
    }
    Ok(())
}

/// What `--renderer auto` is asked for: one of `--target-error` and `--time-budget`, and none
/// of the flags that choose what it chooses (`chosen`: the names of those given).
pub fn check_auto_flags(
    target_error: Option<f64>,
    time_budget: Option<std::time::Duration>,
    chosen: &[&str],
) -> Result<(), String> {
    if !chosen.is_empty() {
        return Err(format!(
            "--renderer auto chooses the renderer and its settings itself, so {} cannot be given with it \
             (name a renderer with --renderer to set {})",
            chosen.join(", "),
            if chosen.len() == 1 { "it" } else { "them" }
        ));
    }
    match (target_error, time_budget) {
        (Some(_), None) | (None, Some(_)) => Ok(()),
        (None, None) => Err("--renderer auto needs a goal: --target-error E (the fastest render predicted to \
                             reach a relative error of E) or --time-budget S (the most accurate predicted \
                             to finish within S seconds)"
            .to_owned()),
        (Some(_), Some(_)) => Err("--renderer auto takes one goal: --target-error or --time-budget, not both \
                                   (it picks the fastest render for an error, or the most accurate for a time)"
            .to_owned()),
    }
}

/// The goal left for the render once the command has spent `spent` seconds (opening the device,
/// the pilot): a time budget covers the whole command, so the render is planned for what is
/// left of it, and stops there (see [`RenderArgs::follow`]). A target error is unchanged.
pub fn goal_left(goal: Goal, spent: f64) -> Result<Goal, String> {
    match goal {
        Goal::Error(_) => Ok(goal),
        Goal::Seconds(budget) if budget - spent > 0.0 => Ok(Goal::Seconds(budget - spent)),
        Goal::Seconds(budget) => Err(format!(
            "--time-budget {budget}: the pilot took {spent:.1} s of it, and nothing is left to render in \
             (the budget covers the whole command, and the pilot measures this machine's speed on every run: \
             give a budget above the pilot's time)"
        )),
    }
}

impl RenderArgs {
    /// `--renderer auto`'s goal, once its flags are checked ([`check_auto_flags`],
    /// [`illum_auto::plan::check_goal`]): before anything is measured.
    pub fn auto_goal(&self) -> anyhow::Result<Goal> {
        let mut chosen = crate::given_flags(&[
            (self.settings.spp.is_some(), "--spp"),
            (self.settings.bounces.is_some(), "--bounces"),
            (self.sequence.is_some(), "--sequence"),
            (self.caustics.is_some(), "--caustics"),
            (self.adaptive, "--adaptive"),
            (self.resume.is_some(), "--resume"),
            (self.sample_range.is_some(), "--sample-range"),
            (self.checkpoint_seconds.is_some(), "--checkpoint-seconds"),
            (self.denoise.is_some(), "--denoise"),
        ]);
        chosen.extend(self.raster.given());
        chosen.extend(self.whitted.given());
        check_auto_flags(self.target_error, self.time_budget, &chosen).map_err(anyhow::Error::msg)?;
        let goal = match (self.target_error, self.time_budget) {
            (Some(error), _) => Goal::Error(error),
            (None, budget) => Goal::Seconds(budget.expect("one goal (checked)").as_secs_f64()),
        };
        illum_auto::plan::check_goal(goal).map_err(anyhow::Error::msg)?;
        Ok(goal)
    }

    /// Sets the flags that name the planned renderer and settings, as a user would type them,
    /// in place of the goal (`scene`: the scene planned for). With a time budget (`goal`, what
    /// is left of it, [`goal_left`]) a path-traced render also stops there if its planned spp
    /// is not reached by then.
    pub fn follow(&mut self, choice: &Planned, scene: &Scene, goal: Goal) {
        self.target_error = None;
        self.time_budget = match (goal, &choice.candidate.setting) {
            (Goal::Seconds(left), Setting::PathTrace { .. }) => {
                Some(std::time::Duration::from_secs_f64(left))
            }
            _ => None,
        };
        match &choice.candidate.setting {
            Setting::Raster { look, effects } => {
                self.renderer = Some(RendererChoice::Kind(RendererKind::Raster));
                self.raster.look = Some(*look);
                self.raster.no_shadows = !effects.shadows;
                self.raster.no_pcf = !effects.pcf;
                self.raster.no_refraction = !effects.refraction;
                self.raster.no_reflection = !effects.reflection;
                self.raster.no_fresnel = !effects.fresnel;
                self.raster.no_antialiasing = !effects.antialiasing;
            }
            Setting::Whitted { depth, aa } => {
                self.renderer = Some(RendererChoice::Kind(RendererKind::Whitted));
                self.whitted.depth = Some(*depth);
                self.whitted.aa = Some(*aa);
            }
            Setting::PathTrace { bounces, caustics, sequence, adaptive, denoise } => {
                self.renderer = Some(RendererChoice::Kind(RendererKind::PathTrace));
                self.settings.spp = choice.spp;
                self.settings.bounces = Some(*bounces);
                self.sequence = Some(*sequence);
                self.adaptive = *adaptive;
                self.denoise = *denoise;
                // Named only where the scene has a caustic: elsewhere `--caustics` is refused.
                self.caustics = illum_auto::settings::has_caustic(scene).then_some(*caustics);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `render --renderer auto` as typed: every bad goal and every flag that sets what auto
    /// chooses is refused by [`RenderArgs::auto_goal`] (which the example calls before anything
    /// is measured), or by the flag's parser, naming the flag, the value and what is allowed.
    #[test]
    fn bad_goals_and_settings_auto_chooses_are_refused_by_name() {
        use clap::Parser as _;
        let cases: [(&str, &[&str]); 13] = [
            ("--target-error 0", &["--target-error", "0", "above 0"]),
            ("--target-error -0.1", &["--target-error", "-0.1", "above 0"]),
            ("--target-error nan", &["--target-error", "NaN", "finite"]),
            ("--target-error inf", &["--target-error", "finite"]),
            ("--time-budget 0", &["--time-budget", "0", "above 0"]),
            ("--time-budget -5", &["--time-budget", "-5", "above 0"]),
            ("--time-budget 1e12", &["--time-budget", "1000000000000", "30 days"]),
            ("", &["--renderer auto needs a goal", "--target-error", "--time-budget"]),
            ("--target-error 0.1 --time-budget 5", &["one goal", "not both"]),
            (
                "--target-error 0.1 --spp 16 --depth 2",
                &["--spp, --depth", "chooses the renderer and its settings"],
            ),
            ("--target-error 0.1 --caustics on --no-shadows", &["--caustics, --no-shadows"]),
            ("--target-error 0.1 --resume x.exr", &["--resume"]),
            ("--target-error 0.1 --denoise atrous --adaptive", &["--adaptive, --denoise"]),
        ];
        for (flags, expected) in cases {
            let mut words = vec!["render", "scenes/whitted.toml", "--renderer", "auto"];
            words.extend(flags.split_whitespace());
            let refusal = match RenderArgs::try_parse_from(&words) {
                Err(error) => error.to_string(),
                Ok(args) => format!("{:#}", args.auto_goal().expect_err(flags)),
            };
            for part in expected {
                assert!(refusal.contains(part), "{flags}: the refusal lacks {part:?}: {refusal}");
            }
        }
        let goal =
            RenderArgs::try_parse_from(["render", "--renderer", "auto", "--time-budget", "2"]).unwrap();
        assert_eq!(goal.auto_goal().unwrap(), Goal::Seconds(2.0));
        let error =
            RenderArgs::try_parse_from(["render", "--renderer", "automatic"]).unwrap_err().to_string();
        assert!(error.contains("\"automatic\" is not a renderer") && error.contains("\"auto\""), "{error}");
    }

    /// The budget covers the pilot: the render is planned for the rest, and a pilot that spent
    /// it all is an error that says so; an error goal is the pilot's to keep.
    #[test]
    fn a_time_budget_covers_the_pilot_and_the_render_gets_the_rest() {
        assert_eq!(goal_left(Goal::Seconds(10.0), 4.0), Ok(Goal::Seconds(6.0)));
        assert_eq!(goal_left(Goal::Error(0.05), 40.0), Ok(Goal::Error(0.05)));
        for spent in [10.0, 12.5] {
            let error = goal_left(Goal::Seconds(10.0), spent).unwrap_err();
            assert!(error.contains("--time-budget 10") && error.contains("nothing is left"), "{error}");
        }
    }

    #[test]
    fn auto_needs_exactly_one_goal_and_none_of_the_settings_it_chooses() {
        let second = Some(std::time::Duration::from_secs(1));
        assert!(check_auto_flags(Some(0.1), None, &[]).is_ok());
        assert!(check_auto_flags(None, second, &[]).is_ok());
        assert!(check_auto_flags(None, None, &[]).unwrap_err().contains("needs a goal"));
        assert!(check_auto_flags(Some(0.1), second, &[]).unwrap_err().contains("not both"));
        let error = check_auto_flags(Some(0.1), None, &["--spp", "--depth"]).unwrap_err();
        assert!(error.contains("--spp, --depth cannot be given"), "{error}");
    }
}
