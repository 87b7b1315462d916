//! What a scene asks of a renderer, and the check that a renderer can give it.
//!
//! [`Scene::features`] is the typed set of what a scene uses; each renderer derives its pipeline's
//! specialisation from it. Each renderer declares what it implements with one exhaustive
//! `match` (a `fn(Feature) -> bool`, so a new feature cannot be forgotten), and
//! [`Scene::require`] refuses a scene that uses anything else, naming the feature, the object
//! (or section) that uses it and the renderer. A renderer never renders a scene wrong by
//! skipping what it does not know.

use std::fmt;

use crate::error::SceneError;
use crate::materials::MaterialKind;
#[cfg(doc)]
use crate::renderers::RendererKind;
use crate::scene::Scene;
use crate::shapes::Shape;

/// One thing a scene can contain.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Feature {
    BoxShape,
    QuadShape,
    SphereShape,
    /// A triangle mesh shaded with each triangle's geometric normal.
    MeshShape,
    /// A triangle mesh shaded with normals interpolated from its file's vertex normals.
    SmoothShading,
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
    pub const ALL: [Feature; 13] = [
        Feature::BoxShape,
        Feature::QuadShape,
        Feature::SphereShape,
        Feature::MeshShape,
        Feature::SmoothShading,
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

impl Feature {
    fn bit(self) -> u16 {
        1 << self as u16
    }
}

/// A set of [`Feature`]s.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct FeatureSet(u16);

impl FeatureSet {
    pub fn contains(self, feature: Feature) -> bool {
        self.0 & feature.bit() != 0
    }

    pub fn insert(&mut self, feature: Feature) {
        self.0 |= feature.bit();
    }

    /// Whether any of `features` is in the set.
    pub fn any(self, features: &[Feature]) -> bool {
        features.iter().any(|&f| self.contains(f))
    }

    /// The features in the set, in the order of [`Feature::ALL`].
    pub fn iter(self) -> impl Iterator<Item = Feature> {
        Feature::ALL.into_iter().filter(move |&f| self.contains(f))
    }
}

impl FromIterator<Feature> for FeatureSet {
    fn from_iter<I: IntoIterator<Item = Feature>>(features: I) -> Self {
        let mut set = FeatureSet::default();
        for feature in features {
            set.insert(feature);
        }
        set
    }
}

impl fmt::Display for Feature {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Feature::BoxShape => "a box",
            Feature::QuadShape => "a quad",
            Feature::SphereShape => "a sphere",
            Feature::MeshShape => "a triangle mesh",
            Feature::SmoothShading => {
                "a triangle mesh with vertex normals (smooth shading; `flat = true` shades it flat)"
            }
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
    /// The features the scene uses.
    pub fn features(&self) -> FeatureSet {
        self.feature_uses().into_iter().map(|(feature, _)| feature).collect()
    }

    /// Every use of a feature, with the place that uses it (`objects[3] ("name")`,
    /// `[directional_light]`, ...), in file order.
    pub fn feature_uses(&self) -> Vec<(Feature, String)> {
        let mut used = Vec::new();
        for (i, object) in self.objects.iter().enumerate() {
            let place = self.object_label(i);
            used.push((
                match &object.shape {
                    Shape::Box(_) => Feature::BoxShape,
                    Shape::Quad(_) => Feature::QuadShape,
                    Shape::Sphere(_) => Feature::SphereShape,
                    Shape::Mesh(_) => Feature::MeshShape,
                },
                place.clone(),
            ));
            if let Shape::Mesh(mesh) = &object.shape
                && mesh.smooth()
            {
                used.push((Feature::SmoothShading, format!("{place}, file {:?}", mesh.file)));
            }
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

    /// Ok if `renderer` (named in words, as [`RendererKind::noun`] names one) implements every
    /// feature the scene uses, as its exhaustive `implements` says; otherwise the first use of a
    /// feature it lacks, as [`SceneError::Unsupported`].
    pub fn require(&self, renderer: &str, implements: impl Fn(Feature) -> bool) -> Result<(), SceneError> {
        match self.feature_uses().into_iter().find(|&(f, _)| !implements(f)) {
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
