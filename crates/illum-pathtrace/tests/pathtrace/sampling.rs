//! Chi-square tests of the WGSL sampling routines, run on the GPU through a small compute
//! harness so that the shader code itself is what is tested (as Mitsuba tests its samplers).
//!
//! Each routine draws N = 2^20 samples from `illum::rng`. The samples are binned on a grid whose
//! cell probabilities are integrated from the routine's pdf in closed form here, in f64,
//! independently of the shader; Pearson's statistic is compared with the chi-square critical
//! value at alpha = 0.01 (Wilson-Hilferty approximation, accurate to <1% at these degrees of
//! freedom). Cells expecting fewer than 5 samples are pooled, as the test requires.

use std::f64::consts::PI;

use glam::DVec3;
use illum_oracle::chi_square;
use illum_pathtrace::SAMPLING_MODULES;

use crate::common;

const N: u32 = 1 << 20;
const ALPHA: f64 = 0.01;

/// Runs `expression` (WGSL, may use u1, u2 in [0, 1) and must give a vec3<f32>) for N samples.
fn run_on_gpu(expression: &str, seed: u32) -> Vec<DVec3> {
    let source = format!(
        "#import illum::rng::{{rng_seed, rng_f32}}
#import illum::sampling::{{sample_cosine_hemisphere, sample_uniform_hemisphere, sample_uniform_cone, to_world, sample_parallelogram, sample_disc, sample_light_bilinear}}
@group(0) @binding(0) var<storage, read_write> samples: array<vec4<f32>>;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {{
    let i = gid.x + 65536u * gid.y;
    if (i >= arrayLength(&samples)) {{ return; }}
    var rng = rng_seed({seed}u, i, 0u);
    let u1 = rng_f32(&rng);
    let u2 = rng_f32(&rng);
    samples[i] = vec4<f32>({expression}, 0.0);
}}
"
    );
    let groups = N / 64;
    let bytes = common::run_compute(
        "sampling harness",
        SAMPLING_MODULES,
        source,
        &[],
        N as u64 * 16,
        (groups.min(1024), groups.div_ceil(1024), 1),
    );
    bytes
        .chunks_exact(16)
        .map(|c| {
            let f = |i: usize| f32::from_le_bytes(c[4 * i..4 * i + 4].try_into().expect("4 bytes")) as f64;
            DVec3::new(f(0), f(1), f(2))
        })
        .collect()
}

/// Pearson's test of observed counts against cell probabilities (`illum_oracle::chi_square`,
/// which pools cells expecting < 5) at alpha = [`ALPHA`].
fn chi_square_test(name: &str, observed: &[u64], probability: &[f64]) {
    let outcome = chi_square::pearson(observed, probability, ALPHA);
    let (statistic, critical) = (outcome.statistic, outcome.critical);
    println!("{name}: chi2 = {statistic:.1}, critical {critical:.1} ({} cells)", outcome.cells);
    assert!(statistic < critical, "{name}: chi-square {statistic:.1} exceeds {critical:.1} at alpha {ALPHA}");
}

/// An orthonormal frame (t, b) around n, built independently of the shader's.
fn frame(n: DVec3) -> (DVec3, DVec3) {
    let helper = if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    let t = n.cross(helper).normalize();
    (t, n.cross(t))
}

const THETA_BINS: usize = 16;
const PHI_BINS: usize = 16;

/// Bins directions by (theta, phi) around n; also checks they are unit and in the hemisphere.
fn bin_directions(name: &str, samples: &[DVec3], n: DVec3) -> Vec<u64> {
    let (t, b) = frame(n);
    let mut counts = vec![0u64; THETA_BINS * PHI_BINS];
    for d in samples {
        assert!((d.length() - 1.0).abs() < 1e-5, "{name}: direction {d} is not unit length");
        let cos_theta = d.dot(n);
        assert!(cos_theta >= -1e-6, "{name}: direction {d} is below the hemisphere");
        let theta = cos_theta.clamp(0.0, 1.0).acos();
        let phi = d.dot(b).atan2(d.dot(t)).rem_euclid(2.0 * PI);
        let i = ((theta / (PI / 2.0) * THETA_BINS as f64) as usize).min(THETA_BINS - 1);
        let j = ((phi / (2.0 * PI) * PHI_BINS as f64) as usize).min(PHI_BINS - 1);
        counts[i * PHI_BINS + j] += 1;
    }
    counts
}

/// Cell probabilities from a pdf that depends on theta only, through its integral over theta:
/// P(cell) = (dphi / 2pi) * (F(theta1) - F(theta0)), F = CDF of theta.
fn theta_cells(theta_cdf: impl Fn(f64) -> f64) -> Vec<f64> {
    let mut p = Vec::new();
    for i in 0..THETA_BINS {
        let (t0, t1) = (i as f64, (i + 1) as f64);
        let (t0, t1) = (t0 * PI / 2.0 / THETA_BINS as f64, t1 * PI / 2.0 / THETA_BINS as f64);
        for _ in 0..PHI_BINS {
            p.push((theta_cdf(t1) - theta_cdf(t0)) / PHI_BINS as f64);
        }
    }
    p
}

/// A tilted normal, so the test also covers the shader's frame construction (to_world).
fn tilted_normal() -> (DVec3, &'static str) {
    (DVec3::new(0.3, -0.5, 0.8).normalize(), "normalize(vec3<f32>(0.3, -0.5, 0.8))")
}

#[test]
fn cosine_hemisphere_sampling_follows_cos_theta_over_pi() {
    let (n, n_wgsl) = tilted_normal();
    let samples = run_on_gpu(&format!("to_world({n_wgsl}, sample_cosine_hemisphere(u1, u2))"), 1);
    let counts = bin_directions("cosine", &samples, n);
    // pdf = cos(theta)/pi over solid angle: the theta CDF is sin^2(theta).
    chi_square_test("cosine hemisphere", &counts, &theta_cells(|t| t.sin().powi(2)));
}

#[test]
fn uniform_hemisphere_sampling_follows_one_over_two_pi() {
    let (n, n_wgsl) = tilted_normal();
    let samples = run_on_gpu(&format!("to_world({n_wgsl}, sample_uniform_hemisphere(u1, u2))"), 2);
    let counts = bin_directions("uniform", &samples, n);
    // pdf = 1/(2 pi): the theta CDF is 1 - cos(theta).
    chi_square_test("uniform hemisphere", &counts, &theta_cells(|t| 1.0 - t.cos()));
}

#[test]
fn sun_disc_sampling_is_uniform_over_its_cone() {
    // Cones of half-angle 20 and 0.05 degrees around a tilted axis (the sun's next-event
    // estimation). At 0.05 degrees cos(theta_max) is 1 - 3.8e-7 in f32, a few float steps from
    // 1: the routine takes 1 - cos(theta_max), which keeps its precision there.
    for degrees in [20.0f64, 0.05] {
        check_cone(degrees);
    }
}

fn check_cone(degrees: f64) {
    let (n, n_wgsl) = tilted_normal();
    let theta_max = degrees.to_radians();
    let half = theta_max / 2.0;
    let one_minus_cos_max = (2.0 * half.sin() * half.sin()) as f32;
    let samples = run_on_gpu(
        &format!("normalize(to_world({n_wgsl}, sample_uniform_cone({one_minus_cos_max:?}, u1, u2)))"),
        6,
    );
    let (t, b) = frame(n);
    let mut counts = vec![0u64; THETA_BINS * PHI_BINS];
    for d in &samples {
        // atan2 of sin and cos: acos of a dot product near 1 would lose the small angles.
        let theta = d.cross(n).length().atan2(d.dot(n));
        assert!(
            theta <= theta_max * 1.001,
            "{degrees} degrees: direction {d} outside the cone ({theta} rad)"
        );
        let phi = d.dot(b).atan2(d.dot(t)).rem_euclid(2.0 * PI);
        let i = ((theta / theta_max * THETA_BINS as f64) as usize).min(THETA_BINS - 1);
        let j = ((phi / (2.0 * PI) * PHI_BINS as f64) as usize).min(PHI_BINS - 1);
        counts[i * PHI_BINS + j] += 1;
    }
    // Uniform over the cone's solid angle: the theta CDF is (1 - cos theta) / (1 - cos theta_max)
    // = sin^2(theta / 2) / sin^2(theta_max / 2).
    let cdf = |theta: f64| (theta / 2.0).sin().powi(2) / half.sin().powi(2);
    let mut p = Vec::new();
    for i in 0..THETA_BINS {
        let (t0, t1) =
            (i as f64 * theta_max / THETA_BINS as f64, (i + 1) as f64 * theta_max / THETA_BINS as f64);
        for _ in 0..PHI_BINS {
            p.push((cdf(t1) - cdf(t0)) / PHI_BINS as f64);
        }
    }
    chi_square_test(&format!("sun cone of {degrees} degrees"), &counts, &p);
}

#[test]
fn a_wrong_pdf_is_rejected() {
    // The test has power: cosine-distributed samples fail against the uniform pdf.
    let (n, n_wgsl) = tilted_normal();
    let samples = run_on_gpu(&format!("to_world({n_wgsl}, sample_cosine_hemisphere(u1, u2))"), 3);
    let counts = bin_directions("cosine as uniform", &samples, n);
    let result = std::panic::catch_unwind(|| {
        chi_square_test("cosine tested as uniform", &counts, &theta_cells(|t| 1.0 - t.cos()))
    });
    assert!(result.is_err(), "the chi-square test accepted the wrong pdf");
}

#[test]
fn rectangular_light_sampling_is_uniform_over_area() {
    // A parallelogram with non-axis-aligned, non-orthogonal edges.
    let (corner, u, v) =
        (DVec3::new(1.0, 2.0, 3.0), DVec3::new(130.0, 5.0, 0.0), DVec3::new(10.0, 0.0, 105.0));
    let samples = run_on_gpu(
        "sample_parallelogram(vec3<f32>(1.0, 2.0, 3.0), vec3<f32>(130.0, 5.0, 0.0), vec3<f32>(10.0, 0.0, 105.0), u1, u2)",
        4,
    );
    // Recover (s, t) from p = corner + s u + t v with the dual basis of (u, v) in their plane.
    let normal = u.cross(v);
    let (du, dv) = (v.cross(normal) / u.dot(v.cross(normal)), normal.cross(u) / v.dot(normal.cross(u)));
    const BINS: usize = 16;
    let mut counts = vec![0u64; BINS * BINS];
    for p in &samples {
        let h = *p - corner;
        let (s, t) = (h.dot(du), h.dot(dv));
        assert!(h.dot(normal).abs() < 1e-3 * normal.length(), "sample {p} is off the light's plane");
        assert!((-1e-5..=1.0 + 1e-5).contains(&s) && (-1e-5..=1.0 + 1e-5).contains(&t), "({s}, {t}) outside");
        let i = ((s * BINS as f64) as usize).min(BINS - 1);
        let j = ((t * BINS as f64) as usize).min(BINS - 1);
        counts[i * BINS + j] += 1;
    }
    // pdf = 1/A over area: every cell of the (s, t) grid has the same area, so p = 1/256.
    chi_square_test("rectangle", &counts, &vec![1.0 / (BINS * BINS) as f64; BINS * BINS]);
}

/// The Cornell box's light: corner, edges, and the unit normal of its emitting side.
const LIGHT: [DVec3; 4] =
    [DVec3::new(213.0, 555.0, 225.5), DVec3::new(130.0, 0.0, 0.0), DVec3::new(0.0, 0.0, 105.0), DVec3::NEG_Y];

fn wgsl_vec(v: DVec3) -> String {
    format!("vec3<f32>({:?}, {:?}, {:?})", v.x as f32, v.y as f32, v.z as f32)
}

/// The WGSL call drawing a point on [`LIGHT`] for the shading point p with normal n.
fn bilinear_expression(p: DVec3, n: DVec3) -> String {
    let [corner, u, v, normal] = LIGHT;
    let args = [p, n, corner, u, v, normal].map(wgsl_vec).join(", ");
    format!("sample_light_bilinear({args}, u1, u2)")
}

/// The density next-event estimation draws light points (s, t) with at shading point p (unit
/// normal n), from its definition in crates/illum-pathtrace/shaders/sampling.wgsl, in f64: the bilinear
/// interpolation of cos(theta_x) cos(theta_y) / r^2 at the four corners, each plus a sixteenth
/// of their mean, divided by its mean over the square. `None` where the shader falls back to
/// uniform sampling.
fn bilinear_light_pdf(p: DVec3, n: DVec3) -> Option<impl Fn(f64, f64) -> f64> {
    let [corner, u, v, normal] = LIGHT;
    let g = |q: DVec3| {
        let w = q - p;
        let d2 = w.length_squared();
        (n.dot(w) / d2).max(0.0) * (-normal.dot(w) / d2).max(0.0)
    };
    let mut w = [g(corner), g(corner + u), g(corner + v), g(corner + u + v)];
    let mean = w.iter().sum::<f64>() / 4.0;
    if !(mean > 0.0 && mean < 3.0e38) {
        return None;
    }
    for x in &mut w {
        *x += mean / 16.0;
    }
    let total = mean * 17.0 / 16.0;
    Some(move |s: f64, t: f64| {
        ((1.0 - s) * (1.0 - t) * w[0] + s * (1.0 - t) * w[1] + (1.0 - s) * t * w[2] + s * t * w[3]) / total
    })
}

/// Next-event estimation's light points follow the bilinear density of the geometric term: a
/// chi-square test over a 16 x 16 grid of (s, t) at shading points near and far, facing the
/// light and tilted so that some corners lie behind them; the returned 1 / pdf matches the
/// density; and the test rejects uniform samples where the density is far from uniform.
#[test]
fn light_points_follow_the_bilinear_geometric_term() {
    const BINS: usize = 16;
    let cases = [
        ("floor centre", DVec3::new(278.0, 0.0, 278.0), DVec3::Y),
        ("back wall, 30 below the ceiling", DVec3::new(278.0, 525.0, 555.0), DVec3::NEG_Z),
        ("left wall beside the light", DVec3::new(200.0, 540.0, 278.0), DVec3::new(1.0, 0.0, 0.0)),
        ("tilted, two corners behind", DVec3::new(278.0, 500.0, 278.0), DVec3::new(0.8, 0.6, 0.0)),
        ("1e-3 under the light's centre", DVec3::new(278.0, 554.999, 278.0), DVec3::Y),
        ("1e4 away", DVec3::new(278.0, -9445.0, 278.0), DVec3::Y),
    ];
    for (seed, (name, p, n)) in cases.into_iter().enumerate() {
        let samples = run_on_gpu(&bilinear_expression(p, n), 40 + seed as u32);
        let pdf = bilinear_light_pdf(p, n).unwrap_or_else(|| panic!("{name}: the light is lit from here"));
        let mut counts = vec![0u64; BINS * BINS];
        for (k, q) in samples.iter().enumerate() {
            let (s, t, inverse) = (q.x, q.y, q.z);
            assert!((0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t), "{name}: ({s}, {t}) outside");
            assert!(
                inverse.is_finite() && inverse > 0.0 && inverse <= 17.0 + 1e-4,
                "{name}: 1/pdf = {inverse}"
            );
            if k % 1024 == 0 {
                let expected = 1.0 / pdf(s, t);
                assert!(
                    (inverse - expected).abs() <= 1e-4 * expected,
                    "{name}: 1/pdf {inverse} against {expected}"
                );
            }
            counts[((s * BINS as f64) as usize).min(BINS - 1) * BINS
                + ((t * BINS as f64) as usize).min(BINS - 1)] += 1;
        }
        // A bilinear density's mean over a cell is its value at the cell's centre.
        let cell = |i: usize, j: usize| pdf((i as f64 + 0.5) / BINS as f64, (j as f64 + 0.5) / BINS as f64);
        let probability: Vec<f64> =
            (0..BINS * BINS).map(|k| cell(k / BINS, k % BINS) / (BINS * BINS) as f64).collect();
        chi_square_test(name, &counts, &probability);
        if name.starts_with("left wall") {
            // Power: here the density is far from uniform, and uniform cells must fail.
            let uniform = vec![1.0 / (BINS * BINS) as f64; BINS * BINS];
            let result =
                std::panic::catch_unwind(|| chi_square_test("bilinear as uniform", &counts, &uniform));
            assert!(result.is_err(), "the chi-square test accepted uniform cells for a bilinear density");
        }
    }
}

/// Where no corner weight is usable (the point on a corner, in the light's plane, behind the
/// light, or so far that the weights underflow), sampling falls back to uniform, pdf 1: finite
/// and unbiased.
#[test]
fn light_sampling_falls_back_to_uniform_at_the_extremes() {
    let corner = LIGHT[0];
    for (name, p, n) in [
        ("on a corner", corner, DVec3::Y),
        ("in the light's plane", DVec3::new(100.0, 555.0, 278.0), DVec3::NEG_Y),
        ("behind the light", DVec3::new(278.0, 600.0, 278.0), DVec3::NEG_Y),
        ("1e30 away", DVec3::new(278.0, -1e30, 278.0), DVec3::Y),
    ] {
        let samples = run_on_gpu(&bilinear_expression(p, n), 7);
        for q in samples.iter().step_by(997) {
            assert!(q.x.is_finite() && q.y.is_finite(), "{name}: {q}");
            assert_eq!(q.z, 1.0, "{name}: 1/pdf of the uniform fallback");
        }
        // In f64 the weights 1e30 away do not underflow: only f32's fallback is checked there.
        if p.y > -1e29 {
            assert!(bilinear_light_pdf(p, n).is_none(), "{name}: the f64 density should fall back too");
        }
    }
}

#[test]
fn caustic_emission_is_uniform_over_its_disc() {
    // The caustic's particles cross the plane perpendicular to the light on a disc about a
    // specular object's centre: here radius 1.5 about (4.2, 2.6, -4.2), perpendicular to the
    // Whitted scene's light direction.
    let centre = DVec3::new(4.2, 2.6, -4.2);
    let axis = DVec3::new(-10.0, -13.0, 2.0).normalize();
    let samples = run_on_gpu(
        &format!(
            "sample_disc(vec3<f32>(4.2, 2.6, -4.2), vec3<f32>({:?}, {:?}, {:?}), 1.5, u1, u2)",
            axis.x as f32, axis.y as f32, axis.z as f32
        ),
        8,
    );
    let (t, b) = frame(axis);
    const BINS: usize = 16;
    let mut counts = vec![0u64; BINS * BINS];
    for p in &samples {
        let h = *p - centre;
        assert!(h.dot(axis).abs() < 1e-5, "sample {p} is off the disc's plane");
        let (x, y) = (h.dot(t) / 1.5, h.dot(b) / 1.5);
        let r2 = x * x + y * y;
        assert!(r2 <= 1.0 + 1e-5, "sample {p} outside the disc");
        // Cells of equal area: r^2 in 16 equal steps times 16 equal angles.
        let i = ((r2 * BINS as f64) as usize).min(BINS - 1);
        let phi = y.atan2(x).rem_euclid(std::f64::consts::TAU);
        let j = ((phi / std::f64::consts::TAU * BINS as f64) as usize).min(BINS - 1);
        counts[i * BINS + j] += 1;
    }
    chi_square_test("disc", &counts, &vec![1.0 / (BINS * BINS) as f64; BINS * BINS]);
}

#[test]
fn random_numbers_are_uniform_in_the_half_open_unit_interval() {
    let samples = run_on_gpu("vec3<f32>(u1, u2, 0.0)", 5);
    const BINS: usize = 64;
    let mut counts = vec![0u64; BINS * BINS];
    for s in &samples {
        assert!((0.0..1.0).contains(&s.x) && (0.0..1.0).contains(&s.y), "{s} outside [0, 1)");
        counts[(s.x * BINS as f64) as usize * BINS + (s.y * BINS as f64) as usize] += 1;
    }
    // Pairs binned in 2D also test that consecutive numbers are independent.
    chi_square_test("rng pairs", &counts, &vec![1.0 / (BINS * BINS) as f64; BINS * BINS]);
}

/// Question 2b: with uniform sampling, pdf = 1/(2 pi), the Monte Carlo estimate of
/// the integral of cos(theta) over the hemisphere converges to its value, pi; with cosine
/// sampling every sample gives exactly pi (zero variance, the reason it is the default).
#[test]
fn the_estimators_of_the_cosine_integral_converge_to_pi() {
    let (n, n_wgsl) = tilted_normal();
    let uniform = run_on_gpu(&format!("to_world({n_wgsl}, sample_uniform_hemisphere(u1, u2))"), 6);
    let values: Vec<f64> = uniform.iter().map(|d| d.dot(n).max(0.0) * 2.0 * PI).collect();
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (values.len() - 1) as f64;
    let standard_error = (variance / values.len() as f64).sqrt();
    assert!((mean - PI).abs() < 4.0 * standard_error, "uniform estimate {mean} vs pi (se {standard_error})");

    let cosine = run_on_gpu(&format!("to_world({n_wgsl}, sample_cosine_hemisphere(u1, u2))"), 7);
    for d in cosine.iter().take(1000) {
        let cos_theta = d.dot(n);
        if cos_theta > 1e-3 {
            let estimate = cos_theta / (cos_theta / PI);
            assert!((estimate - PI).abs() < 1e-9);
        }
    }
    // The pdfs integrate to 1 (midpoint rule over theta, with the solid-angle element).
    let steps = 100_000;
    let (mut uniform_total, mut cosine_total) = (0.0, 0.0);
    for i in 0..steps {
        let theta = (i as f64 + 0.5) / steps as f64 * PI / 2.0;
        let d_omega = 2.0 * PI * theta.sin() * (PI / 2.0 / steps as f64);
        uniform_total += 1.0 / (2.0 * PI) * d_omega;
        cosine_total += theta.cos() / PI * d_omega;
    }
    assert!((uniform_total - 1.0).abs() < 1e-6 && (cosine_total - 1.0).abs() < 1e-6);
}
