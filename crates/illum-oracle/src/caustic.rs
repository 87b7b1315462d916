//! The caustic estimator in f64: light tracing from the directional light for the paths
//! L S+ D E, written independently of the GPU's (`crates/illum-pathtrace/shaders/caustic.wgsl`).
//!
//! Path spaces (docs/caustics.md). The camera path tracer (`integrator.rs`) finds every path
//! whose light-side end is an area light or the sky, every path L D ... E through next-event
//! estimation, and, with a sun *disc*, paths E D S+ L by a bounce that happens to reach the disc.
//! The light tracer here owns exactly the paths L S+ D E whose diffuse vertex D is the camera
//! ray's first hit: with it on, the camera path tracer stops counting the sun disc on such
//! paths (`caustic_owned` there), so no path is counted twice. With a delta sun the caustic
//! seen through a specular surface or scattered again by another diffuse surface
//! (E (S|D)* D S+ L but E D S+ L) is the photon gather's (`gather.rs`, from these particles).
//!
//! Emission. The sun's light crosses any plane perpendicular to a direction w of its disc with
//! radiance L (a delta sun: irradiance E along one direction). Only lines that meet a specular
//! object matter (a particle whose first hit is diffuse carries L D paths, which next-event
//! estimation counts already), and each such line crosses the disc of radius R_k about the
//! centre of some specular object's bounding sphere. A particle picks disc k with probability
//! A_k / A (A = sum of the disc areas A_k = pi R_k^2) and a point uniform on it, so the point's
//! density on the plane is c(x) / A, c(x) the number of discs covering x (overlapping discs
//! are counted with this one-sample balance weight), and its flux is
//!     delta sun: Phi = E A / c(x),   disc: Phi = L 2 pi (1 - cos_max) A / c(x)
//! (the disc's direction drawn uniformly in its cone, pdf 1 / (2 pi (1 - cos_max))); one frame
//! of N particles carries Phi / N each.
//!
//! Transport. At a mirror the flux is multiplied by the reflectance. At a dielectric the
//! particle reflects with probability F (exact Fresnel) and otherwise refracts, weight 1 either
//! way, and **no eta^2 factor**: a particle carries power, and the power an interface transmits
//! is (1 - F) times the incident power whatever the indices (Veach 1997, section 5.2: the BSDF
//! of refraction is not symmetric; radiance is scaled by (eta_t / eta_i)^2 when crossing, its
//! adjoint, importance or flux, is not).
//!
//! Connection. At the first diffuse point x (albedo rho, normal n on the particle's side) the
//! particle is connected to the pinhole at the eye e. The pixel value the camera path tracer
//! estimates is the mean radiance over the pixel's rectangle of area A_p on the image plane at
//! distance 1 (rays jittered uniformly in it): I = (1 / A_p) int L(w(s)) ds. A point s of that
//! plane seen at angle theta off the axis is 1 / cos(theta) away and tilted by theta, so
//! ds = dw / cos^3(theta), and dw = cos(theta_x) dA_x / r^2 for the surface point seen along w:
//!     I = int_A L(x -> e) W(x) dA_x,   W(x) = cos(theta_x) / (A_p cos^3(theta) r^2)
//! for x seen through the pixel (zero elsewhere, and where x cannot see the eye). This is the
//! pinhole's importance 1 / (A_p cos^4 theta) per unit solid angle and projected area, times the
//! geometry term cos(theta) cos(theta_x) / r^2. With L(x -> e) = rho / pi E(x) and the particles'
//! flux density estimating the irradiance E(x) dA_x, a particle of flux Phi adds
//!     Phi rho / pi W(x)
//! to the pixel it lands in.
//!
//! Path length: a path L S^k D E corresponds to the camera path E D S^k L, which takes k + 1
//! continuation rays (the bounce at D and the k specular scatterings), so it counts under
//! `Bounces::Fixed(n)` when k + 1 <= n; unbounded, Russian roulette from the fourth scattering
//! on, as in the camera path tracer.

use std::f64::consts::{FRAC_1_PI, PI};

use glam::DVec3;
use illum_scene::{Bounces, MaterialKind};

use crate::gather::Photon;
use crate::integrator::{Contact, Oracle, ROULETTE_AFTER, ROULETTE_MAX_SURVIVAL, UNBOUNDED_LIMIT};
use crate::optics::{reflect, scatter_dielectric};
use crate::particle_source::particle_rng;
use crate::rng::Rng;
use crate::sampling::{local_to_world, uniform_cone};

impl Oracle {
    /// Whether this oracle adds the caustic: `[pathtrace] caustics = true` on a scene with a
    /// directional light and at least one mirror or dielectric.
    pub fn caustics(&self) -> bool {
        self.caustic.is_some()
    }

    /// One particle of a frame of `n` particles, traced to its first diffuse point after at
    /// least one specular scattering (its photon, `gather.rs`), or `None` when it has none.
    pub(crate) fn trace_particle(&self, n: u64, rng: &mut Rng) -> Option<Photon> {
        let source = self.caustic.as_ref()?;
        let sun = self.scene.sun?;
        // The direction the light travels, and the flux per unit area across the plane
        // perpendicular to it.
        let (u1, u2) = (rng.uniform(), rng.uniform());
        let (to_light, flux_density) = if sun.is_delta() {
            (sun.to_light, sun.irradiance)
        } else {
            let w = local_to_world(sun.to_light, uniform_cone(u1, u2, sun.cos_max)).normalize();
            (w, sun.radiance() * (2.0 * PI * (1.0 - sun.cos_max)))
        };
        let d0 = -to_light;
        // A disc by area, a point uniform on it (radius R sqrt(u)).
        let pick = rng.uniform() * source.total_area;
        let mut k = 0;
        let mut acc = 0.0;
        for (i, (_, r)) in source.discs.iter().enumerate() {
            acc += PI * r * r;
            k = i;
            if pick < acc {
                break;
            }
        }
        let (centre, radius) = source.discs[k];
        let (s, phi) = (radius * rng.uniform().sqrt(), 2.0 * PI * rng.uniform());
        let x = centre + local_to_world(d0, DVec3::new(s * phi.cos(), s * phi.sin(), 0.0));
        // c(x): the discs whose sphere's projection covers the line through x.
        let covering = source
            .discs
            .iter()
            .filter(|(c, r)| {
                let m = x - *c;
                (m - d0 * m.dot(d0)).length_squared() <= r * r
            })
            .count()
            .max(1);
        let mut throughput = flux_density * (source.total_area / covering as f64 / n as f64);
        // Start outside the whole scene, on the light's side.
        let mut o = x + d0 * ((source.scene_centre - x).dot(d0) - source.scene_radius - 1.0);
        let mut d = d0;
        let mut scatterings = 0u32;
        loop {
            let hit = self.closest_hit(o, d)?;
            if hit.primitive.emitter {
                return None;
            }
            let Contact { point: p, front, normal: nrm, lift, .. } = hit.contact(o, d);
            match hit.primitive.material {
                MaterialKind::Mirror { reflectance } => {
                    if !self.may_scatter(scatterings, &mut throughput, reflectance.as_dvec3(), rng) {
                        return None;
                    }
                    d = reflect(d, nrm);
                    o = p + nrm * lift;
                }
                MaterialKind::Dielectric { ior } => {
                    if !self.may_scatter(scatterings, &mut throughput, DVec3::ONE, rng) {
                        return None;
                    }
                    // Flux, not radiance: no eta^2 (see the module documentation).
                    (o, d) = scatter_dielectric(d, nrm, nrm, p, front, ior, lift, rng);
                }
                MaterialKind::Lambertian { .. } | MaterialKind::Checker(_) => {
                    // A particle whose first hit is diffuse carries an L D path: not ours.
                    if scatterings == 0 {
                        return None;
                    }
                    return Some(Photon {
                        point: p,
                        normal: nrm,
                        lift,
                        weight: throughput * hit.diffuse_albedo(p) * FRAC_1_PI,
                        scatterings,
                    });
                }
                MaterialKind::Emitter { .. } => unreachable!("emitters are handled above"),
            }
            scatterings += 1;
            if !throughput.cmpgt(DVec3::ZERO).any() {
                return None;
            }
        }
    }

    /// Whether a particle that has scattered `scatterings` times may scatter once more: the
    /// camera path it mirrors needs `scatterings + 2` continuation rays (this one, the
    /// remaining specular ones counted as it goes, and the bounce at D). Multiplies the
    /// throughput by `weight`, and by 1 / q under Russian roulette.
    fn may_scatter(&self, scatterings: u32, throughput: &mut DVec3, weight: DVec3, rng: &mut Rng) -> bool {
        match self.bounces {
            Bounces::Fixed(n) => {
                if scatterings + 2 > n {
                    return false;
                }
            }
            Bounces::Unbounded => {
                if scatterings >= UNBOUNDED_LIMIT {
                    return false;
                }
                if scatterings >= ROULETTE_AFTER {
                    let q = (*throughput * weight).max_element().min(ROULETTE_MAX_SURVIVAL);
                    if !(q > 0.0 && rng.uniform() < q) {
                        return false;
                    }
                    *throughput /= q;
                }
            }
        }
        *throughput *= weight;
        true
    }

    /// The particle of outgoing radiance factor `weight` (flux x rho / pi) at x (normal n on
    /// its side) seen by the camera: its pixel and its contribution weight x W(x) (module
    /// documentation), or `None` if the eye is behind the surface, outside the image or hidden.
    fn connect(&self, x: DVec3, n: DVec3, lift: f64, weight: DVec3) -> Option<(usize, DVec3)> {
        let cam = &self.camera;
        let to_eye = cam.eye - x;
        let r2 = to_eye.length_squared();
        let r = r2.sqrt();
        let w = to_eye / r;
        let cos_x = n.dot(w);
        let v = -w;
        let cos_theta = v.dot(cam.forward);
        if !(cos_x > 0.0 && cos_theta > 0.0) {
            return None;
        }
        // Where the ray from the eye crosses the image plane at distance 1.
        let sx = v.dot(cam.right) / cos_theta;
        let sy = v.dot(cam.up) / cos_theta;
        let px = (sx / (cam.aspect * cam.tan_half_fov) + 1.0) * 0.5 * f64::from(cam.width);
        let py = (1.0 - sy / cam.tan_half_fov) * 0.5 * f64::from(cam.height);
        if !(px >= 0.0 && px < f64::from(cam.width) && py >= 0.0 && py < f64::from(cam.height)) {
            return None;
        }
        let origin = x + n * lift;
        if self.closest_hit(origin, w).is_some_and(|h| h.t < (cam.eye - origin).length()) {
            return None;
        }
        let pixel_area = (2.0 * cam.aspect * cam.tan_half_fov / f64::from(cam.width))
            * (2.0 * cam.tan_half_fov / f64::from(cam.height));
        let importance = cos_x / (pixel_area * cos_theta.powi(3) * r2);
        let pixel = py as usize * cam.width as usize + px as usize;
        Some((pixel, weight * importance))
    }

    /// The caustic image of frame `frame` (the frame that pairs with sample index `frame` of
    /// every pixel): width x height particles, row-major pixels, and with a delta sun the
    /// photon gather of the caustic seen through a specular surface (`gather.rs`) from the same
    /// particles. All zero when caustics are off.
    pub fn caustic_frame(&self, seed: u64, frame: u32) -> Vec<DVec3> {
        let n = u64::from(self.camera.width) * u64::from(self.camera.height);
        let mut image = vec![DVec3::ZERO; n as usize];
        if self.caustic.is_none() {
            return image;
        }
        let mut photons = Vec::new();
        for particle in 0..n {
            let mut rng = particle_rng(seed, particle, frame);
            if let Some(photon) = self.trace_particle(n, &mut rng) {
                if let Some((pixel, value)) =
                    self.connect(photon.point, photon.normal, photon.lift, photon.weight)
                {
                    image[pixel] += value;
                }
                photons.push(photon);
            }
        }
        if self.gathers() {
            self.add_gather(&mut image, photons, seed, frame);
        }
        image
    }
}

/// The caustic's extreme cases, shared by the oracle's tests and the GPU's
/// (illum-pathtrace's `tests/pathtrace/caustic.rs`): a ball's material and the `[directional_light]` lines that
/// go with it. Indices of refraction 1.0001 (grazing refraction, almost no reflection) and 4
/// (total internal reflection chains), the sun at 0.1 and 89.9 degrees of elevation, a sun disc
/// of 20 and of 0.01 degrees, and a perfect mirror.
pub const EXTREME_CASES: [(&str, &str); 7] = [
    ("dielectric = { ior = 1.0001 }", "direction = [-1.0, -1.0, 0.0]"),
    ("dielectric = { ior = 4.0 }", "direction = [-1.0, -1.0, 0.0]"),
    ("dielectric = { ior = 1.5 }", "direction = [-1.0, -0.0017453, 0.0]"),
    ("dielectric = { ior = 1.5 }", "direction = [-0.0017453, -1.0, 0.0]"),
    ("dielectric = { ior = 1.5 }", "direction = [-1.0, -1.0, 0.0]\nangular_radius = 20.0"),
    ("dielectric = { ior = 1.5 }", "direction = [-1.0, -1.0, 0.0]\nangular_radius = 0.01"),
    ("mirror = { reflectance = [1.0, 1.0, 1.0] }", "direction = [-1.0, -1.0, 0.0]"),
];
