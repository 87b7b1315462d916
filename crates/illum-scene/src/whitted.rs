//! The Whitted look-alike's scene (assignment task 1): a glass sphere and a metal sphere over a
//! checkerboard floor, lit by one directional light and an ambient term.
//!
//! A file is marked `renderer = "raster"` (see [`SceneKind`](crate::SceneKind)); its format is
//! documented in `whitted_file.rs` and in `scenes/whitted.toml`. Loading validates every number
//! with the same error style as the path tracer's scenes: file, field, value, what is allowed.

use std::fmt;
use std::path::Path;
use std::str::FromStr;

use glam::{Vec2, Vec3};

use crate::error::{ParseValueError, SceneError};
use crate::kind::SceneKind;
use crate::types::Camera;
use crate::whitted_file::RawWhitted;
use crate::whitted_validate::whitted_from_raw;

/// A validated Whitted look-alike scene.
#[derive(Clone, Debug, PartialEq)]
pub struct WhittedScene {
    /// Scene name (the file's `name`, or its file stem).
    pub name: String,
    /// Perspective camera and output resolution.
    pub camera: Camera,
    /// Near and far clip distances of the camera.
    pub clip: ClipPlanes,
    /// Linear RGB clear colour.
    pub background: Vec3,
    pub light: DirectionalLight,
    pub ambient: AmbientLight,
    pub floor: CheckerFloor,
    /// The refracting sphere, if the scene has one (without it no glass cube map is captured).
    pub glass: Option<GlassSphere>,
    /// The Phong-lit (and, in the whitted look, mirroring) sphere, if the scene has one.
    pub metal: Option<MetalSphere>,
    /// The look used when the caller does not choose one.
    pub look: Look,
    /// The effect toggles used when the caller does not choose them.
    pub effects: Effects,
    pub quality: RasterQuality,
}

/// Near and far clip distances, 0 < near < far.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipPlanes {
    pub near: f32,
    pub far: f32,
}

/// A light at infinity shining from `position` toward `target` (as three.js's directional light:
/// only the direction between the two matters).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalLight {
    pub position: Vec3,
    pub target: Vec3,
    pub color: Vec3,
    pub intensity: f32,
    /// Whether the spheres cast shadows under this light (`false`: no shadow map is drawn).
    pub casts_shadows: bool,
}

impl DirectionalLight {
    /// Unit vector along which the light travels (from `position` toward `target`).
    pub fn direction(&self) -> Vec3 {
        (self.target - self.position).normalize()
    }

    /// Unit vector from a surface toward the light: the L of N.L.
    pub fn to_light(&self) -> Vec3 {
        -self.direction()
    }

    /// `color * intensity`: the irradiance on a surface facing the light.
    pub fn radiance(&self) -> Vec3 {
        self.color * self.intensity
    }
}

/// Light arriving equally from every direction, unshadowed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AmbientLight {
    pub color: Vec3,
    pub intensity: f32,
}

impl AmbientLight {
    pub fn radiance(&self) -> Vec3 {
        self.color * self.intensity
    }
}

/// A horizontal rectangle at height `center.y`, `size.x` long along X and `size.y` along Z,
/// tiled with squares of side `tile`. The tile (i, j), counted from the minimum corner, has
/// colour `colors[(i + j) % 2]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CheckerFloor {
    pub center: Vec3,
    pub size: Vec2,
    pub tile: f32,
    pub colors: [Vec3; 2],
}

impl CheckerFloor {
    /// (x, z) of the corner with the smallest coordinates.
    pub fn min_corner(&self) -> Vec2 {
        Vec2::new(self.center.x, self.center.z) - 0.5 * self.size
    }

    /// (x, z) of the corner with the largest coordinates.
    pub fn max_corner(&self) -> Vec2 {
        Vec2::new(self.center.x, self.center.z) + 0.5 * self.size
    }

    /// The floor's height.
    pub fn height(&self) -> f32 {
        self.center.y
    }
}

/// The transparent sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlassSphere {
    pub center: Vec3,
    pub radius: f32,
    /// Figure look: the colour mixed with the environment; whitted look: the transmission tint.
    pub color: Vec3,
    /// n_outside / n_inside (0.7 in the assignment: glass of index 1 / 0.7 = 1.43), in (0, 1].
    pub refraction_ratio: f32,
    /// Figure look: pixel = (1 - reflectivity) color + reflectivity environment, in [0, 1].
    pub reflectivity: f32,
    /// Whitted look: exponent of the white highlight, > 0.
    pub shininess: f32,
}

/// The Phong-lit sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MetalSphere {
    pub center: Vec3,
    pub radius: f32,
    pub color: Vec3,
    pub specular: Vec3,
    /// Phong exponent, > 0.
    pub shininess: f32,
    /// Whitted look: the fraction of light mirrored (tinted by `color`), in [0, 1].
    pub mirror: f32,
}

/// The two looks of the rasterizer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Look {
    /// The assignment's figure 1: one refraction into a cube map, unlit glass, plain Phong metal.
    #[default]
    Figure,
    /// Closer to a real Whitted ray tracer: mirror metal, Fresnel-weighted reflection plus
    /// refraction through both faces of the glass, specular highlights.
    Whitted,
}

impl Look {
    pub const ALL: [Look; 2] = [Look::Figure, Look::Whitted];

    /// The name used in files and on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            Look::Figure => "figure",
            Look::Whitted => "whitted",
        }
    }
}

/// What `look` accepts, for error messages.
pub(crate) const LOOK_ALLOWED: &str = "must be \"figure\" or \"whitted\"";

impl FromStr for Look {
    type Err = ParseValueError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "figure" => Ok(Look::Figure),
            "whitted" => Ok(Look::Whitted),
            _ => Err(ParseValueError { value: s.to_owned(), allowed: LOOK_ALLOWED.to_owned() }),
        }
    }
}

impl fmt::Display for Look {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Effect toggles. Reflection and Fresnel belong to the whitted look (the figure has neither);
/// the others apply to both looks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Effects {
    /// Shadows from the directional light (a shadow map).
    pub shadows: bool,
    /// Soft shadow edges by percentage-closer filtering; off: one hard depth comparison.
    pub pcf: bool,
    /// Bend the view through the glass; off: the glass shows the environment straight behind it.
    pub refraction: bool,
    /// Whitted look: mirror reflections on the metal and glass.
    pub reflection: bool,
    /// Whitted look: Schlick's Fresnel weight between reflection and refraction on the glass;
    /// off: the normal-incidence weight everywhere.
    pub fresnel: bool,
    /// 4x multisample anti-aliasing of edges.
    pub msaa: bool,
}

impl Effects {
    /// Every effect on.
    pub const ALL_ON: Effects =
        Effects { shadows: true, pcf: true, refraction: true, reflection: true, fresnel: true, msaa: true };
}

impl Default for Effects {
    fn default() -> Self {
        Effects::ALL_ON
    }
}

/// Quality settings that trade speed for fidelity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RasterQuality {
    /// Half-width of the soft shadow edge in scene units (> 0); also sets the shadow map's texel.
    pub pcf_radius: f32,
    /// Side of each cube-map face in texels (>= 1).
    pub cube_size: u32,
}

/// What the device allows, for [`WhittedScene::check_device_limits`] (filled in from
/// `wgpu::Limits` by the caller).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RasterLimits {
    /// Largest 2D texture side (also bounds cube-map faces).
    pub max_texture_dimension_2d: u32,
    /// Largest buffer, in bytes (the image is read back through one).
    pub max_buffer_size: u64,
}

/// Bytes per output pixel (RGBA, 8 bits per channel) and the row alignment GPU copies need.
const READBACK_BYTES_PER_PIXEL: u64 = 4;
const READBACK_ROW_ALIGNMENT: u64 = 256;

impl WhittedScene {
    /// Reads and validates a scene file. Errors name the file as `path` was given.
    pub fn load(path: &Path) -> Result<WhittedScene, SceneError> {
        let label = path.display().to_string();
        let text =
            std::fs::read_to_string(path).map_err(|source| SceneError::Io { file: label.clone(), source })?;
        Self::from_toml_str(&text, &label)
    }

    /// Parses and validates scene text. `file_label` names the source in errors, and its file
    /// stem is the scene's name when the text has no `name`.
    pub fn from_toml_str(text: &str, file_label: &str) -> Result<WhittedScene, SceneError> {
        if SceneKind::from_toml_str(text, file_label)? != SceneKind::Raster {
            return Err(SceneError::invalid(
                file_label,
                crate::kind::RENDERER_KEY,
                "(missing)",
                "must be \"raster\" for a Whitted look-alike scene; without it the file is a \
                 path-tracer scene (load it with illum_scene::Scene::load)",
            ));
        }
        let raw: RawWhitted =
            toml::from_str(text).map_err(|e| SceneError::from_toml(&e, text, file_label))?;
        let default_name = Path::new(file_label)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .filter(|s| !s.is_empty())
            .unwrap_or_else(|| "scene".to_owned());
        whitted_from_raw(raw, file_label, &default_name)
    }

    /// Centre and radius of each sphere the scene has: the glass's first, then the metal's.
    pub fn spheres(&self) -> Vec<(Vec3, f32)> {
        let glass = self.glass.map(|g| (g.center, g.radius));
        glass.into_iter().chain(self.metal.map(|m| (m.center, m.radius))).collect()
    }

    /// Replaces the output resolution, after checking it by the same rules as the file.
    /// `origin` labels the errors (e.g. "command line"), whose fields are `--width` and
    /// `--height`. On error nothing is changed.
    pub fn set_resolution(
        &mut self,
        width: Option<u32>,
        height: Option<u32>,
        origin: &str,
    ) -> Result<(), SceneError> {
        for (field, value) in [("--width", width), ("--height", height)] {
            if value == Some(0) {
                return Err(SceneError::invalid(origin, field, "0", "must be at least 1"));
            }
        }
        self.camera.width = width.unwrap_or(self.camera.width);
        self.camera.height = height.unwrap_or(self.camera.height);
        Ok(())
    }

    /// Checks that the output and the cube maps fit the device: every texture side within
    /// `max_texture_dimension_2d`, and the readback buffer (4 bytes per pixel, rows padded to
    /// 256 bytes) within `max_buffer_size`. Errors are labelled `scene "NAME"`, since the
    /// resolution may come from the file or from the command line.
    pub fn check_device_limits(&self, limits: &RasterLimits) -> Result<(), SceneError> {
        let label = format!("scene {:?}", self.name);
        let max = limits.max_texture_dimension_2d;
        let (w, h) = (self.camera.width, self.camera.height);
        for (field, side) in
            [("camera.width", w), ("camera.height", h), ("quality.cube_size", self.quality.cube_size)]
        {
            if side > max {
                return Err(SceneError::invalid(
                    &label,
                    field,
                    side.to_string(),
                    format!("must be at most {max}, the device's max_texture_dimension_2d"),
                ));
            }
        }
        let row = (u64::from(w) * READBACK_BYTES_PER_PIXEL).next_multiple_of(READBACK_ROW_ALIGNMENT);
        let bytes = row.saturating_mul(u64::from(h));
        if bytes > limits.max_buffer_size {
            return Err(SceneError::invalid(
                &label,
                "camera.width x camera.height",
                format!("{w} x {h} ({bytes} bytes to read back)"),
                format!("must fit in {} bytes, the device's max_buffer_size", limits.max_buffer_size),
            ));
        }
        Ok(())
    }
}
