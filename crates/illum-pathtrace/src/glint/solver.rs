//! The glint's solve: seeds on the film, the specular trees they start, and Newton's method on
//! each chain's film coordinate (the method is described in the parent module).

use glam::DVec3;
use illum_scene::{Bounces, Scene};

use super::bodies::{Bodies, Surface, fresnel};
use super::film::Film;
use super::{Event, GlintPoint, MIN_THROUGHPUT, Step, UNBOUNDED_SCATTERINGS};

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

/// `work(offset, share)` over shares of `items`, one per thread, the results in the order of the
/// shares. With one thread it runs on the caller's.
fn in_shares<T: Sync, R: Send>(
    items: &[T],
    threads: usize,
    work: impl Fn(usize, &[T]) -> R + Sync,
) -> Vec<R> {
    let threads = threads.min(items.len());
    if threads <= 1 {
        return vec![work(0, items)];
    }
    let per_share = items.len().div_ceil(threads);
    let work = &work;
    std::thread::scope(|scope| {
        let handles: Vec<_> = items
            .chunks(per_share)
            .enumerate()
            .map(|(k, share)| scope.spawn(move || work(k * per_share, share)))
            .collect();
        handles.into_iter().map(|h| h.join().expect("a glint solver thread")).collect()
    })
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

    pub(super) fn solve(&self) -> Vec<GlintPoint> {
        let seeds = self.seeds();
        // Each share of the seeds is explored apart; their candidates merge into one map. A
        // chain's starts are its best by (leaving direction, seed index), whatever the shares.
        let shares = in_shares(&seeds, self.threads, |offset, share| {
            let mut found = Candidates::default();
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
            if let Some((d2, weight)) = scatter(self.bodies.surface(hit.object), d, hit.normal, event) {
                chain.push((hit.object, event));
                let t = [0, 1, 2].map(|c| throughput[c] * weight[c]);
                self.explore(index, seed, p, d2, Some(hit.object), t, chain, found);
                chain.pop();
            }
        }
    }

    /// The direction the camera ray through s leaves in after `chain`, and the chain's
    /// throughput; None where the ray does not follow the chain (another object is nearer, an
    /// event is impossible, or the last ray does not escape).
    fn follow(&self, s: [f64; 2], chain: &[Step]) -> Option<(DVec3, [f64; 3])> {
        let mut o = self.film.eye;
        let mut d = self.film.direction(s);
        let mut own = None;
        let mut throughput = [1.0; 3];
        for &(object, event) in chain {
            // The chain's object, and nothing nearer on the way to it.
            let hit = self.bodies.hit(object, o, d, own)?;
            if self.bodies.blocked(o, d, own, hit.t, Some(object)) {
                return None;
            }
            let (d2, weight) = scatter(self.bodies.surface(object), d, hit.normal, event)?;
            throughput = [0, 1, 2].map(|c| throughput[c] * weight[c]);
            o += hit.t * d;
            d = d2;
            own = Some(object);
        }
        (!self.bodies.blocked(o, d, own, f64::INFINITY, None)).then_some((d, throughput))
    }

    /// Gnomonic coordinates of the leaving direction about w (None behind the sun's hemisphere).
    fn residual(&self, s: [f64; 2], chain: &[Step]) -> Option<([f64; 2], [f64; 3])> {
        let (d, throughput) = self.follow(s, chain)?;
        let z = d.dot(self.w);
        (z > 1e-6).then(|| ([d.dot(self.t1) / z, d.dot(self.t2) / z], throughput))
    }

    /// dg/ds at s by central differences of step h (error O(h^2), enough to steer Newton's
    /// method), retrying with smaller steps where a difference leaves the chain.
    fn newton_jacobian(&self, s: [f64; 2], chain: &[Step]) -> Option<[[f64; 2]; 2]> {
        let mut h = JACOBIAN_STEP;
        for _ in 0..6 {
            if let Some(j) = self.central(s, chain, h) {
                return Some(j);
            }
            h *= 0.1;
        }
        None
    }

    /// dg/ds at s, for the glint's value: central differences of step h and h/2, extrapolated
    /// (error O(h^4)). Retries with smaller steps where a difference leaves the chain.
    fn jacobian(&self, s: [f64; 2], chain: &[Step]) -> Option<[[f64; 2]; 2]> {
        let mut h = JACOBIAN_STEP;
        for _ in 0..6 {
            if let (Some(a), Some(b)) = (self.central(s, chain, h), self.central(s, chain, 0.5 * h)) {
                let mut j = [[0.0; 2]; 2];
                for r in 0..2 {
                    for c in 0..2 {
                        j[r][c] = (4.0 * b[r][c] - a[r][c]) / 3.0;
                    }
                }
                return Some(j);
            }
            h *= 0.1;
        }
        None
    }

    /// j[r][c] = d g_r / d s_c by central differences of step h.
    fn central(&self, s: [f64; 2], chain: &[Step], h: f64) -> Option<[[f64; 2]; 2]> {
        let mut j = [[0.0; 2]; 2];
        for c in 0..2 {
            let (mut plus, mut minus) = (s, s);
            plus[c] += h;
            minus[c] -= h;
            let (gp, _) = self.residual(plus, chain)?;
            let (gm, _) = self.residual(minus, chain)?;
            for r in 0..2 {
                j[r][c] = (gp[r] - gm[r]) / (2.0 * h);
            }
        }
        Some(j)
    }

    /// Newton's method on the film coordinate for `chain` from `seed`, with the step halved
    /// until it stays on the chain and lowers the residual. The root's glint, if it converges
    /// onto the film.
    fn newton(&self, seed: [f64; 2], chain: &[Step]) -> Option<GlintPoint> {
        let mut s = seed;
        let (mut g, _) = self.residual(s, chain)?;
        for _ in 0..NEWTON_ITERATIONS {
            let j = self.newton_jacobian(s, chain)?;
            let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
            if det == 0.0 || !det.is_finite() {
                return None;
            }
            let delta = [(-j[1][1] * g[0] + j[0][1] * g[1]) / det, (j[1][0] * g[0] - j[0][0] * g[1]) / det];
            let mut scale = 1.0;
            let mut moved = None;
            for _ in 0..40 {
                let next = [s[0] + scale * delta[0], s[1] + scale * delta[1]];
                if let Some((g2, _)) = self.residual(next, chain)
                    && norm2(g2) < norm2(g)
                {
                    moved = Some((next, g2));
                    break;
                }
                scale *= 0.5;
            }
            let Some((next, g2)) = moved else {
                // No step lowers the residual: converged to rounding, or stuck off a root.
                return (norm2(g) < ROOT_RESIDUAL).then(|| self.point(s, chain)).flatten();
            };
            let step = scale * norm2(delta);
            s = next;
            g = g2;
            if step < 1e-12 * (1.0 + norm2(s)) || norm2(g) < 1e-15 {
                return (norm2(g) < ROOT_RESIDUAL).then(|| self.point(s, chain)).flatten();
            }
        }
        (norm2(g) < ROOT_RESIDUAL).then(|| self.point(s, chain)).flatten()
    }

    fn point(&self, s: [f64; 2], chain: &[Step]) -> Option<GlintPoint> {
        let pixel = self.film.pixel(s)?;
        let (_, throughput) = self.residual(s, chain)?;
        let j = self.jacobian(s, chain)?;
        let jacobian = (j[0][0] * j[1][1] - j[0][1] * j[1][0]).abs();
        let value = [0, 1, 2].map(|c| self.irradiance[c] * throughput[c] / jacobian);
        let direction = self.film.direction(s);
        let camera_solid_angle = self.film.pixel_area() * direction.dot(self.film.forward).powi(3);
        value.iter().all(|v| v.is_finite()).then(|| GlintPoint {
            film: s,
            pixel,
            value,
            throughput,
            jacobian,
            direction: direction.to_array(),
            eye_irradiance: value.map(|v| v * camera_solid_angle),
            chain: chain.to_vec(),
        })
    }
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
/// Film step (pixels) of the Jacobian's differences.
const JACOBIAN_STEP: f64 = 1e-3;
/// A root's largest residual: the angle (radians) between its leaving direction and the sun.
const ROOT_RESIDUAL: f64 = 1e-10;

/// The direction a ray along d leaves a surface of outward normal n in by `event`, and the
/// weight per channel; None where the surface cannot do it (a diffuse surface, a mirror's
/// refraction, total internal reflection's refraction).
fn scatter(surface: Surface, d: DVec3, n: DVec3, event: Event) -> Option<(DVec3, [f64; 3])> {
    let reflect = |n: DVec3| d - 2.0 * d.dot(n) * n;
    match (surface, event) {
        (Surface::Mirror { reflectance }, Event::Reflect) => Some((reflect(n), reflectance)),
        (Surface::Dielectric { ior }, _) => {
            let front = d.dot(n) < 0.0;
            let n = if front { n } else { -n };
            let eta = if front { 1.0 / ior } else { ior };
            let cos_i = -d.dot(n);
            let (f, cos_t) = fresnel(cos_i, eta);
            match event {
                Event::Reflect => Some((reflect(n), [f; 3])),
                Event::Refract => {
                    let cos_t = cos_t?;
                    let t = (eta * d + (eta * cos_i - cos_t) * n).normalize();
                    Some((t, [1.0 - f; 3]))
                }
            }
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_glints_do_not_depend_on_how_many_threads_share_the_solve() {
        // The Whitted scene with a row of small glass and mirror balls before it: hundreds of
        // chains, whose starts come from shares of the seeds cut where the thread count says.
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/whitted.toml");
        let mut text = std::fs::read_to_string(&path).expect("scenes/whitted.toml");
        for k in 0..6 {
            let material = if k % 2 == 0 { "glass" } else { "metal" };
            let z = -6.0 + 1.2 * f64::from(k);
            text += &format!(
                "\n[[objects]]\nmaterial = \"{material}\"\nsphere = {{ center = [1.0, 0.35, {z:?}], radius = 0.35 }}\n"
            );
        }
        let mut scene = Scene::from_toml_str(&text, "whitted-row.toml").unwrap_or_else(|e| panic!("{e}"));
        scene.camera.width = 320;
        scene.camera.height = 180;
        let mut solver = Solver::new(&scene);
        solver.threads = 1;
        let one = solver.solve();
        assert!(one.len() > 40, "{} glints", one.len());
        for threads in [2, 3, 7] {
            solver.threads = threads;
            assert_eq!(solver.solve(), one, "{threads} threads against 1");
        }
    }
}
