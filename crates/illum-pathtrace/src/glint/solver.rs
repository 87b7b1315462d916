//! The glint's solve: seeds on the film, the specular trees they start, and Newton's method on
//! each chain's film coordinate (the method is described in the parent module).

use glam::DVec3;
use illum_scene::{Bounces, Scene};

use super::bodies::{Bodies, Surface, fresnel};
use super::film::Film;
use super::{Event, GlintPoint, MIN_THROUGHPUT, Step, UNBOUNDED_SCATTERINGS};

mod shares;
use shares::in_shares;

pub(super) struct Solver {
    bodies: Bodies,
    film: Film,
    /// Toward the sun, and two unit vectors completing the frame (the gnomonic axes).
    w: DVec3,
    t1: DVec3,
    t2: DVec3,
    irradiance: [f64; 3],
    max_scatterings: usize,
    /// Threads the solve shares its work among: the host's (1 where it has none, as a browser).
    /// The glints do not depend on it.
    threads: usize,
}

/// A seed whose specular tree has a leaf of some chain, and how near the sun that leaf leaves.
#[derive(Clone, Copy, Debug)]
struct Start {
    cos_to_sun: f64,
    /// The seed's index in [`Solver::seeds`]: ties in `cos_to_sun` go to the earlier seed, so
    /// the starts do not depend on how the seeds were shared among threads.
    index: usize,
    seed: [f64; 2],
}

impl Start {
    /// Whether `self` is a better start than `other`: leaving nearer the sun, then the earlier seed.
    fn before(&self, other: &Start) -> bool {
        other.cos_to_sun.total_cmp(&self.cos_to_sun).then(self.index.cmp(&other.index)).is_lt()
    }
}

/// Per chain, its best [`NEWTON_STARTS`] starts, best first.
#[derive(Default)]
struct Candidates(std::collections::HashMap<Vec<Step>, Vec<Start>>);

impl Candidates {
    /// Keeps `start` if it is among the chain's best: the result does not depend on the order
    /// of the offers ([`Start::before`] is a total order).
    fn offer(&mut self, chain: &[Step], start: Start) {
        let starts = match self.0.get_mut(chain) {
            Some(starts) => starts,
            None => self.0.entry(chain.to_vec()).or_default(),
        };
        if starts.len() == NEWTON_STARTS && !start.before(&starts[NEWTON_STARTS - 1]) {
            return;
        }
        let at = starts.iter().position(|s| start.before(s)).unwrap_or(starts.len());
        starts.insert(at, start);
        starts.truncate(NEWTON_STARTS);
    }
}

impl Solver {
    pub(super) fn new(scene: &Scene) -> Self {
        let light = scene.directional_light.expect("glint_active checked the light");
        let w = light.to_light().as_dvec3().normalize();
        let (t1, t2) = w.any_orthonormal_pair();
        let max_scatterings = match scene.pathtrace.bounces {
            Bounces::Fixed(n) => n as usize,
            Bounces::Unbounded => UNBOUNDED_SCATTERINGS,
        };
        Self {
            bodies: Bodies::new(scene),
            film: Film::new(scene),
            w,
            t1,
            t2,
            irradiance: light.irradiance.as_dvec3().to_array(),
            max_scatterings,
            threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
        }
    }

    /// The glints, sorted by pixel; once `stop` returns true (checked between shares of the
    /// work) the rest is skipped and the result is incomplete, for a caller that will not read it.
    pub(super) fn solve(&self, stop: &(dyn Fn() -> bool + Sync)) -> Vec<GlintPoint> {
        let seeds = self.seeds();
        // Each share of the seeds is explored apart; their candidates merge into one map. A
        // chain's starts are its best by (leaving direction, seed index), whatever the shares.
        let shares = in_shares(&seeds, self.threads, |offset, share| {
            let mut found = Candidates::default();
            if stop() {
                return found;
            }
            let mut chain = Vec::new();
            for (i, &seed) in share.iter().enumerate() {
                let d = self.film.direction(seed);
                self.explore(offset + i, seed, self.film.eye, d, None, [1.0; 3], &mut chain, &mut found);
            }
            found
        });
        let mut candidates = Candidates::default();
        for share in shares {
            for (chain, starts) in share.0 {
                for start in starts {
                    candidates.offer(&chain, start);
                }
            }
        }
        // The sun seen directly: the empty chain, seeded at the sun's own film point.
        let mut chains: Vec<(Vec<Step>, Vec<Start>)> = candidates.0.into_iter().collect();
        if let Some(s) = self.film.film_point(self.w) {
            chains.push((Vec::new(), vec![Start { cos_to_sun: 1.0, index: 0, seed: s }]));
        }
        chains.sort_by(|a, b| a.0.cmp(&b.0));
        // Newton from each chain's starts, the chains shared out the same way.
        let mut points: Vec<GlintPoint> = in_shares(&chains, self.threads, |_, share| {
            if stop() {
                return Vec::new();
            }
            share.iter().flat_map(|(c, s)| self.roots(c, s)).collect::<Vec<_>>()
        })
        .into_iter()
        .flatten()
        .collect();
        points.sort_by(|a, b| a.pixel.cmp(&b.pixel).then(a.chain.cmp(&b.chain)));
        points
    }

    /// The distinct roots Newton's method finds for `chain` from its starts, best first.
    fn roots(&self, chain: &[Step], starts: &[Start]) -> Vec<GlintPoint> {
        let mut points: Vec<GlintPoint> = Vec::new();
        for start in starts {
            if let Some(point) = self.newton(start.seed, chain)
                && !points.iter().any(|p| same_point(p.film, point.film))
            {
                points.push(point);
            }
        }
        points
    }

    /// Seeds on the film (pixels): over each specular sphere's disc as the eye sees it, on rings
    /// crowded toward the rim (where the chains change fastest), and a grid over the film when a
    /// flat face is specular or the eye is inside a sphere.
    fn seeds(&self) -> Vec<[f64; 2]> {
        let mut seeds = Vec::new();
        let mut grid = self.bodies.has_flat_specular();
        for (_, center, radius) in self.bodies.specular_spheres() {
            let to_center = center - self.film.eye;
            let dist = to_center.length();
            if dist <= radius * (1.0 + 1e-9) {
                grid = true;
                continue;
            }
            let axis = to_center / dist;
            let (a1, a2) = axis.any_orthonormal_pair();
            let half_angle = (radius / dist).asin();
            for i in 0..SEED_RINGS {
                // rho = sin(pi/2 x): rings evenly spaced in angle near the centre, crowded at the rim.
                let x = (i as f64 + 0.5) / SEED_RINGS as f64;
                let theta = half_angle * (std::f64::consts::FRAC_PI_2 * x).sin();
                for j in 0..SEED_AZIMUTHS {
                    let phi =
                        std::f64::consts::TAU * (j as f64 + 0.5 * (i % 2) as f64) / SEED_AZIMUTHS as f64;
                    let d = theta.cos() * axis + theta.sin() * (phi.cos() * a1 + phi.sin() * a2);
                    if let Some(s) = self.film.film_point(d) {
                        seeds.push(s);
                    }
                }
            }
        }
        if grid {
            for i in 0..GRID_SEEDS {
                for j in 0..GRID_SEEDS {
                    seeds.push([
                        (i as f64 + 0.5) / GRID_SEEDS as f64 * self.film.width,
                        (j as f64 + 0.5) / GRID_SEEDS as f64 * self.film.height,
                    ]);
                }
            }
        }
        seeds
    }

    /// Follows every branch of the specular tree of the ray `o + t d` (leaving `own`), pushing
    /// the leaves that escape the scene.
    #[allow(clippy::too_many_arguments)]
    fn explore(
        &self,
        index: usize,
        seed: [f64; 2],
        o: DVec3,
        d: DVec3,
        own: Option<usize>,
        throughput: [f64; 3],
        chain: &mut Vec<Step>,
        found: &mut Candidates,
    ) {
        let Some(hit) = self.bodies.nearest(o, d, own) else {
            if !chain.is_empty() {
                found.offer(chain, Start { cos_to_sun: d.dot(self.w), index, seed });
            }
            return;
        };
        if chain.len() >= self.max_scatterings || throughput.iter().all(|&t| t < MIN_THROUGHPUT) {
            return;
        }
        let p = o + hit.t * d;
        for event in [Event::Reflect, Event::Refract] {
            // The tree needs no derivatives: zero ones cost a few multiplications.
            let none = [DVec3::ZERO; 2];
            if let Some((d2, _, weight)) =
                scatter(self.bodies.surface(hit.object), d, none, hit.normal, none, event)
            {
                chain.push((hit.object, event));
                let t = [0, 1, 2].map(|c| throughput[c] * weight[c]);
                self.explore(index, seed, p, d2, Some(hit.object), t, chain, found);
                chain.pop();
            }
        }
    }

    /// The camera ray through s followed along `chain`: the direction its last ray leaves in,
    /// that direction's derivatives per film coordinate, and the chain's throughput; None where
    /// the ray does not follow the chain's own geometry (it misses one of its objects, or an
    /// event is impossible) or leaves behind the sun's hemisphere, and, with `Blockers::Checked`,
    /// where another object is nearer on a segment or the last ray does not escape.
    fn follow(
        &self,
        s: [f64; 2],
        chain: &[Step],
        blockers: Blockers,
    ) -> Option<(DVec3, [DVec3; 2], [f64; 3])> {
        let mut o = self.film.eye;
        let mut d_o = [DVec3::ZERO; 2];
        let (mut d, mut dd) = self.film.direction_and_derivatives(s);
        let mut own = None;
        let mut throughput = [1.0; 3];
        // The segments (origin, direction, object left, length, object hit), kept when blockers
        // are checked, and checked once the chain's own geometry holds.
        let mut segments = Vec::with_capacity(if blockers == Blockers::Checked { chain.len() } else { 0 });
        for &(object, event) in chain {
            let hit = self.bodies.hit(object, o, d, own)?;
            if blockers == Blockers::Checked {
                segments.push((o, d, own, hit.t, object));
            }
            // The hit point p = o + t d stays on the surface as s moves: n . dp = 0 gives dt, and
            // the normal turns by the curvature times dp.
            let dp = [0, 1].map(|c| {
                let along = d_o[c] + hit.t * dd[c];
                along - d * (hit.normal.dot(along) / hit.normal.dot(d))
            });
            let curvature = self.bodies.curvature(object);
            let dn = dp.map(|v| curvature * v);
            let (d2, dd2, weight) = scatter(self.bodies.surface(object), d, dd, hit.normal, dn, event)?;
            throughput = [0, 1, 2].map(|c| throughput[c] * weight[c]);
            o += hit.t * d;
            d_o = dp;
            d = d2;
            dd = dd2;
            own = Some(object);
        }
        if d.dot(self.w) <= SUN_HEMISPHERE {
            return None;
        }
        if blockers == Blockers::Ignored {
            return Some((d, dd, throughput));
        }
        let blocked =
            segments.iter().any(|&(o, d, own, t, object)| self.bodies.blocked(o, d, own, t, Some(object)));
        (!blocked && !self.bodies.blocked(o, d, own, f64::INFINITY, None)).then_some((d, dd, throughput))
    }

    /// The gnomonic coordinates g of the leaving direction about w, their Jacobian dg/ds and the
    /// chain's throughput at s (None where [`Self::follow`] has none).
    fn residual(&self, s: [f64; 2], chain: &[Step], blockers: Blockers) -> Option<Residual> {
        let (d, dd, throughput) = self.follow(s, chain, blockers)?;
        let z = d.dot(self.w);
        let g = [d.dot(self.t1) / z, d.dot(self.t2) / z];
        // g_r = d . t_r / z, z = d . w: dg_r = (dd . t_r - g_r dd . w) / z.
        let mut j = [[0.0; 2]; 2];
        for (r, t) in [self.t1, self.t2].into_iter().enumerate() {
            for c in 0..2 {
                j[r][c] = (dd[c].dot(t) - g[r] * dd[c].dot(self.w)) / z;
            }
        }
        Some(Residual { g, j, throughput })
    }

    /// Newton's method on the film coordinate for `chain` from `seed`, with the step halved
    /// until it stays on the chain and lowers the residual. The root's glint, if it converges
    /// onto the film and nothing blocks the chain there.
    ///
    /// The walk follows the chain's own geometry only; other objects are looked for once, at
    /// the root. A blocker changes whether a root shines, not where it is: checked at every
    /// trial point, it would cost a walk of the hierarchy per segment (most of the solve's
    /// time, at the trial points of chains with no root) and would stop a start whose way to an
    /// unblocked root crosses a shadow.
    fn newton(&self, seed: [f64; 2], chain: &[Step]) -> Option<GlintPoint> {
        let mut s = seed;
        let mut at = self.residual(s, chain, Blockers::Ignored)?;
        for _ in 0..NEWTON_ITERATIONS {
            if norm2(at.g) < 1e-15 {
                break;
            }
            let (j, g) = (at.j, at.g);
            let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
            if det == 0.0 || !det.is_finite() {
                return None;
            }
            let delta = [(-j[1][1] * g[0] + j[0][1] * g[1]) / det, (j[1][0] * g[0] - j[0][0] * g[1]) / det];
            let mut scale = 1.0;
            let mut moved = None;
            for _ in 0..LINE_SEARCH_HALVINGS {
                let next = [s[0] + scale * delta[0], s[1] + scale * delta[1]];
                if let Some(r) = self.residual(next, chain, Blockers::Ignored)
                    && norm2(r.g) < norm2(g)
                {
                    moved = Some((next, r));
                    break;
                }
                // Steps below the rounding of s leave it where it is (or move it by rounding).
                if scale * norm2(delta) < 1e-12 * (1.0 + norm2(s)) {
                    break;
                }
                scale *= 0.5;
            }
            // No step lowers the residual: converged to rounding, or stuck off a root.
            let Some((next, r)) = moved else { break };
            s = next;
            at = r;
            if scale * norm2(delta) < 1e-12 * (1.0 + norm2(s)) {
                break;
            }
        }
        let unblocked_root =
            norm2(at.g) < ROOT_RESIDUAL && self.follow(s, chain, Blockers::Checked).is_some();
        unblocked_root.then(|| self.point(s, &at, chain)).flatten()
    }

    fn point(&self, s: [f64; 2], at: &Residual, chain: &[Step]) -> Option<GlintPoint> {
        let pixel = self.film.pixel(s)?;
        let j = at.j;
        let jacobian = (j[0][0] * j[1][1] - j[0][1] * j[1][0]).abs();
        let value = [0, 1, 2].map(|c| self.irradiance[c] * at.throughput[c] / jacobian);
        let direction = self.film.direction(s);
        let camera_solid_angle = self.film.pixel_area() * direction.dot(self.film.forward).powi(3);
        value.iter().all(|v| v.is_finite()).then(|| GlintPoint {
            film: s,
            pixel,
            value,
            throughput: at.throughput,
            jacobian,
            direction: direction.to_array(),
            eye_irradiance: value.map(|v| v * camera_solid_angle),
            chain: chain.to_vec(),
        })
    }
}

/// Whether [`Solver::follow`] looks for objects other than the chain's own on its segments.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Blockers {
    Ignored,
    Checked,
}

/// A chain's state at a film point: the gnomonic coordinates g of its leaving direction about
/// the sun (0 at a root), their Jacobian j[r][c] = d g_r / d s_c, and the chain's throughput.
struct Residual {
    g: [f64; 2],
    j: [[f64; 2]; 2],
    throughput: [f64; 3],
}

fn norm2(v: [f64; 2]) -> f64 {
    v[0].hypot(v[1])
}

fn same_point(a: [f64; 2], b: [f64; 2]) -> bool {
    (a[0] - b[0]).abs() < 1e-6 && (a[1] - b[1]).abs() < 1e-6
}

/// Rings and azimuths of seeds over each specular sphere's disc.
const SEED_RINGS: usize = 48;
const SEED_AZIMUTHS: usize = 64;
/// Seeds per side of the film's grid (flat specular faces, the eye inside a sphere).
const GRID_SEEDS: usize = 96;
/// Newton starts per chain, from its seeds nearest the sun.
const NEWTON_STARTS: usize = 6;
const NEWTON_ITERATIONS: usize = 60;
/// Halvings of a Newton step before the start counts as stuck. A step cut to 2^-12 of Newton's
/// lowers the residual by about that fraction, so a start that needs it cannot converge within
/// [`NEWTON_ITERATIONS`] (60 x 2^-12 = 1.5%): it has met the edge of its chain's region. Further
/// halvings would cost a residual each, most of the solve's time (docs/performance-caustics.md).
const LINE_SEARCH_HALVINGS: usize = 12;
/// The least cosine between a chain's leaving direction and the sun for the gnomonic
/// coordinates (which divide by it) to be kept.
const SUN_HEMISPHERE: f64 = 1e-6;
/// A root's largest residual: the angle (radians) between its leaving direction and the sun.
const ROOT_RESIDUAL: f64 = 1e-10;

/// The direction a ray along d leaves a surface of outward normal n in by `event`, its
/// derivatives per film coordinate (from dd and dn, those of d and n), and the weight per
/// channel; None where the surface cannot do it (a diffuse surface, a mirror's refraction,
/// total internal reflection's refraction).
fn scatter(
    surface: Surface,
    d: DVec3,
    dd: [DVec3; 2],
    n: DVec3,
    dn: [DVec3; 2],
    event: Event,
) -> Option<(DVec3, [DVec3; 2], [f64; 3])> {
    // r = d - 2 (d . n) n, differentiated in d and n.
    let reflect = |n: DVec3, dn: [DVec3; 2]| {
        let dot = d.dot(n);
        let dr = [0, 1].map(|c| dd[c] - 2.0 * ((dd[c].dot(n) + d.dot(dn[c])) * n + dot * dn[c]));
        (d - 2.0 * dot * n, dr)
    };
    match (surface, event) {
        (Surface::Mirror { reflectance }, Event::Reflect) => {
            let (r, dr) = reflect(n, dn);
            Some((r, dr, reflectance))
        }
        (Surface::Dielectric { ior }, _) => {
            let front = d.dot(n) < 0.0;
            let (n, dn) = if front { (n, dn) } else { (-n, dn.map(|v| -v)) };
            let eta = if front { 1.0 / ior } else { ior };
            let cos_i = -d.dot(n);
            let (f, cos_t) = fresnel(cos_i, eta);
            match event {
                Event::Reflect => {
                    let (r, dr) = reflect(n, dn);
                    Some((r, dr, [f; 3]))
                }
                Event::Refract => {
                    let cos_t = cos_t?;
                    // u = eta d + (eta cos_i - cos_t) n, cos_t^2 = 1 - eta^2 (1 - cos_i^2), t = u / |u|.
                    let k = eta * cos_i - cos_t;
                    let u = eta * d + k * n;
                    let length = u.length();
                    let t = u / length;
                    let dt = [0, 1].map(|c| {
                        let dcos_i = -(dd[c].dot(n) + d.dot(dn[c]));
                        let dcos_t = eta * eta * cos_i * dcos_i / cos_t;
                        let du = eta * dd[c] + (eta * dcos_i - dcos_t) * n + k * dn[c];
                        (du - t * t.dot(du)) / length
                    });
                    Some((t, dt, [1.0 - f; 3]))
                }
            }
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests;
