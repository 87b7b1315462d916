//! The scene file as written: serde structs that mirror the TOML one to one.
//!
//! Everything here is only *shaped* like a scene: numbers may still be NaN, extents negative,
//! names dangling. `validate.rs` turns these into a [`Scene`](crate::Scene). Numbers are read as
//! f64 / i64 so that range checks (`spp = 0`, `width = -1`, `vfov = 1e40`) happen in validation,
//! where the error can name the field, rather than inside serde.
//!
//! Format (all lengths in scene units, angles in degrees):
//!
//! ```toml
//! name = "cornell"                 # optional; default: the file's stem
//! [camera]                         # pinhole camera
//! eye = [278.0, 278.0, -724.26]
//! target = [278.0, 278.0, 0.0]
//! up = [0.0, 1.0, 0.0]
//! vfov = 45.0                      # full vertical field of view
//! width = 512                      # output size in pixels
//! height = 512
//! [render]                         # optional, as is each key in it
//! spp = 16                         # samples per pixel, >= 1
//! bounces = 2                      # 0..=MAX_BOUNCES, or "unbounded" (Russian roulette)
//! seed = 0
//! sampling = "cosine"              # or "uniform"
//! [materials.NAME]                 # any number of Lambertian materials
//! albedo = [0.5, 0.5, 0.5]         # default [0, 0, 0]; each channel in [0, 1]
//! emission = [0.0, 0.0, 0.0]       # default [0, 0, 0]; radiance, each channel >= 0
//! [[objects]]                      # one table per object, each with exactly one shape
//! name = "..."                     # optional; default "objects[i]"
//! material = "NAME"
//! box = { center = [..], half_extent = [..] }            # or min = [..], max = [..];
//!                                                        # optional rotate_y, pivot, translate
//! quad = { corner = [..], edge_u = [..], edge_v = [..] } # front side: edge_u x edge_v
//! sphere = { center = [..], radius = 1.0 }
//! ```

use std::collections::BTreeMap;
use std::fmt;

use serde::Deserialize;
use serde::de::{self, Deserializer, SeqAccess, Visitor};

/// A whole scene file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawScene {
    pub name: Option<String>,
    pub camera: RawCamera,
    #[serde(default)]
    pub render: RawRender,
    /// Sorted by name; `Scene::materials` keeps this order.
    #[serde(default)]
    pub materials: BTreeMap<String, RawMaterial>,
    #[serde(default)]
    pub objects: Vec<RawObject>,
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
}

/// `[render]`: every key optional. `bounces` is kept as a raw TOML value because it is either an
/// integer or the string "unbounded"; validation tells the two apart with a precise message.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(crate) struct RawRender {
    pub spp: Int,
    pub bounces: toml::Value,
    pub seed: Int,
    pub sampling: String,
}

impl Default for RawRender {
    /// The assignment's defaults: 16 spp, two bounces (its figure 3), seed 0, cosine sampling.
    fn default() -> Self {
        RawRender {
            spp: Int(16),
            bounces: toml::Value::Integer(2),
            seed: Int(0),
            sampling: "cosine".to_owned(),
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawMaterial {
    #[serde(default)]
    pub albedo: RawVec3,
    #[serde(default)]
    pub emission: RawVec3,
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
        let err = toml::from_str::<RawRender>("spp = 1.5").unwrap_err();
        assert!(err.message().contains("an integer"), "{}", err.message());
    }
}
