//! The raster scene at the extremes. Every case checks that the image is
//! finite and measures a physical property against a value computed here (ray casts in f64, or a
//! second render that must agree). Each prints what it measured; docs/raster-extremes.md's table
//! "Raster extremes" quotes these numbers.
//!
//! Long (one test per extreme) but one concept: the rasterizer at the extremes of its inputs.

use glam::{DVec3, Vec3};
use illum_image::RgbImage32;
use illum_raster::RasterScene;
use illum_raster::{Look, Options};
use illum_scene::Camera;

use crate::{HEIGHT, WIDTH, camera, level, ray_sphere, render, scene};

fn finite(image: &RgbImage32, what: &str) {
    assert!(!image.has_non_finite(), "{what}: the image holds NaN or Inf");
}

fn spheres(s: &RasterScene) -> [(Vec3, f32); 2] {
    [(s.glass.unwrap().center, s.glass.unwrap().radius), (s.metal.unwrap().center, s.metal.unwrap().radius)]
}

/// The scene with its light moved to `degrees` of elevation above the floor, same azimuth, seen
/// from above: from the file's camera the long shadows of a low
/// light fall on the far floor straight behind the glass sphere.
fn light_at_elevation(degrees: f32) -> RasterScene {
    let mut s = scene();
    s.camera.eye = Vec3::new(10.0, 18.0, 6.0);
    s.camera.target = Vec3::new(-7.0, 0.0, -1.0);
    let to_light = s.light.to_light();
    let horizontal = Vec3::new(to_light.x, 0.0, to_light.z).normalize();
    let e = degrees.to_radians();
    s.light.direction = -(e.cos() * horizontal + e.sin() * Vec3::Y);
    s
}

/// How far the ray from floor point p toward the light passes outside sphere (c, r), in f64
/// (negative: it goes through the sphere, so p is in that sphere's exact shadow).
fn exact_margin(s: &RasterScene, p: DVec3, (c, r): (Vec3, f32)) -> f64 {
    let l = s.light.to_light().as_dvec3().normalize();
    let oc = c.as_dvec3() - p;
    let t = oc.dot(l).max(0.0);
    (oc - t * l).length() - f64::from(r)
}

/// What the camera ray through pixel point (x, y) meets first.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Hit {
    Sky,
    Floor(Vec3),
    Glass,
    Metal,
}

/// The first surface the camera ray along `dir` meets, from either side of the floor. The floor
/// is clipped by the near plane like any polygon (where it is nearer, the ray sees what lies
/// beyond); a sphere is not: its impostor keeps it closed (near_plane_cutting_the_glass_sphere).
fn trace_camera(s: &RasterScene, cam: &Camera, dir: Vec3) -> Hit {
    let hit = trace(s, cam.eye, dir, true);
    match hit {
        Hit::Floor(p) if (p - cam.eye).dot(cam.basis().forward) < s.clip.near => {
            let beyond = p + 1e-4 * dir;
            match trace(s, beyond, dir, true) {
                Hit::Floor(_) => Hit::Sky,
                other => other,
            }
        }
        other => other,
    }
}

/// The first surface along origin + t dir (t > 0), from either side of the floor. `with_glass`
/// false leaves the glass out (what its cube map sees).
fn trace(s: &RasterScene, origin: Vec3, dir: Vec3, with_glass: bool) -> Hit {
    let glass = if with_glass {
        ray_sphere(origin, dir, s.glass.unwrap().center, s.glass.unwrap().radius)
    } else {
        None
    };
    let metal = ray_sphere(origin, dir, s.metal.unwrap().center, s.metal.unwrap().radius);
    let floor = (dir.y != 0.0)
        .then(|| (s.floor.height() - origin.y) / dir.y)
        .filter(|t| *t > 0.0)
        .map(|t| (t, origin + t * dir))
        .filter(|(_, p)| {
            let (lo, hi) = (s.floor.min_corner(), s.floor.max_corner());
            p.x > lo.x && p.x < hi.x && p.z > lo.y && p.z < hi.y
        });
    let mut best = (f32::INFINITY, Hit::Sky);
    for (t, hit) in [(glass, Hit::Glass), (metal, Hit::Metal)] {
        if let Some(t) = t.filter(|t| *t < best.0) {
            best = (t, hit);
        }
    }
    if let Some((t, p)) = floor.filter(|(t, _)| *t < best.0) {
        best = (t, Hit::Floor(p));
    }
    best.1
}

/// Pixels whose ray meets nothing, and how many of them do not show the background exactly.
#[derive(Default)]
struct SkyCount {
    sky: u32,
    wrong: u32,
}

impl SkyCount {
    fn add(&mut self, image: &RgbImage32, x: u32, y: u32, background: [i32; 3]) {
        self.sky += 1;
        if image.get(x, y).map(level) != background {
            self.wrong += 1;
        }
    }
}

/// What pixel (x, y) sees, if its centre and four points 0.6 px away see the same kind of
/// surface (no silhouette or floor edge within the pixel). Floor hits return the centre's point.
fn interior(s: &RasterScene, cam: &Camera, x: u32, y: u32) -> Option<Hit> {
    let (cx, cy) = (x as f32 + 0.5, y as f32 + 0.5);
    let centre = trace_camera(s, cam, cam.ray_direction(cx, cy));
    let kind = |h: Hit| std::mem::discriminant(&h);
    [(-0.6, -0.6), (0.6, -0.6), (-0.6, 0.6), (0.6, 0.6)]
        .iter()
        .all(|(dx, dy)| kind(trace_camera(s, cam, cam.ray_direction(cx + dx, cy + dy))) == kind(centre))
        .then_some(centre)
}

/// Floor points seen at the pixel's centre and its four corners, when all five are floor.
fn floor_corners(s: &RasterScene, cam: &Camera, x: u32, y: u32) -> Option<[Vec3; 5]> {
    let (cx, cy) = (x as f32 + 0.5, y as f32 + 0.5);
    let mut out = [Vec3::ZERO; 5];
    for (k, (dx, dy)) in [(0.0, 0.0), (-0.5, -0.5), (0.5, -0.5), (-0.5, 0.5), (0.5, 0.5)].iter().enumerate() {
        match trace_camera(s, cam, cam.ray_direction(cx + dx, cy + dy)) {
            Hit::Floor(p) => out[k] = p,
            _ => return None,
        }
    }
    Some(out)
}

// ---------------------------------------------------------------------------------------------
// 1. Shadow-map bias at light elevations of 5 and 85 degrees.

struct ShadowMeasure {
    lit: usize,
    umbra: usize,
    acne: usize,
    missing: usize,
    extra: usize,
    /// Distance between the rendered and the exact shadow's centroids (scene units): of all the
    /// shadow on screen, then of each sphere's own (None when the other sphere's shadow covers
    /// all of it on the floor, as at 5 degrees, where both fall on the same far band).
    centroid_offset: [Option<f64>; 3],
    metal_checked: usize,
    metal_changed: usize,
    /// The farthest checked umbra pixel from the nearer sphere's centre, horizontally.
    umbra_reach: f32,
}

fn measure_shadows(s: &RasterScene) -> ShadowMeasure {
    let options = Options::all_on(Look::Figure);
    let image = render(s, &options);
    finite(&image, "shadows on");
    let mut off = options;
    off.effects.shadows = false;
    let unshadowed = render(s, &off);
    finite(&unshadowed, "shadows off");
    let cam = camera(s, WIDTH, HEIGHT);
    let (red, ambient, direct) = crate::floor_red_lighting(s, "the visibility");
    let lit_level = level(red * (ambient + direct));
    // The soft edge: the PCF kernel's reach (1.5 pcf_radius, measured across the light, which
    // is what exact_margin measures) plus a shadow-map texel and rounding.
    let pen = f64::from(1.5 * s.quality.pcf_radius + 0.02);
    let forward = cam.basis().forward;
    let mut m = ShadowMeasure {
        lit: 0,
        umbra: 0,
        acne: 0,
        missing: 0,
        extra: 0,
        centroid_offset: [None; 3],
        metal_checked: 0,
        metal_changed: 0,
        umbra_reach: 0.0,
    };
    // All shadow, then per sphere: (weight, weighted position) of the rendered and exact shadow.
    let mut rendered = [(0.0f64, DVec3::ZERO); 3];
    let mut exact = [(0.0f64, DVec3::ZERO); 3];
    for y in 0..HEIGHT {
        for x in 0..WIDTH {
            let Some(points) = floor_corners(s, &cam, x, y) else { continue };
            let margins: Vec<[f64; 2]> =
                points.iter().map(|p| spheres(s).map(|sp| exact_margin(s, p.as_dvec3(), sp))).collect();
            let got = image.get(x, y)[0];
            let visibility = (got / red - ambient) / direct;
            let in_umbra = margins.iter().all(|m| m[0] < -pen || m[1] < -pen);
            let in_light = margins.iter().all(|m| m[0] > pen && m[1] > pen);
            if in_light {
                m.lit += 1;
                if level(got) < lit_level - 2 {
                    m.acne += 1;
                }
                if visibility < 0.5 {
                    m.extra += 1;
                }
            } else if in_umbra {
                m.umbra += 1;
                let p = points[0];
                let reach = spheres(s).map(|(c, _)| Vec3::new(p.x - c.x, 0.0, p.z - c.z).length());
                m.umbra_reach = m.umbra_reach.max(reach[0].min(reach[1]));
                if visibility > 0.5 {
                    m.missing += 1;
                }
            }
            // Centroids over the floor within 0.5 (across the light) of an exact shadow, penumbra
            // included, weighted by the floor area the pixel covers; a pixel belongs to the
            // sphere whose shadow it is nearer. (Farther out, the 8-bit rounding of lit pixels
            // would add a faint uniform "shadow" that pulls the centroid.)
            if margins[0][0].min(margins[0][1]) > 0.5 {
                continue;
            }
            let p = points[0];
            let k = if margins[0][0] <= margins[0][1] { 1 } else { 2 };
            let dir = cam.ray_direction(x as f32 + 0.5, y as f32 + 0.5);
            let t = p.distance(cam.eye);
            let area = f64::from(dir.dot(forward).powi(3) * t * t / dir.y.abs());
            let shadow = f64::from((1.0 - visibility).clamp(0.0, 1.0));
            let inside = if margins[0][k - 1] < 0.0 { 1.0 } else { 0.0 };
            let p = p.as_dvec3();
            for k in [0, k] {
                rendered[k] = (rendered[k].0 + area * shadow, rendered[k].1 + area * shadow * p);
                exact[k] = (exact[k].0 + area * inside, exact[k].1 + area * inside * p);
            }
        }
    }
    // No exact shadow on screen leaves every centroid None; callers that need one assert it.
    for k in 0..3 {
        if exact[k].0 > 0.0 {
            m.centroid_offset[k] = Some((rendered[k].1 / rendered[k].0).distance(exact[k].1 / exact[k].0));
        }
    }
    // The metal sphere against its own depth in the map: where the light reaches it clear of the
    // glass (and of the glass's soft edge), shadows must not change a pixel.
    let clear = f64::from(3.0 * s.quality.pcf_radius + 0.05);
    for y in 0..HEIGHT {
        for x in 0..WIDTH {
            if interior(s, &cam, x, y) != Some(Hit::Metal) {
                continue;
            }
            let dir = cam.ray_direction(x as f32 + 0.5, y as f32 + 0.5);
            let Some(t) = ray_sphere(cam.eye, dir, s.metal.unwrap().center, s.metal.unwrap().radius) else {
                continue;
            };
            let p = (cam.eye + t * dir).as_dvec3();
            if exact_margin(s, p, (s.glass.unwrap().center, s.glass.unwrap().radius)) <= clear {
                continue;
            }
            m.metal_checked += 1;
            let (u, v) = (image.get(x, y), unshadowed.get(x, y));
            if (0..3).any(|c| (level(u[c]) - level(v[c])).abs() > 2) {
                m.metal_changed += 1;
            }
        }
    }
    m
}

#[test]
fn shadow_bias_at_light_elevations_of_5_and_85_degrees() {
    for degrees in [5.0, 85.0] {
        let s = light_at_elevation(degrees);
        let m = measure_shadows(&s);
        let mismatch = (m.missing + m.extra) as f64 / (m.lit + m.umbra) as f64;
        println!(
            "elevation {degrees}: lit {} (acne {}), umbra {} (missing {}), extra {}, mismatch {:.5}, \
             umbra reaches {:.1} from a sphere, centroid offsets (all, glass, metal) {:?}, metal pixels {} (changed by shadows {})",
            m.lit,
            m.acne,
            m.umbra,
            m.missing,
            m.extra,
            mismatch,
            m.umbra_reach,
            m.centroid_offset,
            m.metal_checked,
            m.metal_changed
        );
        assert!(m.lit > 5000 && m.umbra > 100, "{degrees} deg: too few pixels checked");
        assert_eq!(m.acne, 0, "{degrees} deg: lit floor pixels darker than lit (acne)");
        assert_eq!(m.missing + m.extra, 0, "{degrees} deg: shadow mask differs from the exact one");
        if degrees < 10.0 {
            // The shadow map is fitted to the casters along the light, so a shadow ten sphere
            // heights long is covered to the floor's far end (x = -23, ~27 from the spheres).
            assert!(
                m.umbra_reach > 20.0,
                "5 deg: the checked umbra ends {:.1} from the spheres",
                m.umbra_reach
            );
        }
        assert!(m.centroid_offset[0].is_some(), "{degrees} deg: no shadow on screen");
        for (k, offset) in m.centroid_offset.iter().enumerate() {
            let offset = offset.unwrap_or(0.0);
            assert!(offset < 0.05, "{degrees} deg: centroid {k} is {offset:.3} from the exact one");
        }
        assert!(m.metal_checked > 100, "{degrees} deg: only {} metal pixels", m.metal_checked);
        assert_eq!(m.metal_changed, 0, "{degrees} deg: shadows changed lit metal pixels (acne)");
    }
}

// ---------------------------------------------------------------------------------------------
// 2. The camera at the near and far planes, and orbiting down to the horizon.

/// Pixels whose largest channel differs by more than `tolerance` levels between a and b.
fn count_changed(a: &RgbImage32, b: &RgbImage32, keep: impl Fn(u32, u32) -> bool, tolerance: i32) -> usize {
    let mut n = 0;
    for y in 0..a.height {
        for x in 0..a.width {
            let (p, q) = (a.get(x, y), b.get(x, y));
            if keep(x, y) && (0..3).any(|c| (level(p[c]) - level(q[c])).abs() > tolerance) {
                n += 1;
            }
        }
    }
    n
}

/// The largest channel of `rgb` in levels.
fn max_level(rgb: [f32; 3]) -> i32 {
    rgb.into_iter().map(level).max().unwrap_or(0)
}

/// Glass pixel checks shared by several cases: the environment the pixel shows, E (figure look:
/// pixel = 0.1 white + 0.9 E; enhanced look: the pixel itself, a mix of environment lookups plus
/// a highlight), must be a colour in [0, 1] whose brightest channel is at least `floor` levels:
/// no black holes. Returns (glass pixels, darkest max channel of E in levels).
fn check_glass_pixels(
    s: &RasterScene,
    image: &RgbImage32,
    look: Look,
    floor: i32,
    what: &str,
) -> (usize, i32) {
    let cam = camera(s, image.width, image.height);
    let mix = s.glass.unwrap().reflectivity;
    let base = (1.0 - mix) * s.glass.unwrap().color;
    let (mut n, mut darkest) = (0, i32::MAX);
    for y in 0..image.height {
        for x in 0..image.width {
            if interior(s, &cam, x, y) != Some(Hit::Glass) {
                continue;
            }
            n += 1;
            let p = image.get(x, y);
            let e = match look {
                Look::Figure => [0, 1, 2].map(|c| (p[c] - base[c]) / mix),
                Look::Enhanced => p,
            };
            let slack = 2.5 / 255.0 / mix;
            assert!(
                e.iter().all(|v| (-slack..=1.0 + slack).contains(v)),
                "{what}: glass pixel ({x}, {y}) = {:?} is not a 0.1 white + 0.9 E mix",
                p.map(level)
            );
            darkest = darkest.min(max_level(e));
        }
    }
    assert!(
        darkest >= floor,
        "{what}: a glass pixel shows an environment of {darkest} levels, below {floor}"
    );
    (n, darkest)
}

#[test]
fn near_plane_cutting_the_glass_sphere() {
    // The eye 0.5 from the glass's surface with the near plane at 0.6: the plane cuts a cap off
    // the sphere. The impostor computes the surface point per pixel, so what the near plane
    // removes must not open a hole: every pixel whose ray meets the glass shows glass (a 0.1 + 0.9 E
    // mix, no black), every pixel whose ray meets nothing shows the background exactly.
    let mut s = scene();
    s.camera.eye = s.glass.unwrap().center + Vec3::new(1.5, 0.0, 0.0);
    s.camera.target = s.glass.unwrap().center;
    s.clip.near = 0.6;
    let image = render(&s, &Options::all_on(Look::Figure));
    finite(&image, "near plane");
    let cam = camera(&s, WIDTH, HEIGHT);
    let background = s.background.to_array().map(level);
    let (mut sky_count, mut cut) = (SkyCount::default(), 0);
    for y in 0..HEIGHT {
        for x in 0..WIDTH {
            match interior(&s, &cam, x, y) {
                Some(Hit::Sky) => sky_count.add(&image, x, y, background),
                Some(Hit::Glass) => {
                    let dir = cam.ray_direction(x as f32 + 0.5, y as f32 + 0.5);
                    let t = ray_sphere(cam.eye, dir, s.glass.unwrap().center, s.glass.unwrap().radius)
                        .unwrap_or(0.0);
                    if t * dir.dot(cam.basis().forward) < s.clip.near {
                        cut += 1;
                    }
                }
                _ => {}
            }
        }
    }
    let SkyCount { sky, wrong: sky_wrong } = sky_count;
    let (glass, darkest) = check_glass_pixels(&s, &image, Look::Figure, 40, "near plane");
    println!(
        "near plane 0.6, eye 0.5 from the glass: {glass} glass pixels ({cut} of them nearer than the near plane), \
         darkest E {darkest}, {sky} sky pixels, {sky_wrong} not background"
    );
    assert!(cut > 1000, "the near plane cuts only {cut} pixels of the sphere");
    assert!(sky > 1000 && sky_wrong == 0);
}

#[test]
fn far_plane_just_beyond_and_before_the_floor_end() {
    // A camera looking down the floor's length (from the file's camera the far floor hides
    // behind the glass). `end` is the depth of the floor's farthest corner along the view axis.
    let mut s = scene();
    s.camera.eye = Vec3::new(7.5, 6.0, 0.0);
    s.camera.target = Vec3::new(-8.0, 0.0, 0.0);
    let options = Options::all_on(Look::Figure);
    let reference = render(&s, &options);
    let cam = camera(&s, WIDTH, HEIGHT);
    let forward = cam.basis().forward;
    let (lo, hi) = (s.floor.min_corner(), s.floor.max_corner());
    let end = [(lo.x, lo.y), (lo.x, hi.y), (hi.x, lo.y), (hi.x, hi.y)]
        .map(|(x, z)| (Vec3::new(x, s.floor.height(), z) - cam.eye).dot(forward))
        .into_iter()
        .fold(0.0f32, f32::max);
    let cut = end - 8.0;
    let background = s.background.to_array().map(level);
    let mut beyond = s.clone();
    beyond.clip.far = end + 0.5;
    let image = render(&beyond, &options);
    finite(&image, "far 31");
    let changed = count_changed(&image, &reference, |_, _| true, 2);
    println!(
        "far plane {:.2} (0.5 beyond the floor's end): {changed} pixels differ from far 3000 by > 2 levels",
        end + 0.5
    );
    assert_eq!(changed, 0);

    let mut before = s.clone();
    before.clip.far = cut;
    let image = render(&before, &options);
    finite(&image, "far before the end");
    let (mut clipped, mut clipped_wrong, mut kept, mut kept_wrong) = (0, 0, 0, 0);
    for y in 0..HEIGHT {
        for x in 0..WIDTH {
            let Some(points) = floor_corners(&s, &cam, x, y) else { continue };
            let depths = points.map(|p| (p - cam.eye).dot(forward));
            let got = image.get(x, y);
            if depths.iter().all(|d| *d > cut + 0.05) {
                clipped += 1;
                if got.map(level) != background {
                    clipped_wrong += 1;
                }
            } else if depths.iter().all(|d| *d < cut - 0.05) {
                kept += 1;
                let want = reference.get(x, y);
                if (0..3).any(|c| (level(got[c]) - level(want[c])).abs() > 2) {
                    kept_wrong += 1;
                }
            }
        }
    }
    println!(
        "far plane {cut:.2} (8 before the floor's end): {clipped} floor pixels beyond it ({clipped_wrong} not background), {kept} before it \
         ({kept_wrong} differ from far 3000)"
    );
    assert!(clipped > 500 && kept > 5000);
    assert_eq!((clipped_wrong, kept_wrong), (0, 0));
}

/// The file's camera orbited in its vertical plane around the target down to eye height `y`
/// (it then looks up at the target), or, `level`, moved to height `y` looking level along -X,
/// so that the horizon crosses the middle of the view.
fn camera_at_height(y: f32, level: bool) -> RasterScene {
    let mut s = scene();
    let t = s.camera.target;
    if level {
        s.camera.eye.y = y;
        s.camera.target = Vec3::new(-8.0, y, t.z);
        return s;
    }
    let radius = s.camera.eye.distance(t);
    let horizontal = (s.camera.eye - t).with_y(0.0).normalize();
    let sin = (y - t.y) / radius;
    s.camera.eye = t + radius * ((1.0 - sin * sin).sqrt() * horizontal) + Vec3::new(0.0, y - t.y, 0.0);
    s
}

#[test]
fn orbiting_down_to_the_horizon() {
    for (height, level_view) in
        [(0.25, false), (0.0, false), (-0.01, false), (0.25, true), (0.0, true), (-0.01, true)]
    {
        let s = camera_at_height(height, level_view);
        let what = format!("eye height {height} ({})", if level_view { "level" } else { "orbit" });
        let image = render(&s, &Options::all_on(Look::Figure));
        finite(&image, &what);
        let cam = camera(&s, WIDTH, HEIGHT);
        let background = s.background.to_array().map(level);
        let (mut sky_count, mut under, mut under_wrong) = (SkyCount::default(), 0, 0);
        let underside = level(s.floor.colors[0].x * s.ambient.x);
        // The far floor band: pixels whose footprint spans more than two tiles along X, clear of
        // any shadow. The filtered checker must give the even blend of the two tiles there.
        let mut band = Vec::new();
        for y in 0..HEIGHT {
            for x in 0..WIDTH {
                match interior(&s, &cam, x, y) {
                    Some(Hit::Sky) => sky_count.add(&image, x, y, background),
                    Some(Hit::Floor(_)) if cam.eye.y < s.floor.height() => {
                        // The floor's underside faces away from the light: ambient only.
                        under += 1;
                        if (level(image.get(x, y)[0]) - underside).abs() > 1 {
                            under_wrong += 1;
                        }
                    }
                    Some(Hit::Floor(_)) => {
                        let Some(points) = floor_corners(&s, &cam, x, y) else { continue };
                        let xs = points.map(|p| p.x);
                        let extent = xs.iter().fold(f32::MIN, |a, b| a.max(*b))
                            - xs.iter().fold(f32::MAX, |a, b| a.min(*b));
                        let clear = points
                            .iter()
                            .all(|p| spheres(&s).iter().all(|sp| exact_margin(&s, p.as_dvec3(), *sp) > 0.2));
                        if extent > 2.0 * s.floor.tile && clear {
                            band.push(f64::from(image.get(x, y)[1]) * 255.0);
                        }
                    }
                    _ => {}
                }
            }
        }
        let SkyCount { sky, wrong: sky_wrong } = sky_count;
        let blend = 0.5
            * (s.floor.colors[0].y + s.floor.colors[1].y)
            * (s.ambient.y + s.light.radiance().y * s.light.to_light().y);
        let (mean, sd) = if band.is_empty() {
            (f64::NAN, f64::NAN)
        } else {
            let n = band.len() as f64;
            let mean = band.iter().sum::<f64>() / n;
            (mean, (band.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt())
        };
        println!(
            "{what}: {sky} sky pixels ({sky_wrong} not background), {under} underside pixels ({under_wrong} not \
             ambient-only), far band {} pixels: green mean {mean:.2} (even blend {:.2}), sd {sd:.2} levels",
            band.len(),
            blend * 255.0
        );
        assert!(sky > 1000 && sky_wrong == 0, "{what}");
        assert_eq!(under_wrong, 0, "{what}");
        if level_view && height < 0.0 {
            assert!(under > 300, "{what}: only {under} underside pixels");
        }
        if level_view && height > 0.0 {
            assert!(band.len() > 100, "{what}: only {} far-band pixels", band.len());
            assert!(
                (mean - f64::from(blend) * 255.0).abs() < 3.0 && sd < 3.0,
                "{what}: the far band aliases"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// 3. Refraction ratio 1: the glass must vanish into its background.

/// Whether pixel (x, y)'s rays (centre and four points 0.6 px away) see the sky both from the
/// eye (past the glass) and from the glass's centre (where its cube map is captured): there the
/// cube-map lookup and the true background agree exactly.
fn sky_behind_glass(s: &RasterScene, cam: &Camera, x: u32, y: u32) -> bool {
    let (cx, cy) = (x as f32 + 0.5, y as f32 + 0.5);
    [(0.0, 0.0), (-0.6, -0.6), (0.6, -0.6), (-0.6, 0.6), (0.6, 0.6)].iter().all(|(dx, dy)| {
        let d = cam.ray_direction(cx + dx, cy + dy);
        trace(s, cam.eye, d, false) == Hit::Sky && trace(s, s.glass.unwrap().center, d, false) == Hit::Sky
    })
}

/// The scene without its glass sphere.
fn without_glass(s: &RasterScene) -> RasterScene {
    RasterScene { glass: None, ..s.clone() }
}

/// The Blinn-Phong highlight of the glass at pixel (x, y), in levels (0 off the glass).
fn glass_highlight_levels(s: &RasterScene, cam: &Camera, x: u32, y: u32) -> f32 {
    let dir = cam.ray_direction(x as f32 + 0.5, y as f32 + 0.5);
    let Some(t) = ray_sphere(cam.eye, dir, s.glass.unwrap().center, s.glass.unwrap().radius) else {
        return 0.0;
    };
    let n = (cam.eye + t * dir - s.glass.unwrap().center).normalize();
    let l = s.light.to_light();
    if n.dot(l) <= 0.0 {
        return 0.0;
    }
    255.0 * n.dot((l - dir).normalize()).max(0.0).powf(s.glass.unwrap().shininess)
}

#[test]
fn refraction_ratio_one_makes_the_glass_vanish() {
    let mut s = scene();
    s.glass.as_mut().unwrap().refraction_ratio = 1.0;
    let cam = camera(&s, WIDTH, HEIGHT);
    let white = s.glass.unwrap().color;
    let mix = s.glass.unwrap().reflectivity;
    for look in Look::ALL {
        let mut on = Options::all_on(look);
        on.effects.fresnel = false;
        let mut off = on;
        off.effects.refraction = false;
        let bent = render(&s, &on);
        let straight = render(&s, &off);
        let behind = render(&without_glass(&s), &on);
        for (image, what) in [(&bent, "refraction on"), (&straight, "refraction off"), (&behind, "no glass")]
        {
            finite(image, what);
        }
        let (
            mut glass,
            mut bent_vs_straight,
            mut sky,
            mut sky_wrong,
            mut highlight,
            mut all_close,
            mut worst,
        ) = (0, 0, 0, 0, 0, 0, 0);
        for y in 0..HEIGHT {
            for x in 0..WIDTH {
                if interior(&s, &cam, x, y) != Some(Hit::Glass) {
                    continue;
                }
                glass += 1;
                let (p, q) = (bent.get(x, y), straight.get(x, y));
                if (0..3).any(|c| (level(p[c]) - level(q[c])).abs() > 1) {
                    bent_vs_straight += 1;
                }
                // What the pixel should be: figure look 0.1 white + 0.9 behind; enhanced look
                // (F0 = 0 at ratio 1, white tint) what is behind.
                let b = behind.get(x, y);
                let want = match look {
                    Look::Figure => [0, 1, 2].map(|c| (1.0 - mix) * white[c] + mix * b[c]),
                    Look::Enhanced => b,
                };
                let diff = (0..3).map(|c| (level(p[c]) - level(want[c])).abs()).max().unwrap_or(0);
                if look == Look::Enhanced && glass_highlight_levels(&s, &cam, x, y) > 0.5 {
                    highlight += 1;
                    continue;
                }
                worst = worst.max(diff);
                if diff <= 2 {
                    all_close += 1;
                }
                if sky_behind_glass(&s, &cam, x, y) {
                    sky += 1;
                    if diff > 1 {
                        sky_wrong += 1;
                    }
                }
            }
        }
        println!(
            "ratio 1, look {look}: {glass} glass pixels; refraction on vs off: {bent_vs_straight} differ by > 1 \
             level; sky behind: {sky} pixels, {sky_wrong} off the expected by > 1 level; highlight pixels \
             left out: {highlight}; all glass pixels within 2 levels of the expected: {all_close} of {} \
             (the rest: the cube map looks from the centre, not the surface; worst {worst} levels)",
            glass - highlight
        );
        assert!(glass > 5000 && sky > 1000, "look {look}: too few pixels checked");
        assert_eq!(bent_vs_straight, 0, "look {look}: ratio 1 still bends the view");
        assert_eq!(sky_wrong, 0, "look {look}: the sky through the glass differs from the sky behind it");
    }
}

// ---------------------------------------------------------------------------------------------
// 4. Total internal reflection and extreme ratios: no NaN, no black holes.

#[test]
fn extreme_refraction_ratios_leave_no_black_holes() {
    // The validator allows ratios in (0, 1] (glass denser than air); 2.0 (a bubble: the sphere
    // less dense than its surroundings, with total internal reflection at the front face beyond
    // 30 degrees of incidence) can only be set through the API, and is tested so the shader stays
    // robust. The floor: the darkest environment colour anywhere else in the frame (its largest
    // channel), less 3 levels of filtering slack.
    for ratio in [0.3, 0.7, 1.0, 2.0] {
        for look in Look::ALL {
            let mut s = scene();
            s.glass.as_mut().unwrap().refraction_ratio = ratio;
            let image = render(&s, &Options::all_on(look));
            let what = format!("ratio {ratio}, look {look}");
            finite(&image, &what);
            let cam = camera(&s, WIDTH, HEIGHT);
            let mut darkest_elsewhere = i32::MAX;
            for y in 0..HEIGHT {
                for x in 0..WIDTH {
                    if matches!(interior(&s, &cam, x, y), Some(Hit::Sky | Hit::Floor(_) | Hit::Metal)) {
                        darkest_elsewhere = darkest_elsewhere.min(max_level(image.get(x, y)));
                    }
                }
            }
            let (n, darkest) = check_glass_pixels(&s, &image, look, darkest_elsewhere - 3, &what);
            println!(
                "{what}: {n} glass pixels, darkest environment seen through it {darkest} levels (elsewhere {darkest_elsewhere})"
            );
        }
    }
}

/// For a pixel of the glass whose rays (centre and four points 0.6 px away) all meet the glass
/// beyond the critical angle of ratio `eta` (with a margin), what the mirror directions see from
/// the glass's centre (where the cube map is captured), if the same for all five: the sky, or the
/// floor with the red channel it has there (equal on both tiles: colour x (ambient + light N.L) or,
/// in shadow, colour x ambient), at least 0.15 from any shadow edge.
fn totally_reflected_red(s: &RasterScene, cam: &Camera, x: u32, y: u32, eta: f32) -> Option<f32> {
    let (cx, cy) = (x as f32 + 0.5, y as f32 + 0.5);
    let red = s.floor.colors[0].x;
    let (ambient, direct) = (s.ambient.x, s.light.radiance().x * s.light.to_light().y);
    let mut seen = Vec::new();
    for (dx, dy) in [(0.0, 0.0), (-0.6, -0.6), (0.6, -0.6), (-0.6, 0.6), (0.6, 0.6)] {
        let d = cam.ray_direction(cx + dx, cy + dy);
        let t = ray_sphere(cam.eye, d, s.glass.unwrap().center, s.glass.unwrap().radius)?;
        let n = (cam.eye + t * d - s.glass.unwrap().center).normalize();
        let cos = -n.dot(d);
        if eta * eta * (1.0 - cos * cos) < 1.05 {
            return None;
        }
        let m = d + 2.0 * cos * n;
        seen.push(match trace(s, s.glass.unwrap().center, m, false) {
            Hit::Sky => s.background.x,
            Hit::Floor(q) => {
                let margin = spheres(s)
                    .map(|sp| exact_margin(s, q.as_dvec3(), sp))
                    .into_iter()
                    .fold(f64::MAX, f64::min);
                if margin.abs() < 0.15 {
                    return None;
                }
                red * (ambient + if margin > 0.0 { direct } else { 0.0 })
            }
            _ => return None,
        });
    }
    seen.iter().all(|v| (v - seen[0]).abs() < 1e-6).then_some(seen[0])
}

#[test]
fn total_internal_reflection_mirrors_the_environment() {
    // Ratio 2 (set through the API; see above): beyond 30 degrees of incidence nothing enters
    // the sphere. Where the mirror direction sees the sky or the floor (away from shadow edges),
    // the red channel must be the figure's 0.1 white + 0.9 E or, in the enhanced look (Fresnel 1
    // under total reflection), E itself, E the red of what the mirror direction sees.
    let mut s = scene();
    s.glass.as_mut().unwrap().refraction_ratio = 2.0;
    let cam = camera(&s, WIDTH, HEIGHT);
    for look in Look::ALL {
        let image = render(&s, &Options::all_on(look));
        finite(&image, "ratio 2");
        let (mut sky, mut floor, mut wrong, mut worst) = (0, 0, 0, 0);
        for y in 0..HEIGHT {
            for x in 0..WIDTH {
                if interior(&s, &cam, x, y) != Some(Hit::Glass)
                    || glass_highlight_levels(&s, &cam, x, y) > 0.5
                {
                    continue;
                }
                let Some(e) = totally_reflected_red(&s, &cam, x, y, 2.0) else { continue };
                if e == s.background.x {
                    sky += 1;
                } else {
                    floor += 1;
                }
                let want = match look {
                    Look::Figure => level(
                        (1.0 - s.glass.unwrap().reflectivity) * s.glass.unwrap().color.x
                            + s.glass.unwrap().reflectivity * e,
                    ),
                    Look::Enhanced => level(e),
                };
                let diff = (level(image.get(x, y)[0]) - want).abs();
                worst = worst.max(diff);
                if diff > 3 {
                    wrong += 1;
                }
            }
        }
        println!(
            "ratio 2, look {look}: totally reflecting pixels mirroring the sky {sky}, the floor {floor}; \
             {wrong} off by > 3 levels in red (worst {worst})"
        );
        assert!(sky > 300 && floor > 100, "look {look}: too few pixels checked");
        assert!(
            (wrong as f64) < 0.01 * (sky + floor) as f64,
            "look {look}: total internal reflection does not mirror the environment"
        );
    }
}

/// The extremes matrix's sun rows for the rasterizer (docs/extremes.md): the light grazing at
/// 0.5 and 0.01 deg and straight down. The closed form is the exact f64 ray-cast shadow mask and
/// the lit floor's colour x (ambient + N.L): no acne, no pixel of the mask missing or extra, lit
/// metal unchanged by shadows. At 0.01 deg the shadows run about 1e4 sphere heights, far past
/// the floor's end, and N.L = 1.7e-4; straight down, the shadow map looks along -Y, parallel to
/// the scene's up.
#[test]
fn shadow_masks_with_the_light_grazing_and_overhead() {
    for degrees in [0.5, 0.01, 90.0] {
        let s = light_at_elevation(degrees);
        let m = measure_shadows(&s);
        println!(
            "elevation {degrees}: lit {} (acne {}), umbra {} (missing {}), extra {}, centroid offsets {:?}, metal pixels {} (changed by shadows {})",
            m.lit, m.acne, m.umbra, m.missing, m.extra, m.centroid_offset, m.metal_checked, m.metal_changed
        );
        assert!(m.lit > 5000, "{degrees} deg: too few lit pixels checked");
        assert_eq!(m.acne, 0, "{degrees} deg: lit floor pixels darker than lit (acne)");
        assert_eq!(m.missing + m.extra, 0, "{degrees} deg: shadow mask differs from the exact one");
        assert!(m.metal_checked > 100, "{degrees} deg: only {} metal pixels", m.metal_checked);
        assert_eq!(m.metal_changed, 0, "{degrees} deg: shadows changed lit metal pixels (acne)");
        // Under 1 deg the spheres' shadows begin past the floor's end (the glass's lowest point,
        // 1.6 up, casts 1.6 / tan(0.5 deg) = 183 units away); overhead they are on screen.
        if degrees > 45.0 {
            assert!(m.umbra > 100, "{degrees} deg: only {} umbra pixels", m.umbra);
            for (k, offset) in m.centroid_offset.iter().enumerate() {
                let offset = offset.expect("a shadow on screen");
                assert!(offset < 0.05, "{degrees} deg: centroid {k} is {offset:.3} from the exact one");
            }
        } else {
            assert_eq!(m.umbra, 0, "{degrees} deg: an exact umbra on the floor");
        }
    }
}
