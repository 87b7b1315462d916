//! From the raw file structs to a validated [`Scene`].
//!
//! Checks run in file order (camera, render, materials, objects) and stop at the first problem.
//! Every number is checked for finiteness *after* conversion to f32 — TOML happily accepts
//! `nan` and `inf`, and a finite f64 such as 1e39 becomes infinite in f32 — before any check
//! that compares it, because NaN fails every comparison silently. Positions are then measured
//! from the frame's origin in f64 and rounded once (`frame.rs`); errors show them as the file
//! gives them.
//!
//! This file holds the validation context [`Check`], its number and camera checks, and the order
//! of the whole conversion; the materials, the objects and the lights and per-renderer sections
//! are checked in `validate_materials.rs`, `validate_objects.rs` and `validate_sections.rs`.

use glam::{DVec3, Vec3};

use crate::camera::{Camera, ClipPlanes, robust_normalize};
use crate::error::SceneError;
use crate::file::{Int, Num, RawCamera, RawScene, RawVec3};
use crate::frame::frame_origin;
use crate::mesh_load::{ReadFile, load_meshes};
use crate::renderers::RendererKind;
use crate::scene::Scene;
use crate::settings::RENDERER_ALLOWED;
use crate::spelling::{fmt_num, fmt_vec, fmt_vec32};

const FINITE_ALLOWED: &str =
    "must be a finite number within f32 range (|x| <= 3.4e38); nan and inf are not allowed";

/// Below this, |normalize(forward) x normalize(up)| counts as parallel: the camera's right
/// vector would be dominated by rounding.
const CAMERA_PARALLEL_SIN: f32 = 1e-6;

/// Validates `raw` (read from `file`) into a scene named `raw.name` or else `default_name`.
/// Mesh files are read by `read` (`validate_mesh.rs`) before anything else is checked, since
/// their vertices count toward the frame's origin.
pub(crate) fn scene_from_raw(
    raw: RawScene,
    file: &str,
    default_name: &str,
    read: &mut ReadFile<'_>,
) -> Result<Scene, SceneError> {
    let loaded = load_meshes(&raw, file, read)?;
    let mesh_bounds: Vec<(DVec3, DVec3)> = raw
        .objects
        .iter()
        .zip(&loaded)
        .filter_map(|(o, l)| l.as_ref()?.world_bounds(o.mesh.as_ref()?))
        .collect();
    let origin = frame_origin(&raw, &mesh_bounds);
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
            "a scene needs at least one object (an [[objects]] table with a box, quad, sphere or mesh)",
        ));
    }
    let objects = raw
        .objects
        .iter()
        .enumerate()
        .map(|(i, o)| check.object(i, o, &materials, &index_of, &raw.materials, loaded[i].as_ref()))
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

    pub(crate) fn beyond_f32_from_eye(&self) -> String {
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
}
