//! From the raw file structs to a validated [`Scene`].
//!
//! Checks run in file order (camera, render, materials, objects) and stop at the first problem.
//! Every number is checked for finiteness *after* conversion to f32 — TOML happily accepts
//! `nan` and `inf`, and a finite f64 such as 1e39 becomes infinite in f32 — before any check
//! that compares it, because NaN fails every comparison silently. Positions are then measured
//! from the frame's origin in f64 and rounded once (`frame.rs`); errors show them as the file
//! gives them.
//!
//! Over 450 lines: every rule of the conversion, in the order the file is read (the per-renderer
//! sections are in `validate_sections.rs`).

use std::collections::BTreeMap;

use glam::{DVec3, Vec3};

use crate::camera::{Camera, ClipPlanes, robust_normalize};
use crate::error::SceneError;
use crate::file::{Int, Num, RawBox, RawCamera, RawMaterial, RawObject, RawScene, RawVec3};
use crate::frame::{box_local_bounds, box_local_to_world, frame_origin};
use crate::materials::{Checker, Material, MaterialKind};
use crate::renderers::RendererKind;
use crate::scene::{Object, Scene};
use crate::settings::RENDERER_ALLOWED;
use crate::shapes::{BoxShape, Quad, Shape, Sphere};

pub(crate) const FINITE_ALLOWED: &str =
    "must be a finite number within f32 range (|x| <= 3.4e38); nan and inf are not allowed";

/// The relative size of |edge_u x edge_v| below which a quad counts as degenerate:
/// |u x v| = |u| |v| sin(angle), so this is sin(angle) < 1e-12 between the edges.
const QUAD_DEGENERATE_SIN: f64 = 1e-12;

/// Below this, |normalize(forward) x normalize(up)| counts as parallel: the camera's right
/// vector would be dominated by rounding.
const CAMERA_PARALLEL_SIN: f32 = 1e-6;

/// More checker tiles than this along one edge of a quad and the f32 tile coordinate of the far
/// edge loses its fraction (2^24 / 100000 ~ 168 steps per tile remain), so the board would break
/// up.
const MAX_TILES_PER_EDGE: f64 = 100_000.0;

/// Validates `raw` (read from `file`) into a scene named `raw.name` or else `default_name`.
pub(crate) fn scene_from_raw(raw: RawScene, file: &str, default_name: &str) -> Result<Scene, SceneError> {
    let origin = frame_origin(&raw);
    let check = Check { file, origin };
    let renderer = match &raw.renderer {
        None => RendererKind::PathTrace,
        Some(s) => s.parse().map_err(|_| check.invalid("renderer", format!("{s:?}"), RENDERER_ALLOWED))?,
    };
    let camera = check.camera(&raw.camera)?;
    let clip = check.clip_planes(raw.camera.near, raw.camera.far)?;
    let environment = raw.environment.as_ref().map(|e| check.environment(e)).transpose()?;
    let directional_light = raw.directional_light.as_ref().map(|l| check.directional_light(l)).transpose()?;
    let (materials, index_of) = check.materials(&raw.materials)?;
    if raw.objects.is_empty() {
        return Err(check.invalid(
            "objects",
            "[]",
            "a scene needs at least one object (an [[objects]] table with a box, quad or sphere)",
        ));
    }
    let objects = raw
        .objects
        .iter()
        .enumerate()
        .map(|(i, o)| check.object(i, o, &materials, &index_of, &raw.materials))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Scene {
        name: raw.name.unwrap_or_else(|| default_name.to_owned()),
        source: file.to_owned(),
        renderer,
        origin,
        camera,
        clip,
        materials,
        objects,
        directional_light,
        environment,
        pathtrace: check.pathtrace(&raw.pathtrace)?,
        raster: check.raster(&raw.raster)?,
        whitted: check.whitted(&raw.whitted)?,
        shading: check.shading(&raw.shading)?,
    })
}

/// Validation context: the file label every error carries, and the origin positions are
/// measured from (`frame.rs`). The sections' checks are in `validate_sections.rs`.
pub(crate) struct Check<'a> {
    pub(crate) file: &'a str,
    pub(crate) origin: DVec3,
}

impl Check<'_> {
    pub(crate) fn invalid(
        &self,
        field: impl Into<String>,
        value: impl Into<String>,
        allowed: impl Into<String>,
    ) -> SceneError {
        SceneError::invalid(self.file, field, value, allowed)
    }

    pub(crate) fn number(&self, field: &str, x: Num) -> Result<f32, SceneError> {
        let y = x.0 as f32;
        if y.is_finite() { Ok(y) } else { Err(self.invalid(field, fmt_num(x.0), FINITE_ALLOWED)) }
    }

    pub(crate) fn vec3(&self, field: &str, v: RawVec3) -> Result<Vec3, SceneError> {
        let y = Vec3::from_array(v.0.map(|x| x as f32));
        if y.is_finite() {
            Ok(y)
        } else {
            Err(self.invalid(field, fmt_vec(v.0), format!("every component {FINITE_ALLOWED}")))
        }
    }

    /// A position: finite in f32 as the file gives it (the rule for every number), then measured
    /// from the frame's origin in f64 and rounded to f32 once (`frame.rs`).
    pub(crate) fn position(&self, field: &str, v: RawVec3) -> Result<Vec3, SceneError> {
        let world = self.vec3(field, v)?;
        if self.origin == DVec3::ZERO {
            return Ok(world);
        }
        let local = (DVec3::from_array(v.0) - self.origin).as_vec3();
        if local.is_finite() {
            Ok(local)
        } else {
            Err(self.invalid(field, fmt_vec(v.0), self.beyond_f32_from_eye()))
        }
    }

    fn beyond_f32_from_eye(&self) -> String {
        format!(
            "must lie within f32 range (3.4e38) of camera.eye = {}, which positions are measured from",
            fmt_vec(self.origin.to_array())
        )
    }

    /// How an error shows a position converted by [`Check::position`]: as the file gives it.
    fn shown(&self, v: Vec3) -> String {
        if self.origin == DVec3::ZERO {
            fmt_vec32(v)
        } else {
            fmt_vec((self.origin + v.as_dvec3()).to_array())
        }
    }

    /// An integer in `min..=u32::MAX`.
    pub(crate) fn u32_at_least(&self, field: &str, x: Int, min: u32) -> Result<u32, SceneError> {
        let allowed = if x.0 < i64::from(min) {
            format!("must be at least {min}")
        } else {
            match u32::try_from(x.0) {
                Ok(v) => return Ok(v),
                Err(_) => format!("must be at most {}", u32::MAX),
            }
        };
        Err(self.invalid(field, x.0.to_string(), allowed))
    }

    pub(crate) fn camera(&self, raw: &RawCamera) -> Result<Camera, SceneError> {
        let eye = self.position("camera.eye", raw.eye)?;
        let target = self.position("camera.target", raw.target)?;
        let up = self.vec3("camera.up", raw.up)?;
        let vfov_deg = self.number("camera.vfov", raw.vfov)?;
        // tan(vfov / 2) must be finite and positive: 0 and 180 degrees are excluded.
        if !(vfov_deg > 0.0 && vfov_deg < 180.0) {
            return Err(self.invalid(
                "camera.vfov",
                fmt_num(raw.vfov.0),
                "must be in the open interval (0, 180) degrees (full vertical field of view)",
            ));
        }
        let width = self.u32_at_least("camera.width", raw.width, 1)?;
        let height = self.u32_at_least("camera.height", raw.height, 1)?;
        self.view(eye, target, up)?;
        Ok(Camera { eye, target, up, vfov_deg, width, height })
    }

    /// The view must define a frame: target - eye non-zero (and finite in f32), up non-zero
    /// and not parallel to it, else right = forward x up is undefined.
    pub(crate) fn view(&self, eye: Vec3, target: Vec3, up: Vec3) -> Result<(), SceneError> {
        let Some(forward) = robust_normalize(target - eye) else {
            return Err(self.invalid(
                "camera.target",
                self.shown(target),
                format!(
                    "must differ from camera.eye = {} (the view direction target - eye must be \
                     non-zero and finite)",
                    self.shown(eye)
                ),
            ));
        };
        let parallel = match robust_normalize(up) {
            None => true,
            Some(up) => forward.cross(up).length() < CAMERA_PARALLEL_SIN,
        };
        if parallel {
            return Err(self.invalid(
                "camera.up",
                fmt_vec32(up),
                format!(
                    "must be non-zero and not parallel to the view direction target - eye = {}",
                    fmt_vec32(target - eye)
                ),
            ));
        }
        Ok(())
    }

    /// `camera.near` and `camera.far`: both or neither, 0 < near < far.
    fn clip_planes(&self, near: Option<Num>, far: Option<Num>) -> Result<Option<ClipPlanes>, SceneError> {
        let (near, far) = match (near, far) {
            (None, None) => return Ok(None),
            (Some(near), Some(far)) => (near, far),
            (Some(_), None) => {
                return Err(self.invalid("camera.far", "(missing)", "must be given with camera.near"));
            }
            (None, Some(_)) => {
                return Err(self.invalid("camera.near", "(missing)", "must be given with camera.far"));
            }
        };
        let near32 = self.positive("camera.near", near)?;
        let far32 = self.number("camera.far", far)?;
        if far32 <= near32 {
            return Err(self.invalid(
                "camera.far",
                fmt_num(far.0),
                format!("must be greater than camera.near = {}", fmt_num(near.0)),
            ));
        }
        Ok(Some(ClipPlanes { near: near32, far: far32 }))
    }

    /// Materials in sorted-name order, plus the name -> index map objects resolve against.
    fn materials(
        &self,
        raw: &BTreeMap<String, RawMaterial>,
    ) -> Result<(Vec<Material>, BTreeMap<String, usize>), SceneError> {
        let mut materials = Vec::with_capacity(raw.len());
        let mut index_of = BTreeMap::new();
        for (name, m) in raw {
            let path = format!("materials.{}", toml_key(name));
            index_of.insert(name.clone(), materials.len());
            materials.push(Material { name: name.clone(), kind: self.material_kind(&path, m)? });
        }
        Ok((materials, index_of))
    }

    fn material_kind(&self, path: &str, m: &RawMaterial) -> Result<MaterialKind, SceneError> {
        let given: Vec<&str> = [
            (m.albedo.is_some(), "albedo"),
            (m.checker.is_some(), "checker"),
            (m.dielectric.is_some(), "dielectric"),
            (m.mirror.is_some(), "mirror"),
            (m.emission.is_some(), "emission"),
        ]
        .into_iter()
        .filter_map(|(present, key)| present.then_some(key))
        .collect();
        if given.len() != 1 {
            let value =
                if given.is_empty() { "{}".to_owned() } else { format!("{{ {} }}", given.join(", ")) };
            return Err(self.invalid(
                path,
                value,
                "a material needs exactly one of albedo (Lambertian), checker (Lambertian \
                 checkerboard), dielectric (glass), mirror, emission (area light)",
            ));
        }
        if let Some(albedo) = m.albedo {
            return Ok(MaterialKind::Lambertian {
                albedo: self.reflectance(&format!("{path}.albedo"), albedo)?,
            });
        }
        if let Some(c) = &m.checker {
            return Ok(MaterialKind::Checker(Checker {
                even: self.reflectance(&format!("{path}.checker.even"), c.even)?,
                odd: self.reflectance(&format!("{path}.checker.odd"), c.odd)?,
                tile: self.positive(&format!("{path}.checker.tile"), c.tile)?,
            }));
        }
        if let Some(d) = &m.dielectric {
            let field = format!("{path}.dielectric.ior");
            let ior = self.number(&field, d.ior)?;
            if ior <= 0.0 {
                return Err(self.invalid(
                    field,
                    fmt_num(d.ior.0),
                    "must be > 0 (the index of refraction inside; outside is 1, so 1 makes the \
                     surface vanish and 1.43 is glass)",
                ));
            }
            return Ok(MaterialKind::Dielectric { ior });
        }
        if let Some(mirror) = &m.mirror {
            let reflectance = self.reflectance(&format!("{path}.mirror.reflectance"), mirror.reflectance)?;
            return Ok(MaterialKind::Mirror { reflectance });
        }
        let raw = m.emission.expect("exactly one key is present");
        let field = format!("{path}.emission");
        let radiance = self.vec3(&field, raw)?;
        if !(radiance.cmpge(Vec3::ZERO).all() && radiance.max_element() > 0.0) {
            return Err(self.invalid(
                field,
                fmt_vec(raw.0),
                "every channel must be >= 0 and one > 0 (emitted radiance; for a black surface \
                 write albedo = [0, 0, 0])",
            ));
        }
        Ok(MaterialKind::Emitter { radiance })
    }

    fn object(
        &self,
        i: usize,
        raw: &RawObject,
        materials: &[Material],
        index_of: &BTreeMap<String, usize>,
        raw_materials: &BTreeMap<String, RawMaterial>,
    ) -> Result<Object, SceneError> {
        let label = match &raw.name {
            Some(name) => format!("objects[{i}] ({name:?})"),
            None => format!("objects[{i}]"),
        };
        let shape = match (&raw.box_, &raw.quad, &raw.sphere) {
            (Some(b), None, None) => Shape::Box(self.box_shape(&format!("{label}.box"), b)?),
            (None, Some(q), None) => {
                let path = format!("{label}.quad");
                let quad = Quad {
                    corner: self.position(&format!("{path}.corner"), q.corner)?,
                    edge_u: self.vec3(&format!("{path}.edge_u"), q.edge_u)?,
                    edge_v: self.vec3(&format!("{path}.edge_v"), q.edge_v)?,
                };
                self.quad_area(&path, q.edge_u.0, q.edge_v.0, &quad)?;
                Shape::Quad(quad)
            }
            (None, None, Some(s)) => {
                let path = format!("{label}.sphere");
                let center = self.position(&format!("{path}.center"), s.center)?;
                let radius_path = format!("{path}.radius");
                let radius = self.number(&radius_path, s.radius)?;
                if radius <= 0.0 {
                    return Err(self.invalid(radius_path, fmt_num(s.radius.0), "must be > 0"));
                }
                Shape::Sphere(Sphere { center, radius })
            }
            (b, q, s) => {
                let given: Vec<&str> = [(b.is_some(), "box"), (q.is_some(), "quad")]
                    .into_iter()
                    .chain([(s.is_some(), "sphere")])
                    .filter_map(|(present, key)| present.then_some(key))
                    .collect();
                let value = if given.is_empty() {
                    "(no shape)".to_owned()
                } else {
                    format!("(both {})", given.join(" and "))
                };
                return Err(self.invalid(label, value, "each object needs exactly one of box, quad, sphere"));
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

/// A number as TOML would spell it: `nan`, `inf`, exponent form for very large or small
/// magnitudes, else Rust's shortest round-trip decimal.
pub(crate) fn fmt_num(x: f64) -> String {
    if x.is_nan() {
        "nan".to_owned()
    } else if x.is_infinite() {
        if x > 0.0 { "inf" } else { "-inf" }.to_owned()
    } else if x != 0.0 && !(1e-5..1e16).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        x.to_string()
    }
}

pub(crate) fn fmt_vec(v: [f64; 3]) -> String {
    format!("[{}, {}, {}]", fmt_num(v[0]), fmt_num(v[1]), fmt_num(v[2]))
}

/// An f32 in its own shortest form (0.5608, not 0.5608000159263611), by the same rules as
/// `fmt_num`: how errors show a number that validation has already converted.
pub fn fmt_f32(x: f32) -> String {
    if x.is_finite() && (x == 0.0 || (1e-5..1e16).contains(&x.abs())) {
        x.to_string()
    } else if x.is_finite() {
        format!("{x:e}")
    } else {
        fmt_num(f64::from(x))
    }
}

/// A vector of f32s, each as [`fmt_f32`] shows it.
pub(crate) fn fmt_vec32(v: Vec3) -> String {
    format!("[{}, {}, {}]", fmt_f32(v.x), fmt_f32(v.y), fmt_f32(v.z))
}

/// A TOML key as it would be written in a dotted path: bare if it can be, quoted otherwise.
pub fn toml_key(name: &str) -> String {
    let bare = !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    if bare { name.to_owned() } else { format!("{name:?}") }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn number_formatting_uses_toml_spellings() {
        assert_eq!(fmt_num(f64::NAN), "nan");
        assert_eq!(fmt_num(f64::INFINITY), "inf");
        assert_eq!(fmt_num(f64::NEG_INFINITY), "-inf");
        assert_eq!(fmt_num(278.0), "278");
        assert_eq!(fmt_num(0.0), "0");
        assert_eq!(fmt_num(1e39), "1e39");
        assert_eq!(fmt_num(-2.5e-7), "-2.5e-7");
        assert_eq!(fmt_vec([1.0, -724.26, 0.5]), "[1, -724.26, 0.5]");
        assert_eq!(fmt_vec32(Vec3::new(0.5608, 1.0, f32::NAN)), "[0.5608, 1, nan]");
    }

    #[test]
    fn keys_are_quoted_only_when_needed() {
        assert_eq!(toml_key("red"), "red");
        assert_eq!(toml_key("light-2_b"), "light-2_b");
        assert_eq!(toml_key("my red"), "\"my red\"");
        assert_eq!(toml_key("a.b"), "\"a.b\"");
        assert_eq!(toml_key(""), "\"\"");
    }
}
