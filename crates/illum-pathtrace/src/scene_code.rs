//! What code a scene's path-tracing pipeline needs: the one place that reads a scene's features
//! for the shaders' switches. A leaf: the upload (`gpu_scene.rs`) records it, and the
//! specialisation (`specialise.rs`) and the shaders' composition read it.

use illum_scene::{Bounces, Feature, Sampling, Scene};

use crate::estimators::Estimators;

/// What of the scene model a scene's pipeline contains, derived from [`Scene::features`], its
/// lights and the render settings that choose code rather than numbers. Code a scene does not
/// use is not compiled: on a CPU driver code costs time by being in the shader, even where no
/// lane runs it (docs/performance.md, "What lavapipe does with a branch").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SceneCode {
    /// Next-event estimation on rectangular lights.
    pub area_lights: bool,
    /// More than one area light: a light is chosen per sample.
    pub light_choice: bool,
    /// A directional light.
    pub sun: bool,
    /// ... of finite angular radius (sampled in its cone).
    pub sun_disc: bool,
    /// An environment light.
    pub sky: bool,
    /// A mirror or a dielectric.
    pub specular: bool,
    pub checker: bool,
    /// Manifold next-event estimation ([`Estimators::manifold`], `shaders/manifold.wgsl`).
    pub manifold: bool,
    /// The caustic's light tracer ([`Estimators::light_tracer`]).
    pub caustic: bool,
    /// ... with the photon gather (E (S|D)* D S+ L but E D S+ L, `shaders/gather.wgsl`): the
    /// caustic with a delta sun and a diffuse surface to gather on.
    /// With a sun disc the camera paths find those paths themselves.
    pub caustic_gather: bool,
    /// `sampling = "uniform"` hemisphere sampling instead of cosine.
    pub uniform_sampling: bool,
    /// `bounces = "unbounded"`: Russian roulette.
    pub unbounded_bounces: bool,
    /// A mesh shaded with its vertex normals (illum-rtcore's mesh_shading.wgsl).
    pub smooth_shading: bool,
}

impl SceneCode {
    /// The code `scene` needs, with `area_lights` uploaded lights.
    pub fn new(scene: &Scene, area_lights: usize) -> Self {
        let features = scene.features();
        SceneCode {
            area_lights: area_lights > 0,
            light_choice: area_lights > 1,
            sun: features.any(&[Feature::DeltaDirectionalLight, Feature::SunDisc]),
            sun_disc: features.contains(Feature::SunDisc),
            sky: features.contains(Feature::Environment),
            specular: features.any(&[Feature::Mirror, Feature::Dielectric]),
            checker: features.contains(Feature::Checker),
            manifold: Estimators::of(scene).manifold(),
            caustic: Estimators::of(scene).light_tracer(),
            caustic_gather: Estimators::of(scene).photon_gather(),
            uniform_sampling: scene.pathtrace.sampling == Sampling::Uniform,
            unbounded_bounces: scene.pathtrace.bounces == Bounces::Unbounded,
            smooth_shading: features.contains(Feature::SmoothShading),
        }
    }
}
