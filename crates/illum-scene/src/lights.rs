//! Lights other than area lights (which are quads with an emitting material, see
//! [`Scene::emitters`](crate::Scene::emitters)).

use glam::Vec3;

/// A light at infinity: parallel rays travelling along `direction`.
///
/// `irradiance` is what a surface facing the light receives (per channel). A Lambertian surface
/// of albedo rho at angle theta to the light then has radiance rho x irradiance / pi x cos(theta):
/// a three.js `DirectionalLight` of intensity I corresponds to irradiance pi x I.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalLight {
    /// Unit vector along which the light travels.
    pub direction: Vec3,
    pub irradiance: Vec3,
    /// Half-angle of the light's disc as seen from the scene, in degrees, in [0, 90): 0 is a
    /// delta light (hard shadows), more is a sun disc of uniform radiance (soft shadows).
    pub angular_radius_deg: f32,
}

impl DirectionalLight {
    /// Unit vector from a surface toward the light: the L of N.L.
    pub fn to_light(&self) -> Vec3 {
        -self.direction
    }

    /// Whether the light has no size (angular radius 0).
    pub fn is_delta(&self) -> bool {
        self.angular_radius_deg == 0.0
    }
}

/// A constant environment: every ray that leaves the scene sees `radiance`, and that light
/// illuminates the scene like a uniform sky.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Environment {
    pub radiance: Vec3,
}
