//! Which passes a frame records: only those the scene and the options need.
//!
//! "Model only what a scene requires": a pass whose result nothing reads is not recorded, not
//! drawn into and not timed.
//! - The shadow map needs a light that casts shadows, shadows switched on, and a sphere or a
//!   mesh to cast one (the floor casts on nothing).
//! - The glass sphere's cube maps (fine and coarse) exist for the glass alone: no glass, none.
//! - The metal sphere's cube map is read only by its mirror: the enhanced look with reflection on
//!   and a mirror fraction above zero.
//! - The shadow map and the cube maps do not depend on the camera: when the previous frame made
//!   them for the same scene and options, the frame reuses them ([`FramePlan::reuse_views`]),
//!   so a viewer whose camera moves over an unchanged scene draws the main pass alone.

use illum_scene::Look;

use crate::scene::RasterScene;

use crate::options::Options;
use crate::shadow_fit::ShadowFit;
use crate::views::CUBE_FACE_NAMES;

/// A cube map a frame captures.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Cube {
    /// Six faces from the glass sphere's centre, showing everything but the glass.
    Glass,
    /// The same six views at an eighth of the side: the glass's prefiltered level.
    GlassCoarse,
    /// Six faces from the metal sphere's centre, showing everything but the metal.
    Metal,
}

impl Cube {
    /// Its name in the timed passes ("cube NAME +X", ...).
    pub fn name(self) -> &'static str {
        match self {
            Cube::Glass => "glass",
            Cube::GlassCoarse => "glass coarse",
            Cube::Metal => "metal",
        }
    }
}

/// One pass of a frame (see [`FramePlan::passes`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Pass {
    /// The spheres' depth from the light, into the shadow map.
    Shadow,
    /// The six faces of a cube map.
    Capture(Cube),
    /// The view of the camera, multisampled and resolved into the output.
    Main,
}

/// What one pass draws (see [`FramePlan::draws`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Draws {
    pub floor: bool,
    /// The floor's shadow receiver.
    pub receiver: bool,
    pub glass: bool,
    pub metal: bool,
    /// The triangle meshes.
    pub meshes: bool,
}

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
    /// The main pass draws the floor's shadows as each sphere's penumbra ring (with the shadow
    /// lookups) and umbra disc (dark, without them) instead of the receiver parallelogram
    /// (`ShadowFit::rings`, floor.wgsl).
    pub shadow_rings: bool,
    /// The scene has triangle meshes: every pass draws them (the shadow pass their depth).
    pub meshes: bool,
    /// The shadow map and cube maps of the previous frame are this frame's (same scene but for
    /// the camera, same options): their passes are not recorded.
    pub reuse_views: bool,
}

impl FramePlan {
    pub fn new(scene: &RasterScene, options: &Options, fit: &ShadowFit) -> Self {
        let glass = scene.glass.is_some();
        let shadow_pass = options.effects.shadows && !scene.casters().is_empty();
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
            shadow_rings: shadow_pass && fit.rings,
            meshes: !scene.meshes.is_empty(),
            reuse_views: false,
        }
    }

    /// The passes of the frame, in recording order: the shadow pass, the glass sphere's cube
    /// map and its coarse level, the metal sphere's cube map, the main pass; each only when the
    /// frame needs it, and only the main pass when the frame reuses the others' results. The
    /// frame walks this list.
    pub fn passes(&self) -> Vec<Pass> {
        let mut passes = Vec::new();
        if self.shadow_pass && !self.reuse_views {
            passes.push(Pass::Shadow);
        }
        if self.glass && !self.reuse_views {
            passes.extend([Pass::Capture(Cube::Glass), Pass::Capture(Cube::GlassCoarse)]);
        }
        if self.metal_cube && !self.reuse_views {
            passes.push(Pass::Capture(Cube::Metal));
        }
        passes.push(Pass::Main);
        passes
    }

    /// What `pass` draws. The shadow pass draws the casters' depth only, the spheres (see
    /// [`Self::shadow_casters`]) and the meshes; every other pass draws the floor, with its
    /// shadow receiver when the shadow pass ran, the meshes, and the spheres it can see: a cube
    /// map shows everything but the sphere it is captured from.
    pub fn draws(&self, pass: Pass) -> Draws {
        let receiver = self.shadow_pass;
        let meshes = self.meshes;
        match pass {
            Pass::Shadow => {
                Draws { floor: false, receiver: false, glass: self.glass, metal: self.metal, meshes }
            }
            Pass::Capture(Cube::Glass | Cube::GlassCoarse) => {
                Draws { floor: true, receiver, glass: false, metal: self.metal, meshes }
            }
            Pass::Capture(Cube::Metal) => {
                Draws { floor: true, receiver, glass: self.glass, metal: false, meshes }
            }
            Pass::Main => Draws { floor: true, receiver, glass: self.glass, metal: self.metal, meshes },
        }
    }

    /// The timed passes, in recording order: "shadow", the cube faces ("cube glass +X", ...,
    /// "cube glass coarse +X", ..., "cube metal +X", ...), "main".
    pub fn pass_names(&self) -> Vec<String> {
        let mut names = Vec::new();
        for pass in self.passes() {
            match pass {
                Pass::Shadow => names.push("shadow".to_owned()),
                Pass::Capture(cube) => {
                    names.extend(CUBE_FACE_NAMES.iter().map(|face| format!("cube {} {face}", cube.name())))
                }
                Pass::Main => names.push("main".to_owned()),
            }
        }
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

    #[test]
    fn passes_are_recorded_in_order_and_cube_maps_hide_their_own_sphere() {
        let s = scene();
        let p = plan(&s, &Options::all_on(Look::Enhanced));
        assert_eq!(
            p.passes(),
            [
                Pass::Shadow,
                Pass::Capture(Cube::Glass),
                Pass::Capture(Cube::GlassCoarse),
                Pass::Capture(Cube::Metal),
                Pass::Main
            ]
        );
        assert!(!p.draws(Pass::Capture(Cube::Glass)).glass && p.draws(Pass::Capture(Cube::Glass)).metal);
        assert!(p.draws(Pass::Capture(Cube::Metal)).glass && !p.draws(Pass::Capture(Cube::Metal)).metal);
        assert_eq!(p.pass_names().len(), 1 + 3 * 6 + 1);
        // Reusing the views leaves the main pass alone, still reading the shadow map.
        let reused = FramePlan { reuse_views: true, ..p };
        assert_eq!(reused.passes(), [Pass::Main]);
        assert_eq!(reused.pass_names(), ["main"]);
        assert_eq!(reused.draws(Pass::Main), p.draws(Pass::Main));
    }
}
