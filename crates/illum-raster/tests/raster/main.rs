//! GPU tests of the rasterizer (one test binary, one device, on lavapipe).
//!
//! - `reference`: both looks against checked-in 320 x 180 references, with a stated tolerance;
//! - `figure`: checks of the figure look that need no reference: the floor's Lambert shading,
//!   the background value, where the shadows fall, and the glass's 0.1 white + 0.9 environment;
//! - `edges`: anti-aliased edges against their exact coverage, computed in f64;
//! - `effects`: every toggle does what it says (and only that), no shadow acne, anti-aliasing
//!   only on edges;
//! - `extremes`: the scene at its extremes (low and high light, near and far
//!   planes, the horizon, refraction ratio 1, total internal reflection), tabulated in
//!   docs/raster-extremes.md;
//! - `passes`: a frame records only the passes its scene needs, and skipping one changes nothing;
//! - `bands`: a large frame drawn in bands of rows is the frame drawn whole, and a frame read
//!   back without waiting is the frame rendered.
//!
//! The render example's raster path is tested beside it, in illum-cli's `tests/raster.rs`.
//!
//! The expected values are computed here from the scene file and illum-scene's camera, never
//! from the renderer's own matrices.

use std::sync::{Mutex, MutexGuard, OnceLock};

use glam::Vec3;
use illum_gpu::testing;
use illum_image::RgbImage32;
use illum_raster::RasterScene;
use illum_raster::{Options, RasterRenderer};
use illum_scene::Camera;

mod bands;
mod edges;
mod effects;
mod extremes;
mod figure;
mod passes;
mod reference;

/// The size of the reference images and of most checks.
pub const WIDTH: u32 = 320;
pub const HEIGHT: u32 = 180;

/// scenes/whitted.toml as shipped.
pub fn scene() -> RasterScene {
    RasterScene::load(&testing::workspace_path("scenes/whitted.toml")).unwrap_or_else(|e| panic!("{e}"))
}

/// One renderer for the whole binary (pipelines are compiled once); tests take turns.
fn renderer() -> MutexGuard<'static, RasterRenderer> {
    static RENDERER: OnceLock<Mutex<RasterRenderer>> = OnceLock::new();
    RENDERER
        .get_or_init(|| {
            let renderer = RasterRenderer::new(testing::gpu(), &scene(), WIDTH, HEIGHT)
                .unwrap_or_else(|e| panic!("the rasterizer builds: {e}"));
            Mutex::new(renderer)
        })
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// `scene` rendered with `options` at `width` x `height`.
pub fn render_at(scene: &RasterScene, options: &Options, width: u32, height: u32) -> RgbImage32 {
    let mut r = renderer();
    if r.size() != (width, height) {
        r.resize(width, height).unwrap_or_else(|e| panic!("{e}"));
    }
    r.set_scene(scene).unwrap_or_else(|e| panic!("{e}"));
    let image = r.render(options).unwrap_or_else(|e| panic!("{e}"));
    assert!(!image.has_non_finite());
    image
}

pub fn render(scene: &RasterScene, options: &Options) -> RgbImage32 {
    render_at(scene, options, WIDTH, HEIGHT)
}

/// A channel as the 8-bit value written to the PNG.
pub fn level(v: f32) -> i32 {
    (v * 255.0).round() as i32
}

/// The scene's camera set to an image of `width` x `height`.
pub fn camera(scene: &RasterScene, width: u32, height: u32) -> Camera {
    Camera { width, height, ..scene.camera }
}

/// Distance from `center` to the ray origin + t dir (t >= 0, dir unit).
pub fn ray_distance(origin: Vec3, dir: Vec3, center: Vec3) -> f32 {
    let t = (center - origin).dot(dir).max(0.0);
    (origin + t * dir - center).length()
}

/// The nearer hit of the ray with a sphere, if any.
pub fn ray_sphere(origin: Vec3, dir: Vec3, center: Vec3, radius: f32) -> Option<f32> {
    let oc = origin - center;
    let b = oc.dot(dir);
    let disc = b * b - (oc.length_squared() - radius * radius);
    (disc >= 0.0).then(|| -b - disc.sqrt()).filter(|t| *t > 0.0)
}

/// Where the camera ray through pixel centre (px, py) meets the floor plane, if inside the
/// floor's rectangle and not behind a sphere.
pub fn floor_hit(scene: &RasterScene, camera: &Camera, px: f32, py: f32) -> Option<Vec3> {
    let dir = camera.ray_direction(px, py);
    let eye = camera.eye;
    if dir.y >= 0.0 {
        return None;
    }
    let t = (scene.floor.height() - eye.y) / dir.y;
    let p = eye + t * dir;
    let (lo, hi) = (scene.floor.min_corner(), scene.floor.max_corner());
    let inside = p.x > lo.x && p.x < hi.x && p.z > lo.y && p.z < hi.y;
    let hidden =
        scene.spheres().into_iter().any(|(c, r)| ray_sphere(eye, dir, c, r).is_some_and(|ts| ts < t));
    (inside && !hidden).then_some(p)
}

/// The floor's red channel as shadow tests read it: (red albedo, ambient, direct irradiance
/// N.L x radiance), after checking both tiles have the same red, so that `what` (a shadow
/// fraction or visibility) can be read off it on any tile.
pub fn floor_red_lighting(s: &RasterScene, what: &str) -> (f32, f32, f32) {
    let [a, b] = s.floor.colors;
    assert_eq!(a.x, b.x, "{what} is read off the red channel, equal on both tiles");
    (a.x, s.ambient.x, s.light.radiance().x * s.light.to_light().y)
}
