//! The scene file as written: serde structs that mirror the TOML one to one.
//!
//! Everything here is only *shaped* like a scene: numbers may still be NaN, extents negative,
//! names dangling. `validate.rs` turns these into a [`Scene`](crate::Scene). Numbers are read as
//! f64 / i64 so that range checks (`spp = 0`, `width = -1`, `vfov = 1e40`) happen in validation,
//! where the error can name the field, rather than inside serde.
//!
//! Format (lengths in scene units, angles in degrees, colours linear RGB). Every section but
//! `[camera]` and `[[objects]]` is optional:
//!
//! ```toml
//! name = "cornell"                 # default: the file's stem
//! renderer = "pathtrace"           # the renderer tools use by default: "pathtrace", "raster"
//!                                  # or "whitted"
//! [camera]                         # pinhole camera
//! eye = [278.0, 278.0, -724.26]
//! target = [278.0, 278.0, 0.0]
//! up = [0.0, 1.0, 0.0]
//! vfov = 45.0                      # full vertical field of view, in (0, 180)
//! width = 512                      # output size in pixels
//! height = 512
//! near = 0.1                       # clip planes, 0 < near < far: only the rasterizer needs them
//! far = 3000.0
//! [environment]                    # constant radiance seen by every ray that leaves the scene
//! radiance = [0.3, 0.5, 0.9]
//! [directional_light]              # a light at infinity
//! direction = [-10.0, -13.0, 2.0]  # the way its light travels (any length)
//! irradiance = [3.14159265, 3.14159265, 3.14159265]  # on a surface facing it
//! angular_radius = 0.0             # the sun disc's half-angle, in [0, 90); 0 = delta light
//! [materials.NAME]                 # exactly one of these keys per material:
//! albedo = [0.5, 0.5, 0.5]         #   Lambertian, each channel in [0, 1]
//! checker = { even = [..], odd = [..], tile = 1.0 }  # Lambertian checkerboard (quads only)
//! dielectric = { ior = 1.43 }      #   smooth glass, index of refraction > 0
//! mirror = { reflectance = [..] }  #   smooth tinted mirror, each channel in [0, 1]
//! emission = [30.0, 30.0, 30.0]    #   area light: emitted radiance >= 0 (quads only)
//! [[objects]]                      # one table per object, each with exactly one shape
//! name = "..."                     # default "objects[i]"
//! material = "NAME"
//! box = { center = [..], half_extent = [..] }            # or min = [..], max = [..];
//!                                                        # optional rotate_y, pivot, translate
//! quad = { corner = [..], edge_u = [..], edge_v = [..] } # front side: edge_u x edge_v
//! sphere = { center = [..], radius = 1.0 }
//! mesh = { file = "models/x.obj" }                      # OBJ, relative to this file; optional
//!                                                        # translate, scale, rotate, flat
//! [pathtrace]                      # the path tracer
//! spp = 16                         # samples per pixel, >= 1
//! bounces = 2                      # 0..=MAX_BOUNCES, or "unbounded" (Russian roulette)
//! seed = 0
//! sampling = "cosine"              # or "uniform"
//! sequence = "independent"         # or "low-discrepancy"
//! caustics = false                 # true: light tracing from the directional light through
//!                                  # mirrors and glass onto diffuse surfaces (the caustic)
//! caustic_method = "light-tracer"  # or "manifold": solved through each specular sphere
//! [raster]                         # the rasterizer
//! look = "figure"                  # or "enhanced"
//! pcf_radius = 0.05                # half-width of the soft shadow edge
//! cube_size = 256                  # side of each cube-map face, in texels
//! glass_color = [1.0, 1.0, 1.0]    # figure: (1 - r) glass_color + r environment; enhanced: tint
//! glass_reflectivity = 0.9         # the r above, in [0, 1]
//! [raster.effects]                 # every toggle defaults to true
//! shadows = true
//! pcf = true
//! refraction = true
//! reflection = true
//! fresnel = true
//! antialiasing = true             # anti-aliased edges at one sample per pixel (analytic
//!                                  # coverage); `msaa`, the key's former name, is still read
//! [whitted]                        # the Whitted ray tracer
//! depth = 8                        # recursion depth, 0..=64
//! aa = 2                           # n x n rays per pixel, 1..=16
//! [shading]                        # local Phong model of the rasterizer and Whitted ray tracer
//! ambient = [0.23, 0.23, 0.23]
//! dielectric = { shininess = 200.0 }
//! mirror = { specular = [1.0, 1.0, 1.0], shininess = 30.0, weight = 0.6 }
//! ```

use std::collections::BTreeMap;
use std::fmt;

use serde::Deserialize;
use serde::de::{self, Deserializer, SeqAccess, Visitor};

use crate::renderers::Effects;

/// A whole scene file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawScene {
    pub name: Option<String>,
    pub renderer: Option<String>,
    pub camera: RawCamera,
    pub environment: Option<RawEnvironment>,
    pub directional_light: Option<RawDirectionalLight>,
    /// Sorted by name; `Scene::materials` keeps this order.
    #[serde(default)]
    pub materials: BTreeMap<String, RawMaterial>,
    #[serde(default)]
    pub objects: Vec<RawObject>,
    #[serde(default)]
    pub pathtrace: RawPathTrace,
    #[serde(default)]
    pub raster: RawRaster,
    #[serde(default)]
    pub whitted: RawWhitted,
    #[serde(default)]
    pub shading: RawShading,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawCamera {
    pub eye: RawVec3,
    pub target: RawVec3,
    pub up: RawVec3,
    pub vfov: Num,
    pub width: Int,
    pub height: Int,
    pub near: Option<Num>,
    pub far: Option<Num>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawEnvironment {
    pub radiance: RawVec3,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawDirectionalLight {
    pub direction: RawVec3,
    pub irradiance: RawVec3,
    #[serde(default)]
    pub angular_radius: Num,
}

/// `[pathtrace]`: every key optional. `bounces` is kept as a raw TOML value because it is
/// either an integer or the string "unbounded"; validation tells the two apart with a precise
/// message.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(crate) struct RawPathTrace {
    pub spp: Int,
    pub bounces: toml::Value,
    pub seed: Int,
    pub sampling: String,
    pub sequence: String,
    pub caustics: bool,
    pub caustic_method: String,
}

impl Default for RawPathTrace {
    /// The assignment's defaults: 16 spp, two bounces (its figure 3), seed 0, cosine sampling.
    fn default() -> Self {
        RawPathTrace {
            spp: Int(16),
            bounces: toml::Value::Integer(2),
            seed: Int(0),
            sampling: "cosine".to_owned(),
            sequence: "independent".to_owned(),
            caustics: false,
            caustic_method: "light-tracer".to_owned(),
        }
    }
}

/// `[raster]`: every key optional.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(crate) struct RawRaster {
    pub look: String,
    pub pcf_radius: Num,
    pub cube_size: Int,
    pub glass_color: RawVec3,
    pub glass_reflectivity: Num,
    /// Read straight into [`Effects`]: plain booleans need no validation, and each absent key
    /// takes `Effects::default()`'s value (on).
    pub effects: Effects,
}

impl Default for RawRaster {
    fn default() -> Self {
        RawRaster {
            look: "figure".to_owned(),
            pcf_radius: Num(0.05),
            cube_size: Int(256),
            glass_color: RawVec3([1.0; 3]),
            glass_reflectivity: Num(0.9),
            effects: Effects::default(),
        }
    }
}

/// `[whitted]`: every key optional.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(crate) struct RawWhitted {
    pub depth: Int,
    pub aa: Int,
}

impl Default for RawWhitted {
    fn default() -> Self {
        RawWhitted { depth: Int(8), aa: Int(2) }
    }
}

/// `[shading]`: every key optional.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(crate) struct RawShading {
    pub ambient: RawVec3,
    pub dielectric: RawDielectricShading,
    pub mirror: RawMirrorShading,
}

impl Default for RawShading {
    fn default() -> Self {
        RawShading {
            ambient: RawVec3([0.0; 3]),
            dielectric: RawDielectricShading::default(),
            mirror: RawMirrorShading::default(),
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(crate) struct RawDielectricShading {
    pub shininess: Num,
}

impl Default for RawDielectricShading {
    fn default() -> Self {
        RawDielectricShading { shininess: Num(200.0) }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(crate) struct RawMirrorShading {
    pub specular: RawVec3,
    pub shininess: Num,
    pub weight: Num,
}

impl Default for RawMirrorShading {
    fn default() -> Self {
        RawMirrorShading { specular: RawVec3([1.0; 3]), shininess: Num(30.0), weight: Num(0.6) }
    }
}

/// One `[materials.NAME]` table. The kind keys are all optional here; validation insists on
/// exactly one.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawMaterial {
    pub albedo: Option<RawVec3>,
    pub checker: Option<RawChecker>,
    pub dielectric: Option<RawDielectric>,
    pub mirror: Option<RawMirror>,
    pub emission: Option<RawVec3>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawChecker {
    pub even: RawVec3,
    pub odd: RawVec3,
    pub tile: Num,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawDielectric {
    pub ior: Num,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawMirror {
    pub reflectance: RawVec3,
}

/// One `[[objects]]` entry. The three shape keys are all optional here; validation insists on
/// exactly one.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawObject {
    pub name: Option<String>,
    pub material: String,
    #[serde(rename = "box")]
    pub box_: Option<RawBox>,
    pub quad: Option<RawQuad>,
    pub sphere: Option<RawSphere>,
    pub mesh: Option<RawMesh>,
}

/// A box by centre + half-extent or by min + max corners (validation checks it is one or the
/// other), optionally rotated about +Y around `pivot` and then translated.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawBox {
    pub center: Option<RawVec3>,
    pub half_extent: Option<RawVec3>,
    pub min: Option<RawVec3>,
    pub max: Option<RawVec3>,
    #[serde(default)]
    pub rotate_y: Num,
    #[serde(default)]
    pub pivot: RawVec3,
    #[serde(default)]
    pub translate: RawVec3,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawQuad {
    pub corner: RawVec3,
    pub edge_u: RawVec3,
    pub edge_v: RawVec3,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawSphere {
    pub center: RawVec3,
    pub radius: Num,
}

/// A triangle mesh read from a file (`validate_mesh.rs`), placed by `translate + scale R local`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawMesh {
    /// Relative to the scene file's folder.
    pub file: String,
    #[serde(default)]
    pub translate: RawVec3,
    #[serde(default = "one")]
    pub scale: Num,
    /// Degrees about +X, then +Y, then +Z.
    #[serde(default)]
    pub rotate: RawVec3,
    /// Shade with each triangle's own normal even when the file gives vertex normals.
    #[serde(default)]
    pub flat: bool,
}

fn one() -> Num {
    Num(1.0)
}

/// A TOML number: float or integer (so `radius = 50` works as well as `radius = 50.0`). May be
/// NaN or infinite; validation rejects those.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Num(pub f64);

/// A TOML integer, range-checked later by validation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Int(pub i64);

/// `[x, y, z]`, three numbers.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct RawVec3(pub [f64; 3]);

struct NumVisitor;

impl Visitor<'_> for NumVisitor {
    type Value = Num;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number")
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Num, E> {
        Ok(Num(v))
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Num, E> {
        Ok(Num(v as f64))
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Num, E> {
        Ok(Num(v as f64))
    }
}

impl<'de> Deserialize<'de> for Num {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_f64(NumVisitor)
    }
}

struct IntVisitor;

impl Visitor<'_> for IntVisitor {
    type Value = Int;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("an integer")
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Int, E> {
        Ok(Int(v))
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Int, E> {
        i64::try_from(v).map(Int).map_err(|_| E::invalid_value(de::Unexpected::Unsigned(v), &self))
    }
}

impl<'de> Deserialize<'de> for Int {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_i64(IntVisitor)
    }
}

struct Vec3Visitor;

impl<'de> Visitor<'de> for Vec3Visitor {
    type Value = RawVec3;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("an array of three numbers [x, y, z]")
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<RawVec3, A::Error> {
        let mut v = [0.0; 3];
        for (i, slot) in v.iter_mut().enumerate() {
            match seq.next_element::<Num>()? {
                Some(Num(x)) => *slot = x,
                None => return Err(de::Error::invalid_length(i, &self)),
            }
        }
        // Count the surplus elements so the message can say how many there were.
        let mut len = 3;
        while seq.next_element::<de::IgnoredAny>()?.is_some() {
            len += 1;
        }
        if len != 3 {
            return Err(de::Error::invalid_length(len, &self));
        }
        Ok(RawVec3(v))
    }
}

impl<'de> Deserialize<'de> for RawVec3 {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_seq(Vec3Visitor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<RawSphere, toml::de::Error> {
        toml::from_str(text)
    }

    #[test]
    fn numbers_accept_integers_and_special_floats() {
        let s = parse("center = [1, 2.5, -3]\nradius = 4").unwrap();
        assert_eq!(s.center, RawVec3([1.0, 2.5, -3.0]));
        assert_eq!(s.radius, Num(4.0));
        let s = parse("center = [nan, inf, -inf]\nradius = 1.0").unwrap();
        assert!(s.center.0[0].is_nan());
        assert_eq!(s.center.0[1], f64::INFINITY);
        assert_eq!(s.center.0[2], f64::NEG_INFINITY);
    }

    #[test]
    fn vectors_need_exactly_three_numbers() {
        for bad in ["[1, 2]", "[1, 2, 3, 4]", "[1, 2, \"3\"]", "1.0"] {
            let err = parse(&format!("center = {bad}\nradius = 1.0")).unwrap_err();
            let msg = err.message();
            assert!(msg.contains("array of three numbers") || msg.contains("a number"), "{bad}: {msg}");
        }
        let err = parse("center = [1, 2, 3, 4]\nradius = 1.0").unwrap_err();
        assert!(err.message().contains("length 4"), "{}", err.message());
    }

    #[test]
    fn integers_reject_floats() {
        let err = toml::from_str::<RawPathTrace>("spp = 1.5").unwrap_err();
        assert!(err.message().contains("an integer"), "{}", err.message());
    }
}
