//! The optical rules the oracle's estimators share, in f64: mirror reflection, Snell's
//! refraction, the exact unpolarised Fresnel reflectance, the stochastic step through a smooth
//! dielectric that the path integrator and the caustic's light tracer both take, and the
//! checkerboard's albedo. Whitted's deterministic tracer uses the same rules, weighting by F
//! instead of choosing by it.

use glam::DVec3;

use crate::geometry::{Parallelogram, dvec};

/// The checker's albedo at p on `quad`: tile (i, j) counted from the corner along the edges.
pub(crate) fn checker_albedo(quad: &Parallelogram, checker: illum_scene::Checker, p: DVec3) -> DVec3 {
    let q = p - quad.corner;
    // Coordinates along the edges, in units of each edge's length, then in tiles.
    let (lu, lv) = (quad.u.length(), quad.v.length());
    let (s, r) = (q.dot(quad.u) / (lu * lu), q.dot(quad.v) / (lv * lv));
    let tile = f64::from(checker.tile);
    let (i, j) = ((s * lu / tile).floor() as i64, (r * lv / tile).floor() as i64);
    if (i + j).rem_euclid(2) == 0 { dvec(checker.even) } else { dvec(checker.odd) }
}

/// The mirror direction of `d` at unit normal `n`.
pub(crate) fn reflect(d: DVec3, n: DVec3) -> DVec3 {
    d - 2.0 * d.dot(n) * n
}

/// Snell's law: the refracted unit direction of unit `d` at unit normal `n` (against the ray)
/// with eta = n_from / n_to, or `None` under total internal reflection.
pub(crate) fn refract(d: DVec3, n: DVec3, eta: f64) -> Option<DVec3> {
    let cos_i = -d.dot(n);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t > 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((eta * d + (eta * cos_i - cos_t) * n).normalize())
}

/// The normal a mirror reflects unit `d` about at a surface of geometric normal `n` and shading
/// normal `shading` (a smooth mesh's; both facing d): the shading normal, unless d arrives from
/// behind it or the reflection about it would go into the surface; then the geometric one. No
/// reflection leaves a mirror on the side it arrived from.
pub(crate) fn mirror_normal(d: DVec3, n: DVec3, shading: DVec3) -> DVec3 {
    if d.dot(shading) < 0.0 && reflect(d, shading).dot(n) > 0.0 { shading } else { n }
}

/// The normal a dielectric's reflection and refraction of unit `d` use (eta = n_from / n_to;
/// `n` and `shading` as for [`mirror_normal`]): the shading normal, unless d arrives from
/// behind it, its reflection goes into the surface or its refraction stays out; then the
/// geometric one.
pub(crate) fn dielectric_normal(d: DVec3, n: DVec3, shading: DVec3, eta: f64) -> DVec3 {
    let arrives = d.dot(shading) < 0.0;
    let reflects_out = reflect(d, shading).dot(n) > 0.0;
    let refracts_in = refract(d, shading, eta).is_none_or(|t| t.dot(n) < 0.0);
    if arrives && reflects_out && refracts_in { shading } else { n }
}

/// One stochastic step through a smooth dielectric at point `p`, for the path tracer and the
/// caustic's light tracer alike: `n` faces the incoming unit ray `d`, `front` says whether the
/// ray arrives from outside (eta = 1 / ior) or inside (eta = ior). Reflect about `optic` (n, or
/// the normal [`dielectric_normal`] chooses on a smooth mesh) with probability F (the exact
/// Fresnel reflectance; 1 under total internal reflection), else refract through it, so the
/// weight is F / F = (1 - F) / (1 - F) = 1. The new origin is `lift` off the surface along n
/// on the side the ray leaves to. Returns (origin, direction).
#[allow(clippy::too_many_arguments)]
pub(crate) fn scatter_dielectric(
    d: DVec3,
    n: DVec3,
    optic: DVec3,
    p: DVec3,
    front: bool,
    ior: f32,
    lift: f64,
    rng: &mut crate::rng::Rng,
) -> (DVec3, DVec3) {
    let eta = if front { 1.0 / f64::from(ior) } else { f64::from(ior) };
    let cos_i = -d.dot(optic);
    match refract(d, optic, eta).filter(|t| rng.uniform() >= fresnel(cos_i, -t.dot(optic), eta)) {
        Some(t) => (p - n * lift, t),
        None => (p + n * lift, reflect(d, optic)),
    }
}

/// The exact unpolarised Fresnel reflectance of a dielectric interface: the mean of the s- and
/// p-polarised reflectances, for cosines of incidence `cos_i` and transmission `cos_t` and
/// eta = n_from / n_to.
pub fn fresnel(cos_i: f64, cos_t: f64, eta: f64) -> f64 {
    // With n_from = eta and n_to = 1 (only the ratio matters):
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (rs * rs + rp * rp)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresnel_at_normal_incidence_and_its_symmetry() {
        // ((n - 1) / (n + 1))^2 at normal incidence, from either side.
        for n in [1.0001f64, 1.4285715, 1.5, 4.0] {
            let f0 = ((n - 1.0) / (n + 1.0)).powi(2);
            assert!((fresnel(1.0, 1.0, 1.0 / n) - f0).abs() < 1e-15, "n = {n}");
            assert!((fresnel(1.0, 1.0, n) - f0).abs() < 1e-15, "n = {n}");
        }
        // Index 1: nothing is reflected at any angle.
        for c in [0.01f64, 0.3, 0.9] {
            assert!(fresnel(c, c, 1.0).abs() < 1e-15);
        }
        // Grazing incidence from outside reflects everything.
        let eta = 1.0 / 1.5;
        let cos_t = (1.0f64 - eta * eta).sqrt();
        assert!((fresnel(0.0, cos_t, eta) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn refraction_obeys_snell_and_reports_total_internal_reflection() {
        let n = DVec3::Z;
        let d = DVec3::new(0.6, 0.0, -0.8);
        let eta = 1.0 / 1.5;
        let t = refract(d, n, eta).unwrap();
        // sin_t = eta sin_i.
        assert!((t.x - eta * 0.6).abs() < 1e-15 && (t.length() - 1.0).abs() < 1e-15);
        // From inside glass at 45 degrees (beyond the critical angle 41.8 degrees): none.
        let inside = DVec3::new(0.5f64.sqrt(), 0.0, -(0.5f64.sqrt()));
        assert!(refract(inside, n, 1.5).is_none());
    }
}
