//! Manifold next-event estimation (MNEE) with a delta sun through one specular sphere, in f64:
//! the irradiance the sun sends to a diffuse point x through a chain of specular events on one
//! sphere (`manifold_chain.rs` derives the chains), summed over every such path exactly, with
//! no random numbers. docs/caustics-manifold.md has the derivation and what it leaves out.
//!
//! 1-D reduction. A sun ray meeting sphere k (centre c, radius R) and everything it does inside
//! stays in the meridional plane spanned by the axis through c along w_s and the ray. For x:
//! v = x - c, z = v.w_s, rho = v - z w_s, r_x = |rho|, e = rho / r_x; in the plane's
//! coordinates (r along e, z along w_s, unit R) a path to x is a theta1 with g(theta1) = 0 and
//! t = u.(x' - q) > 0 (x' = (r_x, z) / R, exit point q, direction u).
//!
//! Weight. Sun rays of impact parameter b in db and azimuth in dpsi carry E |b| db dpsi; at x
//! they cover |dg/db| db across the ray in the plane and r_x dpsi out of it (rotation about the
//! axis), both perpendicular to the 3-D arrival direction u3 = u_r e + u_z w_s. So the beam's
//! concentration is C = |b| / (|dg/db| r_x) = |sin theta1| cos theta1 / (|dg/dtheta1| r_x / R)
//! (C = 1 with no sphere: g = b - r_x), and the path adds
//!     E_sun w C max(n_s.(-u3), 0),   zero unless n_g.(-u3) > 0,
//! w the chain's weight (a mirror's reflectance, or F, (1 - F)^2, (1 - F)^2 F for R, TT, TRT).
//! C diverges at folds (dg/db = 0, the caustic's rim) and on the axis (r_x = 0); it is clamped
//! to `max_concentration` when one is set. Unbounded, a path of infinite C (x exactly on a
//! fold or the axis, a set of measure zero) is left out rather than poisoning the image.
//!
//! Visibility. The sun's segment from the first hit p1 toward the light and the segment from x
//! to the exit point must be unblocked; the chain's inside is not tested, which is why the
//! estimator is defined only for spheres no other object enters (illum-scene's `specular_spheres::solvable_spheres`, the rule the path tracer also asks).
//!
//! Roots. g is tabulated (in unit-sphere coordinates, linear in x': z sin f - r cos f + sin theta1)
//! on `intervals` equal intervals of theta1 over (-pi/2, pi/2). A sign change is refined by
//! safeguarded Newton; an interval without one is searched for a hidden pair of roots (near a
//! fold) when both ends are within 2 h max|dg/dtheta1| of zero, h the interval's width (g cannot
//! reach zero inside otherwise; the factor 2 covers f' between nodes): if g' changes sign there
//! and g heads toward zero, the extremum is found by bisection on g' and, if g crosses zero
//! there, both roots are refined. What this misses needs three or more roots within one
//! interval (~8e-4 rad for 4096), which happens only next to a cusp of the caustic.
//!
//! Path length: a chain of k events at a diffuse vertex of depth d (continuation rays before
//! it) counts under `Bounces::Fixed(n)` when d + k + 1 <= n, as the light tracer's L S^k D E.

use std::f64::consts::{FRAC_PI_2, PI};

use glam::{DVec2, DVec3};
use illum_scene::{Bounces, MaterialKind};

use crate::geometry::Surface;
use crate::manifold_chain::Chain;
use crate::sampling::local_to_world;
use crate::scene::{Primitive, Sun};

/// What MNEE adds: which chains, the bound on the concentration and the root grid.
#[derive(Clone, Debug, PartialEq)]
pub struct ManifoldSettings {
    /// The chains tried on every dielectric sphere; a mirror sphere takes only `Chain::R`.
    pub chains: Vec<Chain>,
    /// The bound C_max on the concentration C (`None`: unbounded).
    pub max_concentration: Option<f64>,
    /// Equal intervals of theta1 over (-pi/2, pi/2) in the root search.
    pub intervals: usize,
}

impl ManifoldSettings {
    /// R and T R^m T for m = 0..=`internal` (internal reflections at most `internal`),
    /// unbounded C, 4096 intervals.
    pub fn with_internal_reflections(internal: u32) -> ManifoldSettings {
        ManifoldSettings {
            chains: (0..=internal + 1).map(|chords| Chain { chords }).collect(),
            max_concentration: None,
            intervals: 4096,
        }
    }
}

impl Default for ManifoldSettings {
    /// R, TT and TRT (K = 1), unbounded.
    fn default() -> Self {
        ManifoldSettings::with_internal_reflections(1)
    }
}

/// One path MNEE found at a point: its sphere (index among the specular spheres, scene order),
/// chain, incidence theta1, concentration C (after the bound) and irradiance.
#[derive(Clone, Copy, Debug)]
pub struct ManifoldPath {
    pub sphere: usize,
    pub chain: Chain,
    pub theta1: f64,
    pub concentration: f64,
    pub irradiance: DVec3,
}

/// g's pieces at the grid's nodes for one chain and index: sin f, cos f, sin theta1, f',
/// cos theta1 (NaN where the chain does not exist).
#[derive(Clone, Debug)]
pub(crate) struct ChainTable {
    chain: Chain,
    n: f64,
    rows: Vec<[f64; 5]>,
    /// max |f'| over the nodes, for the bound |dg/dtheta1| <= max|f'| |x'| + 1.
    rate_bound: f64,
}

impl ChainTable {
    pub(crate) fn new(chain: Chain, n: f64, intervals: usize) -> ChainTable {
        let rows: Vec<[f64; 5]> = (0..=intervals)
            .map(|i| {
                let theta1 = node(i, intervals);
                chain
                    .exit(n, theta1)
                    .map_or([f64::NAN; 5], |e| [e.u.x, e.u.y, theta1.sin(), e.turn_rate, theta1.cos()])
            })
            .collect();
        let rate_bound = rows.iter().map(|r| r[3].abs()).filter(|r| r.is_finite()).fold(0.0, f64::max);
        ChainTable { chain, n, rows, rate_bound }
    }

    /// Every theta1 with g = 0 for the unit-sphere point `x`, in increasing order.
    pub(crate) fn roots(&self, x: DVec2, out: &mut Vec<f64>) {
        let intervals = self.rows.len() - 1;
        // Twice the bound on |g(b) - g(a)|: f' between nodes may exceed its largest node value.
        let near = 2.0 * PI / intervals as f64 * (self.rate_bound * x.length() + 1.0);
        let g = |r: &[f64; 5]| x.y * r[0] - x.x * r[1] + r[2];
        let dg = |r: &[f64; 5]| r[3] * (x.y * r[1] + x.x * r[0]) + r[4];
        let mut ga = g(&self.rows[0]);
        for i in 0..intervals {
            let gb = g(&self.rows[i + 1]);
            let (a, b) = (node(i, intervals), node(i + 1, intervals));
            if ga == 0.0 {
                out.push(a);
            } else if ga * gb < 0.0 {
                out.push(self.refine(x, a, b, ga));
            } else if ga.abs() < near && gb.abs() < near {
                let (da, db) = (dg(&self.rows[i]), dg(&self.rows[i + 1]));
                if da * db < 0.0 && ga * da < 0.0 {
                    self.hidden_pair(x, a, b, ga, da, out);
                }
            }
            ga = gb;
        }
    }

    /// g(a) and g(b) share a sign, g'(a) = `da` heads toward zero and g' changes sign on
    /// (a, b): bisection on g' for the extremum m, then the roots on each side if g(m) crosses.
    fn hidden_pair(&self, x: DVec2, a: f64, b: f64, ga: f64, da: f64, out: &mut Vec<f64>) {
        let (mut lo, mut hi) = (a, b);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            match self.chain.miss(self.n, mid, x) {
                Some((_, d)) if (d > 0.0) == (da > 0.0) => lo = mid,
                Some(_) => hi = mid,
                None => return,
            }
        }
        let m = 0.5 * (lo + hi);
        let Some((gm, _)) = self.chain.miss(self.n, m, x) else { return };
        if gm == 0.0 {
            out.push(m);
        } else if gm * ga < 0.0 {
            out.push(self.refine(x, a, m, ga));
            out.push(self.refine(x, m, b, gm));
        }
    }

    /// The root in (lo, hi) given g(lo) = `g_lo` and g(hi) of the other sign: Newton, falling
    /// back to bisection when a step leaves the bracket, to |step| or the bracket below 1e-13.
    fn refine(&self, x: DVec2, mut lo: f64, mut hi: f64, g_lo: f64) -> f64 {
        let mut t = 0.5 * (lo + hi);
        for _ in 0..100 {
            let Some((g, dg)) = self.chain.miss(self.n, t, x) else { return t };
            if g == 0.0 {
                return t;
            }
            if (g > 0.0) == (g_lo > 0.0) {
                lo = t;
            } else {
                hi = t;
            }
            let newton = t - g / dg;
            let next = if newton > lo && newton < hi { newton } else { 0.5 * (lo + hi) };
            let step = (next - t).abs();
            t = next;
            if step < 1e-14 || hi - lo < 1e-13 {
                break;
            }
        }
        t
    }
}

/// Node i of `intervals` equal intervals over [-pi/2, pi/2].
fn node(i: usize, intervals: usize) -> f64 {
    -FRAC_PI_2 + PI * i as f64 / intervals as f64
}

#[derive(Clone, Copy, Debug)]
enum SphereOptics {
    Mirror(DVec3),
    Dielectric(f64),
}

#[derive(Clone, Debug)]
struct SpecularSphere {
    centre: DVec3,
    radius: f64,
    optics: SphereOptics,
    tables: Vec<ChainTable>,
}

/// MNEE's precomputed state: the settings and, per specular sphere, its chains' tables.
#[derive(Clone, Debug)]
pub(crate) struct Manifold {
    settings: ManifoldSettings,
    spheres: Vec<SpecularSphere>,
}

/// The oracle's shadow-ray offsets (integrator.rs): how far a ray starts off its surface, relative
/// to the point's magnitude, and the fraction a segment to a surface ends short of it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Offsets {
    pub spawn: f64,
    pub shorten: f64,
}

impl Manifold {
    /// MNEE over the specular spheres among `surfaces`.
    pub(crate) fn new(surfaces: &[Primitive], settings: ManifoldSettings) -> Manifold {
        let spheres = surfaces
            .iter()
            .filter_map(|p| {
                let Surface::Ball(ball) = p.surface else { return None };
                let (optics, chains): (SphereOptics, Vec<Chain>) = match p.material {
                    MaterialKind::Mirror { reflectance } => (
                        SphereOptics::Mirror(reflectance.as_dvec3()),
                        settings.chains.iter().copied().filter(|c| c.chords == 0).collect(),
                    ),
                    MaterialKind::Dielectric { ior } => {
                        (SphereOptics::Dielectric(f64::from(ior)), settings.chains.clone())
                    }
                    _ => return None,
                };
                let n = match optics {
                    SphereOptics::Dielectric(n) => n,
                    SphereOptics::Mirror(_) => 1.0,
                };
                let tables = chains.into_iter().map(|c| ChainTable::new(c, n, settings.intervals)).collect();
                Some(SpecularSphere { centre: ball.center, radius: ball.radius, optics, tables })
            })
            .collect();
        Manifold { settings, spheres }
    }
}

impl Manifold {
    /// Every path MNEE finds at x with a nonzero contribution (see the oracle's
    /// `manifold_paths`), under `sun` and `bounces`; `blocked(o, d, t_max)` is the oracle's
    /// shadow test and `offsets` its offsets.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn paths(
        &self,
        sun: Sun,
        bounces: Bounces,
        offsets: Offsets,
        blocked: &dyn Fn(DVec3, DVec3, f64) -> bool,
        (x, normal, shading): (DVec3, DVec3, DVec3),
        depth: u32,
    ) -> Vec<ManifoldPath> {
        let mut paths = Vec::new();
        if !sun.is_delta() {
            return paths;
        }
        let manifold = self;
        let w_s = -sun.to_light;
        let mut roots = Vec::new();
        for (index, sphere) in self.spheres.iter().enumerate() {
            let v = x - sphere.centre;
            let z = v.dot(w_s);
            let rho = v - z * w_s;
            let r_x = rho.length();
            // On the axis any e will do: C is infinite there (clamped, or left out).
            let e = if r_x > 0.0 { rho / r_x } else { local_to_world(w_s, DVec3::X) };
            let unit = DVec2::new(r_x, z) / sphere.radius;
            for table in &sphere.tables {
                if let Bounces::Fixed(n) = bounces
                    && depth + table.chain.events() + 1 > n
                {
                    continue;
                }
                roots.clear();
                table.roots(unit, &mut roots);
                for &theta1 in &roots {
                    let at = (x, normal, shading);
                    if let Some(path) =
                        manifold.path(sun, offsets, blocked, sphere, table, at, (e, unit, theta1))
                    {
                        paths.push(ManifoldPath { sphere: index, ..path });
                    }
                }
            }
        }
        paths
    }

    /// The contribution of the root theta1 of `table` at x (plane frame e, unit-sphere point
    /// `unit`), or `None` when it is behind the exit, from behind the surface, blocked or
    /// carries nothing.
    #[allow(clippy::too_many_arguments)]
    fn path(
        &self,
        sun: Sun,
        offsets: Offsets,
        blocked: &dyn Fn(DVec3, DVec3, f64) -> bool,
        sphere: &SpecularSphere,
        table: &ChainTable,
        (x, normal, shading): (DVec3, DVec3, DVec3),
        (e, unit, theta1): (DVec3, DVec2, f64),
    ) -> Option<ManifoldPath> {
        let manifold = self;
        let w_s = -sun.to_light;
        let exit = table.chain.exit(table.n, theta1)?;
        if exit.u.dot(unit - exit.q) <= 0.0 {
            return None;
        }
        let (_, dg) = table.chain.miss(table.n, theta1, unit)?;
        let mut concentration = theta1.sin().abs() * theta1.cos() / (dg.abs() * unit.x);
        if let Some(bound) = manifold.settings.max_concentration {
            concentration = concentration.min(bound);
        }
        let u3 = exit.u.x * e + exit.u.y * w_s;
        let cos_s = shading.dot(-u3);
        if !(concentration.is_finite() && concentration > 0.0 && cos_s > 0.0 && normal.dot(-u3) > 0.0) {
            return None;
        }
        let weight = match sphere.optics {
            SphereOptics::Mirror(reflectance) => reflectance,
            SphereOptics::Dielectric(n) => DVec3::splat(table.chain.dielectric_weight(n, theta1)),
        };
        if !weight.cmpgt(DVec3::ZERO).any() {
            return None;
        }
        // The sun's segment from the first hit, lifted off the sphere along its normal.
        let n1 = theta1.sin() * e - theta1.cos() * w_s;
        let p1 = sphere.centre + sphere.radius * n1;
        let lift = offsets.spawn * p1.abs().max_element().max(1.0);
        if blocked(p1 + lift * n1, sun.to_light, f64::INFINITY) {
            return None;
        }
        // The segment from x to the exit point, ending short of the sphere.
        let q = sphere.centre + sphere.radius * (exit.q.x * e + exit.q.y * w_s);
        let dist = (q - x).length();
        if blocked(x, (q - x) / dist, dist * (1.0 - offsets.shorten)) {
            return None;
        }
        Some(ManifoldPath {
            sphere: 0,
            chain: table.chain,
            theta1,
            concentration,
            irradiance: sun.irradiance * weight * (concentration * cos_s),
        })
    }
}
