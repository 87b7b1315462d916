//! What a scene asks of a renderer, and the check that a renderer can give it.
//!
//! Each renderer declares the [`Feature`]s it implements; [`Scene::require`] refuses a scene
//! that uses anything else, naming the feature, the object (or section) that uses it and the
//! renderer. A renderer never renders a scene wrong by skipping what it does not know.

use std::fmt;

use crate::error::SceneError;
use crate::materials::MaterialKind;
use crate::renderers::RendererKind;
use crate::scene::Scene;
use crate::shapes::Shape;

/// One thing a scene can contain.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Feature {
    BoxShape,
    QuadShape,
    SphereShape,
    Lambertian,
    Checker,
    Dielectric,
    Mirror,
    /// A quad with an emitting material.
    AreaLight,
    /// A directional light of angular radius 0.
    DeltaDirectionalLight,
    /// A directional light of finite angular radius.
    SunDisc,
    Environment,
}

impl Feature {
    /// Every feature of the scene model.
    pub const ALL: [Feature; 11] = [
        Feature::BoxShape,
        Feature::QuadShape,
        Feature::SphereShape,
        Feature::Lambertian,
        Feature::Checker,
        Feature::Dielectric,
        Feature::Mirror,
        Feature::AreaLight,
        Feature::DeltaDirectionalLight,
        Feature::SunDisc,
        Feature::Environment,
    ];
}

impl fmt::Display for Feature {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Feature::BoxShape => "a box",
            Feature::QuadShape => "a quad",
            Feature::SphereShape => "a sphere",
            Feature::Lambertian => "a Lambertian material",
            Feature::Checker => "a checkerboard material",
            Feature::Dielectric => "a dielectric (glass) material",
            Feature::Mirror => "a mirror material",
            Feature::AreaLight => "an area light (a quad with an emitting material)",
            Feature::DeltaDirectionalLight => "a directional light",
            Feature::SunDisc => "a directional light of finite angular radius (a sun disc)",
            Feature::Environment => "an environment light",
        })
    }
}

impl Scene {
    /// Every feature the scene uses, each with the place that uses it (`objects[3] ("name")`,
    /// `[directional_light]`, ...), in file order.
    pub fn features(&self) -> Vec<(Feature, String)> {
        let mut used = Vec::new();
        for (i, object) in self.objects.iter().enumerate() {
            let place = self.object_label(i);
            used.push((
                match object.shape {
                    Shape::Box(_) => Feature::BoxShape,
                    Shape::Quad(_) => Feature::QuadShape,
                    Shape::Sphere(_) => Feature::SphereShape,
                },
                place.clone(),
            ));
            let material = self.material_of(object);
            let feature = match material.kind {
                MaterialKind::Lambertian { .. } => Feature::Lambertian,
                MaterialKind::Checker(_) => Feature::Checker,
                MaterialKind::Dielectric { .. } => Feature::Dielectric,
                MaterialKind::Mirror { .. } => Feature::Mirror,
                MaterialKind::Emitter { .. } => Feature::AreaLight,
            };
            used.push((feature, format!("{place}, material {:?}", material.name)));
        }
        if let Some(light) = &self.directional_light {
            let feature = if light.is_delta() { Feature::DeltaDirectionalLight } else { Feature::SunDisc };
            used.push((feature, "[directional_light]".to_owned()));
        }
        if self.environment.is_some() {
            used.push((Feature::Environment, "[environment]".to_owned()));
        }
        used
    }

    /// Ok if `renderer` implements every feature the scene uses; otherwise the first one it
    /// lacks, as [`SceneError::Unsupported`].
    pub fn require(&self, renderer: RendererKind, supported: &[Feature]) -> Result<(), SceneError> {
        self.require_for(renderer.noun(), supported)
    }

    /// [`Scene::require`] for a renderer named in words (one that is not a [`RendererKind`]
    /// yet, such as the oracle's copy of Whitted's algorithm).
    pub fn require_for(&self, renderer: &str, supported: &[Feature]) -> Result<(), SceneError> {
        self.require_where(renderer, |f| supported.contains(&f))
    }

    /// [`Scene::require_for`] with the supported features given by a predicate (for example
    /// "everything but a sun disc").
    pub fn require_where(
        &self,
        renderer: &str,
        supported: impl Fn(Feature) -> bool,
    ) -> Result<(), SceneError> {
        match self.features().into_iter().find(|&(f, _)| !supported(f)) {
            None => Ok(()),
            Some((feature, place)) => Err(SceneError::Unsupported {
                file: self.source.clone(),
                place,
                feature: feature.to_string(),
                renderer: renderer.to_owned(),
            }),
        }
    }
}
