//! Randomly generated valid scenes, rendered for a few samples: no panic, no NaN or Inf in the
//! image, and no dropped sample. Each scene is written as a scene file and goes through the
//! parser and validator like a user's; the generator covers every feature the path tracer
//! renders (`illum_pathtrace::implements`: boxes, rotated boxes, quads and spheres; Lambertian,
//! checkerboard, mirror and glass materials; quad area lights, a delta or disc sun, a constant
//! sky; the caustic's light tracer), with the camera anywhere, objects at random sizes (1e-3 to
//! 1e3) and places (up to 1e4 away), degenerate-but-valid ones (flat boxes, needle quads, tiny
//! spheres, objects through the camera, lights facing away, albedo 0 and 1, reflectance 0 and 1,
//! index of refraction from 1e-3 to 1e3 and exactly 1, a sun of angular radius up to 89 degrees,
//! emission, irradiance and sky radiance from 1e-6 up to f32::MAX).
//!
//! The generic traversal is used so that the few hundred scenes share one compiled pipeline
//! (the specialised one is compiled per scene, which would take minutes on lavapipe). Every
//! [`SPECIALISED_EVERY`]th scene is also rendered with the default options, the specialised
//! traversal generated from the scene (its numbers as constants, occluders that cannot block
//! pruned) with paired paths: the same seed traces the same paths, so each pixel must agree with
//! the generic traversal's to f32 rounding, except where a ray grazes an edge and the two
//! roundings send it to different sides (at most [`MAX_DISAGREEING`] of the pixels compared).

use illum_pathtrace::{PathTracer, TracerOptions, Traversal};
use illum_scene::Scene;

use crate::common::gpu;

/// Scenes per run.
const SCENES: u32 = 300;
/// Every this many scenes, the specialised traversal too (one pipeline compiled per scene).
const SPECIALISED_EVERY: u32 = 5;
/// Two traversals agree on a pixel when every channel differs by at most this, relative to the
/// larger: f32 rounding along a path of up to a few dozen operations per bounce.
const AGREE: f64 = 1e-4;
/// The fraction of compared pixels allowed to disagree (a grazing ray's sample on the other side).
const MAX_DISAGREEING: f64 = 0.01;

/// A small deterministic generator (SplitMix64): the same scenes every run, so a failure
/// reproduces; the scene's text is printed when it fails.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    /// Log-uniform in [lo, hi] (sizes from tiny to huge).
    fn log(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + (hi.ln() - lo.ln()) * self.unit()).exp()
    }
    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[(self.next() % items.len() as u64) as usize]
    }
    fn vec3(&mut self, scale: f64) -> String {
        format!(
            "[{:?}, {:?}, {:?}]",
            self.range(-scale, scale),
            self.range(-scale, scale),
            self.range(-scale, scale)
        )
    }
}

/// One random scene file.
fn random_scene(rng: &mut Rng) -> String {
    let world = *rng.pick(&[1.0, 10.0, 1e3, 1e4]);
    let mut text = String::new();
    let eye = rng.vec3(world);
    let target = rng.vec3(world * 0.5);
    text += &format!(
        "[camera]\neye = {eye}\ntarget = {target}\nup = [0.0, 1.0, 0.0]\nvfov = {:?}\nwidth = {}\nheight = {}\n\n",
        rng.range(1.0, 170.0),
        rng.pick(&[1, 3, 8, 16]),
        rng.pick(&[1, 5, 8, 16])
    );
    let materials = 1 + rng.next() % 4;
    for m in 0..materials {
        let albedo = *rng.pick(&[0.0, 1.0, 0.5, 0.18]);
        let kind = match rng.next() % 4 {
            0 => {
                let any = rng.log(0.1, 10.0);
                format!("dielectric = {{ ior = {:?} }}", rng.pick(&[1.0, 1.5, 1.4285715, 1e-3, 1e3, any]))
            }
            1 => format!("mirror = {{ reflectance = [{albedo:?}, {:?}, 1.0] }}", rng.unit()),
            _ => format!("albedo = [{albedo:?}, {:?}, {:?}]", rng.unit(), rng.unit()),
        };
        text += &format!("[materials.m{m}]\n{kind}\n");
    }
    // A checkerboard is for quads only (its tiles are counted along a quad's edges).
    text += &format!(
        "[materials.checker]\nchecker = {{ even = [{:?}, {:?}, 0.0], odd = [{:?}, 1.0, {:?}], tile = {:?} }}\n",
        rng.pick(&[0.0, 1.0, 0.5]),
        rng.unit(),
        rng.unit(),
        rng.unit(),
        rng.log(1e-3, 1e3)
    );
    let brightness = [1e-6, 1.0, std::f64::consts::PI, 1e6, 1e30, f32::MAX as f64];
    let sun = rng.next().is_multiple_of(2);
    if sun {
        text += &format!(
            "[directional_light]\ndirection = {}\nirradiance = [{:e}, 1.0, 0.5]\nangular_radius = {:?}\n\n",
            rng.vec3(1.0),
            rng.pick(&brightness),
            rng.pick(&[0.0, 0.0, 0.5, 10.0, 89.0])
        );
    }
    if rng.next().is_multiple_of(2) {
        text += &format!("[environment]\nradiance = [{:e}, 0.5, 1.0]\n\n", rng.pick(&brightness));
    }
    let lights = 1 + rng.next() % 2;
    for l in 0..lights {
        let e = *rng.pick(&[1e-6, 1.0, 30.0, 1e6, 1e30, f32::MAX as f64]);
        text += &format!("[materials.light{l}]\nemission = [{e:e}, {:e}, 1.0]\n", e * rng.unit());
    }
    // The caustic's light tracer compiles its own pipelines for each scene (slow on lavapipe):
    // one scene with a sun in 16, about 10 a run.
    let caustics = sun && rng.next().is_multiple_of(16);
    text += &format!(
        "[pathtrace]\nbounces = {}\nseed = {}\nsampling = \"{}\"\ncaustics = {caustics}\n\n",
        rng.pick(&["0", "1", "2", "8", "\"unbounded\""]),
        rng.next() % 1000,
        rng.pick(&["cosine", "uniform"])
    );
    let objects = rng.next() % 6;
    for o in 0..objects {
        let size = rng.log(1e-3, 1e3);
        let mut material = format!("m{}", rng.next() % materials);
        let kind = rng.next() % 4;
        if kind == 3 && rng.next().is_multiple_of(3) {
            material = "checker".to_owned();
        }
        let shape = match kind {
            0 => format!(
                "box = {{ center = {}, half_extent = [{:?}, {:?}, {:?}] }}",
                rng.vec3(world),
                size,
                size * rng.log(1e-3, 1.0),
                size * rng.range(0.1, 2.0)
            ),
            1 => format!(
                "box = {{ min = [0.0, 0.0, 0.0], max = [{size:?}, {:?}, {size:?}], rotate_y = {:?}, pivot = {}, translate = {} }}",
                size * rng.range(0.01, 3.0),
                rng.range(-360.0, 360.0),
                rng.vec3(size),
                rng.vec3(world)
            ),
            2 => format!("sphere = {{ center = {}, radius = {size:?} }}", rng.vec3(world)),
            _ => format!(
                "quad = {{ corner = {}, edge_u = [{size:?}, 0.0, {:?}], edge_v = [0.0, {:?}, {:?}] }}",
                rng.vec3(world),
                rng.range(-1.0, 1.0) * size,
                size * rng.log(1e-3, 10.0),
                rng.range(-1.0, 1.0)
            ),
        };
        text += &format!("[[objects]]\nname = \"o{o}\"\nmaterial = \"{material}\"\n{shape}\n\n");
    }
    for l in 0..lights {
        let size = rng.log(1e-2, world.max(1.0));
        // Facing either way: a light facing away from everything is valid, and renders black.
        let flip = if rng.next().is_multiple_of(2) { 1.0 } else { -1.0 };
        text += &format!(
            "[[objects]]\nname = \"light {l}\"\nmaterial = \"light{l}\"\nquad = {{ corner = {}, edge_u = [{size:?}, 0.0, 0.0], edge_v = [0.0, 0.0, {:?}] }}\n\n",
            rng.vec3(world),
            flip * size * rng.range(0.1, 1.0)
        );
    }
    text
}

#[test]
fn random_valid_scenes_render_without_nan_or_dropped_samples() {
    let mut rng = Rng(0x1111_5eed);
    let (mut rendered, mut refused, mut caustic_scenes) = (0, Vec::new(), 0);
    let (mut specialised, mut compared, mut disagreeing, mut worst) = (0, 0usize, 0usize, 0.0f64);
    for i in 0..SCENES {
        let text = random_scene(&mut rng);
        let scene = match Scene::from_toml_str(&text, &format!("random-{i}.toml")) {
            Ok(scene) => scene,
            // The generator aims at valid scenes; the few it misses (eye == target after
            // rounding, a camera looking straight up) must be refused by name, never panic.
            Err(e) => {
                refused.push(e.to_string());
                continue;
            }
        };
        let options = TracerOptions { traversal: Traversal::Generic, ..Default::default() };
        let mut tracer = PathTracer::with_options(gpu(), &scene, options)
            .unwrap_or_else(|e| panic!("scene {i} was valid but the tracer refused it: {e}\n{text}"));
        tracer.add_samples_in_one_pass(4).unwrap_or_else(|e| panic!("scene {i}: {e}\n{text}"));
        caustic_scenes += u32::from(tracer.caustics());
        let acc = tracer.accumulator();
        let image = acc.mean_image();
        assert!(!image.has_non_finite(), "scene {i}: NaN or Inf in the image\n{text}");
        assert_eq!(acc.dropped_samples(), 0, "scene {i}: dropped samples\n{text}");
        assert!(
            acc.estimated_rel_mse().is_finite() || acc.min_samples() < 2,
            "scene {i}: infinite error estimate\n{text}"
        );
        rendered += 1;
        if i % SPECIALISED_EVERY == 0 {
            let mut tracer = PathTracer::with_options(gpu(), &scene, TracerOptions::default())
                .unwrap_or_else(|e| panic!("scene {i}: the specialised traversal refused it: {e}\n{text}"));
            tracer
                .add_samples_in_one_pass(4)
                .unwrap_or_else(|e| panic!("scene {i}, specialised: {e}\n{text}"));
            let acc = tracer.accumulator();
            let other = acc.mean_image();
            assert!(!other.has_non_finite(), "scene {i}, specialised: NaN or Inf in the image\n{text}");
            assert_eq!(acc.dropped_samples(), 0, "scene {i}, specialised: dropped samples\n{text}");
            for (a, b) in image.pixels.iter().zip(&other.pixels) {
                let difference = (0..3)
                    .map(|c| {
                        let (a, b) = (f64::from(a[c]), f64::from(b[c]));
                        if a == b { 0.0 } else { (a - b).abs() / a.abs().max(b.abs()) }
                    })
                    .fold(0.0, f64::max);
                worst = worst.max(difference);
                disagreeing += usize::from(difference > AGREE);
                compared += 1;
            }
            specialised += 1;
        }
    }
    let fraction = disagreeing as f64 / compared as f64;
    println!(
        "{specialised} scenes also with the specialised traversal: {disagreeing} of {compared} pixels differ by more \
         than {AGREE:e} relative ({fraction:.4}); largest relative difference {worst:.2e}"
    );
    assert!(specialised >= SCENES / SPECIALISED_EVERY * 9 / 10, "only {specialised} scenes were specialised");
    assert!(
        fraction <= MAX_DISAGREEING,
        "the specialised traversal disagrees with the generic one on {disagreeing} of {compared} pixels"
    );
    println!(
        "{rendered} random scenes rendered ({caustic_scenes} with the caustic's light tracer), {} refused by the validator",
        refused.len()
    );
    assert!(caustic_scenes >= 3, "only {caustic_scenes} scenes ran the caustic's light tracer");
    assert!(
        rendered >= SCENES * 9 / 10,
        "only {rendered} of {SCENES} generated scenes were valid: {refused:?}"
    );
}
