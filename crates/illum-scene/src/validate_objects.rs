//! Validation of the `[[objects]]`: one shape each, its numbers finite and its size non-zero in
//! f32, positions measured from the frame's origin (`frame.rs`), and a material that exists and
//! is defined on that shape.

use std::collections::BTreeMap;

use glam::{DVec3, Vec3};

use crate::error::SceneError;
use crate::file::{RawBox, RawMaterial, RawObject};
use crate::frame::{box_local_bounds, box_local_to_world};
use crate::materials::{Material, MaterialKind};
use crate::mesh_load::LoadedMesh;
use crate::scene::Object;
use crate::shapes::{BoxShape, Quad, Shape, Sphere};
use crate::spelling::object_label;
use crate::spelling::{fmt_f32, fmt_num, fmt_vec, fmt_vec32, toml_key};
use crate::validate::Check;

/// The relative size of |edge_u x edge_v| below which a quad counts as degenerate:
/// |u x v| = |u| |v| sin(angle), so this is sin(angle) < 1e-12 between the edges.
const QUAD_DEGENERATE_SIN: f64 = 1e-12;

/// More checker tiles than this along one edge of a quad and the f32 tile coordinate of the far
/// edge loses its fraction (2^24 / 100000 ~ 168 steps per tile remain), so the board would break
/// up.
const MAX_TILES_PER_EDGE: f64 = 100_000.0;

impl Check<'_> {
    pub(crate) fn object(
        &self,
        i: usize,
        raw: &RawObject,
        materials: &[Material],
        index_of: &BTreeMap<String, usize>,
        raw_materials: &BTreeMap<String, RawMaterial>,
        loaded: Option<&LoadedMesh>,
    ) -> Result<Object, SceneError> {
        let label = object_label(i, raw.name.as_deref());
        let shape = match (&raw.box_, &raw.quad, &raw.sphere, &raw.mesh) {
            (Some(b), None, None, None) => Shape::Box(self.box_shape(&format!("{label}.box"), b)?),
            (None, None, None, Some(m)) => {
                let loaded = loaded.expect("every mesh object's file is loaded before its validation");
                Shape::Mesh(self.mesh(&label, m, loaded)?)
            }
            (None, Some(q), None, None) => {
                let path = format!("{label}.quad");
                let quad = Quad {
                    corner: self.position(&format!("{path}.corner"), q.corner)?,
                    edge_u: self.vec3(&format!("{path}.edge_u"), q.edge_u)?,
                    edge_v: self.vec3(&format!("{path}.edge_v"), q.edge_v)?,
                };
                self.quad_area(&path, q.edge_u.0, q.edge_v.0, &quad)?;
                Shape::Quad(quad)
            }
            (None, None, Some(s), None) => {
                let path = format!("{label}.sphere");
                let center = self.position(&format!("{path}.center"), s.center)?;
                let radius_path = format!("{path}.radius");
                let radius = self.number(&radius_path, s.radius)?;
                if radius <= 0.0 {
                    return Err(self.invalid(radius_path, fmt_num(s.radius.0), "must be > 0"));
                }
                Shape::Sphere(Sphere { center, radius })
            }
            (b, q, s, m) => {
                let given: Vec<&str> = [
                    (b.is_some(), "box"),
                    (q.is_some(), "quad"),
                    (s.is_some(), "sphere"),
                    (m.is_some(), "mesh"),
                ]
                .into_iter()
                .filter_map(|(present, key)| present.then_some(key))
                .collect();
                let value = if given.is_empty() {
                    "(no shape)".to_owned()
                } else {
                    format!("(both {})", given.join(" and "))
                };
                return Err(self.invalid(
                    label,
                    value,
                    "each object needs exactly one of box, quad, sphere, mesh",
                ));
            }
        };

        let material_path = format!("{label}.material");
        let Some(&material) = index_of.get(&raw.material) else {
            let allowed = if materials.is_empty() {
                "must name a material, but none are defined; add a [materials.NAME] table".to_owned()
            } else {
                let known: Vec<&str> = materials.iter().map(|m| m.name.as_str()).collect();
                format!("must name a material defined under [materials]; known: {}", known.join(", "))
            };
            return Err(self.invalid(material_path, format!("{:?}", raw.material), allowed));
        };
        let raw_tile = raw_materials.get(&raw.material).and_then(|m| m.checker.as_ref()).map(|c| c.tile.0);
        self.material_fits_shape(&material_path, &raw.material, &materials[material], raw_tile, &shape)?;
        Ok(Object { name: raw.name.clone().unwrap_or_else(|| format!("objects[{i}]")), material, shape })
    }

    /// Emitters and checkerboards are defined on quads only: area lights are sampled as
    /// rectangles, and a checkerboard counts its tiles along a quad's edges.
    fn material_fits_shape(
        &self,
        field: &str,
        name: &str,
        material: &Material,
        raw_tile: Option<f64>,
        shape: &Shape,
    ) -> Result<(), SceneError> {
        let quad = match shape {
            Shape::Quad(quad) => quad,
            other => {
                let allowed = match material.kind {
                    MaterialKind::Emitter { radiance } => format!(
                        "emission is supported on quad objects only (this object is a {} and material \
                         {name:?} emits {}; area lights are sampled as rectangles)",
                        other.kind(),
                        fmt_vec32(radiance)
                    ),
                    MaterialKind::Checker(_) => format!(
                        "a checkerboard is supported on quad objects only (this object is a {} and \
                         material {name:?} is a checker; its tiles are counted along a quad's edges)",
                        other.kind()
                    ),
                    _ => return Ok(()),
                };
                return Err(self.invalid(field, format!("{name:?}"), allowed));
            }
        };
        if let MaterialKind::Checker(c) = material.kind {
            let tiles = f64::from(quad.edge_u.length().max(quad.edge_v.length())) / f64::from(c.tile);
            if tiles > MAX_TILES_PER_EDGE {
                return Err(self.invalid(
                    format!("materials.{}.checker.tile", toml_key(name)),
                    raw_tile.map_or_else(|| fmt_f32(c.tile), fmt_num),
                    format!(
                        "must give at most {MAX_TILES_PER_EDGE} tiles along each edge of a quad it is on \
                         (this quad gives {}); f32 tile coordinates lose their fraction beyond that",
                        fmt_num(tiles)
                    ),
                ));
            }
        }
        Ok(())
    }

    fn box_shape(&self, path: &str, raw: &RawBox) -> Result<BoxShape, SceneError> {
        let (min, max) = match (raw.center, raw.half_extent, raw.min, raw.max) {
            (Some(c), Some(h), None, None) => {
                let center = self.vec3(&format!("{path}.center"), c)?;
                let half_path = format!("{path}.half_extent");
                let half = self.vec3(&half_path, h)?;
                if !half.cmpgt(Vec3::ZERO).all() {
                    return Err(self.invalid(
                        half_path,
                        fmt_vec(h.0),
                        "every component must be > 0 (a box needs positive size on each axis)",
                    ));
                }
                let (min, max) = (center - half, center + half);
                // A half-extent tiny next to the centre can vanish in f32 rounding.
                if !(min.is_finite() && max.is_finite() && max.cmpgt(min).all()) {
                    return Err(self.invalid(
                        half_path,
                        fmt_vec(h.0),
                        format!(
                            "must keep center - half_extent < center + half_extent finite and \
                             distinct in f32 on every axis (center = {})",
                            fmt_vec(c.0)
                        ),
                    ));
                }
                (min, max)
            }
            (None, None, Some(lo), Some(hi)) => {
                let min = self.vec3(&format!("{path}.min"), lo)?;
                let max_path = format!("{path}.max");
                let max = self.vec3(&max_path, hi)?;
                if !max.cmpgt(min).all() {
                    return Err(self.invalid(
                        max_path,
                        fmt_vec(hi.0),
                        format!(
                            "must be greater than {path}.min = {} on every axis (a box needs \
                             positive size on each axis)",
                            fmt_vec(lo.0)
                        ),
                    ));
                }
                (min, max)
            }
            (c, h, lo, hi) => {
                let given: Vec<&str> = [
                    (c.is_some(), "center"),
                    (h.is_some(), "half_extent"),
                    (lo.is_some(), "min"),
                    (hi.is_some(), "max"),
                ]
                .into_iter()
                .filter_map(|(present, key)| present.then_some(key))
                .collect();
                return Err(self.invalid(
                    path,
                    format!("{{ {} }}", given.join(", ")),
                    "give either center + half_extent or min + max (not both, not a mix)",
                ));
            }
        };
        let shape = BoxShape {
            min,
            max,
            rotate_y_deg: self.number(&format!("{path}.rotate_y"), raw.rotate_y)?,
            pivot: self.vec3(&format!("{path}.pivot"), raw.pivot)?,
            translate: self.vec3(&format!("{path}.translate"), raw.translate)?,
        };
        if self.origin == DVec3::ZERO {
            return Ok(shape);
        }
        // Measured from the origin, the box is re-expressed about its own centre c, in f64:
        // world - origin = R (local - c) + (R c + offset - origin), so the local bounds become
        // +-half and the pivot 0, and the one large number, the box's place, is rebased before
        // it is rounded. (The renderers' R is the f32 rotation of the same angle, applied only
        // to +-half: its rounding moves the box by about 1e-7 of its size, as at the origin.)
        let (lo, hi) = box_local_bounds(raw).expect("a box's bounds were checked above");
        let (rotation, offset) = box_local_to_world(raw);
        let (centre, half) = ((lo + hi) * 0.5, (hi - lo) * 0.5);
        let rebased = BoxShape {
            min: (-half).as_vec3(),
            max: half.as_vec3(),
            pivot: Vec3::ZERO,
            translate: (rotation * centre + offset - self.origin).as_vec3(),
            ..shape
        };
        if !(rebased.translate.is_finite() && rebased.max.cmpgt(rebased.min).all()) {
            return Err(self.invalid(
                path,
                format!("{{ centre = {} }}", fmt_vec(centre.to_array())),
                self.beyond_f32_from_eye(),
            ));
        }
        Ok(rebased)
    }

    /// |u x v| = |u| |v| sin(angle) is the quad's area. It must be clearly non-zero relative to
    /// the edge lengths (in f64, from the file's numbers), and the f32 quad the renderer gets
    /// must still have a finite, non-zero area and a finite normal.
    fn quad_area(&self, path: &str, u: [f64; 3], v: [f64; 3], quad: &Quad) -> Result<(), SceneError> {
        let (du, dv) = (glam::DVec3::from_array(u), glam::DVec3::from_array(v));
        let area64 = du.cross(dv).length();
        let scale = du.length() * dv.length();
        let ok64 = scale > 0.0 && area64 >= QUAD_DEGENERATE_SIN * scale;
        let area32 = quad.area();
        let ok32 = area32 > 0.0 && area32.is_finite() && quad.normal().is_finite();
        if ok64 && ok32 {
            return Ok(());
        }
        if ok64 {
            return Err(self.invalid(
                path,
                format!("{{ edge_u = {}, edge_v = {} }}", fmt_vec(u), fmt_vec(v)),
                format!(
                    "the quad's area |edge_u x edge_v| = {} is beyond f32's range (at most {:e}): make it smaller",
                    fmt_num(area64),
                    f32::MAX
                ),
            ));
        }
        Err(self.invalid(
            path,
            format!("{{ edge_u = {}, edge_v = {} }}", fmt_vec(u), fmt_vec(v)),
            "edge_u and edge_v must be non-zero and not parallel (|edge_u x edge_v| is the \
             quad's area, which must be > 0 and finite)",
        ))
    }
}
