//! The GPU Whitted ray tracer against the independent f64 copy of the algorithm
//! (`illum_oracle::whitted`), pixel by pixel, on both scenes at depths 0, 1, 2 and 8.
//!
//! Both are deterministic, so the only differences are f32 rounding and what it can flip:
//!
//! - **Tolerance.** A pixel agrees when each channel is within [`tolerance`] of the oracle's,
//!   relative to the larger of 1 and the oracle's value: f32's unit roundoff u = 2^-24 times
//!   [`ROUNDINGS_PER_BOUNCE`] for each of the depth + 1 segments of a ray's tree.
//! - **Edges.** A ray that grazes an edge (a silhouette, a shadow's boundary, a tile's border,
//!   directly or after bounces) can fall on the other side in f32, which changes that ray's
//!   whole colour. A pixel beyond the tolerance is allowed only where the oracle shows such an
//!   edge: moving the pixel's rays by [`EDGE_MOVE`] of a pixel (more than f32 and the spawn
//!   offsets move them, far less than any smooth change of the image across it) changes one of
//!   the oracle's rays by at least half the pixel's difference, counted at its share of the
//!   pixel ([`edge_change`]). Such pixels are at most [`MAX_EDGE_FRACTION`] of the image.
//! - **Power.** The same comparison must fail the GPU image with a 4 x 4 patch of smooth
//!   pixels made 3% brighter, or one pixel made 1% brighter.

use illum_gpu::testing::gpu;
use illum_image::RgbImage32;
use illum_oracle::WhittedOracle;
use illum_scene::Scene;
use illum_whitted::WhittedTracer;

/// f32's unit roundoff, 2^-24.
const U: f64 = f32::EPSILON as f64 / 2.0;

/// Roundings a colour carries per segment of a ray's tree, as a bound: a segment is a ray
/// set up, intersected (a normalised direction, a quadratic with one square root, a hit point
/// and its normal: about 40 operations on values of the scene's size), shaded (dot products,
/// a half vector, Fresnel: about 40 more) and its colour added to its parent's. The highlight
/// raises a cosine to the shininess (100 on the glass), which multiplies that cosine's
/// relative error by 100, and is computed by `pow` (exp2 of log2, a few ulp each): about 250
/// in all. Measured, the largest is 203 u at depth 0 (the glass's highlight on the Whitted
/// scene) and 2.6e-4 at depth 64; twice the estimate leaves room for another driver's `pow`.
/// The error adds over the segments of the tree.
const ROUNDINGS_PER_BOUNCE: f64 = 512.0;

/// The largest difference of a channel, relative to the larger of 1 and the oracle's value,
/// that f32 rounding explains in a pixel whose rays follow `depth` bounces:
/// (depth + 1) x 512 x 2^-24, 3.1e-5 at depth 0 and 2.7e-4 at depth 8.
fn tolerance(depth: u32) -> f64 {
    f64::from(depth + 1) * ROUNDINGS_PER_BOUNCE * U
}

/// How far a pixel's rays are moved, in pixels, to find an edge under it. f32 rounding moves a
/// camera ray's point on the film by about 1e-5 pixel here, but a new ray starts off its surface
/// by the shape's error bound (2^-18 of its size: 1.1e-4 units on the Whitted scene's 30-unit
/// floor, whose pixels are 0.03 to 0.1 units wide at 160 x 90), so a shadow ray or a bounce can
/// start up to 4e-3 pixel from the oracle's; 1e-2 pixel covers that. A smooth image changes
/// across it by 1e-2 of its change across a pixel.
const EDGE_MOVE: f64 = 1e-2;

/// The most pixels that may differ beyond the tolerance at an edge: edges are lines, and a ray
/// must pass within f32's reach of one, so such pixels are few (measured: at most 15 of 14400 on
/// the Whitted scene, 11 of 5184 in the extremes, 1 of 4096 on the Cornell box); 0.5% is 72 of
/// 14400.
const MAX_EDGE_FRACTION: f64 = 0.005;

/// What a comparison found.
#[derive(Debug)]
struct Comparison {
    pixels: usize,
    /// Pixels beyond the tolerance at an edge.
    edges: usize,
    /// Pixels beyond the tolerance with no edge to explain them: (x, y, difference).
    unexplained: Vec<(u32, u32, f64)>,
    /// The largest difference among the pixels within the tolerance.
    worst_within: f64,
}

impl Comparison {
    fn passes(&self) -> bool {
        self.unexplained.is_empty() && self.edges as f64 <= MAX_EDGE_FRACTION * self.pixels as f64
    }
}

/// The largest difference of a channel between `a` and the oracle's `o`, relative to the
/// larger of 1 and the oracle's value.
fn difference(a: [f64; 3], o: [f64; 3]) -> f64 {
    (0..3).map(|c| (a[c] - o[c]).abs() / o[c].max(1.0)).fold(0.0, f64::max)
}

/// Compares `image` with the oracle's `reference` (its render of the same scene), pixel by
/// pixel, as the module's comment says.
fn compare(image: &RgbImage32, reference: &[[f64; 3]], oracle: &WhittedOracle, depth: u32) -> Comparison {
    let tolerance = tolerance(depth);
    let mut comparison =
        Comparison { pixels: reference.len(), edges: 0, unexplained: Vec::new(), worst_within: 0.0 };
    for (i, (g, &o)) in image.pixels.iter().zip(reference).enumerate() {
        let d = difference(g.map(f64::from), o);
        if d <= tolerance {
            comparison.worst_within = comparison.worst_within.max(d);
            continue;
        }
        let (x, y) = ((i % image.width as usize) as u32, (i / image.width as usize) as u32);
        if edge_change(oracle, x, y) >= 0.5 * d {
            comparison.edges += 1;
        } else {
            comparison.unexplained.push((x, y, d));
        }
    }
    comparison
}

/// How much one of pixel (x, y)'s rays changes, at its share of the pixel (1 / aa²), when the
/// rays move by [`EDGE_MOVE`] along either axis: the largest difference a ray at an edge can
/// make to the pixel.
fn edge_change(oracle: &WhittedOracle, x: u32, y: u32) -> f64 {
    let rays = oracle.rays_moved(x, y, 0.0, 0.0);
    let share = 1.0 / rays.len() as f64;
    [(EDGE_MOVE, 0.0), (-EDGE_MOVE, 0.0), (0.0, EDGE_MOVE), (0.0, -EDGE_MOVE)]
        .iter()
        .flat_map(|&(dx, dy)| {
            let moved = oracle.rays_moved(x, y, dx, dy);
            rays.iter().zip(moved).map(|(&r, m)| share * difference(m, r)).collect::<Vec<_>>()
        })
        .fold(0.0, f64::max)
}

fn render(scene: &Scene) -> (RgbImage32, WhittedOracle, Vec<[f64; 3]>) {
    let image = WhittedTracer::new(gpu(), scene).unwrap_or_else(|e| panic!("{e}")).render().unwrap();
    let oracle = WhittedOracle::new(scene).unwrap_or_else(|e| panic!("{e}"));
    let reference = oracle.render(2);
    (image, oracle, reference)
}

/// The top-left corner of a 4 x 4 block of pixels whose rays change by at most 1e-3 of a pixel
/// when they move (no edge in it, so a 1% error there is not explained by one) and are not
/// black, nearest the image's centre.
fn smooth_block(oracle: &WhittedOracle, reference: &[[f64; 3]], width: u32, height: u32) -> (u32, u32) {
    let smooth = |x: u32, y: u32| {
        reference[(y * width + x) as usize].iter().any(|&c| c > 0.05) && edge_change(oracle, x, y) <= 1e-3
    };
    let mut blocks: Vec<(u32, u32)> =
        (0..height - 3).step_by(4).flat_map(|y| (0..width - 3).step_by(4).map(move |x| (x, y))).collect();
    blocks.sort_by_key(|&(x, y)| (2 * x + 4).abs_diff(width) + (2 * y + 4).abs_diff(height));
    blocks
        .into_iter()
        .find(|&(x0, y0)| (y0..y0 + 4).all(|y| (x0..x0 + 4).all(|x| smooth(x, y))))
        .expect("a smooth 4 x 4 block")
}

/// The comparison passes the GPU's image and fails it with a small local error: a 4 x 4 patch
/// of smooth pixels 3% too bright, or one of them 1% too bright.
fn check(name: &str, scene: &Scene) {
    let depth = scene.whitted.depth;
    let (image, oracle, reference) = render(scene);
    let comparison = compare(&image, &reference, &oracle, depth);
    println!(
        "{name}, depth {depth}: {} of {} pixels at edges beyond {:.1e}; largest difference within it {:.2e}",
        comparison.edges,
        comparison.pixels,
        tolerance(depth),
        comparison.worst_within
    );
    assert!(comparison.passes(), "{name}, depth {depth}: {comparison:?}");

    let (x0, y0) = smooth_block(&oracle, &reference, image.width, image.height);
    let brighten = |pixels: &[(u32, u32)], factor: f32| {
        let mut wrong = image.clone();
        for &(x, y) in pixels {
            let p = &mut wrong.pixels[(y * image.width + x) as usize];
            *p = p.map(|c| c * factor);
        }
        compare(&wrong, &reference, &oracle, depth)
    };
    let patch: Vec<(u32, u32)> = (y0..y0 + 4).flat_map(|y| (x0..x0 + 4).map(move |x| (x, y))).collect();
    for (what, pixels, factor) in
        [("a 4 x 4 patch 3% too bright", &patch[..], 1.03), ("one pixel 1% too bright", &patch[5..6], 1.01)]
    {
        let wrong = brighten(pixels, factor);
        assert!(!wrong.passes(), "{name}, depth {depth}: {what} at ({x0}, {y0}) passes: {wrong:?}");
    }
}

#[test]
fn the_whitted_scene_matches_the_f64_copy() {
    for depth in [0, 1, 2, 8] {
        let mut scene = illum_scene::testing::shipped_scene("whitted.toml", 160, 90);
        scene.whitted.depth = depth;
        check("whitted", &scene);
    }
}

#[test]
fn the_cornell_box_matches_the_f64_copy() {
    for depth in [0, 1, 2, 8] {
        let mut scene = illum_scene::testing::shipped_scene("cornell.toml", 64, 64);
        scene.whitted.depth = depth;
        check("cornell", &scene);
    }
}

#[test]
fn a_sun_of_finite_size_is_refused_by_name() {
    let mut scene = illum_scene::testing::shipped_scene("whitted.toml", 8, 8);
    if let Some(sun) = &mut scene.directional_light {
        sun.angular_radius_deg = 0.5;
    }
    let err = WhittedTracer::new(gpu(), &scene).err().expect("refused").to_string();
    assert!(err.contains("Whitted ray tracer cannot render") && err.contains("sun disc"), "{err}");
}

#[test]
fn extremes_agree_with_the_f64_copy_and_stay_finite() {
    // Depth 64 and total-internal-reflection chains (index 4), a glass barely denser than air
    // (1.0001) and one that vanishes (1), on the Whitted scene.
    for (ior, depth) in [(4.0f32, 64u32), (1.0001, 8), (1.0, 8), (1.4285715, 64)] {
        let mut scene = illum_scene::testing::shipped_scene("whitted.toml", 96, 54);
        for m in &mut scene.materials {
            if let illum_scene::MaterialKind::Dielectric { ior: value } = &mut m.kind {
                *value = ior;
            }
        }
        scene.whitted.depth = depth;
        let (image, oracle, reference) = render(&scene);
        assert!(
            image.pixels.iter().flatten().all(|c| c.is_finite() && *c >= 0.0),
            "ior {ior}, depth {depth}"
        );
        let comparison = compare(&image, &reference, &oracle, depth);
        println!("ior {ior}, depth {depth}: {comparison:?}");
        assert!(comparison.passes(), "ior {ior}, depth {depth}: {comparison:?}");
    }
}
