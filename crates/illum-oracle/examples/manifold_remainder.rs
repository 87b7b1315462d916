//! What manifold next-event estimation (MNEE, `manifold.rs`) leaves out on the Whitted view:
//! the oracle at 64 x 36 pixels, bounces 8, twice with the same seed,
//!   (a) complete: camera paths + the caustic's light tracer + the photon gather,
//!   (b) camera paths + MNEE (K internal reflections at most, default 1: chains R, TT, TRT;
//!       unbounded concentration),
//! and per region the mean of (b) - (a) with its standard error. MNEE leaves out chains with
//! more than K internal reflections and chains through both balls (sun -> mirror -> glass ->
//! floor, ...), so the difference should be small and negative, plus the gather's kernel bias.
//!
//! MNEE draws no random numbers and the light tracer's and the gather's are keyed apart, so
//! sample k of a pixel follows the same camera path in (a) and (b): the difference is taken
//! sample by sample (MNEE's sum along the path minus caustic frame k at the pixel), and its
//! standard error comes from those differences (the camera paths' own noise cancels).
//!
//! Printed per region: red and green (the floor's checker has no blue albedo, so nothing the
//! balls send onto it is blue; blue's difference is exactly 0) and red as a percentage.
//! Regions: the whole image; the glass sphere's shadow (the pixel centre's camera ray hits the
//! floor where the sun's ray is blocked by the glass sphere); the pixels that see a ball.
//!
//! With the third argument `glass-only` the metal sphere is removed, which leaves out every
//! chain through both balls: what remains of the difference is the truncation and the gather's
//! kernel bias.
//!
//!     cargo run --release -p illum-oracle --example manifold_remainder [SPP] [K] [glass-only]

use glam::DVec3;
use illum_oracle::{ManifoldSettings, Oracle, PinholeCamera};
use illum_scene::{Scene, Shape};

const SEED: u64 = 7;

/// Where the ray o + t d (d unit) first meets the ball (c, r), if ahead.
fn hit_ball(o: DVec3, d: DVec3, (c, r): (DVec3, f64)) -> Option<f64> {
    let m = o - c;
    let b = m.dot(d);
    let disc = b * b - (m.length_squared() - r * r);
    let t = -b - disc.max(0.0).sqrt();
    (disc > 0.0 && t > 0.0).then_some(t)
}

/// Per pixel (sum of a, sum of d, sum of d^2) over samples `from..to`.
fn accumulate(
    a: &Oracle,
    b: &Oracle,
    frames: &[Vec<DVec3>],
    from: u32,
    width: u32,
    rows: std::ops::Range<u32>,
) -> Vec<[DVec3; 3]> {
    let mut out = Vec::new();
    for y in rows {
        for x in 0..width {
            let index = (y * width + x) as usize;
            let mut s = [DVec3::ZERO; 3];
            for (k, frame) in frames.iter().enumerate() {
                let sample = from + k as u32;
                let camera = a.pixel_sample(x, y, SEED, sample);
                let full = camera + frame[index];
                let d = b.pixel_sample(x, y, SEED, sample) - full;
                s[0] += full;
                s[1] += d;
                s[2] += d * d;
            }
            out.push(s);
        }
    }
    out
}

fn main() {
    let mut args = std::env::args().skip(1);
    let spp: u32 = args.next().map_or(1024, |s| s.parse().expect("SPP must be a positive integer"));
    let internal: u32 =
        args.next().map_or(1, |s| s.parse().expect("K must be a count of internal reflections"));
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/whitted.toml");
    let mut scene = Scene::load(std::path::Path::new(path)).expect("scenes/whitted.toml");
    scene.camera.width = 64;
    scene.camera.height = 36;
    scene.pathtrace.caustics = true;
    let glass_only = args.next().is_some_and(|a| a == "glass-only");
    if glass_only {
        scene.objects.retain(|o| o.name != "metal sphere");
    }
    illum_scene::specular_spheres::solvable_spheres(&scene).expect("MNEE is defined for the Whitted scene");
    let (width, height) = (scene.camera.width, scene.camera.height);
    let complete = Oracle::new(&scene).expect("the oracle renders this scene");
    assert!(complete.caustics() && complete.gathers());
    let mnee = complete.clone().with_manifold(Some(ManifoldSettings::with_internal_reflections(internal)));
    let threads = illum_oracle::default_threads();
    let start = std::time::Instant::now();
    let mut sums = vec![[DVec3::ZERO; 3]; (width * height) as usize];
    // Chunks of 64 frames keep the frames' memory small.
    for from in (0..spp).step_by(64) {
        let count = 64.min(spp - from);
        let frames: Vec<Vec<DVec3>> = (from..from + count).map(|k| complete.caustic_frame(SEED, k)).collect();
        let per_thread = height.div_ceil(threads as u32);
        let parts: Vec<Vec<[DVec3; 3]>> = std::thread::scope(|scope| {
            let workers: Vec<_> = (0..threads as u32)
                .map(|t| {
                    let rows = (t * per_thread).min(height)..((t + 1) * per_thread).min(height);
                    let (a, b, f) = (&complete, &mnee, &frames);
                    scope.spawn(move || accumulate(a, b, f, from, width, rows))
                })
                .collect();
            workers.into_iter().map(|w| w.join().expect("worker")).collect()
        });
        for (sum, part) in sums.iter_mut().zip(parts.into_iter().flatten()) {
            for i in 0..3 {
                sum[i] += part[i];
            }
        }
        eprintln!("{} of {spp} samples, {:.0} s", from + count, start.elapsed().as_secs_f64());
    }
    let camera = PinholeCamera::new(&scene.camera);
    let ball = |name: &str| {
        scene.objects.iter().find(|o| o.name == name).and_then(|o| match o.shape {
            Shape::Sphere(s) => Some((s.center.as_dvec3(), f64::from(s.radius))),
            _ => None,
        })
    };
    let balls: Vec<(DVec3, f64)> = ["glass sphere", "metal sphere"].into_iter().filter_map(ball).collect();
    let to_sun = -scene.directional_light.expect("a sun").direction.as_dvec3().normalize();
    let first_ball =
        |d: DVec3| balls.iter().filter_map(|&b| hit_ball(camera.eye, d, b)).fold(f64::INFINITY, f64::min);
    let sees_ball = |x: u32, y: u32| first_ball(camera.direction(x, y, 0.5, 0.5).normalize()).is_finite();
    let in_glass_shadow = |x: u32, y: u32| {
        let d = camera.direction(x, y, 0.5, 0.5).normalize();
        // The floor is the plane y = 0 (x in [-23, 7], z in [-7.5, 7.5]).
        let t = -camera.eye.y / d.y;
        let p = camera.eye + t * d;
        d.y < 0.0
            && t < first_ball(d)
            && (-23.0..=7.0).contains(&p.x)
            && (-7.5..=7.5).contains(&p.z)
            && hit_ball(p, to_sun, balls[0]).is_some()
    };
    let n = f64::from(spp);
    println!(
        "Whitted view 64 x 36, bounces 8, {spp} spp, seed {SEED}: (b) MNEE K = {internal} minus (a) light tracer + gather{}",
        if glass_only { ", metal sphere removed" } else { "" }
    );
    println!("| region | pixels | mean (a) r / g / b | (b) - (a) red | green | red, % of (a) |");
    println!("|---|---|---|---|---|---|");
    type Region<'a> = (&'a str, &'a dyn Fn(u32, u32) -> bool);
    let regions: [Region; 3] = [
        ("whole image", &|_, _| true),
        ("glass sphere's shadow", &in_glass_shadow),
        ("pixels that see a ball", &sees_ball),
    ];
    for (label, keep) in regions {
        let (mut count, mut base, mut diff, mut var) = (0.0, DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
        for y in 0..height {
            for x in 0..width {
                if !keep(x, y) {
                    continue;
                }
                let [a, d, d2] = sums[(y * width + x) as usize];
                let mean_d = d / n;
                count += 1.0;
                base += a / n;
                diff += mean_d;
                // Unbiased variance of the samples' differences, over n: the squared standard
                // error of this pixel's mean difference.
                var += (d2 - n * mean_d * mean_d) / (n - 1.0) / n;
            }
        }
        let (base, diff, se) =
            (base / count, diff / count, DVec3::new(var.x.sqrt(), var.y.sqrt(), var.z.sqrt()) / count);
        println!(
            "| {label} | {count} | {:.3} / {:.3} / {:.3} | {:+.5} ± {:.5} | {:+.5} ± {:.5} | {:+.2} ± {:.2} |",
            base.x,
            base.y,
            base.z,
            diff.x,
            se.x,
            diff.y,
            se.y,
            100.0 * diff.x / base.x,
            100.0 * se.x / base.x
        );
    }
    eprintln!("{:.0} s", start.elapsed().as_secs_f64());
}
