//! The photon gather of a delta sun's caustic, paths E (S|D)* D S+ L other than E D S+ L (the
//! light tracer's connection): the caustic seen in a mirror or through glass, and the caustic's
//! light scattered again by diffuse surfaces, by probabilistic progressive photon mapping (Knaus
//! and Zwicker 2011), in f64 and written independently of the GPU's
//! (`crates/illum-pathtrace/shaders/gather.wgsl`).
//!
//! Neither the camera paths nor the light tracer's connection to the pinhole can find these
//! paths with a delta sun: a camera path never reaches a light of zero size (and next-event
//! estimation's shadow ray from D meets the specular object), and a particle leaving D through
//! a mirror, glass or another diffuse bounce never reaches a pinhole. Photon mapping joins the
//! two halves at D with a kernel of radius r instead of an exact connection.
//!
//! Photons. Frame k's particles (`caustic.rs`) stop at their first diffuse point after s >= 1
//! specular scatterings; there each is a photon of weight Phi rho(x_p) / pi (its flux Phi, the
//! albedo at the photon). The N particles of a frame carry the whole power the sun sends
//! through the specular objects, so the photons' weights within r of x, divided by pi r^2,
//! estimate the radiance rho / pi E(x) leaving x, blurred over the disc of radius r.
//!
//! Gathering paths. Sample k of a pixel adds one camera path, traced with its own random
//! numbers, through mirrors (weight the reflectance), glass (the Fresnel choice, weight 1) and
//! diffuse surfaces (a cosine bounce, weight the albedo). At each diffuse vertex D after m >= 1
//! continuation rays its throughput multiplies
//!     L(D) = sum over photons p of frame k with |x_p - D| < r_k and n_p . n_D > 0 of
//!            weight_p / (pi r_k^2)
//! (n_p faces the side the particle arrived from, n_D the side the path arrived from: a photon
//! on the other side of a surface is not counted). Under `Bounces::Fixed(n)` a photon of s
//! scatterings counts when m + s + 1 <= n, the continuation rays of the path E ... D S^s L;
//! unbounded, both halves play Russian roulette as their estimators do. The camera ray's own hit
//! (m = 0) gathers nothing: E D S+ L is the light tracer's connection. Every other path with a
//! delta sun either ends L D (next-event estimation's), L S+ D E (the light tracer's) or
//! E S+ L (the sun's glint, a point on the film that none of these finds), so no path is
//! counted twice. With a sun disc the camera paths find all of these themselves (a bounce that
//! reaches the disc) and the gather is off.
//!
//! Radius. Frame k (sample index k, from 0) has its own photon map and radius
//!     r_k = r_1 (k + 1)^((alpha - 1) / 2),   alpha = 2/3,   r_1 = RADIUS_FRACTION R_max
//! (R_max the largest specular object's bounding radius). Frames are independent, so the
//! per-pixel mean and variance of the samples stay valid; the kernel's bias falls as r_k^2 and
//! its variance grows as 1 / r_k^2 ~ k^(1 - alpha), so the mean over K frames converges
//! (bias ~ K^(alpha - 1), variance ~ K^(-alpha)).

use std::collections::HashMap;
use std::f64::consts::PI;

use glam::DVec3;
use illum_scene::{Bounces, MaterialKind};

use crate::integrator::{Contact, Oracle};
use crate::optics::{reflect, scatter_dielectric};
use crate::particle_source::particle_rng;
use crate::rng::Rng;

/// r_1 as a fraction of the largest specular object's bounding radius.
pub const RADIUS_FRACTION: f64 = 0.02;
/// Knaus and Zwicker's alpha: the kernel's area shrinks as k^(alpha - 1).
pub const ALPHA: f64 = 2.0 / 3.0;
/// Key mixed into the gather paths' seed, so that they share no random numbers with the camera
/// paths or the particles.
const GATHER_SEED_KEY: u64 = 0x9a7e_e4ca_0571_c0de;

/// A particle at its first diffuse point after at least one specular scattering.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Photon {
    pub(crate) point: DVec3,
    /// The surface normal on the side the particle arrived from.
    pub(crate) normal: DVec3,
    /// How far along `normal` a ray from the point starts.
    pub(crate) lift: f64,
    /// Flux x albedo / pi.
    pub(crate) weight: DVec3,
    /// Specular scatterings before the point (at least 1).
    pub(crate) scatterings: u32,
}

/// The kernel radius of frame `frame` for r_1 = `first`.
pub fn radius(first: f64, frame: u32) -> f64 {
    first * (f64::from(frame) + 1.0).powf((ALPHA - 1.0) / 2.0)
}

/// One frame's photons in a hash map of cubic cells of side r: the photons within r of a point
/// lie in its cell or one of the 26 around it.
struct PhotonMap {
    photons: Vec<Photon>,
    cells: HashMap<[i64; 3], Vec<usize>>,
    r: f64,
}

impl PhotonMap {
    fn new(photons: Vec<Photon>, r: f64) -> Self {
        let mut cells: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
        for (i, p) in photons.iter().enumerate() {
            cells.entry(Self::cell(p.point, r)).or_default().push(i);
        }
        PhotonMap { photons, cells, r }
    }

    fn cell(x: DVec3, r: f64) -> [i64; 3] {
        let c = (x / r).floor();
        [c.x as i64, c.y as i64, c.z as i64]
    }

    /// The radiance estimate at x (normal n facing the gathering path) from the photons a path
    /// that reached x after `specular` scatterings may join.
    fn radiance(&self, x: DVec3, n: DVec3, specular: u32, bounces: Bounces) -> DVec3 {
        let [cx, cy, cz] = Self::cell(x, self.r);
        let mut sum = DVec3::ZERO;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(list) = self.cells.get(&[cx + dx, cy + dy, cz + dz]) else { continue };
                    for p in list.iter().map(|&i| &self.photons[i]) {
                        let joins = match bounces {
                            Bounces::Fixed(limit) => specular + p.scatterings < limit,
                            Bounces::Unbounded => true,
                        };
                        if joins && (p.point - x).length_squared() < self.r * self.r && p.normal.dot(n) > 0.0
                        {
                            sum += p.weight;
                        }
                    }
                }
            }
        }
        sum / (PI * self.r * self.r)
    }
}

impl Oracle {
    /// Whether the caustic's frames add the photon gather: caustics on with a delta sun.
    pub fn gathers(&self) -> bool {
        self.gather && self.caustic.is_some() && self.scene.sun.is_some_and(|s| s.is_delta())
    }

    /// Turns the photon gather off (`false`) or back on; it runs only where [`Self::gathers`]
    /// allows. Off, the image misses E (S|D)* D S+ L (but E D S+ L) as the light tracer alone
    /// does.
    pub fn with_gather(mut self, on: bool) -> Oracle {
        self.gather = on;
        self
    }

    /// Adds frame `frame`'s gather to its image: one gathering path per pixel, against the
    /// frame's `photons`.
    pub(crate) fn add_gather(&self, image: &mut [DVec3], photons: Vec<Photon>, seed: u64, frame: u32) {
        let Some(map) = self.photon_map(photons, frame) else { return };
        let width = self.camera.width;
        for (pixel, value) in image.iter_mut().enumerate() {
            *value += self.gather_pixel(&map, pixel as u32 % width, pixel as u32 / width, seed, frame);
        }
    }

    /// Frame `frame`'s gather at `pixels` (x, y) alone, its particles traced again: what
    /// [`Oracle::caustic_frame`] adds there besides the light tracer's connections (which
    /// land only where the camera ray's own hit is diffuse). Zeros when the gather is off.
    pub fn gather_at(&self, seed: u64, frame: u32, pixels: &[(u32, u32)]) -> Vec<DVec3> {
        let n = u64::from(self.camera.width) * u64::from(self.camera.height);
        let photons = (0..n)
            .filter_map(|particle| {
                let mut rng = particle_rng(seed, particle, frame);
                self.trace_particle(n, &mut rng)
            })
            .collect();
        match self.photon_map(photons, frame) {
            Some(map) => pixels.iter().map(|&(x, y)| self.gather_pixel(&map, x, y, seed, frame)).collect(),
            None => vec![DVec3::ZERO; pixels.len()],
        }
    }

    fn photon_map(&self, photons: Vec<Photon>, frame: u32) -> Option<PhotonMap> {
        let source = self.caustic.as_ref().filter(|_| self.gathers())?;
        Some(PhotonMap::new(photons, radius(RADIUS_FRACTION * source.largest_radius, frame)))
    }

    fn gather_pixel(&self, map: &PhotonMap, x: u32, y: u32, seed: u64, frame: u32) -> DVec3 {
        let pixel = u64::from(y) * u64::from(self.camera.width) + u64::from(x);
        let mut rng = Rng::for_sample(seed ^ GATHER_SEED_KEY, pixel, u64::from(frame));
        self.gather_path(map, x, y, &mut rng)
    }

    /// One gathering camera path through pixel (x, y), jittered: the photon estimates at its
    /// diffuse vertices after the camera ray's own hit, each times the throughput there.
    fn gather_path(&self, map: &PhotonMap, x: u32, y: u32, rng: &mut Rng) -> DVec3 {
        let (jx, jy) = (rng.uniform(), rng.uniform());
        let mut d = self.camera.direction(x, y, jx, jy);
        let mut o = self.camera.eye;
        let mut throughput = DVec3::ONE;
        let mut sum = DVec3::ZERO;
        // Continuation rays taken so far.
        let mut taken = 0u32;
        loop {
            let Some(hit) = self.closest_hit(o, d) else { return sum };
            if hit.primitive.emitter {
                return sum;
            }
            let Contact { point, front, normal, lift, .. } = hit.contact(o, d);
            match hit.primitive.material {
                MaterialKind::Mirror { reflectance } => {
                    let reflectance = reflectance.as_dvec3();
                    if !self.may_continue(taken)
                        || !self.roulette(taken, throughput * reflectance, &mut throughput, rng)
                    {
                        return sum;
                    }
                    throughput *= reflectance;
                    d = reflect(d, normal);
                    o = point + normal * lift;
                }
                MaterialKind::Dielectric { ior } => {
                    if !self.may_continue(taken) || !self.roulette(taken, throughput, &mut throughput, rng) {
                        return sum;
                    }
                    (o, d) = scatter_dielectric(d, normal, normal, point, front, ior, lift, rng);
                }
                MaterialKind::Lambertian { .. } | MaterialKind::Checker(_) => {
                    if taken > 0 {
                        sum += throughput * map.radiance(point, normal, taken, self.bounces);
                    }
                    let albedo = hit.diffuse_albedo(point);
                    // A later diffuse vertex joins photons of s >= 1 scatterings after at least
                    // taken + 1 rays: nothing counts under a limit below taken + 3.
                    let useful = match self.bounces {
                        Bounces::Fixed(n) => taken + 3 <= n,
                        Bounces::Unbounded => true,
                    };
                    if !useful
                        || !self.may_continue(taken)
                        || !self.roulette(taken, throughput * albedo, &mut throughput, rng)
                    {
                        return sum;
                    }
                    throughput *= albedo;
                    let local = crate::sampling::cosine_hemisphere(rng.uniform(), rng.uniform());
                    d = crate::sampling::local_to_world(normal, local).normalize();
                    o = point + normal * lift;
                }
                MaterialKind::Emitter { .. } => unreachable!("emitters are handled above"),
            }
            if !throughput.cmpgt(DVec3::ZERO).any() {
                return sum;
            }
            taken += 1;
        }
    }
}
