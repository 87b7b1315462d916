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
//! root their area element is the solid angle's). The pixel containing s* gains I, once, in the
//! accumulator's mean ([`crate::Accumulator::set_glint`]): no noise, the error estimate unchanged.
//!
//! The solve: the camera rays through dense seeds (over each specular sphere's disc on the film,
//! finer toward its rim, and a grid over the film when a flat face is specular) are followed
//! through every branch of the specular tree, up to the render's bounce limit (a chain of k
//! scatterings takes k continuation rays, counted when k <= bounces); the leaves that escape the
//! scene name the chains. For each chain, Newton's method on the film coordinate, from the seeds
//! whose leaving direction is nearest w, finds the roots, with the Jacobian by central
//! differences extrapolated (Richardson) to fourth order. The empty chain is the sun seen
//! directly.

mod bodies;

use glam::DVec3;
use illum_scene::{Bounces, Scene};

use bodies::{Bodies, Surface, fresnel};

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
    crate::gpu_scene::caustics_active(scene) && scene.directional_light.is_some_and(|l| l.is_delta())
}

/// The glints of `scene` (empty when [`glint_active`] is false), sorted by pixel.
pub fn solve(scene: &Scene) -> Vec<GlintPoint> {
    if !glint_active(scene) {
        return Vec::new();
    }
    Solver::new(scene).solve()
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

/// The pinhole camera in f64, built from the same f32 basis the GPU uses.
struct Film {
    eye: DVec3,
    forward: DVec3,
    right: DVec3,
    up: DVec3,
    tan_half_fov: f64,
    aspect: f64,
    width: f64,
    height: f64,
}

impl Film {
    fn new(scene: &Scene) -> Self {
        let b = scene.camera.basis();
        Self {
            eye: scene.camera.eye.as_dvec3(),
            forward: b.forward.as_dvec3(),
            right: b.right.as_dvec3(),
            up: b.up.as_dvec3(),
            tan_half_fov: f64::from(b.tan_half_fov),
            aspect: f64::from(b.aspect),
            width: f64::from(scene.camera.width),
            height: f64::from(scene.camera.height),
        }
    }

    /// Unit direction of the camera ray through film point s (pixels).
    fn direction(&self, s: [f64; 2]) -> DVec3 {
        let x = (2.0 * s[0] / self.width - 1.0) * self.aspect * self.tan_half_fov;
        let y = (1.0 - 2.0 * s[1] / self.height) * self.tan_half_fov;
        (self.forward + x * self.right + y * self.up).normalize()
    }

    /// Film point (pixels) of direction d from the eye; None behind the eye.
    fn film_point(&self, d: DVec3) -> Option<[f64; 2]> {
        let z = d.dot(self.forward);
        if z <= 1e-9 {
            return None;
        }
        let x = d.dot(self.right) / z;
        let y = d.dot(self.up) / z;
        Some([
            (x / (self.aspect * self.tan_half_fov) + 1.0) * 0.5 * self.width,
            (1.0 - y / self.tan_half_fov) * 0.5 * self.height,
        ])
    }

    /// Area of one pixel on the image plane at distance 1.
    fn pixel_area(&self) -> f64 {
        (2.0 * self.aspect * self.tan_half_fov / self.width) * (2.0 * self.tan_half_fov / self.height)
    }

    fn pixel(&self, s: [f64; 2]) -> Option<usize> {
        let inside = s[0] >= 0.0 && s[0] < self.width && s[1] >= 0.0 && s[1] < self.height;
        inside.then(|| s[1].floor() as usize * self.width as usize + s[0].floor() as usize)
    }
}

struct Solver {
    bodies: Bodies,
    film: Film,
    /// Toward the sun, and two unit vectors completing the frame (the gnomonic axes).
    w: DVec3,
    t1: DVec3,
    t2: DVec3,
    irradiance: [f64; 3],
    max_scatterings: usize,
}

/// A leaf of the specular tree from one seed: its chain and the direction it leaves in.
struct Leaf {
    chain: Vec<Step>,
    seed: [f64; 2],
    cos_to_sun: f64,
}

impl Solver {
    fn new(scene: &Scene) -> Self {
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
        }
    }

    fn solve(&self) -> Vec<GlintPoint> {
        let mut leaves = Vec::new();
        for seed in self.seeds() {
            let mut chain = Vec::new();
            let d = self.film.direction(seed);
            self.explore(seed, self.film.eye, d, None, [1.0; 3], &mut chain, &mut leaves);
        }
        // The sun seen directly: the empty chain, seeded at the sun's own film point.
        if let Some(s) = self.film.film_point(self.w) {
            leaves.push(Leaf { chain: Vec::new(), seed: s, cos_to_sun: 1.0 });
        }
        leaves.sort_by(|a, b| a.chain.cmp(&b.chain).then(b.cos_to_sun.total_cmp(&a.cos_to_sun)));
        let mut points: Vec<GlintPoint> = Vec::new();
        let mut start = 0;
        while start < leaves.len() {
            let end = start + leaves[start..].iter().take_while(|l| l.chain == leaves[start].chain).count();
            let chain = &leaves[start].chain;
            // The seeds nearest the sun first; Newton from each of the best few.
            for leaf in leaves[start..end].iter().take(NEWTON_STARTS) {
                if let Some(point) = self.newton(leaf.seed, chain)
                    && !points.iter().any(|p| p.chain == point.chain && same_point(p.film, point.film))
                {
                    points.push(point);
                }
            }
            start = end;
        }
        points.sort_by(|a, b| a.pixel.cmp(&b.pixel).then(a.chain.cmp(&b.chain)));
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
        seed: [f64; 2],
        o: DVec3,
        d: DVec3,
        own: Option<usize>,
        throughput: [f64; 3],
        chain: &mut Vec<Step>,
        leaves: &mut Vec<Leaf>,
    ) {
        let Some(hit) = self.bodies.nearest(o, d, own) else {
            if !chain.is_empty() {
                leaves.push(Leaf { chain: chain.clone(), seed, cos_to_sun: d.dot(self.w) });
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
                self.explore(seed, p, d2, Some(hit.object), t, chain, leaves);
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
            let hit = self.bodies.nearest(o, d, own).filter(|h| h.object == object)?;
            let (d2, weight) = scatter(self.bodies.surface(object), d, hit.normal, event)?;
            throughput = [0, 1, 2].map(|c| throughput[c] * weight[c]);
            o += hit.t * d;
            d = d2;
            own = Some(object);
        }
        self.bodies.nearest(o, d, own).is_none().then_some((d, throughput))
    }

    /// Gnomonic coordinates of the leaving direction about w (None behind the sun's hemisphere).
    fn residual(&self, s: [f64; 2], chain: &[Step]) -> Option<([f64; 2], [f64; 3])> {
        let (d, throughput) = self.follow(s, chain)?;
        let z = d.dot(self.w);
        (z > 1e-6).then(|| ([d.dot(self.t1) / z, d.dot(self.t2) / z], throughput))
    }

    /// dg/ds at s: central differences of step h and h/2, extrapolated (error O(h^4)). Retries
    /// with smaller steps where a difference leaves the chain.
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
            let j = self.jacobian(s, chain)?;
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
