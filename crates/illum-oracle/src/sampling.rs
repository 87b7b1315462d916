//! Direction sampling on the hemisphere around a unit normal n, in a local frame where n is +z.
//!
//! - Uniform: pdf 1 / (2 pi) per steradian. With z = cos(theta) uniform on [0, 1) the solid
//!   angle measure sin(theta) dtheta dphi = dz dphi is uniform, so z = u1, phi = 2 pi u2.
//! - Cosine: pdf cos(theta) / pi. Project a uniform point of the unit disk up onto the
//!   hemisphere (Malley's method): the disk's area element r dr dphi equals
//!   cos(theta) domega, so with r = sqrt(u1), phi = 2 pi u2 the direction is
//!   (r cos phi, r sin phi, sqrt(1 - r^2)).

use std::f64::consts::TAU;

use glam::DVec3;

/// Two unit vectors completing the unit vector n to an orthonormal, right-handed frame
/// (t, b, n). The helper axis is the world axis least aligned with n, so the cross product is
/// never close to zero.
pub fn tangent_frame(n: DVec3) -> (DVec3, DVec3) {
    let a = n.abs();
    let helper = if a.x <= a.y && a.x <= a.z {
        DVec3::X
    } else if a.y <= a.z {
        DVec3::Y
    } else {
        DVec3::Z
    };
    let t = helper.cross(n).normalize();
    let b = n.cross(t);
    (t, b)
}

/// Local direction to world: x along t, y along b, z along n.
pub fn local_to_world(n: DVec3, local: DVec3) -> DVec3 {
    let (t, b) = tangent_frame(n);
    local.x * t + local.y * b + local.z * n
}

/// Local direction with pdf 1 / (2 pi).
pub fn uniform_hemisphere(u1: f64, u2: f64) -> DVec3 {
    let z = u1;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = (TAU * u2).sin_cos();
    DVec3::new(r * c, r * s, z)
}

/// Local direction with pdf z / pi.
pub fn cosine_hemisphere(u1: f64, u2: f64) -> DVec3 {
    let r = u1.sqrt();
    let (s, c) = (TAU * u2).sin_cos();
    DVec3::new(r * c, r * s, (1.0 - u1).max(0.0).sqrt())
}

/// A direction uniform in the cone of half-angle acos(cos_max) around +z, in the local frame:
/// cos(theta) = 1 - u1 (1 - cos_max) (the solid angle is linear in cos theta), phi = 2 pi u2;
/// pdf 1 / (2 pi (1 - cos_max)).
pub fn uniform_cone(u1: f64, u2: f64, cos_max: f64) -> DVec3 {
    let cos = 1.0 - u1 * (1.0 - cos_max);
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let phi = 2.0 * std::f64::consts::PI * u2;
    DVec3::new(sin * phi.cos(), sin * phi.sin(), cos)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    #[test]
    fn frames_are_orthonormal_and_right_handed() {
        let mut rng = Rng::from_state(5);
        let mut normals = vec![DVec3::X, DVec3::NEG_Y, DVec3::Z, DVec3::new(1.0, 1.0, 1.0).normalize()];
        for _ in 0..100 {
            let v = DVec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5);
            normals.push(v.normalize());
        }
        for n in normals {
            let (t, b) = tangent_frame(n);
            for (x, y) in [(t, b), (t, n), (b, n)] {
                assert!(x.dot(y).abs() < 1e-12);
            }
            assert!((t.length() - 1.0).abs() < 1e-12 && (b.length() - 1.0).abs() < 1e-12);
            assert!((t.cross(b) - n).length() < 1e-12);
        }
    }

    /// Checks E[z^k] of the sampled directions against the pdf's moments, per k, to within 5
    /// standard errors, and that every direction is a unit vector in the upper hemisphere.
    fn check_moments(sample: fn(f64, f64) -> DVec3, moment: fn(i32) -> f64) {
        let mut rng = Rng::from_state(99);
        let n = 100_000;
        let mut sums = [0.0; 3];
        let mut sum_x = 0.0;
        for _ in 0..n {
            let d = sample(rng.uniform(), rng.uniform());
            assert!((d.length() - 1.0).abs() < 1e-12 && d.z >= 0.0, "{d:?}");
            for (k, s) in sums.iter_mut().enumerate() {
                *s += d.z.powi(k as i32 + 1);
            }
            sum_x += d.x;
        }
        for (k, s) in sums.iter().enumerate() {
            let k = k as i32 + 1;
            let mean = s / n as f64;
            let sd = ((moment(2 * k) - moment(k).powi(2)) / n as f64).sqrt();
            assert!((mean - moment(k)).abs() < 5.0 * sd, "E[z^{k}] = {mean}, expected {}", moment(k));
        }
        assert!((sum_x / n as f64).abs() < 5.0 * (0.5 / n as f64).sqrt(), "x is not symmetric");
    }

    #[test]
    fn uniform_hemisphere_moments() {
        // pdf 1/(2 pi): E[cos^k] = int_0^1 z^k dz = 1 / (k + 1).
        check_moments(uniform_hemisphere, |k| 1.0 / f64::from(k + 1));
    }

    #[test]
    fn cosine_hemisphere_moments() {
        // pdf cos/pi: E[cos^k] = 2 int_0^1 z^(k+1) dz = 2 / (k + 2).
        check_moments(cosine_hemisphere, |k| 2.0 / f64::from(k + 2));
    }
}
