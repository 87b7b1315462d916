//! What the photon gather owns (paths E (S|D)* D S+ L but E D S+ L: the caustic seen in the mirror
//! ball and through the glass, and the caustic's light scattered again by the floor), measured
//! with the f64 oracle on the Whitted view at 64 x 36, bounces 8, in the pixels whose camera ray
//! (through the pixel's centre) first meets the metal sphere, those that first meet the glass,
//! and the floor seen directly (where the gather finds only light the floor receives from the
//! caustic's image in the mirror ball, E D S+ D S+ L):
//!
//! - delta sun, light tracer alone (what the truth had before the photon gather);
//! - delta sun with the photon gather (`gather.rs`);
//! - a sun disc of RADIUS degrees, where the camera paths find those paths by chance (a bounce
//!   from the floor that reaches the disc through the glass or off the mirror): the independent
//!   cross-check. The disc also adds the sun's glint E S+ L, which neither delta estimate has:
//!   the floor's blue albedo is 0, so E S+ D S+ L has no blue and the blue difference is the
//!   glint (with what the disc's blur moves in the sky's reflection: nothing, the sky is
//!   uniform). Pixels where the disc adds blue beyond 4 sigma are left out of the comparison.
//!
//! Printed per region and channel: the means and the differences with their standard errors,
//! and the per-pixel z-scores of disc - gather.
//!
//!     cargo run --release -p illum-oracle --example mirror_caustic [SPP] [RADIUS]

use glam::DVec3;
use illum_oracle::{Oracle, PinholeCamera};
use illum_scene::{Bounces, Scene, Shape};

/// Per-pixel sums of samples and squares.
#[derive(Clone, Copy, Default)]
struct Sums {
    sum: DVec3,
    sq: DVec3,
}

impl Sums {
    fn add(&mut self, v: DVec3) {
        self.sum += v;
        self.sq += v * v;
    }
    fn merge(&mut self, o: &Sums) {
        self.sum += o.sum;
        self.sq += o.sq;
    }
    /// Mean and squared standard error of the mean over n samples.
    fn stats(&self, n: f64) -> (DVec3, DVec3) {
        let mean = self.sum / n;
        (mean, (self.sq / n - mean * mean) / (n - 1.0))
    }
}

fn main() {
    let mut args = std::env::args().skip(1);
    let spp: u32 = args.next().map_or(2048, |s| s.parse().expect("SPP must be a positive integer"));
    let radius: f32 = args.next().map_or(1.0, |s| s.parse().expect("RADIUS must be a number of degrees"));
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/whitted.toml");
    let mut scene = Scene::load(std::path::Path::new(path)).expect("scenes/whitted.toml");
    scene.camera.width = 64;
    scene.camera.height = 36;
    scene.pathtrace.caustics = true;
    let oracle = |scene: &Scene| {
        Oracle::new(scene).expect("the oracle renders this scene").with_bounces(Bounces::Fixed(8))
    };
    let delta = oracle(&scene);
    assert!(delta.gathers());
    let mut disc_scene = scene.clone();
    disc_scene.directional_light.as_mut().expect("a sun").angular_radius_deg = radius;
    let disc = oracle(&disc_scene);

    let camera = PinholeCamera::new(&scene.camera);
    let spheres: Vec<(String, DVec3, f64)> = scene
        .objects
        .iter()
        .filter_map(|o| match o.shape {
            Shape::Sphere(s) => Some((o.name.clone(), s.center.as_dvec3(), f64::from(s.radius))),
            _ => None,
        })
        .collect();
    // The nearest sphere the centre ray meets, if any.
    let first_sphere = |x: u32, y: u32| {
        let d = camera.direction(x, y, 0.5, 0.5);
        spheres
            .iter()
            .filter_map(|(name, c, r)| {
                let m = camera.eye - *c;
                let b = m.dot(d);
                let disc = b * b - (m.length_squared() - r * r);
                (disc > 0.0 && -b - disc.sqrt() > 0.0).then(|| (-b - disc.sqrt(), name.clone()))
            })
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, name)| name)
    };
    let threads = illum_oracle::default_threads();
    let mut regions: Vec<String> = spheres.iter().map(|s| s.0.clone()).collect();
    regions.push("floor".to_owned());
    for name in &regions {
        let pixels: Vec<(u32, u32)> = (0..36)
            .flat_map(|y| (0..64).map(move |x| (x, y)))
            .filter(|&(x, y)| match first_sphere(x, y) {
                Some(sphere) => &sphere == name,
                None => name == "floor" && camera.direction(x, y, 0.5, 0.5).y < 0.0,
            })
            .collect();
        // Per pixel: delta camera alone, delta camera + gather, disc camera.
        let partial: Vec<Vec<[Sums; 3]>> = std::thread::scope(|scope| {
            let workers: Vec<_> = (0..threads as u32)
                .map(|t| {
                    let (delta, disc, pixels) = (&delta, &disc, &pixels);
                    scope.spawn(move || {
                        let mut sums = vec![[Sums::default(); 3]; pixels.len()];
                        for k in (t..spp).step_by(threads) {
                            let gather = delta.gather_at(11, k, pixels);
                            for (i, &(x, y)) in pixels.iter().enumerate() {
                                let camera = delta.pixel_sample(x, y, 11, k);
                                sums[i][0].add(camera);
                                sums[i][1].add(camera + gather[i]);
                                sums[i][2].add(disc.pixel_sample(x, y, 12, k));
                            }
                        }
                        sums
                    })
                })
                .collect();
            workers.into_iter().map(|w| w.join().expect("worker")).collect()
        });
        let mut sums = vec![[Sums::default(); 3]; pixels.len()];
        for part in &partial {
            for (s, p) in sums.iter_mut().zip(part) {
                for e in 0..3 {
                    s[e].merge(&p[e]);
                }
            }
        }
        let n = f64::from(spp);
        let stats: Vec<[(DVec3, DVec3); 3]> =
            sums.iter().map(|s| [s[0].stats(n), s[1].stats(n), s[2].stats(n)]).collect();
        // Glint pixels: the disc adds blue beyond 4 sigma.
        let glint = |s: &[(DVec3, DVec3); 3]| (s[2].0.z - s[1].0.z) / (s[2].1.z + s[1].1.z).sqrt() > 4.0;
        let kept: Vec<&[(DVec3, DVec3); 3]> = stats.iter().filter(|s| !glint(s)).collect();
        println!(
            "{name}: {} pixels, {} with the disc's glint left out; {spp} spp, disc {radius} deg",
            pixels.len(),
            pixels.len() - kept.len()
        );
        let m = kept.len() as f64;
        let mean = |e: usize| kept.iter().map(|s| s[e].0).sum::<DVec3>() / m;
        let var = |e: usize| kept.iter().map(|s| s[e].1).sum::<DVec3>() / (m * m);
        let (before, gathered, finite) = (mean(0), mean(1), mean(2));
        let (vb, vg, vf) = (var(0), var(1), var(2));
        for (c, label) in ["red", "green", "blue"].iter().enumerate() {
            println!(
                "  {label:5}: light tracer alone {:.5} +- {:.5}, with gather {:.5} +- {:.5} (gather adds {:+.2}%), \
                 disc {:.5} +- {:.5}, disc - gather {:+.5} +- {:.5} ({:+.2}%)",
                before[c],
                vb[c].sqrt(),
                gathered[c],
                vg[c].sqrt(),
                100.0 * (gathered[c] - before[c]) / before[c],
                finite[c],
                vf[c].sqrt(),
                finite[c] - gathered[c],
                (vf[c] + vg[c]).sqrt(),
                100.0 * (finite[c] - gathered[c]) / gathered[c],
            );
        }
        // Per-pixel z of disc - gather, red and green, the kept pixels.
        let mut z: Vec<f64> = kept
            .iter()
            .flat_map(|s| (0..2).map(move |c| (s[2].0[c] - s[1].0[c]) / (s[2].1[c] + s[1].1[c]).sqrt()))
            .filter(|z| z.is_finite())
            .collect();
        z.sort_by(f64::total_cmp);
        let over = |t: f64| z.iter().filter(|v| v.abs() > t).count();
        println!(
            "  per-pixel z (red, green; {} values): mean {:+.3}, |z| > 3: {}, |z| > 4: {}, max |z| {:.2}",
            z.len(),
            z.iter().sum::<f64>() / z.len() as f64,
            over(3.0),
            over(4.0),
            z.iter().fold(0.0f64, |a, v| a.max(v.abs()))
        );
    }
}
