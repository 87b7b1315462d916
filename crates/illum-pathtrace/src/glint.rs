//! The sun's glint, E S* L with a delta sun, solved on the host in f64 (docs/glint.md).
//!
//! A delta sun sends radiance only along one direction w (toward the sun). A specular chain
//! from the eye (mirror reflections, glass reflections and refractions) maps the film point s to
//! the direction d(s) the chain's last ray leaves in; the chain sees the sun where d(s) = w, and
//! nowhere else: a point mass on the film, which no camera ray (the sun has no size) and no
//! particle (the pinhole cannot be hit) finds. Its weight follows from the pixel's definition,
//! the mean radiance over the pixel (box filter, rays jittered uniformly inside it, film
//! coordinates in pixels so that the pixel's area is 1):
//!
//! ```text
//! I = int_pixel E T delta(d(s) - w) ds = E T / |det(dg / ds)|   at the root s*,
//! ```
//!
//! with E the sun's irradiance, T the chain's throughput (mirror reflectances, Fresnel F for a
//! glass reflection and 1 - F for a refraction, no eta^2: the chain starts and ends outside the
//! glass, as the path tracer's camera paths) and g the gnomonic coordinates of d about w (at the
//! root their area element is the solid angle's). The pixel containing s* gains I, once, as the
//! image's exact part ([`crate::Accumulator::set_exact`], joined to the means by
//! [`crate::ImageParts`]): no noise, the error estimate unchanged.
//!
//! The solve: the camera rays through dense seeds (over each specular sphere's disc on the film,
//! finer toward its rim, and a grid over the film when a flat face is specular) are followed
//! through every branch of the specular tree, up to the render's bounce limit (a chain of k
//! scatterings takes k continuation rays, counted when k <= bounces); the leaves that escape the
//! scene name the chains. For each chain, Newton's method on the film coordinate, from the seeds
//! whose leaving direction is nearest w, finds the roots, with the Jacobian by forward
//! derivatives carried along the chain with the ray (each hit point moving on its surface, the
//! normal turning by its curvature, reflection and refraction differentiated). The empty chain
//! is the sun seen directly.

mod bodies;
mod film;
mod solver;
mod tree;

use illum_scene::Scene;

use solver::Solver;

/// What a chain does at one of its vertices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Event {
    Reflect,
    Refract,
}

/// One scattering of a chain: the object (index into `Scene::objects`) and what it does.
pub type Step = (usize, Event);

/// One solved glint: where it lands on the film and what it adds to that pixel's mean.
#[derive(Clone, Debug, PartialEq)]
pub struct GlintPoint {
    /// Film point in pixels from the top-left corner, y down (pixel (i, j) covers
    /// [i, i+1] x [j, j+1]).
    pub film: [f64; 2],
    /// Index `y * width + x` of the pixel it lands in.
    pub pixel: usize,
    /// Radiance it adds to that pixel's mean: E T / |det(dg / ds)|.
    pub value: [f64; 3],
    /// The chain's throughput T.
    pub throughput: [f64; 3],
    /// |det(dg / ds)|: solid angle of leaving directions per pixel of film.
    pub jacobian: f64,
    /// The camera ray's unit direction toward the glint.
    pub direction: [f64; 3],
    /// The irradiance the glint brings to the eye, E T / |dOmega_out / dOmega_camera|: its
    /// value times the camera solid angle of the pixel at that point (A_p cos^3 of the angle
    /// to the view axis), a figure that does not depend on the film.
    pub eye_irradiance: [f64; 3],
    /// The chain from the eye: each scattering's object and event.
    pub chain: Vec<Step>,
}

/// Scatterings a chain may have when the bounces are unbounded (the path tracer's Russian
/// roulette has no limit; chains beyond this carry less than [`MIN_THROUGHPUT`] in the scenes
/// measured, docs/glint.md).
pub const UNBOUNDED_SCATTERINGS: usize = 32;

/// Branches whose throughput falls below this (in every channel) are not followed: their glint
/// would be under 1e-12 of the sun's seen in a perfect mirror of the same curvature.
pub const MIN_THROUGHPUT: f64 = 1e-12;

/// Whether the path tracer adds the glint to `scene`'s image: the caustic's estimators are on
/// (`[pathtrace] caustics = true`, a directional light and a specular object) and the sun is a
/// delta light (a sun disc is found by the camera paths themselves).
pub fn glint_active(scene: &Scene) -> bool {
    crate::estimators::Estimators::of(scene).glint()
}

/// The glints of `scene` (empty when [`glint_active`] is false), sorted by pixel.
pub fn solve(scene: &Scene) -> Vec<GlintPoint> {
    solve_unless(scene, &|| false)
}

/// As [`solve`], but skips what is left once `stop` returns true (checked between shares of
/// the work): the result is then incomplete, for a caller that will not read it.
pub fn solve_unless(scene: &Scene, stop: &(dyn Fn() -> bool + Sync)) -> Vec<GlintPoint> {
    if !glint_active(scene) {
        return Vec::new();
    }
    Solver::new(scene).solve(stop)
}

/// The glints summed per pixel: (pixel, radiance), sorted by pixel.
pub fn pixel_values(points: &[GlintPoint]) -> Vec<(usize, [f64; 3])> {
    let mut out: Vec<(usize, [f64; 3])> = Vec::new();
    let mut sorted: Vec<&GlintPoint> = points.iter().collect();
    sorted.sort_by_key(|p| p.pixel);
    for p in sorted {
        match out.last_mut() {
            Some((pixel, v)) if *pixel == p.pixel => (0..3).for_each(|c| v[c] += p.value[c]),
            _ => out.push((p.pixel, p.value)),
        }
    }
    out
}
