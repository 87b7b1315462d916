//! Throughput of the oracle on the assignment's Cornell box: 32 x 32 pixels, 2 bounces,
//! cosine sampling, on all cores and on one.
//!
//!     cargo run --release -p illum-oracle --example oracle_speed [SPP]

use std::time::Instant;

use illum_oracle::Oracle;
use illum_scene::{Bounces, Sampling, Scene};

fn main() {
    let spp: u32 =
        std::env::args().nth(1).map_or(256, |s| s.parse().expect("SPP must be a positive integer"));
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/cornell.toml");
    let mut scene = Scene::load(std::path::Path::new(path)).expect("scenes/cornell.toml");
    scene.camera.width = 32;
    scene.camera.height = 32;
    let oracle = Oracle::new(&scene)
        .expect("the oracle renders this scene")
        .with_bounces(Bounces::Fixed(2))
        .with_sampling(Sampling::Cosine);
    let samples = f64::from(spp) * 32.0 * 32.0;
    for threads in [illum_oracle::default_threads(), 1] {
        let start = Instant::now();
        let image = oracle.render(spp, 0, threads);
        let seconds = start.elapsed().as_secs_f64();
        let (mean, var) = image.overall_mean();
        println!(
            "32x32, 2 bounces, {spp} spp, {threads} thread(s): {seconds:.2} s, {:.3e} samples/s \
             (image mean {mean:.5} +- {:.5})",
            samples / seconds,
            var.sqrt()
        );
    }
}
