//! The oracle on the assignment's Cornell box (scenes/cornell.toml): the light's tie with the
//! ceiling, bounce settings, sampling pdfs, determinism and image orientation.

use glam::DVec3;
use illum_oracle::{Oracle, OracleImage, Rng};
use illum_scene::{Bounces, Sampling, Scene};

fn cornell(width: u32, height: u32) -> Scene {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/cornell.toml");
    let mut scene = Scene::load(std::path::Path::new(path)).expect("scenes/cornell.toml loads");
    scene.camera.width = width;
    scene.camera.height = height;
    scene
}

fn render(scene: &Scene, bounces: Bounces, sampling: Sampling, spp: u32, seed: u64) -> OracleImage {
    Oracle::new(scene)
        .expect("the oracle renders this scene")
        .with_bounces(bounces)
        .with_sampling(sampling)
        .render(spp, seed, illum_oracle::default_threads())
}

/// Rows 4.. of a 16-row image: below the light (which the camera sees in row 2), whose pixels'
/// 0-or-30 samples would swamp the variance of any mean that includes them.
const REGION_ROWS: std::ops::Range<u32> = 4..16;

/// Mean over the region's pixels and channels, and its squared standard error.
fn region_mean(img: &OracleImage, columns: std::ops::Range<u32>, rows: std::ops::Range<u32>) -> (f64, f64) {
    let (mut m, mut v, mut n) = (0.0, 0.0, 0.0);
    for y in rows {
        for x in columns.clone() {
            let i = img.index(x, y);
            m += img.mean[i].iter().sum::<f64>();
            v += img.variance_of_mean[i].iter().sum::<f64>();
            n += 3.0;
        }
    }
    (m / n, v / (n * n))
}

/// z-score of the difference of two independent images' means over the region.
fn z_of_difference(
    a: &OracleImage,
    b: &OracleImage,
    columns: std::ops::Range<u32>,
    rows: std::ops::Range<u32>,
) -> (f64, f64) {
    let (ma, va) = region_mean(a, columns.clone(), rows.clone());
    let (mb, vb) = region_mean(b, columns, rows);
    ((ma - mb) / (va + vb).sqrt(), ma - mb)
}

/// The Cornell box with the white albedo raised from 0.5 to 0.9, so that deep bounces carry
/// a sizeable share of the light (64 fixed bounces exceed 5 by ~3.5% in the region).
fn bright_cornell(width: u32, height: u32) -> Scene {
    let mut scene = cornell(width, height);
    for m in &mut scene.materials {
        if m.name == "white" {
            m.kind = illum_scene::MaterialKind::Lambertian { albedo: glam::Vec3::splat(0.9) };
        }
    }
    scene
}

/// The light (y = 555, x in [213, 343], z in [225.5, 330.5]) lies in the plane of the
/// ceiling's inner face; rays meeting that plane inside the rectangle must see the light's
/// radiance 30, exactly, for every sample — including rays aimed just inside its edges.
#[test]
fn light_wins_the_tie_with_the_coplanar_ceiling() {
    let oracle = Oracle::new(&cornell(64, 64)).expect("the oracle renders this scene");
    // The task's case: from the floor (the centre of the floor is clear of both blocks)
    // straight up at the light's centre.
    for s in 0..16 {
        let l =
            oracle.radiance(DVec3::new(278.0, 1.0 + 1e-6, 278.0), DVec3::Y, &mut Rng::for_sample(1, 2, s));
        assert_eq!(l, DVec3::splat(30.0));
    }
    let targets =
        [(278.0, 278.0), (213.001, 225.501), (342.999, 330.499), (213.001, 330.499), (300.0, 226.0)];
    for (x, z) in targets {
        // Straight up from below (y = 340 clears both blocks' tops, 165 and 330), and from two
        // points in the open air of the room.
        for origin in
            [DVec3::new(x, 340.0, z), DVec3::new(450.0, 500.0, 150.0), DVec3::new(100.0, 300.0, 500.0)]
        {
            let dir = DVec3::new(x, 555.0, z) - origin;
            for s in 0..16 {
                let l = oracle.radiance(origin, dir, &mut Rng::for_sample(1, 2, s));
                assert_eq!(l, DVec3::splat(30.0), "ray from {origin:?} to ({x}, 555, {z})");
            }
        }
    }
    // Just outside the rectangle the ray sees the ceiling, which is dimmer than the light.
    let outside = Oracle::new(&cornell(64, 64)).expect("the oracle renders this scene");
    let mut sum = DVec3::ZERO;
    for s in 0..256 {
        sum += outside.radiance(DVec3::new(212.0, 2.0, 278.0), DVec3::Y, &mut Rng::for_sample(1, 2, s));
    }
    assert!(sum.max_element() / 256.0 < 5.0, "ceiling next to the light: {sum:?}");

    // Through the camera: at 512 x 512 the light covers image rows ~76..93 and columns
    // ~219..293, so pixel (256, 85) sees only the light.
    let est = illum_oracle::radiance_at_pixel(&cornell(512, 512), 256, 85, 32, 5)
        .expect("the oracle renders this scene");
    assert_eq!(est.mean, [30.0; 3]);
    assert_eq!(est.variance_of_mean, [0.0; 3]);
}

/// With the same seed, Fixed(n + 1) repeats Fixed(n)'s random numbers and adds one more
/// (non-negative) bounce term per sample, so every pixel's mean can only grow with n; the
/// growth of the image mean must be real, not rounding.
#[test]
fn fixed_bounces_add_light_monotonically() {
    let scene = cornell(12, 12);
    let images: Vec<OracleImage> =
        (0..=3).map(|n| render(&scene, Bounces::Fixed(n), Sampling::Cosine, 16, 3)).collect();
    for n in 0..3 {
        let (lo, hi) = (&images[n], &images[n + 1]);
        for (i, (a, b)) in lo.mean.iter().zip(&hi.mean).enumerate() {
            for c in 0..3 {
                assert!(
                    b[c] >= a[c],
                    "pixel {i} channel {c}: {n} bounces {} > {} bounces {}",
                    a[c],
                    n + 1,
                    b[c]
                );
            }
        }
        let (m_lo, _) = lo.overall_mean();
        let (m_hi, _) = hi.overall_mean();
        assert!(m_hi > m_lo * 1.001, "{n} -> {} bounces: {m_lo} -> {m_hi}", n + 1);
    }
}

/// Russian roulette is unbiased: unbounded paths match 64 fixed bounces (a path in this open
/// box practically never survives 64 bounces: < 0.9^64 = 0.1% of the light lies beyond, less
/// still after escapes through the open front). On the brighter box the same test tells 5
/// bounces from 64, so it has the power to fail.
#[test]
fn unbounded_matches_fixed_64() {
    for (name, scene) in [("cornell", cornell(16, 16)), ("bright cornell", bright_cornell(16, 16))] {
        let unbounded = render(&scene, Bounces::Unbounded, Sampling::Cosine, 256, 10);
        let fixed64 = render(&scene, Bounces::Fixed(64), Sampling::Cosine, 256, 11);
        let (z, diff) = z_of_difference(&unbounded, &fixed64, 0..16, REGION_ROWS);
        assert!(z.abs() < 4.0, "{name}: unbounded vs 64 bounces: z = {z:.2} (difference {diff})");
        assert_eq!(unbounded.dropped + fixed64.dropped, 0);
        if name == "bright cornell" {
            let fixed5 = render(&scene, Bounces::Fixed(5), Sampling::Cosine, 256, 12);
            let (z, diff) = z_of_difference(&fixed64, &fixed5, 0..16, REGION_ROWS);
            assert!(z > 5.0, "{name}: 64 vs 5 bounces should differ clearly: z = {z:.2} (difference {diff})");
        }
    }
}

/// Uniform and cosine hemisphere sampling estimate the same integral: the region's mean, and
/// each of its four quarters' means, agree within 4 standard errors, at 2 bounces on the
/// assignment's box and unbounded on the bright one.
#[test]
fn uniform_and_cosine_sampling_agree() {
    for (scene, bounces) in
        [(cornell(16, 16), Bounces::Fixed(2)), (bright_cornell(16, 16), Bounces::Unbounded)]
    {
        let cosine = render(&scene, bounces, Sampling::Cosine, 128, 20);
        let uniform = render(&scene, bounces, Sampling::Uniform, 128, 21);
        let (z, diff) = z_of_difference(&cosine, &uniform, 0..16, REGION_ROWS);
        assert!(z.abs() < 4.0, "{bounces:?}: cosine vs uniform: z = {z:.2} (difference {diff})");
        for (columns, rows) in [(0..8, 4..10), (8..16, 4..10), (0..8, 10..16), (8..16, 10..16)] {
            let (z, diff) = z_of_difference(&cosine, &uniform, columns.clone(), rows.clone());
            assert!(z.abs() < 4.0, "{bounces:?}: columns {columns:?} rows {rows:?}: z = {z:.2} ({diff})");
        }
    }
}

/// Results depend only on (seed, pixel, sample): any thread count gives the same bits, a single
/// pixel gives the same value as in the image, and another seed gives another image.
#[test]
fn results_do_not_depend_on_threads() {
    let scene = cornell(12, 10);
    let oracle = Oracle::new(&scene).expect("the oracle renders this scene");
    let one = oracle.render(4, 77, 1);
    for threads in [2, 3, 16] {
        assert_eq!(oracle.render(4, 77, threads), one, "{threads} threads");
    }
    assert_eq!(illum_oracle::render(&scene, 4, 77).expect("the oracle renders this scene"), one);
    let px = illum_oracle::radiance_at_pixel(&scene, 7, 3, 4, 77).expect("the oracle renders this scene");
    assert_eq!(px.mean, one.mean[one.index(7, 3)]);
    assert_eq!(px.variance_of_mean, one.variance_of_mean[one.index(7, 3)]);
    assert_ne!(oracle.render(4, 78, 2).mean, one.mean);
    assert_eq!((one.width, one.height, one.spp, one.mean.len()), (12, 10, 4, 120));
}

/// Screen-right is world -X: the red wall (x = 555) fills the image's left edge and the green
/// wall (x = 1) its right edge.
#[test]
fn red_wall_left_green_wall_right() {
    let image = render(&cornell(16, 16), Bounces::Fixed(0), Sampling::Cosine, 8, 1);
    for y in 4..12 {
        let left = image.mean[image.index(0, y)];
        let right = image.mean[image.index(15, y)];
        assert!(left[0] > 2.0 * left[1], "row {y} left {left:?} should be red");
        assert!(right[1] > 2.0 * right[0], "row {y} right {right:?} should be green");
    }
}
