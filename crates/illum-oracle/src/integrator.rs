//! The path estimator, written from the rendering equation for Lambertian surfaces.
//!
//! At a diffuse point x with albedo rho and normal n (turned to face the arriving ray),
//!     L(x) = int_lights rho/pi Le cos_x cos_y / |x - y|^2 V(x, y) dA_y
//!          + int_hemisphere rho/pi L_indirect(x, w) cos(w) dw.
//! The first integral is estimated with one point y uniform on the union of the emitting
//! parallelograms (pdf 1 / A_total): rho/pi Le cos_x cos_y / r^2 A_total, zero when y is behind x,
//! x is behind the (one-sided) light, or a non-emitting surface blocks the segment. The second
//! is estimated by one direction w drawn from the hemisphere (cosine: weight rho; uniform:
//! weight 2 rho cos) and recursion at the next surface. Because emitted light was already
//! counted by the light integral, a continuation ray that reaches an emitter (or nothing) ends
//! the path with nothing added; only the camera ray itself may see an emitter directly.
//!
//! On a smooth mesh the shading normal n_s stands in for n in cos_x, in the light's cosine and
//! as the axis of the hemisphere a direction is drawn from, while the geometric normal n_g keeps
//! deciding sides: light arriving from behind the geometric surface counts nothing, so the
//! integrand is rho/pi L(w) max(n_s.w, 0) [n_g.w > 0], and a direction drawn below the geometric
//! surface ends the path. Specular scattering uses n_s where its directions stay on their sides
//! ([`mirror_normal`], [`dielectric_normal`]). These are the GPU's rules (illum-rtcore's
//! mesh_shading.wgsl), written here apart.
//!
//! Path length: `Bounces::Fixed(n)` allows n continuation rays (0 = direct light only).
//! `Bounces::Unbounded` continues forever in principle; from the fourth continuation on, a
//! path survives each step with probability q (the largest channel of throughput x albedo, at
//! most 0.95) and its throughput is divided by q, which keeps the expectation unchanged
//! (Russian roulette).

use std::f64::consts::{FRAC_1_PI, PI};

use glam::DVec3;
use illum_scene::{Bounces, MaterialKind, Sampling, Scene};

use crate::camera::PinholeCamera;
use crate::geometry::Surface;
use crate::manifold::ManifoldSettings;
use crate::optics::{dielectric_normal, mirror_normal, reflect, scatter_dielectric};
use crate::particle_source::ParticleSource;
use crate::rng::Rng;
use crate::sampling::{cosine_hemisphere, local_to_world, uniform_cone, uniform_hemisphere};
use crate::scene::{Primitive, TraceScene};

/// Relative distance by which an emitter may lie behind the nearest other surface and still
/// be the one that is hit: lights set into a coplanar ceiling win the tie.
const EMITTER_TIE: f64 = 1e-9;
/// A new ray starts this far (relative to the point's largest coordinate, at least 1e-9) off
/// the surface along the facing normal. f64 hit points carry errors ~1e-16 |p|.
pub(crate) const SPAWN_OFFSET: f64 = 1e-9;
/// Shadow rays end this fraction short of the light point, so the light's own plane (and a
/// surface coplanar with it) does not shadow it.
pub(crate) const SHADOW_SHORTEN: f64 = 1e-8;
/// Continuation rays taken without Russian roulette in unbounded mode.
pub(crate) const ROULETTE_AFTER: u32 = 3;
pub(crate) const ROULETTE_MAX_SURVIVAL: f64 = 0.95;
/// A safety limit for unbounded paths; reaching it has probability below 0.95^100000.
pub(crate) const UNBOUNDED_LIMIT: u32 = 100_000;

/// What a ray hit: the primitive, distance, geometric normal and shading normal.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Hit<'a> {
    pub(crate) primitive: &'a Primitive,
    pub(crate) t: f64,
    pub(crate) normal: DVec3,
    pub(crate) shading: DVec3,
}

/// Where a ray meets the surface it hit, as both estimators (the camera's paths here and the
/// caustic's light tracer) scatter from it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Contact {
    /// The hit point.
    pub(crate) point: DVec3,
    /// Whether the ray meets the front side (against the geometric normal).
    pub(crate) front: bool,
    /// The geometric normal turned to face the arriving ray.
    pub(crate) normal: DVec3,
    /// How far along `normal` a new ray starts (see [`SPAWN_OFFSET`]).
    pub(crate) lift: f64,
    /// The shading normal, turned as `normal` is (on its side of the surface).
    pub(crate) shading: DVec3,
}

impl Hit<'_> {
    /// This hit as the ray `o + t d` meets it.
    pub(crate) fn contact(&self, o: DVec3, d: DVec3) -> Contact {
        let point = o + self.t * d;
        let front = self.normal.dot(d) < 0.0;
        let (normal, shading) =
            if front { (self.normal, self.shading) } else { (-self.normal, -self.shading) };
        Contact { point, front, normal, lift: SPAWN_OFFSET * point.abs().max_element().max(1.0), shading }
    }

    /// The diffuse albedo at `point` of this (Lambertian or checker) hit: a checker's tile
    /// colour there, else the material's albedo.
    pub(crate) fn diffuse_albedo(&self, point: DVec3) -> DVec3 {
        match (self.primitive.material, self.primitive.surface) {
            (MaterialKind::Checker(c), Surface::Parallelogram(quad)) => {
                crate::optics::checker_albedo(&quad, c, point)
            }
            _ => self.primitive.albedo,
        }
    }
}

/// Nearest hit with t in (0, inf) among `list`.
fn nearest_in(list: &[Primitive], o: DVec3, d: DVec3) -> Option<Hit<'_>> {
    let mut best: Option<Hit<'_>> = None;
    for primitive in list {
        let limit = best.map_or(f64::INFINITY, |h| h.t);
        if let Some(h) = primitive.surface.intersect(o, d, limit) {
            best = Some(Hit { primitive, t: h.t, normal: h.normal, shading: h.shading });
        }
    }
    best
}

/// A scene prepared for tracing with the settings of one estimate.
#[derive(Clone, Debug)]
pub struct Oracle {
    pub(crate) scene: TraceScene,
    pub camera: PinholeCamera,
    pub bounces: Bounces,
    pub sampling: Sampling,
    /// The light tracer of the caustic (`caustic.rs`), when on and the scene can have one.
    pub(crate) caustic: Option<ParticleSource>,
    /// Whether the caustic's frames add the photon gather (`gather.rs`; with a delta sun only).
    pub(crate) gather: bool,
    /// Manifold next-event estimation through one sphere (`manifold.rs`), when on.
    pub(crate) manifold: Option<crate::manifold::Manifold>,
}

impl Oracle {
    /// Prepares `scene` with its own path-tracer settings (`scene.pathtrace.bounces` and
    /// `.sampling`), or says which feature of the scene the oracle does not implement.
    pub fn new(scene: &Scene) -> Result<Oracle, illum_scene::SceneError> {
        let oracle = Oracle {
            scene: TraceScene::new(scene)?,
            camera: PinholeCamera::new(&scene.camera),
            bounces: scene.pathtrace.bounces,
            sampling: scene.pathtrace.sampling,
            caustic: None,
            gather: true,
            manifold: None,
        };
        let oracle = oracle.with_caustics(scene.pathtrace.caustics);
        // `caustic_method = "manifold"`, where the scene can take it (illum-scene's rule, which
        // the GPU path tracer's estimators follow too): the solve with the path tracer's bound.
        let manifold = scene.pathtrace.caustics
            && scene.pathtrace.caustic_method == illum_scene::CausticMethod::Manifold
            && illum_scene::specular_spheres::solvable_spheres(scene).is_ok();
        Ok(oracle.with_manifold(manifold.then(|| ManifoldSettings {
            max_concentration: Some(f64::from(illum_scene::specular_spheres::MAX_CONCENTRATION)),
            // The search for hidden pairs finds the roots a coarser grid's sign changes miss,
            // so the count of intervals sets the time, not which roots are found.
            intervals: 512,
            ..ManifoldSettings::default()
        })))
    }

    /// Turns the caustic's light tracer on or off (on has an effect only with a directional
    /// light and a mirror or dielectric, and none while manifold next-event estimation is on).
    pub fn with_caustics(mut self, on: bool) -> Oracle {
        self.caustic = None;
        if on && self.manifold.is_none() {
            self.caustic = ParticleSource::new(&self.scene);
        }
        self
    }

    pub fn with_bounces(mut self, bounces: Bounces) -> Oracle {
        self.bounces = bounces;
        self
    }

    pub fn with_sampling(mut self, sampling: Sampling) -> Oracle {
        self.sampling = sampling;
        self
    }

    /// Total area of the emitting parallelograms.
    pub fn light_area(&self) -> f64 {
        self.scene.light_area
    }

    /// Nearest hit along o + t d (d unit) with t in (0, inf); an emitter wins a tie with a
    /// surface up to the relative distance EMITTER_TIE behind it.
    pub(crate) fn closest_hit(&self, o: DVec3, d: DVec3) -> Option<Hit<'_>> {
        let surface = nearest_in(&self.scene.surfaces, o, d);
        let emitter = nearest_in(&self.scene.emitters, o, d);
        match (surface, emitter) {
            (Some(s), Some(e)) => Some(if e.t <= s.t * (1.0 + EMITTER_TIE) { e } else { s }),
            (s, e) => s.or(e),
        }
    }

    /// True when a non-emitting surface crosses o + t d for some t in (0, t_max).
    pub(crate) fn blocked(&self, o: DVec3, d: DVec3, t_max: f64) -> bool {
        self.scene.surfaces.iter().any(|p| p.surface.intersect(o, d, t_max).is_some())
    }

    /// One-sample estimate of the light arriving at x (already offset off the surface) with
    /// facing normal n and shading normal n_s, weighted by cos_x = n_s.w: Le cos_x cos_y / r^2
    /// A_total, or zero (also for light from behind n).
    fn light_sample(&self, x: DVec3, n: DVec3, shading: DVec3, rng: &mut Rng) -> DVec3 {
        let lights = &self.scene.lights;
        if lights.is_empty() {
            return DVec3::ZERO;
        }
        let (s, r) = (rng.uniform(), rng.uniform());
        let pick = rng.uniform() * self.scene.light_area;
        let index = lights.partition_point(|l| l.cumulative_area <= pick).min(lights.len() - 1);
        let light = &lights[index];
        let y = light.shape.point(s, r);
        let to_light = y - x;
        let dist_sq = to_light.length_squared();
        let dist = dist_sq.sqrt();
        let w = to_light / dist;
        let cos_x = shading.dot(w);
        let cos_y = -light.shape.normal.dot(w);
        if !(cos_x > 0.0 && cos_y > 0.0 && n.dot(w) > 0.0)
            || self.blocked(x, w, dist * (1.0 - SHADOW_SHORTEN))
        {
            return DVec3::ZERO;
        }
        light.emission * (cos_x * cos_y / dist_sq * self.scene.light_area)
    }

    /// Whether the path may take continuation ray number `taken + 1`, given `taken` so far.
    pub(crate) fn may_continue(&self, taken: u32) -> bool {
        match self.bounces {
            Bounces::Fixed(n) => taken < n,
            Bounces::Unbounded => taken < UNBOUNDED_LIMIT,
        }
    }

    /// One sample of the directional light's contribution to the integral of incoming radiance
    /// x cos over the hemisphere at x (offset off the surface) with facing normal n and shading
    /// normal n_s (cos = n_s.w; nothing from behind n): for a delta light E cos V; for a disc,
    /// one direction uniform in its cone (pdf 1 / (2 pi (1 - cos_max))) with L_sun cos V / pdf.
    fn sun_sample(&self, x: DVec3, n: DVec3, shading: DVec3, rng: &mut Rng) -> DVec3 {
        let Some(sun) = self.scene.sun else { return DVec3::ZERO };
        if sun.is_delta() {
            let cos = shading.dot(sun.to_light);
            if cos <= 0.0 || n.dot(sun.to_light) <= 0.0 || self.blocked(x, sun.to_light, f64::INFINITY) {
                return DVec3::ZERO;
            }
            return sun.irradiance * cos;
        }
        let (u1, u2) = (rng.uniform(), rng.uniform());
        let w = local_to_world(sun.to_light, uniform_cone(u1, u2, sun.cos_max)).normalize();
        let cos = shading.dot(w);
        if cos <= 0.0 || n.dot(w) <= 0.0 || self.blocked(x, w, f64::INFINITY) {
            return DVec3::ZERO;
        }
        sun.radiance() * (cos * 2.0 * PI * (1.0 - sun.cos_max))
    }

    /// What a ray leaving the scene along d sees: the sky, and the sun's disc where it counts
    /// (camera and specular rays only: next-event estimation already counted it for diffuse
    /// ones). A delta sun is never seen.
    fn escaped(&self, d: DVec3, direct_counts: bool, caustic_owned: bool) -> DVec3 {
        let sun = match self.scene.sun {
            Some(sun)
                if direct_counts
                    && !caustic_owned
                    && !sun.is_delta()
                    && d.dot(sun.to_light) >= sun.cos_max =>
            {
                sun.radiance()
            }
            _ => DVec3::ZERO,
        };
        self.scene.sky + sun
    }

    /// Russian roulette in unbounded mode from the fourth continuation on: survives with
    /// probability q = min(max channel of `weight`, 0.95) and then divides `throughput` by q.
    /// Returns false when the path ends.
    pub(crate) fn roulette(&self, taken: u32, weight: DVec3, throughput: &mut DVec3, rng: &mut Rng) -> bool {
        if self.bounces == Bounces::Unbounded && taken >= ROULETTE_AFTER {
            let q = weight.max_element().min(ROULETTE_MAX_SURVIVAL);
            if !(q > 0.0 && rng.uniform() < q) {
                return false;
            }
            *throughput /= q;
        }
        true
    }

    /// One sample of the radiance arriving at `origin` from direction -`dir` (the quantity a
    /// camera ray from `origin` along `dir` measures). `dir` need not be normalised.
    pub fn radiance(&self, origin: DVec3, dir: DVec3, rng: &mut Rng) -> DVec3 {
        let mut d = dir.normalize();
        let mut o = origin;
        let mut sum = DVec3::ZERO;
        let mut throughput = DVec3::ONE;
        let mut taken = 0u32;
        // Whether light reaching this ray straight from an emitter or the sun's disc counts: for
        // the camera ray and after specular scattering, which next-event estimation cannot
        // follow; not after a diffuse bounce, whose point already sampled the lights.
        let mut direct_counts = true;
        // Whether the path so far is E D S* with D the camera ray's own hit: its end at the sun
        // disc (E D S+ L) belongs to the caustic's light tracer when that is on (caustic.rs).
        let mut caustic_owned = false;
        loop {
            let Some(hit) = self.closest_hit(o, d) else {
                sum += throughput * self.escaped(d, direct_counts, caustic_owned);
                break;
            };
            if hit.primitive.emitter {
                // One-sided: only the front (normal against the ray) emits.
                if direct_counts && hit.normal.dot(d) < 0.0 {
                    sum += throughput * hit.primitive.emission;
                }
                break;
            }
            let Contact { point: x, front, normal: n, lift, shading } = hit.contact(o, d);
            match hit.primitive.material {
                MaterialKind::Mirror { reflectance } => {
                    // A smooth mirror: one direction, weight = its reflectance.
                    let reflectance = reflectance.as_dvec3();
                    if !self.may_continue(taken)
                        || !self.roulette(taken, throughput * reflectance, &mut throughput, rng)
                    {
                        break;
                    }
                    throughput *= reflectance;
                    d = reflect(d, mirror_normal(d, n, shading));
                    o = x + n * lift;
                    direct_counts = true;
                }
                MaterialKind::Dielectric { ior } => {
                    // Reflect with probability F (the exact Fresnel reflectance), else refract:
                    // the weight F / F = (1 - F) / (1 - F) = 1. Radiance is not scaled by eta^2
                    // across the interface: every diffuse surface and light is outside, so a
                    // path enters and leaves a ball as often and the factors cancel.
                    if !self.may_continue(taken) || !self.roulette(taken, throughput, &mut throughput, rng) {
                        break;
                    }
                    let eta = if front { 1.0 / f64::from(ior) } else { f64::from(ior) };
                    let optic = dielectric_normal(d, n, shading, eta);
                    (o, d) = scatter_dielectric(d, n, optic, x, front, ior, lift, rng);
                    direct_counts = true;
                }
                MaterialKind::Lambertian { .. } | MaterialKind::Checker(_) => {
                    let albedo = hit.diffuse_albedo(x);
                    let x_off = x + n * lift;
                    let mut incident =
                        self.light_sample(x_off, n, shading, rng) + self.sun_sample(x_off, n, shading, rng);
                    if self.manifold.is_some() {
                        incident += self.manifold_irradiance(x_off, n, shading, taken);
                    }
                    sum += throughput * albedo * FRAC_1_PI * incident;
                    if !self.may_continue(taken)
                        || !self.roulette(taken, throughput * albedo, &mut throughput, rng)
                    {
                        break;
                    }
                    let (u1, u2) = (rng.uniform(), rng.uniform());
                    let local = match self.sampling {
                        Sampling::Cosine => {
                            // (rho/pi) cos / (cos/pi) = rho
                            throughput *= albedo;
                            cosine_hemisphere(u1, u2)
                        }
                        Sampling::Uniform => {
                            let local = uniform_hemisphere(u1, u2);
                            // (rho/pi) cos / (1/(2 pi)) = 2 rho cos
                            throughput *= albedo * (2.0 * local.z);
                            local
                        }
                    };
                    d = local_to_world(shading, local).normalize();
                    if d.dot(n) <= 0.0 {
                        // Below the geometric surface: no light leaks through it.
                        break;
                    }
                    o = x_off;
                    direct_counts = false;
                    caustic_owned = taken == 0 && self.caustic.is_some();
                }
                MaterialKind::Emitter { .. } => unreachable!("emitters are handled above"),
            }
            // Nothing more can be added once every channel is zero (or not a number).
            if !throughput.cmpgt(DVec3::ZERO).any() {
                break;
            }
            taken += 1;
        }
        sum
    }

    /// Sample `sample` of pixel (x, y) under `seed`: jittered camera ray, then [`Self::radiance`].
    pub fn pixel_sample(&self, x: u32, y: u32, seed: u64, sample: u32) -> DVec3 {
        let pixel = u64::from(y) * u64::from(self.camera.width) + u64::from(x);
        let mut rng = Rng::for_sample(seed, pixel, u64::from(sample));
        let (jx, jy) = (rng.uniform(), rng.uniform());
        let d = self.camera.direction(x, y, jx, jy);
        self.radiance(self.camera.eye, d, &mut rng)
    }
}
