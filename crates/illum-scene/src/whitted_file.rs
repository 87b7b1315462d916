//! The Whitted look-alike's scene file as written: serde structs that mirror the TOML one to one.
//!
//! As in `file.rs`, numbers are read as f64 / i64 and may still be NaN or out of range;
//! `whitted_validate.rs` checks them and names the field. Unknown keys are rejected everywhere.
//!
//! Format (lengths in scene units, angles in degrees, colours linear RGB):
//!
//! ```toml
//! renderer = "raster"              # required: marks the file as a rasterizer scene
//! name = "whitted"                 # optional; default: the file's stem
//! look = "figure"                  # optional: "figure" (default) or "whitted"
//! [camera]                         # perspective camera
//! eye = [7.5, 2.3, -4.2]
//! target = [4.2, 2.3, -4.2]
//! up = [0.0, 1.0, 0.0]
//! vfov = 60.0                      # full vertical field of view, in (0, 180)
//! near = 0.1                       # clip planes, 0 < near < far
//! far = 3000.0
//! width = 1280                     # output size in pixels
//! height = 720
//! [background]
//! color = [0.3, 0.5, 0.9]          # the clear colour, each channel >= 0
//! [light]                          # a directional light shining from position toward target
//! position = [10.0, 13.0, -2.0]
//! target = [0.0, 0.0, 0.0]         # optional, default the origin
//! color = [1.0, 1.0, 1.0]          # optional, default white
//! intensity = 1.0                  # optional, default 1
//! casts_shadows = true             # optional, default true; false: no shadow pass at all
//! [ambient]                        # optional table; uniform light from everywhere
//! color = [1.0, 1.0, 1.0]          # optional, default white
//! intensity = 0.23                 # optional, default 0
//! [floor]                          # horizontal checkerboard rectangle
//! center = [-8.0, 0.0, 0.0]        # its height is center.y
//! size = [30.0, 15.0]              # extent along X and along Z, both > 0
//! tile = 1.0                       # tile side, > 0
//! colors = [[0.8, 0.8, 0.0], [0.8, 0.0, 0.0]]  # colors[0] on the tile at the minimum corner
//! [glass]                          # optional: the transparent sphere (absent: no glass cube map)
//! center = [4.2, 2.6, -4.2]
//! radius = 1.0
//! color = [1.0, 1.0, 1.0]          # optional: figure mix colour / whitted transmission tint
//! refraction_ratio = 0.7           # n_outside / n_inside, in (0, 1]
//! reflectivity = 0.9               # optional: figure look mixes (1 - r) color + r environment
//! shininess = 200.0                # optional: whitted look highlight exponent
//! [metal]                          # optional: the Phong-lit sphere
//! center = [2.0, 1.9, -2.5]
//! radius = 1.0
//! color = [0.792, 0.863, 0.851]
//! specular = [1.0, 1.0, 1.0]       # optional, default white
//! shininess = 30.0                 # optional, default 30
//! mirror = 0.6                     # optional: whitted look reflected fraction, in [0, 1]
//! [effects]                        # optional; every toggle defaults to true
//! shadows = true
//! pcf = true
//! refraction = true
//! reflection = true
//! fresnel = true
//! msaa = true
//! [quality]                        # optional
//! pcf_radius = 0.05                # half-width of the soft shadow edge, in scene units
//! cube_size = 256                  # side of each cube-map face, in texels
//! ```

use serde::Deserialize;

use crate::file::{Int, Num, RawVec3};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawWhitted {
    /// Must be "raster"; `kind.rs` has already checked it by the time this is parsed.
    #[allow(dead_code)]
    pub renderer: String,
    pub name: Option<String>,
    pub look: Option<String>,
    pub camera: RawWhittedCamera,
    pub background: RawBackground,
    pub light: RawLight,
    #[serde(default)]
    pub ambient: RawAmbient,
    pub floor: RawFloor,
    pub glass: Option<RawGlass>,
    pub metal: Option<RawMetal>,
    #[serde(default)]
    pub effects: RawEffects,
    #[serde(default)]
    pub quality: RawQuality,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawWhittedCamera {
    pub eye: RawVec3,
    pub target: RawVec3,
    pub up: RawVec3,
    pub vfov: Num,
    pub near: Num,
    pub far: Num,
    pub width: Int,
    pub height: Int,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawBackground {
    pub color: RawVec3,
}

fn white() -> RawVec3 {
    RawVec3([1.0; 3])
}

fn one() -> Num {
    Num(1.0)
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawLight {
    pub position: RawVec3,
    #[serde(default)]
    pub target: RawVec3,
    #[serde(default = "white")]
    pub color: RawVec3,
    #[serde(default = "one")]
    pub intensity: Num,
    #[serde(default = "yes")]
    pub casts_shadows: bool,
}

fn yes() -> bool {
    true
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(crate) struct RawAmbient {
    pub color: RawVec3,
    pub intensity: Num,
}

impl Default for RawAmbient {
    fn default() -> Self {
        RawAmbient { color: white(), intensity: Num(0.0) }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawFloor {
    pub center: RawVec3,
    /// Two numbers; validation checks the count so the error can name the field.
    pub size: Vec<Num>,
    pub tile: Num,
    /// Two colours; validation checks the count.
    pub colors: Vec<RawVec3>,
}

fn glass_reflectivity() -> Num {
    Num(0.9)
}

fn glass_shininess() -> Num {
    Num(200.0)
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawGlass {
    pub center: RawVec3,
    pub radius: Num,
    #[serde(default = "white")]
    pub color: RawVec3,
    pub refraction_ratio: Num,
    #[serde(default = "glass_reflectivity")]
    pub reflectivity: Num,
    #[serde(default = "glass_shininess")]
    pub shininess: Num,
}

fn metal_shininess() -> Num {
    Num(30.0)
}

fn metal_mirror() -> Num {
    Num(0.6)
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawMetal {
    pub center: RawVec3,
    pub radius: Num,
    pub color: RawVec3,
    #[serde(default = "white")]
    pub specular: RawVec3,
    #[serde(default = "metal_shininess")]
    pub shininess: Num,
    #[serde(default = "metal_mirror")]
    pub mirror: Num,
}

/// Effect toggles; each absent key is on.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(crate) struct RawEffects {
    pub shadows: bool,
    pub pcf: bool,
    pub refraction: bool,
    pub reflection: bool,
    pub fresnel: bool,
    pub msaa: bool,
}

impl Default for RawEffects {
    fn default() -> Self {
        RawEffects { shadows: true, pcf: true, refraction: true, reflection: true, fresnel: true, msaa: true }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(crate) struct RawQuality {
    pub pcf_radius: Num,
    pub cube_size: Int,
}

impl Default for RawQuality {
    fn default() -> Self {
        RawQuality { pcf_radius: Num(0.05), cube_size: Int(256) }
    }
}
