//! Which pipeline variant draws each surface of a frame.
//!
//! The entry shaders declare override constants (ENHANCED, SHADOWS, ...; see `Switches` in
//! scene.wgsl) that fix the effects when a pipeline is created, so the driver compiles out the
//! paths not taken. lavapipe's fragment shaders run both sides of a branch under a lane mask, so
//! an effect behind a uniform flag would cost its full price when off (the measured effect is in
//! docs/performance-raster.md, "Levers"). Keys leave out the
//! switches a surface ignores, so toggling an effect builds only the pipelines it changes.

use illum_scene::Look;

use crate::options::Options;
use crate::plan::FramePlan;

/// A surface drawn by the floor and sphere pipelines.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Surface {
    /// The whole floor without shadow lookups, depth-biased so that it fills in only where the
    /// receiver did not draw (floor.wgsl).
    Floor,
    /// The floor under the shadow map, with shadow lookups (only drawn with shadows on).
    FloorReceiver,
    /// Each sphere's penumbra ring on the floor, with shadow lookups: in the main pass instead of
    /// the receiver when the frame allows it (`FramePlan::shadow_rings`).
    FloorPenumbra,
    /// Each sphere's umbra on the floor inside its ring: shaded dark, no lookups.
    FloorUmbra,
    /// The floor inside the band along its outline, without the outline's coverage: in an
    /// anti-aliased main view, where `Floor` draws only that band (floor.wgsl, PART 3).
    FloorInterior,
    Glass,
    Metal,
    /// The triangle meshes (mesh.wgsl).
    Mesh,
}

/// The kind of target: a cube-map face (half float) or the main view (8-bit), both one sample
/// per pixel. `antialiased`: the main view's edges are blended by their coverage (the EDGE_AA
/// constant of the floor and sphere shaders, and alpha blending); cube faces are never.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Target {
    Cube,
    Main { antialiased: bool },
}

impl Target {
    /// The main view's target for `options`.
    pub fn main(options: &Options) -> Self {
        Target::Main { antialiased: options.effects.antialiasing }
    }

    /// Whether edges are blended by their coverage.
    pub fn antialiased(self) -> bool {
        matches!(self, Target::Main { antialiased: true })
    }
}

/// The override constants of one pipeline (names as in the entry shaders).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Switches {
    pub enhanced: bool,
    pub shadows: bool,
    pub pcf: bool,
    pub refraction: bool,
    pub reflection: bool,
    pub fresnel: bool,
    pub metal_env: bool,
}

/// A pipeline: what it draws, where, and with which switches.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PipelineKey {
    pub surface: Surface,
    pub target: Target,
    pub switches: Switches,
}

impl PipelineKey {
    /// The pipeline that draws `surface` into `target` for `options`, with only the switches
    /// that surface reads and only what `plan` says the frame has: a sphere's shadow lookup only
    /// where the other sphere can shade it (`shadow_fit::can_shadow`), the metal's mirror only in
    /// the main pass of a frame that captured its cube map.
    pub fn new(surface: Surface, target: Target, options: &Options, plan: &FramePlan) -> Self {
        let e = &options.effects;
        let enhanced = options.look == Look::Enhanced;
        let switches = match surface {
            Surface::Floor => Switches::default(),
            Surface::FloorReceiver | Surface::FloorPenumbra => {
                Switches { shadows: true, pcf: e.pcf, ..Default::default() }
            }
            Surface::FloorUmbra | Surface::FloorInterior => Switches::default(),
            // The figure's glass is unlit: only refraction matters.
            Surface::Glass if !enhanced => Switches { refraction: e.refraction, ..Default::default() },
            Surface::Glass => Switches {
                enhanced,
                shadows: plan.glass_shadowed,
                pcf: e.pcf,
                refraction: e.refraction,
                reflection: e.reflection,
                fresnel: e.fresnel && e.reflection,
                metal_env: false,
            },
            // A mesh can be shadowed by any caster, itself included.
            Surface::Mesh => Switches { shadows: plan.shadow_pass, pcf: e.pcf, ..Default::default() },
            Surface::Metal => {
                let mirror = plan.metal_cube && matches!(target, Target::Main { .. });
                Switches {
                    enhanced: mirror,
                    shadows: plan.metal_shadowed,
                    pcf: e.pcf,
                    reflection: mirror,
                    metal_env: mirror,
                    ..Default::default()
                }
            }
        };
        let switches = Switches { pcf: switches.pcf && switches.shadows, ..switches };
        PipelineKey { surface, target, switches }
    }

    /// The pipeline-overridable constants for the entry shader of this key.
    pub fn constants(&self) -> Vec<(&'static str, f64)> {
        let s = &self.switches;
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        // The floor's interior is wholly inside the outline: nothing there to anti-alias.
        let edge_aa = flag(self.target.antialiased() && self.surface != Surface::FloorInterior);
        let floor_part = match self.surface {
            Surface::Floor | Surface::FloorReceiver => Some(0.0),
            Surface::FloorPenumbra => Some(1.0),
            Surface::FloorUmbra => Some(2.0),
            Surface::FloorInterior => Some(3.0),
            Surface::Glass | Surface::Metal | Surface::Mesh => None,
        };
        if let Some(part) = floor_part {
            return vec![
                ("RECEIVER", flag(s.shadows)),
                ("PCF", flag(s.pcf)),
                ("EDGE_AA", edge_aa),
                ("PART", part),
            ];
        }
        let mut constants = vec![("SHADOWS", flag(s.shadows)), ("PCF", flag(s.pcf))];
        if self.surface != Surface::Mesh {
            let sphere = if self.surface == Surface::Glass { 0.0 } else { 1.0 };
            constants.extend([
                ("SPHERE", sphere),
                ("EDGE_AA", edge_aa),
                ("ENHANCED", flag(s.enhanced)),
                ("REFRACTION", flag(s.refraction)),
                ("REFLECTION", flag(s.reflection)),
                ("FRESNEL", flag(s.fresnel)),
                ("METAL_ENV", flag(s.metal_env)),
            ]);
        }
        constants
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use illum_scene::Effects;

    /// The plan of a frame of the assignment's scene (both spheres, a shadow-casting light, a
    /// mirroring metal) under `options`; `shadowed`: whether the spheres can shade each other.
    fn plan(options: &Options, shadowed: bool) -> FramePlan {
        let shadow_pass = options.effects.shadows;
        FramePlan {
            glass: true,
            metal: true,
            shadow_pass,
            glass_shadowed: shadow_pass && shadowed,
            metal_shadowed: shadow_pass && shadowed,
            metal_cube: options.look == Look::Enhanced && options.effects.reflection,
            shadow_rings: shadow_pass,
            meshes: false,
            reuse_views: false,
        }
    }

    #[test]
    fn keys_ignore_switches_a_surface_does_not_read() {
        let figure = Options::all_on(Look::Figure);
        let mut no_fresnel = figure;
        no_fresnel.effects.fresnel = false;
        no_fresnel.effects.reflection = false;
        for surface in [Surface::Floor, Surface::FloorReceiver, Surface::Glass, Surface::Metal] {
            let target = Target::Main { antialiased: true };
            assert_eq!(
                PipelineKey::new(surface, target, &figure, &plan(&figure, true)),
                PipelineKey::new(surface, target, &no_fresnel, &plan(&no_fresnel, true))
            );
        }
        let no_shadows = Options { effects: Effects { shadows: false, ..Effects::ALL_ON }, ..figure };
        let key = PipelineKey::new(Surface::Metal, Target::Cube, &no_shadows, &plan(&no_shadows, true));
        assert!(!key.switches.shadows && !key.switches.pcf, "PCF means nothing without shadows");
        let plain = PipelineKey::new(Surface::Floor, Target::Cube, &figure, &plan(&figure, true));
        assert_eq!(
            plain,
            PipelineKey::new(Surface::Floor, Target::Cube, &no_shadows, &plan(&no_shadows, true))
        );
    }

    #[test]
    fn the_metal_mirrors_only_in_the_enhanced_main_pass() {
        let main = Target::Main { antialiased: false };
        let metal_env = |target, options: &Options, plan: &FramePlan| {
            PipelineKey::new(Surface::Metal, target, options, plan).switches.metal_env
        };
        let enhanced = Options::all_on(Look::Enhanced);
        assert!(metal_env(main, &enhanced, &plan(&enhanced, true)));
        assert!(!metal_env(Target::Cube, &enhanced, &plan(&enhanced, true)));
        // A metal whose cube map the frame skips (mirror = 0) has no lookup into it.
        let unmirrored = FramePlan { metal_cube: false, ..plan(&enhanced, true) };
        let key = PipelineKey::new(Surface::Metal, main, &enhanced, &unmirrored);
        assert!(!key.switches.metal_env && !key.switches.reflection);
        let figure = Options::all_on(Look::Figure);
        assert!(!metal_env(main, &figure, &plan(&figure, true)));
    }

    #[test]
    fn a_sphere_out_of_reach_of_the_other_has_no_shadow_lookup() {
        let options = Options::all_on(Look::Enhanced);
        for surface in [Surface::Glass, Surface::Metal] {
            let target = Target::Main { antialiased: true };
            assert!(PipelineKey::new(surface, target, &options, &plan(&options, true)).switches.shadows);
            let key = PipelineKey::new(surface, target, &options, &plan(&options, false));
            assert!(!key.switches.shadows && !key.switches.pcf);
        }
    }

    #[test]
    fn constants_name_the_overrides_of_each_entry() {
        let key = PipelineKey::new(
            Surface::Glass,
            Target::Main { antialiased: true },
            &Options::all_on(Look::Enhanced),
            &plan(&Options::all_on(Look::Enhanced), true),
        );
        let c = key.constants();
        assert!(
            c.contains(&("SPHERE", 0.0)) && c.contains(&("EDGE_AA", 1.0)) && c.contains(&("ENHANCED", 1.0))
        );
        let enhanced = Options::all_on(Look::Enhanced);
        let receiver =
            PipelineKey::new(Surface::FloorReceiver, Target::Cube, &enhanced, &plan(&enhanced, true))
                .constants();
        assert_eq!(receiver, vec![("RECEIVER", 1.0), ("PCF", 1.0), ("EDGE_AA", 0.0), ("PART", 0.0)]);
        let floor =
            PipelineKey::new(Surface::Floor, Target::Cube, &enhanced, &plan(&enhanced, true)).constants();
        assert_eq!(floor, vec![("RECEIVER", 0.0), ("PCF", 0.0), ("EDGE_AA", 0.0), ("PART", 0.0)]);
        let main_floor =
            PipelineKey::new(Surface::Floor, Target::main(&enhanced), &enhanced, &plan(&enhanced, true));
        assert_eq!(
            main_floor.constants(),
            vec![("RECEIVER", 0.0), ("PCF", 0.0), ("EDGE_AA", 1.0), ("PART", 0.0)]
        );
    }
}
