//! The specular chains of manifold next-event estimation through one sphere, in closed form in
//! the sphere's meridional plane (derivation also in docs/caustics-manifold.md).
//!
//! Coordinates: the unit circle about the origin (lengths in units of the radius R); r across
//! the axis, z along w_s, the direction the sun's light travels. A sun ray at signed angle of
//! incidence theta1 in (-pi/2, pi/2) travels along (0, 1) and meets the circle at
//! p1 = (sin theta1, -cos theta1). The outward normal there is p1 itself, so theta1 is the angle
//! of incidence and b = sin theta1 the signed impact parameter.
//!
//! Write P(a) = (sin a, -cos a) for a point of the circle (its outward normal is P(a) too) and
//! D(f) = (sin f, cos f) for a direction (the sun's is D(0); P(a) = D(pi - a)). Then:
//! - refraction into the ball at P(theta1): the inward normal is D(-theta1) and the ray D(0)
//!   makes theta1 with it; Snell keeps the side, so the refracted ray is D(theta_t - theta1),
//!   sin theta_t = sin theta1 / n (same sign as theta1);
//! - a chord leaving P(a) at angle theta_t to the inward normal forms an isosceles triangle
//!   with the centre: it ends at P(a + pi - 2 theta_t), and the chord from P(a) to P(c) runs
//!   along D(pi/2 - (a + c)/2) (P(c) - P(a) = 2 sin((c - a)/2) (cos m, sin m), m = (a + c)/2);
//! - an internal reflection keeps the angle theta_t, so the next chord advances the point by
//!   the same central angle pi - 2 theta_t; on a sphere every internal angle is theta_t, hence
//!   the exact Fresnel reflectance F(theta1) is the same at every event of a chain (and no
//!   total internal reflection happens inside for n > 1);
//! - leaving at P(a_e), the inside ray makes theta_t with the outward normal D(pi - a_e) and the
//!   exit ray makes theta1 with it on the same side.
//!
//! With k chords (k = 0: the outer reflection R; 1: TT; 2: TRT; k: T R^(k-1) T) this gives
//!     a_e = theta1 + k (pi - 2 theta_t),   f_e = pi - 2 theta1 - k (pi - 2 theta_t) = pi - theta1 - a_e,
//! the exit point q = P(a_e) and direction u = D(f_e) (k = 0: the mirror direction D(pi - 2 theta1)
//! at P(theta1)). The direction turns by theta_t - theta1 at each refraction and by
//! -(pi - 2 theta_t) at each internal reflection. Since cross2(u, q) = -sin(f_e + a_e) = -sin theta1,
//! the exit line passes the centre at distance |b| (the ball conserves the impact parameter).
//!
//! The miss function of a point x' = (r, z), the signed distance from x' to the exit line, is
//!     g(theta1) = cross2(u, x' - q) = z sin f_e - r cos f_e + sin theta1,
//!     dg/dtheta1 = f_e' (z cos f_e + r sin f_e) + cos theta1,
//!     f_e' = -2 + 2 k theta_t',   theta_t' = cos theta1 / (n cos theta_t),
//! and dg/db = (dg/dtheta1) / cos theta1 (db = cos theta1 dtheta1 on the unit circle).

use glam::DVec2;

use crate::optics::fresnel;

/// A chain of specular events on one sphere, named by its number of chords through the inside:
/// 0 is the outer reflection R (a mirror's only chain), 1 is TT, 2 is TRT, k is T R^(k-1) T.
/// It has k + 1 specular events.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Chain {
    pub chords: u32,
}

/// A chain's exit at one theta1 (unit sphere): point, direction and the quantities the weight
/// and the derivative need.
#[derive(Clone, Copy, Debug)]
pub struct Exit {
    /// Exit point q on the unit circle.
    pub q: DVec2,
    /// Unit exit direction u.
    pub u: DVec2,
    /// df_e / dtheta1.
    pub turn_rate: f64,
    /// The angle of refraction theta_t (0 for the outer reflection).
    pub theta_t: f64,
}

impl Chain {
    pub const R: Chain = Chain { chords: 0 };
    pub const TT: Chain = Chain { chords: 1 };
    pub const TRT: Chain = Chain { chords: 2 };

    /// The number of specular events (for the path-length rule).
    pub fn events(self) -> u32 {
        self.chords + 1
    }

    /// The exit point and direction at incidence `theta1` on a unit sphere of index `n` (not
    /// used by the outer reflection), or `None` when the sun's ray cannot enter (an index
    /// below 1 beyond its critical angle).
    pub fn exit(self, n: f64, theta1: f64) -> Option<Exit> {
        let (theta_t, rate) = if self.chords == 0 {
            (0.0, 0.0)
        } else {
            let s = theta1.sin() / n;
            if s.is_nan() || s.abs() > 1.0 {
                return None;
            }
            let theta_t = s.asin();
            (theta_t, theta1.cos() / (n * theta_t.cos()))
        };
        let k = f64::from(self.chords);
        let a = theta1 + k * (std::f64::consts::PI - 2.0 * theta_t);
        let f = std::f64::consts::PI - theta1 - a;
        Some(Exit {
            q: DVec2::new(a.sin(), -a.cos()),
            u: DVec2::new(f.sin(), f.cos()),
            turn_rate: -2.0 + 2.0 * k * rate,
            theta_t,
        })
    }

    /// g(theta1) and dg/dtheta1 for the point `x` = (r, z) of the unit sphere's plane (module
    /// documentation), or `None` where the chain does not exist.
    pub fn miss(self, n: f64, theta1: f64, x: DVec2) -> Option<(f64, f64)> {
        let e = self.exit(n, theta1)?;
        let (sf, cf) = (e.u.x, e.u.y);
        let g = x.y * sf - x.x * cf + theta1.sin();
        let dg = e.turn_rate * (x.y * cf + x.x * sf) + theta1.cos();
        Some((g, dg))
    }

    /// The fraction of power the chain carries on a dielectric of index `n` at incidence
    /// theta1: F for R, (1 - F)^2 F^(k - 1) for k >= 1 chords, F the exact Fresnel reflectance
    /// at theta1 (the same at every event).
    pub fn dielectric_weight(self, n: f64, theta1: f64) -> f64 {
        let s = theta1.sin() / n;
        if s.is_nan() || s.abs() >= 1.0 {
            // No refraction into the ball: everything is reflected.
            return if self.chords == 0 { 1.0 } else { 0.0 };
        }
        let cos_t = (1.0 - s * s).sqrt();
        let f = fresnel(theta1.cos(), cos_t, 1.0 / n);
        match self.chords {
            0 => f,
            k => (1.0 - f) * (1.0 - f) * f.powi(k as i32 - 1),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cross2(a: DVec2, b: DVec2) -> f64 {
        a.x * b.y - a.y * b.x
    }

    fn reflect2(d: DVec2, n: DVec2) -> DVec2 {
        d - 2.0 * d.dot(n) * n
    }

    /// Snell in 2-D with `n` the normal against `d` and eta = n_from / n_to.
    fn refract2(d: DVec2, n: DVec2, eta: f64) -> DVec2 {
        let cos_i = -d.dot(n);
        let cos_t = (1.0 - eta * eta * (1.0 - cos_i * cos_i)).sqrt();
        eta * d + (eta * cos_i - cos_t) * n
    }

    /// The far root of |o + t d| = 1 for a ray from a point on or inside the unit circle.
    fn next_on_circle(o: DVec2, d: DVec2) -> DVec2 {
        let (b, c) = (o.dot(d), o.length_squared() - 1.0);
        o + (-b + (b * b - c).sqrt()) * d
    }

    /// The chain traced event by event from (sin theta1, -10) along (0, 1).
    fn brute_force(chain: Chain, n: f64, theta1: f64) -> (DVec2, DVec2) {
        let (o, d) = (DVec2::new(theta1.sin(), -10.0), DVec2::Y);
        // Entry: the near root.
        let (b, c) = (o.dot(d), o.length_squared() - 1.0);
        let p = o + (-b - (b * b - c).sqrt()) * d;
        if chain.chords == 0 {
            return (p, reflect2(d, p));
        }
        let mut d = refract2(d, p, 1.0 / n).normalize();
        let mut p = p;
        for chord in 0..chain.chords {
            p = next_on_circle(p, d);
            if chord + 1 < chain.chords {
                d = reflect2(d, -p);
            }
        }
        (p, refract2(d, -p, n).normalize())
    }

    /// Guards the closed form of the exit point and direction (and so every sign of the
    /// derivation) against a step-by-step 2-D trace, for R, TT, TRT and TRRT, several indices
    /// and incidences of both signs.
    #[test]
    fn the_closed_form_matches_a_brute_force_trace() {
        for chain in [Chain::R, Chain::TT, Chain::TRT, Chain { chords: 3 }] {
            for n in [1.0, 1.33, 1.4285715, 1.5, 2.4] {
                for i in 1..200 {
                    let theta1 = -1.5 + 3.0 * f64::from(i) / 200.0;
                    let (q, u) = brute_force(chain, n, theta1);
                    let e = chain.exit(n, theta1).unwrap();
                    assert!(
                        (e.q - q).length() < 1e-9,
                        "{chain:?} n {n} theta1 {theta1}: q {:?} vs {q:?}",
                        e.q
                    );
                    assert!(
                        (e.u - u).length() < 1e-9,
                        "{chain:?} n {n} theta1 {theta1}: u {:?} vs {u:?}",
                        e.u
                    );
                    // The exit line keeps the impact parameter.
                    assert!((cross2(e.u, e.q) + theta1.sin()).abs() < 1e-12);
                }
            }
        }
    }

    /// Guards the analytic dg/dtheta1 (the concentration's denominator) against central
    /// differences of g, at points inside, near and far from the sphere.
    #[test]
    fn the_derivative_of_g_matches_central_differences() {
        let points =
            [DVec2::new(0.3, 2.5), DVec2::new(1.7, -0.4), DVec2::new(0.05, 9.0), DVec2::new(4.0, -3.0)];
        for chain in [Chain::R, Chain::TT, Chain::TRT, Chain { chords: 3 }] {
            for n in [1.33, 1.5, 2.4] {
                for x in points {
                    for i in 1..100 {
                        let theta1 = -1.5 + 3.0 * f64::from(i) / 100.0;
                        let h = 1e-6;
                        let (gp, _) = chain.miss(n, theta1 + h, x).unwrap();
                        let (gm, _) = chain.miss(n, theta1 - h, x).unwrap();
                        let (_, dg) = chain.miss(n, theta1, x).unwrap();
                        let fd = (gp - gm) / (2.0 * h);
                        assert!(
                            (fd - dg).abs() < 1e-6 * (1.0 + dg.abs()),
                            "{chain:?} {n} {x:?} {theta1}: {dg} vs {fd}"
                        );
                    }
                }
            }
        }
    }

    /// Guards the weights: power is conserved over all chains (R + sum over k >= 1 of
    /// (1 - F)^2 F^(k - 1) = F + (1 - F) = 1), and an index of 1 transmits everything.
    #[test]
    fn the_chain_weights_sum_to_one() {
        for n in [1.2, 1.5, 2.4] {
            for theta1 in [-1.4, -0.3, 0.0, 0.7, 1.5] {
                let total: f64 = (0..200).map(|k| Chain { chords: k }.dielectric_weight(n, theta1)).sum();
                assert!((total - 1.0).abs() < 1e-12, "n {n} theta1 {theta1}: {total}");
            }
        }
        assert!((Chain::TT.dielectric_weight(1.0, 0.8) - 1.0).abs() < 1e-15);
    }
}
