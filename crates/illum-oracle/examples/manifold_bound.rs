//! The bias of the bound on manifold next-event estimation's concentration
//! (`illum_scene::specular_spheres::MAX_CONCENTRATION`, which both the GPU and the oracle apply):
//! the oracle on the Whitted view at 64 x 36, bounces 8, with the solve (a) unbounded and (b)
//! bounded, on the same camera paths (the solve draws no random numbers), so the difference is
//! taken sample by sample. Printed: the mean of (b) - (a) over the image and over the pixels
//! where it is not zero, red (the floor, where the caustic falls, has no blue albedo).
//!
//!     cargo run --release -p illum-oracle --example manifold_bound [SPP]

use glam::DVec3;
use illum_oracle::{ManifoldSettings, Oracle};
use illum_scene::{CausticMethod, Scene};

const SEED: u64 = 7;

fn main() {
    let spp: u32 =
        std::env::args().nth(1).map_or(256, |s| s.parse().expect("SPP must be a positive integer"));
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/whitted.toml");
    let mut scene = Scene::load(std::path::Path::new(path)).expect("scenes/whitted.toml");
    scene.camera.width = 64;
    scene.camera.height = 36;
    scene.pathtrace.caustic_method = CausticMethod::Manifold;
    let bounded = Oracle::new(&scene).expect("the oracle renders this scene");
    assert!(bounded.manifold());
    let unbounded =
        bounded.clone().with_manifold(Some(ManifoldSettings { intervals: 512, ..Default::default() }));
    let (width, height) = (scene.camera.width, scene.camera.height);
    let pixels = (width * height) as usize;
    let threads = illum_oracle::default_threads();
    let rows_per = height.div_ceil(threads as u32);
    let sums: Vec<(DVec3, DVec3, DVec3)> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads as u32)
            .map(|t| {
                let (a, b) = (&unbounded, &bounded);
                scope.spawn(move || {
                    let mut out = Vec::new();
                    for y in (t * rows_per).min(height)..((t + 1) * rows_per).min(height) {
                        for x in 0..width {
                            let (mut full, mut d, mut d2) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
                            for k in 0..spp {
                                let va = a.pixel_sample(x, y, SEED, k);
                                let diff = b.pixel_sample(x, y, SEED, k) - va;
                                full += va;
                                d += diff;
                                d2 += diff * diff;
                            }
                            out.push((full, d, d2));
                        }
                    }
                    out
                })
            })
            .collect();
        workers.into_iter().flat_map(|w| w.join().expect("worker")).collect()
    });
    let n = f64::from(spp);
    let report = |label: &str, keep: &dyn Fn(&(DVec3, DVec3, DVec3)) -> bool| {
        let chosen: Vec<_> = sums.iter().filter(|s| keep(s)).collect();
        if chosen.is_empty() {
            println!("| {label} | 0 | | no sample reached the bound | |");
            return;
        }
        let m = chosen.len() as f64;
        let mean = chosen.iter().map(|s| s.0.x / n).sum::<f64>() / m;
        let diff = chosen.iter().map(|s| s.1.x / n).sum::<f64>() / m;
        let var = chosen.iter().map(|s| (s.2.x / n - (s.1.x / n).powi(2)) / (n - 1.0)).sum::<f64>() / (m * m);
        println!(
            "| {label} | {} | {mean:.4} | {diff:+.6} ± {:.6} | {:+.3}% |",
            chosen.len(),
            var.sqrt(),
            100.0 * diff / mean
        );
    };
    println!(
        "Whitted view 64 x 36, bounces 8, {spp} spp, seed {SEED}: the solve bounded at C <= {} minus unbounded (red)\n",
        illum_scene::specular_spheres::MAX_CONCENTRATION
    );
    println!("| region | pixels | mean, unbounded | bounded - unbounded | % |\n|---|---|---|---|---|");
    report("whole image", &|_| true);
    report("pixels the bound changes", &|s| s.1.x != 0.0);
    assert_eq!(sums.len(), pixels);
}
