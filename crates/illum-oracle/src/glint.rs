//! The sun's glint in a lone specular sphere, solved in one dimension: the reference the path
//! tracer's host solve (`illum-pathtrace/src/glint.rs`, a 2-D Newton method over the whole
//! scene) is checked against. Nothing is shared with it but the scene file.
//!
//! A sphere and the eye are symmetric about the line through the eye and the centre (the axis
//! a). A camera ray at angle alpha from a, in the plane of a and the sun's direction w, stays
//! in that plane through every reflection and refraction: its chain leaves at a signed angle
//! beta(alpha) from a in the same plane, so the chain sees the sun where beta(alpha) equals w's
//! angle, a 1-D root. Rotating the ray about a rotates the leaving direction with it, so the
//! solid angles of the camera's and the leaving directions are sin|alpha| dalpha dphi and
//! sin|beta| |dbeta| dphi: the chain spreads the sun's irradiance E over
//! |sin beta beta'(alpha) / sin alpha| of camera solid angle, and the irradiance it brings to
//! the eye from that point is E T / |sin beta beta' / sin alpha| (T the chain's throughput:
//! reflectances, Fresnel F and 1 - F). Chains of one sphere: R (k = 1) and T R^(k-2) T.

use glam::{DVec2, DVec3};
use illum_scene::{MaterialKind, Scene, Shape};

use crate::optics::fresnel;

/// One glint: its chain (`R`, `TT`, `TRT`, ...), the camera ray's direction toward it and the
/// irradiance it brings to the eye (per channel).
#[derive(Clone, Debug, PartialEq)]
pub struct OracleGlint {
    pub chain: String,
    pub direction: DVec3,
    pub eye_irradiance: [f64; 3],
}

/// Every glint of chains of at most `max_scatterings` in `scene`'s only object, a mirror or
/// glass sphere, under its directional light, seen from its camera's eye (outside the sphere;
/// the sun not along the axis). Panics for any other scene: this is a test's reference.
pub fn single_sphere_glints(scene: &Scene, max_scatterings: usize) -> Vec<OracleGlint> {
    assert_eq!(scene.objects.len(), 1, "one sphere only");
    let Shape::Sphere(sphere) = scene.objects[0].shape else { panic!("a sphere") };
    let kind = scene.material_of(&scene.objects[0]).kind;
    let light = scene.directional_light.expect("a directional light");
    let eye = scene.camera.eye.as_dvec3();
    let to_center = sphere.center.as_dvec3() - eye;
    let distance = to_center.length();
    let radius = f64::from(sphere.radius);
    let a = to_center / distance;
    let w = (-light.direction.as_dvec3()).normalize();
    let b = (w - w.dot(a) * a).normalize();
    let target = w.dot(b).atan2(w.dot(a));
    let irradiance = light.irradiance.as_dvec3().to_array();
    let ball = Ball { center: DVec2::new(distance, 0.0), radius, kind };
    let max_alpha = (radius / distance).asin();

    let mut chains = vec!["R".to_owned()];
    if matches!(kind, MaterialKind::Dielectric { .. }) {
        for k in 2..=max_scatterings {
            chains.push(format!("T{}T", "R".repeat(k - 2)));
        }
    }
    chains.truncate(max_scatterings);
    let mut out = Vec::new();
    const GRID: usize = 200_000;
    for chain in &chains {
        let miss = |alpha: f64| -> Option<f64> {
            let (beta, _) = ball.chain(alpha, chain)?;
            Some(wrap(beta - target))
        };
        let alpha_at = |i: usize| max_alpha * (2.0 * i as f64 / GRID as f64 - 1.0);
        let mut previous: Option<(f64, f64)> = None;
        for i in 1..GRID {
            let alpha = alpha_at(i);
            let here = miss(alpha);
            if let (Some((lo, f_lo)), Some(f_hi)) = (previous, here)
                && f_lo * f_hi <= 0.0
                && (f_lo - f_hi).abs() < 1.0
            {
                let root = bisect(&miss, lo, alpha, f_lo);
                let (beta, throughput) = ball.chain(root, chain).expect("inside the disc");
                // beta'(alpha): central differences of h and h / 2, Richardson-extrapolated.
                let h = 1e-5 * max_alpha;
                let slope = |h: f64| {
                    let plus = ball.chain(root + h, chain).map(|c| c.0)?;
                    let minus = ball.chain(root - h, chain).map(|c| c.0)?;
                    Some(wrap(plus - minus) / (2.0 * h))
                };
                if let (Some(d1), Some(d2)) = (slope(h), slope(0.5 * h)) {
                    let derivative = (4.0 * d2 - d1) / 3.0;
                    // sin(alpha) -> 0 on the axis: the ratio's limit is beta'(0)^2 there.
                    let spread = if root.abs() < 1e-12 {
                        derivative * derivative
                    } else {
                        (beta.sin() * derivative / root.sin()).abs()
                    };
                    out.push(OracleGlint {
                        chain: chain.clone(),
                        direction: root.cos() * a + root.sin() * b,
                        eye_irradiance: [0, 1, 2].map(|c| irradiance[c] * throughput[c] / spread),
                    });
                }
            }
            previous = here.map(|f| (alpha, f));
        }
    }
    out
}

fn wrap(angle: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    angle - tau * (angle / tau).round()
}

/// Bisection of a sign change of `f` in [lo, hi] (f(lo) = f_lo) down to adjacent floats.
fn bisect(f: &impl Fn(f64) -> Option<f64>, mut lo: f64, mut hi: f64, mut f_lo: f64) -> f64 {
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        let Some(f_mid) = f(mid) else { break };
        if f_mid == 0.0 {
            return mid;
        }
        if (f_mid < 0.0) == (f_lo < 0.0) {
            lo = mid;
            f_lo = f_mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The sphere in the plane of the axis (x) and the sun (y), the eye at the origin.
struct Ball {
    center: DVec2,
    radius: f64,
    kind: MaterialKind,
}

impl Ball {
    /// The leaving angle (from the axis, signed toward the sun's side) and the throughput of
    /// `chain` for the camera ray at angle `alpha`; None where the ray misses the circle.
    fn chain(&self, alpha: f64, chain: &str) -> Option<(f64, [f64; 3])> {
        let mut p = DVec2::ZERO;
        let mut d = DVec2::new(alpha.cos(), alpha.sin());
        let mut throughput = [1.0; 3];
        let mut inside = false;
        for event in chain.chars() {
            let t = self.exit_or_entry(p, d, inside)?;
            p += t * d;
            let outward = (p - self.center) / self.radius;
            // The normal facing the incoming ray.
            let n = if inside { -outward } else { outward };
            let cos_i = -d.dot(n);
            let reflected = d + 2.0 * cos_i * n;
            match (self.kind, event) {
                (MaterialKind::Mirror { reflectance }, 'R') => {
                    throughput = [0, 1, 2].map(|c| throughput[c] * f64::from(reflectance[c]));
                    d = reflected;
                }
                (MaterialKind::Dielectric { ior }, _) => {
                    let ior = f64::from(ior);
                    let eta = if inside { ior } else { 1.0 / ior };
                    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
                    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
                    let f = if sin2_t >= 1.0 { 1.0 } else { fresnel(cos_i, cos_t, eta) };
                    if event == 'R' {
                        throughput = throughput.map(|v| v * f);
                        d = reflected;
                    } else {
                        if sin2_t >= 1.0 {
                            return None;
                        }
                        throughput = throughput.map(|v| v * (1.0 - f));
                        d = eta * d + (eta * cos_i - cos_t) * n;
                        inside = !inside;
                    }
                }
                _ => return None,
            }
            d = d.normalize();
        }
        if inside {
            return None;
        }
        Some((d.y.atan2(d.x), throughput))
    }

    /// Distance along d from p to the circle: the entry from outside (None: a miss), or the
    /// far crossing from a point on the circle inside.
    fn exit_or_entry(&self, p: DVec2, d: DVec2, inside: bool) -> Option<f64> {
        let oc = p - self.center;
        let b = oc.dot(d);
        if inside {
            // p is on the circle: the other root of t^2 + 2 b t = 0.
            return Some(-2.0 * b);
        }
        let perp = oc - b * d;
        let disc = self.radius * self.radius - perp.length_squared();
        if disc < 0.0 || b > 0.0 {
            return None;
        }
        Some(-b - disc.sqrt())
    }
}
