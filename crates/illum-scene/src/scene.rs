//! The scene: one physical description that every renderer reads, plus the per-renderer
//! sections, with command-line overrides and the list of emitters (loading a file is `load.rs`).

use glam::{DVec3, Vec3};

use crate::camera::{Camera, ClipPlanes};
use crate::error::SceneError;
use crate::lights::{DirectionalLight, Environment};
use crate::materials::Material;
use crate::renderers::{
    Bounces, MAX_BOUNCES, PathTraceSettings, RasterSettings, RendererKind, Sampling, Sequence, Shading,
    WhittedSettings,
};
use crate::settings::bounces_allowed;
use crate::shapes::{Quad, Shape};

/// A whole scene as loaded from TOML. Every value has passed validation (see `validate.rs`):
/// vectors are finite, extents positive, the camera is not degenerate and material indices are
/// in range.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Scene name (the file's `name`, or its file stem).
    pub name: String,
    /// Where the scene came from (the file as it was given), for error messages.
    pub source: String,
    /// The renderer a tool uses when the user does not choose one (the file's `renderer`;
    /// default: the path tracer).
    pub renderer: RendererKind,
    /// Where the scene's coordinates are measured from, in the file's (world) coordinates: every
    /// position below (the camera's eye and target, each object's place) is `world - origin`,
    /// computed in f64 and rounded to f32 once. Zero for a scene near the world origin, the eye
    /// for one farther than its own size from it (`frame.rs`), so that the f32 numbers every
    /// renderer computes with are no larger than the scene wherever it sits. Directions and
    /// lengths do not depend on it. [`Scene::world_point`] gives a position back in the file's
    /// coordinates.
    pub origin: DVec3,
    /// Pinhole camera and output resolution.
    pub camera: Camera,
    /// The camera's clip planes (`camera.near`, `camera.far`); only a rasterizer needs them.
    pub clip: Option<ClipPlanes>,
    /// Materials, referenced by index from `objects`.
    pub materials: Vec<Material>,
    /// Geometry, in file order. Quads whose material emits are the area lights.
    pub objects: Vec<Object>,
    /// `[directional_light]`, if any.
    pub directional_light: Option<DirectionalLight>,
    /// `[environment]`, if any: the radiance every escaping ray sees (black without one).
    pub environment: Option<Environment>,
    /// `[pathtrace]`.
    pub pathtrace: PathTraceSettings,
    /// `[raster]`.
    pub raster: RasterSettings,
    /// `[whitted]`.
    pub whitted: WhittedSettings,
    /// `[shading]`.
    pub shading: Shading,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    pub name: String,
    /// Index into `Scene::materials`.
    pub material: usize,
    pub shape: Shape,
}

/// Command-line overrides of the file's settings; `None` keeps the file's value.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Overrides {
    pub spp: Option<u32>,
    pub bounces: Option<Bounces>,
    pub seed: Option<u32>,
    pub sampling: Option<Sampling>,
    pub sequence: Option<Sequence>,
    pub width: Option<u32>,
    pub height: Option<u32>,
}

impl Scene {
    /// Replaces the file's settings with the given overrides, after checking them by the same
    /// rules as the file. `origin` labels the errors (e.g. "command line"), whose fields are the
    /// flag names (`--spp`, `--bounces`, `--width`, `--height`). On error nothing is changed.
    pub fn apply_overrides(&mut self, o: &Overrides, origin: &str) -> Result<(), SceneError> {
        let at_least_one = |field: &str, v: Option<u32>| match v {
            Some(0) => Err(SceneError::invalid(origin, field, "0", "must be at least 1")),
            _ => Ok(()),
        };
        at_least_one("--spp", o.spp)?;
        at_least_one("--width", o.width)?;
        at_least_one("--height", o.height)?;
        if let Some(Bounces::Fixed(n)) = o.bounces
            && n > MAX_BOUNCES
        {
            return Err(SceneError::invalid(origin, "--bounces", n.to_string(), bounces_allowed()));
        }

        let r = &mut self.pathtrace;
        r.spp = o.spp.unwrap_or(r.spp);
        r.bounces = o.bounces.unwrap_or(r.bounces);
        r.seed = o.seed.unwrap_or(r.seed);
        r.sampling = o.sampling.unwrap_or(r.sampling);
        r.sequence = o.sequence.unwrap_or(r.sequence);
        let c = &mut self.camera;
        c.width = o.width.unwrap_or(c.width);
        c.height = o.height.unwrap_or(c.height);
        Ok(())
    }

    /// A position of this scene (measured from [`Scene::origin`]) in the file's coordinates.
    pub fn world_point(&self, p: Vec3) -> DVec3 {
        self.origin + p.as_dvec3()
    }

    /// The area lights: (object index, object, its quad) for every object whose material
    /// emits. Validation guarantees emitters are quads; anything else is skipped.
    pub fn emitters(&self) -> impl Iterator<Item = (usize, &Object, &Quad)> {
        self.objects.iter().enumerate().filter_map(move |(i, object)| match &object.shape {
            Shape::Quad(quad) if self.materials.get(object.material).is_some_and(|m| m.is_emitter()) => {
                Some((i, object, quad))
            }
            _ => None,
        })
    }

    /// How errors name object `i`: `objects[3] ("tall block")`, or `objects[3]` for an object
    /// the file left unnamed (validation's own label).
    pub fn object_label(&self, i: usize) -> String {
        let name = &self.objects[i].name;
        if *name == format!("objects[{i}]") { name.clone() } else { format!("objects[{i}] ({name:?})") }
    }

    /// What loading changed without refusing, one line each for a user to read: the degenerate
    /// triangles dropped from each mesh, with their count.
    pub fn notes(&self) -> Vec<String> {
        self.objects
            .iter()
            .enumerate()
            .filter_map(|(i, o)| match &o.shape {
                Shape::Mesh(m) if m.dropped_degenerate > 0 => Some(format!(
                    "{}: {}: {:?}: {} of its triangles dropped: degenerate (repeated or collinear vertices, no area)",
                    self.source,
                    self.object_label(i),
                    m.file,
                    m.dropped_degenerate
                )),
                _ => None,
            })
            .collect()
    }

    /// The material of `object`.
    pub fn material_of(&self, object: &Object) -> &Material {
        &self.materials[object.material]
    }

    /// The spheres with the given kind of material, in file order, as (object, sphere).
    pub fn spheres_where(
        &self,
        keep: impl Fn(&Material) -> bool,
    ) -> impl Iterator<Item = (&Object, crate::Sphere)> {
        self.objects.iter().filter_map(move |o| match o.shape {
            Shape::Sphere(s) if keep(self.material_of(o)) => Some((o, s)),
            _ => None,
        })
    }
}
