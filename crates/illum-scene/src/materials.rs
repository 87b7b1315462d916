//! Materials: how a surface scatters or emits light, described physically.
//!
//! A scene file's `[materials.NAME]` table holds exactly one of the keys below; the variant of
//! [`MaterialKind`] says which:
//!
//! | key | kind | meaning |
//! |---|---|---|
//! | `albedo = [r, g, b]` | [`MaterialKind::Lambertian`] | ideal diffuse, BRDF albedo / pi |
//! | `checker = { even, odd, tile }` | [`MaterialKind::Checker`] | Lambertian with a checkerboard of two albedos (quads only) |
//! | `dielectric = { ior }` | [`MaterialKind::Dielectric`] | smooth glass: Fresnel reflection and Snell refraction, no absorption |
//! | `mirror = { reflectance }` | [`MaterialKind::Mirror`] | smooth mirror, tinted by `reflectance` at every angle |
//! | `emission = [r, g, b]` | [`MaterialKind::Emitter`] | emitted radiance on the front side; reflects nothing (quads only) |

use glam::Vec3;

#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    pub kind: MaterialKind,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaterialKind {
    /// Lambertian reflection; every channel of `albedo` in [0, 1].
    Lambertian { albedo: Vec3 },
    /// Lambertian reflection with a checkerboard albedo.
    Checker(Checker),
    /// A smooth dielectric of index of refraction `ior` (> 0, finite) inside, in a medium of
    /// index 1 outside.
    Dielectric { ior: f32 },
    /// A smooth mirror reflecting the fraction `reflectance` (each channel in [0, 1]) at every
    /// angle of incidence.
    Mirror { reflectance: Vec3 },
    /// Emits `radiance` (each channel >= 0, one > 0) from its front side; reflects nothing.
    Emitter { radiance: Vec3 },
}

/// A checkerboard on a quad: the tile (i, j), counted from the quad's corner along its two
/// edges, i = floor(s |edge_u| / tile) and j = floor(t |edge_v| / tile), has albedo `even`
/// where i + j is even and `odd` where it is odd.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Checker {
    pub even: Vec3,
    pub odd: Vec3,
    /// Side of a square tile, > 0, in scene units.
    pub tile: f32,
}

impl Material {
    /// Whether this material is a light source (an area light, when on a quad).
    pub fn is_emitter(&self) -> bool {
        matches!(self.kind, MaterialKind::Emitter { .. })
    }

    /// Emitted radiance: zero for everything but an emitter.
    pub fn emission(&self) -> Vec3 {
        match self.kind {
            MaterialKind::Emitter { radiance } => radiance,
            _ => Vec3::ZERO,
        }
    }

    /// The constant diffuse albedo of a Lambertian material, zero for an emitter (which
    /// reflects nothing), `None` for every other kind.
    pub fn diffuse_albedo(&self) -> Option<Vec3> {
        match self.kind {
            MaterialKind::Lambertian { albedo } => Some(albedo),
            MaterialKind::Emitter { .. } => Some(Vec3::ZERO),
            _ => None,
        }
    }
}

impl MaterialKind {
    /// The key a scene file uses for this kind.
    pub fn key(&self) -> &'static str {
        match self {
            MaterialKind::Lambertian { .. } => "albedo",
            MaterialKind::Checker(_) => "checker",
            MaterialKind::Dielectric { .. } => "dielectric",
            MaterialKind::Mirror { .. } => "mirror",
            MaterialKind::Emitter { .. } => "emission",
        }
    }
}
