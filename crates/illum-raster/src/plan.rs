//! Which passes a frame records: only those the scene and the options need.
//!
//! "Model only what a scene requires": a pass whose result nothing reads is not recorded, not
//! drawn into and not timed.
//! - The shadow map needs a light that casts shadows, shadows switched on, and a sphere to cast
//!   one (the floor casts on nothing).
//! - The glass sphere's cube maps (fine and coarse) exist for the glass alone: no glass, none.
//! - The metal sphere's cube map is read only by its mirror: the enhanced look with reflection on
//!   and a mirror fraction above zero.

use illum_scene::Look;

use crate::scene::RasterScene;

use crate::options::Options;
use crate::shadow_fit::ShadowFit;
use crate::views::CUBE_FACE_NAMES;

/// The passes of one frame and what each sphere's pipelines may rely on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FramePlan {
    /// The scene has a glass sphere: it is drawn, and its cube maps are captured.
    pub glass: bool,
    /// The scene has a metal sphere: it is drawn.
    pub metal: bool,
    /// The shadow pass runs and the floor's shadow receiver is drawn.
    pub shadow_pass: bool,
    /// The glass (metal) sphere can receive a shadow from the other one: the shadow pass runs and
    /// the other sphere lies where it can shade it (see `shadow_fit::can_shadow`).
    pub glass_shadowed: bool,
    pub metal_shadowed: bool,
    /// The metal sphere's cube map is captured and mirrored.
    pub metal_cube: bool,
}

impl FramePlan {
    pub fn new(scene: &RasterScene, options: &Options, fit: &ShadowFit) -> Self {
        let glass = scene.glass.is_some();
        let shadow_pass = options.effects.shadows && !scene.spheres().is_empty();
        let metal_cube = options.look == Look::Enhanced
            && options.effects.reflection
            && scene.metal.is_some_and(|metal| metal.mirror > 0.0);
        FramePlan {
            glass,
            metal: scene.metal.is_some(),
            shadow_pass,
            glass_shadowed: shadow_pass && fit.glass_shadowed,
            metal_shadowed: shadow_pass && fit.metal_shadowed,
            metal_cube,
        }
    }

    /// The timed passes, in recording order: "shadow", the cube faces ("cube glass +X", ...,
    /// "cube glass coarse +X", ..., "cube metal +X", ...), "main".
    pub fn pass_names(&self) -> Vec<String> {
        let mut names = Vec::new();
        if self.shadow_pass {
            names.push("shadow".to_owned());
        }
        let cubes = [("glass", self.glass), ("glass coarse", self.glass), ("metal", self.metal_cube)];
        for (cube, captured) in cubes {
            if captured {
                names.extend(CUBE_FACE_NAMES.iter().map(|face| format!("cube {cube} {face}")));
            }
        }
        names.push("main".to_owned());
        names
    }

    /// Instances of the shadow pass's sphere draw (0 glass, 1 metal, as in scene.wgsl).
    pub fn shadow_casters(&self) -> std::ops::Range<u32> {
        let first = if self.glass { 0 } else { 1 };
        let end = if self.metal { 2 } else { 1 };
        first..end
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shadow_fit::fit_shadow;

    fn scene() -> RasterScene {
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/whitted.toml"))
            .expect("scenes/whitted.toml");
        RasterScene::from_toml_str(&text, "whitted.toml").expect("valid")
    }

    fn plan(scene: &RasterScene, options: &Options) -> FramePlan {
        FramePlan::new(scene, options, &fit_shadow(scene, 8192))
    }

    #[test]
    fn metal_cube_only_for_enhanced_reflections_of_a_mirror() {
        let s = scene();
        assert!(!plan(&s, &Options::all_on(Look::Figure)).metal_cube);
        assert!(plan(&s, &Options::all_on(Look::Enhanced)).metal_cube);
        let mut o = Options::all_on(Look::Enhanced);
        o.effects.reflection = false;
        assert!(!plan(&s, &o).metal_cube);
        let mut matte = s.clone();
        matte.metal.as_mut().expect("metal").mirror = 0.0;
        assert!(!plan(&matte, &Options::all_on(Look::Enhanced)).metal_cube);
    }

    #[test]
    fn shadow_pass_needs_shadows_and_a_caster() {
        let s = scene();
        assert!(plan(&s, &Options::all_on(Look::Figure)).shadow_pass);
        let mut o = Options::all_on(Look::Figure);
        o.effects.shadows = false;
        assert!(!plan(&s, &o).shadow_pass);
        let bare = RasterScene { glass: None, metal: None, ..s };
        let p = plan(&bare, &Options::all_on(Look::Figure));
        assert!(!p.shadow_pass && p.shadow_casters().is_empty() && p.pass_names() == ["main"]);
    }
}
