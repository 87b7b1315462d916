//! How much light the camera paths and the light tracer alone miss with the Whitted scene's
//! delta sun (the photon gather off): the sun's glint (E S+ L), the caustic seen in the mirror or
//! through the glass (E S+ D S+ L) and light the caustic sends on to other diffuse surfaces
//! (E .. D S* D S+ L), the last two the gather's when it is on (`mirror_caustic` measures them
//! region by region).
//!
//! With a sun disc the camera paths find those paths too (a bounce or a specular chain that
//! happens to reach the disc), so the image with a disc of radius RADIUS degrees minus the image
//! with the delta sun, both with the caustic's light tracer on, is that remainder plus the
//! disc's blur of the shadows and caustics (whose mean over a region is zero to first order).
//! Printed: the whole image's mean radiance and the difference, and the same over the pixels
//! that see a ball (where the caustic seen through glass or in the mirror lives).
//!
//!     cargo run --release -p illum-oracle --example caustic_remainder [SPP] [RADIUS]

use illum_oracle::Oracle;
use illum_scene::{Bounces, Scene};

fn main() {
    let mut args = std::env::args().skip(1);
    let spp: u32 = args.next().map_or(4096, |s| s.parse().expect("SPP must be a positive integer"));
    let radius: f32 = args.next().map_or(2.0, |s| s.parse().expect("RADIUS must be a number of degrees"));
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/whitted.toml");
    let mut scene = Scene::load(std::path::Path::new(path)).expect("scenes/whitted.toml");
    scene.camera.width = 64;
    scene.camera.height = 36;
    scene.pathtrace.caustics = true;
    let threads = illum_oracle::default_threads();
    let render = |scene: &Scene| {
        Oracle::new(scene)
            .expect("the oracle renders this scene")
            .with_bounces(Bounces::Fixed(8))
            .with_gather(false)
            .render(spp, 11, threads)
    };
    let delta = render(&scene);
    let mut disc = scene.clone();
    disc.directional_light.as_mut().expect("a sun").angular_radius_deg = radius;
    let disc = render(&disc);
    // Pixels that see a ball: the camera ray's first hit is a sphere (traced again here in f64).
    let camera = illum_oracle::PinholeCamera::new(&scene.camera);
    let balls: Vec<(glam::DVec3, f64)> = scene
        .objects
        .iter()
        .filter_map(|o| match o.shape {
            illum_scene::Shape::Sphere(s) => Some((s.center.as_dvec3(), f64::from(s.radius))),
            _ => None,
        })
        .collect();
    let sees_ball = |x: u32, y: u32| {
        let d = camera.direction(x, y, 0.5, 0.5);
        balls.iter().any(|(c, r)| {
            let m = camera.eye - *c;
            let b = m.dot(d);
            b * b - (m.length_squared() - r * r) > 0.0 && -b > 0.0
        })
    };
    for (label, keep) in [
        ("whole image", Box::new(|_, _| true) as Box<dyn Fn(u32, u32) -> bool>),
        ("pixels on a ball", Box::new(sees_ball)),
    ] {
        let (mut n, mut base, mut diff, mut var) = (0.0, [0.0; 3], [0.0; 3], [0.0; 3]);
        for y in 0..36 {
            for x in 0..64 {
                if !keep(x, y) {
                    continue;
                }
                let i = delta.index(x, y);
                n += 1.0;
                for c in 0..3 {
                    base[c] += delta.mean[i][c];
                    diff[c] += disc.mean[i][c] - delta.mean[i][c];
                    var[c] += disc.variance_of_mean[i][c] + delta.variance_of_mean[i][c];
                }
            }
        }
        for c in 0..3 {
            println!(
                "{label}, channel {c}: mean {:.5}, disc - delta {:+.5} +- {:.5} ({:+.2}% of the mean)",
                base[c] / n,
                diff[c] / n,
                var[c].sqrt() / n,
                100.0 * diff[c] / base[c]
            );
        }
    }
}
