//! Validation of the lights and of the per-renderer sections, and the range checks they share
//! with the other validation files (a positive number, a reflectance in [0, 1], ...). Same rules as there:
//! every number is checked for finiteness in f32 before it is compared.

use glam::Vec3;

use crate::camera::robust_normalize;
use crate::error::SceneError;
use crate::file::{
    Int, Num, RawDirectionalLight, RawEnvironment, RawPathTrace, RawRaster, RawShading, RawVec3, RawWhitted,
};
use crate::lights::{DirectionalLight, Environment};
use crate::renderers::{
    Bounces, CausticMethod, DielectricShading, Look, MAX_BOUNCES, MAX_WHITTED_AA, MAX_WHITTED_DEPTH,
    MirrorShading, PathTraceSettings, RasterSettings, Sampling, Sequence, Shading, WhittedSettings,
};
use crate::settings::{LOOK_ALLOWED, UNBOUNDED, bounces_allowed};
use crate::spelling::{fmt_num, fmt_vec};
use crate::validate::Check;

/// Largest angular radius of a sun disc, in degrees (exclusive): at 90 the disc is a hemisphere.
const MAX_ANGULAR_RADIUS_DEG: f32 = 90.0;

impl Check<'_> {
    pub(crate) fn positive(&self, field: &str, x: Num) -> Result<f32, SceneError> {
        let y = self.number(field, x)?;
        if y > 0.0 { Ok(y) } else { Err(self.invalid(field, fmt_num(x.0), "must be > 0")) }
    }

    pub(crate) fn unit_interval(&self, field: &str, x: Num) -> Result<f32, SceneError> {
        let y = self.number(field, x)?;
        if (0.0..=1.0).contains(&y) {
            Ok(y)
        } else {
            Err(self.invalid(field, fmt_num(x.0), "must be in [0, 1]"))
        }
    }

    /// A reflectance (an albedo, a mirror's tint): every channel in [0, 1], since a surface
    /// reflects at most what it receives.
    pub(crate) fn reflectance(&self, field: &str, v: RawVec3) -> Result<Vec3, SceneError> {
        let y = self.vec3(field, v)?;
        if y.cmpge(Vec3::ZERO).all() && y.cmple(Vec3::ONE).all() {
            Ok(y)
        } else {
            Err(self.invalid(
                field,
                fmt_vec(v.0),
                "every channel must be in [0, 1] (the fraction of light reflected)",
            ))
        }
    }

    /// A radiance or irradiance: every channel >= 0.
    pub(crate) fn non_negative(&self, field: &str, v: RawVec3) -> Result<Vec3, SceneError> {
        let y = self.vec3(field, v)?;
        if y.cmpge(Vec3::ZERO).all() {
            Ok(y)
        } else {
            Err(self.invalid(field, fmt_vec(v.0), "every channel must be >= 0"))
        }
    }

    pub(crate) fn environment(&self, raw: &RawEnvironment) -> Result<Environment, SceneError> {
        Ok(Environment { radiance: self.non_negative("environment.radiance", raw.radiance)? })
    }

    pub(crate) fn directional_light(
        &self,
        raw: &RawDirectionalLight,
    ) -> Result<DirectionalLight, SceneError> {
        let field = "directional_light.direction";
        let Some(direction) = robust_normalize(self.vec3(field, raw.direction)?) else {
            return Err(self.invalid(
                field,
                fmt_vec(raw.direction.0),
                "must be non-zero (the direction the light travels, e.g. [-10, -13, 2] for light \
                 from (10, 13, -2) toward the origin)",
            ));
        };
        let irradiance = self.non_negative("directional_light.irradiance", raw.irradiance)?;
        let field = "directional_light.angular_radius";
        let angular_radius_deg = self.number(field, raw.angular_radius)?;
        if !(0.0..MAX_ANGULAR_RADIUS_DEG).contains(&angular_radius_deg) {
            return Err(self.invalid(
                field,
                fmt_num(raw.angular_radius.0),
                "must be in [0, 90) degrees (the sun disc's half-angle; 0 is a delta light)",
            ));
        }
        Ok(DirectionalLight { direction, irradiance, angular_radius_deg })
    }

    pub(crate) fn pathtrace(&self, raw: &RawPathTrace) -> Result<PathTraceSettings, SceneError> {
        let spp = self.u32_at_least("pathtrace.spp", raw.spp, 1)?;
        let bounces = self.bounces(&raw.bounces)?;
        let seed = self.u32_at_least("pathtrace.seed", raw.seed, 0)?;
        let sampling: Sampling = raw.sampling.parse().map_err(|e: crate::ParseValueError| {
            self.invalid("pathtrace.sampling", format!("{:?}", raw.sampling), e.allowed)
        })?;
        let sequence: Sequence = raw.sequence.parse().map_err(|e: crate::ParseValueError| {
            self.invalid("pathtrace.sequence", format!("{:?}", raw.sequence), e.allowed)
        })?;
        let caustic_method: CausticMethod =
            raw.caustic_method.parse().map_err(|e: crate::ParseValueError| {
                self.invalid("pathtrace.caustic_method", format!("{:?}", raw.caustic_method), e.allowed)
            })?;
        Ok(PathTraceSettings {
            spp,
            bounces,
            seed,
            sampling,
            sequence,
            caustics: raw.caustics,
            caustic_method,
        })
    }

    /// `bounces` is an integer in 0..=MAX_BOUNCES or exactly the string "unbounded".
    fn bounces(&self, value: &toml::Value) -> Result<Bounces, SceneError> {
        match value {
            toml::Value::Integer(n) => {
                if let Ok(n) = u32::try_from(*n)
                    && n <= MAX_BOUNCES
                {
                    return Ok(Bounces::Fixed(n));
                }
            }
            toml::Value::String(s) if s == UNBOUNDED => return Ok(Bounces::Unbounded),
            _ => {}
        }
        let shown = match value {
            toml::Value::String(s) => format!("{s:?}"),
            other => other.to_string(),
        };
        Err(self.invalid("pathtrace.bounces", shown, bounces_allowed()))
    }

    pub(crate) fn raster(&self, raw: &RawRaster) -> Result<RasterSettings, SceneError> {
        let look: Look = raw
            .look
            .parse()
            .map_err(|_| self.invalid("raster.look", format!("{:?}", raw.look), LOOK_ALLOWED))?;
        Ok(RasterSettings {
            look,
            effects: raw.effects,
            pcf_radius: self.positive("raster.pcf_radius", raw.pcf_radius)?,
            cube_size: self.u32_at_least("raster.cube_size", raw.cube_size, 1)?,
            glass_color: self.reflectance("raster.glass_color", raw.glass_color)?,
            glass_reflectivity: self.unit_interval("raster.glass_reflectivity", raw.glass_reflectivity)?,
        })
    }

    pub(crate) fn whitted(&self, raw: &RawWhitted) -> Result<WhittedSettings, SceneError> {
        Ok(WhittedSettings {
            depth: self.u32_in("whitted.depth", raw.depth, 0, MAX_WHITTED_DEPTH)?,
            aa: self.u32_in("whitted.aa", raw.aa, 1, MAX_WHITTED_AA)?,
        })
    }

    pub(crate) fn shading(&self, raw: &RawShading) -> Result<Shading, SceneError> {
        Ok(Shading {
            ambient: self.non_negative("shading.ambient", raw.ambient)?,
            dielectric: DielectricShading {
                shininess: self.positive("shading.dielectric.shininess", raw.dielectric.shininess)?,
            },
            mirror: MirrorShading {
                specular: self.reflectance("shading.mirror.specular", raw.mirror.specular)?,
                shininess: self.positive("shading.mirror.shininess", raw.mirror.shininess)?,
                weight: self.unit_interval("shading.mirror.weight", raw.mirror.weight)?,
            },
        })
    }

    /// An integer in `min..=max`.
    fn u32_in(&self, field: &str, x: Int, min: u32, max: u32) -> Result<u32, SceneError> {
        match u32::try_from(x.0) {
            Ok(v) if (min..=max).contains(&v) => Ok(v),
            _ => Err(self.invalid(field, x.0.to_string(), format!("must be an integer in {min}..={max}"))),
        }
    }
}
