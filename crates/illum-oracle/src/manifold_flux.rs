//! The proof of MNEE's weight, independent of its root solve: parallel sun rays traced in 3-D
//! through the oracle's own sphere intersection and optics, each following one chain's events
//! deterministically with that chain's power fraction, land on a floor; each floor cell's power
//! (rays x weight x flux per ray) must equal MNEE's irradiance integrated over the cell by
//! quadrature, within the rays' Poisson noise. Cells across the caustics' bright rims (the
//! glass ball's focal caustic, the rainbow fold of TRT) are included and counted.

use glam::DVec3;
use illum_scene::{Bounces, Scene};

use crate::Oracle;
use crate::geometry::Ball;
use crate::manifold::ManifoldSettings;
use crate::manifold_chain::Chain;
use crate::optics::{fresnel, reflect, refract};
use crate::parallel::in_parallel;
use crate::rng::Rng;
use crate::sampling::local_to_world;

/// One comparison: a ball of radius 1 at height `height` above the floor y = 0 under a sun
/// travelling along `sun`, one `chain`, floor cells of side `cell` over [-half, half]^2.
struct Case {
    label: &'static str,
    material: &'static str,
    chain: Chain,
    /// The index (ignored by a mirror) and a mirror's reflectance.
    n: f64,
    mirror: Option<f64>,
    sun: [f64; 3],
    height: f64,
    half: f64,
    cell: f64,
}

const RAYS: u64 = 4 << 20;
/// A concentration this large marks a cell on a caustic's rim.
const RIM: f64 = 10.0;

impl Case {
    fn centre(&self) -> DVec3 {
        DVec3::new(0.0, self.height, 0.0)
    }

    fn cells(&self) -> usize {
        (2.0 * self.half / self.cell).round() as usize
    }

    fn scene(&self) -> Scene {
        let [a, b, c] = self.sun;
        let text = format!(
            "[camera]\neye = [0.0, 9.0, 0.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 0.0, 1.0]\nvfov = 40.0\n\
             width = 8\nheight = 8\n[directional_light]\ndirection = [{a}, {b}, {c}]\nirradiance = [1.0, 1.0, 1.0]\n\
             [materials.floor]\nalbedo = [0.5, 0.5, 0.5]\n[materials.ball]\n{}\n\
             [[objects]]\nmaterial = \"floor\"\n\
             quad = {{ corner = [-50.0, 0.0, -50.0], edge_u = [0.0, 0.0, 100.0], edge_v = [100.0, 0.0, 0.0] }}\n\
             [[objects]]\nmaterial = \"ball\"\nsphere = {{ center = [0.0, {}, 0.0], radius = 1.0 }}\n",
            self.material, self.height
        );
        Scene::from_toml_str(&text, "flux.toml").unwrap_or_else(|e| panic!("{e}"))
    }

    fn cell_of(&self, p: DVec3) -> Option<usize> {
        let cells = self.cells();
        let (i, j) = (((p.x + self.half) / self.cell).floor(), ((p.z + self.half) / self.cell).floor());
        (i >= 0.0 && j >= 0.0 && (i as usize) < cells && (j as usize) < cells)
            .then(|| j as usize * cells + i as usize)
    }
}

/// A sun ray from `start` along `sun` through the case's chain on its ball, step by step: where it lands on the floor y = 0 and
/// the fraction of its power that arrives, or `None`.
fn trace(case: &Case, start: DVec3, sun: DVec3) -> Option<(DVec3, f64)> {
    let (chain, n, mirror) = (case.chain, case.n, case.mirror);
    let ball = Ball { center: case.centre(), radius: 1.0 };
    let eps = 1e-9;
    let hit = ball.intersect(start, sun, f64::INFINITY)?;
    let (p, normal) = (start + hit.t * sun, hit.normal);
    let (mut o, mut d, mut weight);
    if chain.chords == 0 {
        weight = mirror.unwrap_or_else(|| {
            let t = refract(sun, normal, 1.0 / n);
            t.map_or(1.0, |t| fresnel(-sun.dot(normal), -t.dot(normal), 1.0 / n))
        });
        (o, d) = (p + eps * normal, reflect(sun, normal));
    } else {
        let t = refract(sun, normal, 1.0 / n)?;
        weight = 1.0 - fresnel(-sun.dot(normal), -t.dot(normal), 1.0 / n);
        (o, d) = (p - eps * normal, t);
        for chord in 0..chain.chords {
            let hit = ball.intersect(o, d, f64::INFINITY)?;
            let (p, inward) = (o + hit.t * d, -hit.normal);
            let out = refract(d, inward, n);
            let f = out.map_or(1.0, |t| fresnel(-d.dot(inward), -t.dot(inward), n));
            if chord + 1 < chain.chords {
                weight *= f;
                (o, d) = (p + eps * inward, reflect(d, inward));
            } else {
                weight *= 1.0 - f;
                (o, d) = (p - eps * inward, out?);
            }
        }
    }
    if d.y >= 0.0 {
        return None;
    }
    Some((o - o.y / d.y * d, weight))
}

/// Per cell: the rays' power and its variance (Poisson: flux^2 sum of weight^2).
fn ray_histogram(case: &Case, rays: u64) -> Vec<(f64, f64)> {
    let cells = case.cells();
    let w_s = DVec3::from(case.sun).normalize();
    // Rays uniform on the square [-1, 1]^2 across the beam: flux 4 E R^2 / rays each.
    let flux = 4.0 / rays as f64;
    let batches = 64u32;
    let parts = in_parallel(batches, crate::default_threads(), |batch| {
        let mut rng = Rng::for_sample(0x5eed, u64::from(batch), 0);
        let mut part = vec![(0.0, 0.0); cells * cells];
        for _ in 0..rays / u64::from(batches) {
            let (s, t) = (2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0);
            let o = case.centre() - 5.0 * w_s + local_to_world(w_s, DVec3::new(s, t, 0.0));
            if let Some((p, w)) = trace(case, o, w_s)
                && let Some(c) = case.cell_of(p)
            {
                part[c].0 += flux * w;
                part[c].1 += flux * flux * w * w;
            }
        }
        part
    });
    let mut total = vec![(0.0, 0.0); cells * cells];
    for part in parts {
        for (t, p) in total.iter_mut().zip(part) {
            t.0 += p.0;
            t.1 += p.1;
        }
    }
    total
}

/// MNEE at the floor point (x, z): irradiance (red channel), the number of paths and the
/// largest concentration.
fn floor_irradiance(oracle: &Oracle, x: f64, z: f64) -> (f64, usize, f64) {
    let paths = oracle.manifold_paths(DVec3::new(x, 1e-9, z), DVec3::Y, DVec3::Y, 0);
    let peak = paths.iter().map(|p| p.concentration).fold(0.0, f64::max);
    (paths.iter().map(|p| p.irradiance.x).sum(), paths.len(), peak)
}

/// The integral over the square (x0, z0, side) and the largest concentration met. The rule is
/// the midpoint rule on 4 x 4 points, with the square split into quarters (to `depth` levels)
/// where it is not smooth: where the number of paths differs among those points and the
/// square's corners (a fold, where a pair of paths is born with C -> infinity, or a shadow's
/// edge passes) or C exceeds RIM (near a fold or the sun's axis). A square holding the axis
/// point `axis` (where C grows as 1 / r_x) at the last level is integrated by Duffy's rule:
/// four triangles with apex there, p = apex + s (v0 - apex + t (v1 - v0)),
/// dA = s |cross(v0 - apex, v1 - v0)| ds dt, whose factor s cancels 1 / r_x.
fn cubature(oracle: &Oracle, square: (f64, f64, f64), axis: (f64, f64), depth: u32) -> (f64, f64) {
    let (x0, z0, side) = square;
    let corners = [(x0, z0), (x0 + side, z0), (x0 + side, z0 + side), (x0, z0 + side)];
    let holds_axis = (x0..x0 + side).contains(&axis.0) && (z0..z0 + side).contains(&axis.1);
    let h = side / 4.0;
    let mut points: Vec<((f64, f64), f64)> = (0..16)
        .map(|k| ((x0 + (f64::from(k % 4) + 0.5) * h, z0 + (f64::from(k / 4) + 0.5) * h), h * h))
        .collect();
    if depth == 0 && holds_axis {
        points.clear();
        for k in 0..4 {
            let (v0, v1) = (corners[k], corners[(k + 1) % 4]);
            let (a, b) = ((v0.0 - axis.0, v0.1 - axis.1), (v1.0 - v0.0, v1.1 - v0.1));
            let jacobian = (a.0 * b.1 - a.1 * b.0).abs();
            for i in 0..8 {
                for j in 0..8 {
                    let (s, t) = ((f64::from(i) + 0.5) / 8.0, (f64::from(j) + 0.5) / 8.0);
                    let p = (axis.0 + s * (a.0 + t * b.0), axis.1 + s * (a.1 + t * b.1));
                    points.push((p, s * jacobian / 64.0));
                }
            }
        }
    }
    let (mut sum, mut peak) = (0.0, 0.0f64);
    let mut counts = Vec::with_capacity(points.len() + 4);
    for (p, weight) in &points {
        let (e, n, c) = floor_irradiance(oracle, p.0, p.1);
        sum += e * weight;
        peak = peak.max(c);
        counts.push(n);
    }
    if depth == 0 {
        return (sum, peak);
    }
    for c in corners {
        counts.push(floor_irradiance(oracle, c.0, c.1).1);
    }
    if peak <= RIM && counts.iter().all(|&n| n == counts[0]) {
        return (sum, peak);
    }
    let half = 0.5 * side;
    [(x0, z0), (x0 + half, z0), (x0, z0 + half), (x0 + half, z0 + half)].into_iter().fold(
        (0.0, peak),
        |(total, top), (x, z)| {
            let (s, p) = cubature(oracle, (x, z, half), axis, depth - 1);
            (total + s, top.max(p))
        },
    )
}

/// Per cell: MNEE's irradiance integrated over it ([`cubature`], to 7 levels), and the
/// largest concentration met.
fn mnee_cells(case: &Case, oracle: &Oracle) -> Vec<(f64, f64)> {
    let (cells, half, cell) = (case.cells(), case.half, case.cell);
    let w_s = DVec3::from(case.sun).normalize();
    let axis = case.centre() - case.height / w_s.y * w_s;
    in_parallel((cells * cells) as u32, crate::default_threads(), |c| {
        let (i, j) = (c as usize % cells, c as usize / cells);
        cubature(oracle, (-half + i as f64 * cell, -half + j as f64 * cell, cell), (axis.x, axis.z), 7)
    })
}

/// Compares the two per cell and in total; returns (cells compared, cells on a rim (a fold or
/// the sun's axis: C above RIM), worst |z|).
fn compare(case: &Case) -> (usize, usize, f64) {
    let label = case.label;
    let settings = ManifoldSettings { chains: vec![case.chain], ..ManifoldSettings::default() };
    let oracle =
        Oracle::new(&case.scene()).unwrap().with_bounces(Bounces::Unbounded).with_manifold(Some(settings));
    let start = std::time::Instant::now();
    let rays = ray_histogram(case, RAYS);
    let mnee = mnee_cells(case, &oracle);
    let (mut compared, mut rim, mut worst) = (0, 0, 0.0f64);
    let (mut total_rays, mut total_mnee, mut total_var) = (0.0, 0.0, 0.0);
    let largest = mnee.iter().map(|m| m.0).fold(0.0, f64::max);
    for (c, (&(power, var), &(integral, peak))) in rays.iter().zip(&mnee).enumerate() {
        total_rays += power;
        total_mnee += integral;
        total_var += var;
        if power == 0.0 && integral == 0.0 {
            continue;
        }
        // Poisson noise of the rays (at least that of the expected count), and for the
        // cubature 0.3% of the cell's power plus 0.1% of the largest cell's (a fold clipping
        // a corner can leave a sliver of light thinner than the spacing of the points).
        let quadrature = 0.003 * integral + 0.001 * largest;
        let sigma = (var.max(4.0 / RAYS as f64 * integral) + quadrature * quadrature).sqrt();
        let z = (power - integral) / sigma;
        compared += 1;
        if peak > RIM {
            rim += 1;
        }
        worst = worst.max(z.abs());
        assert!(
            z.abs() < 5.0,
            "{label}: cell {c} rays {power:.6e} +- {:.2e}, MNEE {integral:.6e} (peak C {peak:.1}), z {z:.2}",
            var.sqrt()
        );
    }
    println!(
        "{label}: {compared} cells ({rim} on a rim), worst |z| {worst:.2}, totals rays {total_rays:.5} \
         MNEE {total_mnee:.5}, {:.1} s",
        start.elapsed().as_secs_f64()
    );
    let sigma = (total_var + (0.002 * total_mnee).powi(2)).sqrt();
    assert!(
        (total_rays - total_mnee).abs() < 5.0 * sigma,
        "{label}: totals {total_rays} vs {total_mnee} +- {sigma}"
    );
    (compared, rim, worst)
}

/// Guards MNEE's weight (concentration, Fresnel factors, cosine, root enumeration) for TT, TRT
/// and R on glass and R on a mirror: a wrong factor anywhere, a missed root pair at a fold or a
/// wrong sign moves some cell's power by many standard deviations.
#[test]
fn mnee_irradiance_integrates_to_the_power_traced_rays_deliver() {
    let glass = "dielectric = { ior = 1.5 }";
    let water = "dielectric = { ior = 1.33 }";
    let low = [-1.0, -0.36, 0.15];
    let base = Case {
        label: "",
        material: glass,
        chain: Chain::TT,
        n: 1.5,
        mirror: None,
        sun: low,
        height: 2.0,
        half: 10.0,
        cell: 0.5,
    };
    let cases = [
        // A high sun and the floor through the focal caustic (between the marginal and the
        // paraxial focus, 1 to 1.5 radii from the centre).
        Case { label: "glass TT", sun: [-0.15, -1.0, 0.1], height: 1.25, half: 2.0, cell: 0.1, ..base },
        // Water's rainbow (42 degrees) reaches the floor under a low sun.
        Case { label: "water TRT", material: water, chain: Chain::TRT, n: 1.33, ..base },
        Case { label: "glass R", chain: Chain::R, ..base },
        Case {
            label: "mirror R",
            material: "mirror = { reflectance = [0.9, 0.9, 0.9] }",
            chain: Chain::R,
            mirror: Some(0.9f32 as f64),
            ..base
        },
    ];
    for case in &cases {
        let (compared, rim, _) = compare(case);
        assert!(compared >= 20, "{}: {compared} cells", case.label);
        if case.chain != Chain::R {
            assert!(rim >= 3, "{}: {rim} cells on a rim", case.label);
        }
    }
}
