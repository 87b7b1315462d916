//! Anti-aliased edges: every pixel of a flat-shaded version of the scene against its exact
//! box-filtered value, computed here in f64 by dense sub-sampling of camera rays.
//!
//! The scene is the shipped one made flat: the glass white (figure look, reflectivity 0: the
//! glass shows its colour only), the metal black (colour and highlight 0), the floor one grey
//! (both tiles alike, no shadows), the sky black. Each pixel of the render is then the exact
//! mean over its area of what the rays through it meet, when the edges' coverage is right and
//! each edge is blended over what is behind it: the spheres' silhouettes over the floor, the sky
//! and each other, and the floor's outline (its far and side edges) over the sky. The expected
//! mean is taken over a 64 x 64 grid of rays per pixel (at most 1/128 off for a straight edge
//! along a pixel axis, far less at other angles), from the camera's numbers, in f64, never from
//! the renderer's matrices or shaders.

use glam::{DVec3, Vec3};
use illum_image::RgbImage32;
use illum_raster::{Look, Options, RasterScene};

use crate::{HEIGHT, WIDTH, render, scene};

/// Largest difference allowed on an edge pixel, in 8-bit levels. The shader's coverage is exact
/// for a straight edge (edge_coverage in scene.wgsl); what remains: the output's rounding to 8
/// bits, twice where a sphere blends over a floor that was itself rounded (1 level), the
/// silhouette's curvature within a pixel (about 1 / (8 R), R = 50 and 27 pixels here: up to 1.2
/// levels),
/// and this test's sampling grid (up to 2 levels on an edge along a pixel axis). A common
/// approximation, coverage = clamp(1/2 + distance / |gradient|), is off by up to 0.043 (11 levels) at
/// 45 degrees, and a jagged edge by up to half the contrast.
const EDGE_TOLERANCE_LEVELS: f64 = 4.0;
/// The mean over edge pixels, in levels.
const EDGE_MEAN_TOLERANCE_LEVELS: f64 = 1.0;

/// Rays per pixel side for the expected value.
const GRID: u32 = 64;

/// The flat scene and its grey floor's value.
fn flat_scene() -> (RasterScene, f64) {
    let mut s = scene();
    s.look = Look::Figure;
    s.effects.shadows = false;
    s.background = Vec3::ZERO;
    let glass = s.glass.as_mut().expect("the shipped scene has a glass sphere");
    glass.color = Vec3::ONE;
    glass.reflectivity = 0.0;
    let metal = s.metal.as_mut().expect("the shipped scene has a metal sphere");
    metal.color = Vec3::ZERO;
    metal.specular = Vec3::ZERO;
    let albedo = 0.4;
    s.floor.colors = [Vec3::splat(albedo); 2];
    // Lambert with ambient, no shadows: albedo x (ambient + radiance x N.L), the same everywhere.
    let n_dot_l = f64::from(s.light.to_light().y.max(0.0));
    let floor = f64::from(albedo) * (f64::from(s.ambient.x) + f64::from(s.light.radiance().x) * n_dot_l);
    assert!(
        s.ambient.x == s.ambient.y && s.ambient.y == s.ambient.z && floor > 0.2 && floor < 0.8,
        "a grey floor between black and white: {floor}"
    );
    (s, floor)
}

/// The camera's rays in f64: (eye, forward, right x aspect x tan, up x tan) for a `width` x
/// `height` image, from the scene file's camera numbers.
struct Rays {
    eye: DVec3,
    forward: DVec3,
    right: DVec3,
    up: DVec3,
    width: f64,
    height: f64,
}

impl Rays {
    fn new(s: &RasterScene, width: u32, height: u32) -> Self {
        let cam = &s.camera;
        let eye = cam.eye.as_dvec3();
        let forward = (cam.target.as_dvec3() - eye).normalize();
        let right = forward.cross(cam.up.as_dvec3()).normalize();
        let up = right.cross(forward);
        let tan = (f64::from(cam.vfov_deg).to_radians() * 0.5).tan();
        let aspect = f64::from(width) / f64::from(height);
        Rays {
            eye,
            forward,
            right: right * tan * aspect,
            up: up * tan,
            width: f64::from(width),
            height: f64::from(height),
        }
    }

    /// The (unnormalised) direction through image point (x, y), pixels from the top left, y down.
    fn direction(&self, x: f64, y: f64) -> DVec3 {
        self.forward + (2.0 * x / self.width - 1.0) * self.right + (1.0 - 2.0 * y / self.height) * self.up
    }
}

/// What the flat scene shows along the ray from `eye` along `dir`: (surface id, value). Ids: 0
/// sky, 1 floor, 2 glass, 3 metal.
fn flat_sample(s: &RasterScene, floor_value: f64, eye: DVec3, dir: DVec3) -> (u8, f64) {
    let mut nearest = (f64::INFINITY, 0u8, 0.0);
    let spheres = [(s.glass.unwrap().center, s.glass.unwrap().radius, 2u8, 1.0), {
        let m = s.metal.unwrap();
        (m.center, m.radius, 3u8, 0.0)
    }];
    for (c, r, id, value) in spheres {
        let oc = eye - c.as_dvec3();
        let (a, b) = (dir.length_squared(), oc.dot(dir));
        let disc = b * b - a * (oc.length_squared() - f64::from(r) * f64::from(r));
        if disc >= 0.0 {
            let t = (-b - disc.sqrt()) / a;
            if t > 0.0 && t < nearest.0 {
                nearest = (t, id, value);
            }
        }
    }
    let h = f64::from(s.floor.height());
    if dir.y != 0.0 {
        let t = (h - eye.y) / dir.y;
        let p = eye + t * dir;
        let (lo, hi) = (s.floor.min_corner().as_dvec2(), s.floor.max_corner().as_dvec2());
        let inside = p.x >= lo.x && p.x <= hi.x && p.z >= lo.y && p.z <= hi.y;
        if t > 0.0 && inside && t < nearest.0 {
            nearest = (t, 1, floor_value);
        }
    }
    (nearest.1, nearest.2)
}

/// Whether pixel (px, py) shows more than one surface (probed on a 5 x 5 grid over it, border
/// included), and its exact box-filtered value (`GRID` x `GRID` rays) if so.
fn expected(s: &RasterScene, floor: f64, rays: &Rays, px: u32, py: u32) -> (bool, f64) {
    let (x0, y0) = (f64::from(px), f64::from(py));
    let at = |fx: f64, fy: f64| flat_sample(s, floor, rays.eye, rays.direction(x0 + fx, y0 + fy));
    let centre = at(0.5, 0.5);
    let probes = (0..5).flat_map(|i| (0..5).map(move |j| (f64::from(i) / 4.0, f64::from(j) / 4.0)));
    let edge = probes.into_iter().any(|(fx, fy)| at(fx, fy).0 != centre.0);
    if !edge {
        return (false, centre.1);
    }
    let mut sum = 0.0;
    for i in 0..GRID {
        for j in 0..GRID {
            let (fx, fy) = ((f64::from(i) + 0.5) / f64::from(GRID), (f64::from(j) + 0.5) / f64::from(GRID));
            sum += at(fx, fy).1;
        }
    }
    (true, sum / f64::from(GRID * GRID))
}

/// The largest and mean difference (levels) over edge pixels and the largest over the rest,
/// with where the largest edge difference is.
struct Differences {
    edge_max: f64,
    edge_at: (u32, u32),
    edge_mean: f64,
    edge_pixels: usize,
    interior_max: f64,
}

fn compare(s: &RasterScene, floor: f64, image: &RgbImage32) -> Differences {
    let rays = Rays::new(s, image.width, image.height);
    let mut d =
        Differences { edge_max: 0.0, edge_at: (0, 0), edge_mean: 0.0, edge_pixels: 0, interior_max: 0.0 };
    for py in 0..image.height {
        for px in 0..image.width {
            let (edge, value) = expected(s, floor, &rays, px, py);
            let got = image.get(px, py);
            let diff = (0..3).map(|c| (f64::from(got[c]) - value).abs() * 255.0).fold(0.0, f64::max);
            if edge {
                d.edge_pixels += 1;
                d.edge_mean += diff;
                if diff > d.edge_max {
                    d.edge_max = diff;
                    d.edge_at = (px, py);
                }
            } else {
                d.interior_max = d.interior_max.max(diff);
            }
        }
    }
    d.edge_mean /= d.edge_pixels.max(1) as f64;
    d
}

#[test]
fn edge_pixels_are_the_exact_fraction_of_each_surface_they_cover() {
    let (s, floor) = flat_scene();
    let d = compare(&s, floor, &render(&s, &Options { look: Look::Figure, effects: s.effects }));
    eprintln!(
        "anti-aliased edges at {WIDTH} x {HEIGHT}: {} edge pixels, max {:.2} levels at {:?}, mean {:.3}; \
         elsewhere max {:.2}",
        d.edge_pixels, d.edge_max, d.edge_at, d.edge_mean, d.interior_max
    );
    // Both silhouettes and the floor's far and side edges: about 800 pixels at this size.
    assert!(d.edge_pixels > 600, "only {} edge pixels checked", d.edge_pixels);
    assert!(
        d.edge_max <= EDGE_TOLERANCE_LEVELS && d.edge_mean <= EDGE_MEAN_TOLERANCE_LEVELS,
        "edge pixels off the exact coverage by up to {:.2} levels at {:?} (mean {:.3})",
        d.edge_max,
        d.edge_at,
        d.edge_mean
    );
    // Away from edges nothing but 8-bit rounding.
    assert!(d.interior_max <= 0.51, "a pixel away from any edge is off by {:.2} levels", d.interior_max);
}

#[test]
fn without_antialiasing_the_same_check_fails() {
    // The check above can fail: the jagged image (each pixel what its centre's ray meets) is
    // far off the exact coverage on the edges, and still right inside.
    let (s, floor) = flat_scene();
    let mut options = Options { look: Look::Figure, effects: s.effects };
    options.effects.antialiasing = false;
    let d = compare(&s, floor, &render(&s, &options));
    assert!(
        d.edge_max > 100.0 && d.edge_mean > 10.0,
        "jagged edges: max {:.2}, mean {:.3}",
        d.edge_max,
        d.edge_mean
    );
    assert!(d.interior_max <= 0.51, "a pixel away from any edge is off by {:.2} levels", d.interior_max);
}
