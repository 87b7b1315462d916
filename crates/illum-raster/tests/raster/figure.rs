//! Checks of the figure look that need no reference image: docs/scenes.md, number by
//! number. Expected values come from the scene file and illum-scene's camera rays.

use glam::Vec3;
use illum_image::RgbImage32;
use illum_raster::RasterScene;
use illum_raster::{Look, Options};
use illum_scene::Camera;

use crate::{HEIGHT, WIDTH, camera, floor_hit, level, ray_distance, ray_sphere, render, render_at, scene};

fn figure() -> Options {
    Options::all_on(Look::Figure)
}

/// How far from a shadow's sharp edge a floor point must be to count as fully lit or fully
/// shadowed: the PCF kernel's reach plus slack for the shadow map's texels.
fn penumbra(scene: &RasterScene) -> f32 {
    1.5 * scene.quality.pcf_radius + 0.02
}

fn spheres(scene: &RasterScene) -> [(Vec3, f32); 2] {
    let pair: [(Vec3, f32); 2] = scene.spheres().try_into().expect("the assignment's two spheres");
    pair
}

/// How far the ray from p toward the light passes outside sphere (c, r) (negative: through it).
fn shadow_margin(scene: &RasterScene, p: Vec3, (c, r): (Vec3, f32)) -> f32 {
    ray_distance(p, scene.light.to_light(), c) - r
}

/// True when the floor is hit at pixel (px, py) and at its eight neighbours: no silhouette or
/// floor edge (where anti-aliasing blends) is within a pixel.
fn floor_interior(scene: &RasterScene, cam: &Camera, px: u32, py: u32) -> Option<Vec3> {
    let at =
        |dx: i32, dy: i32| floor_hit(scene, cam, px as f32 + 0.5 + dx as f32, py as f32 + 0.5 + dy as f32);
    for dy in -1..=1 {
        for dx in -1..=1 {
            at(dx, dy)?;
        }
    }
    at(0, 0)
}

/// Position in tiles from the floor's minimum corner.
fn tile_coord(scene: &RasterScene, p: Vec3) -> glam::Vec2 {
    (glam::Vec2::new(p.x, p.z) - scene.floor.min_corner()) / scene.floor.tile
}

/// Checks every floor pixel of `image` (the figure look of `s`) whose footprint lies inside one
/// tile and clear of a penumbra: colour x (ambient + light x N.L) in light, colour x ambient in
/// shadow, within 2 levels. A sphere shadows a point when the ray toward the light passes through
/// it, and only under a light that casts shadows. Returns the counts of lit and shadowed pixels
/// checked.
pub(crate) fn check_floor_shading(s: &RasterScene, image: &RgbImage32) -> (usize, usize) {
    let cam = camera(s, image.width, image.height);
    let n_dot_l = s.light.to_light().y.max(0.0);
    let ambient = s.ambient;
    let light = s.light.radiance();
    let casters = if s.effects.shadows { s.spheres() } else { Vec::new() };
    let (mut lit, mut shadowed, mut wrong) = (0, 0, Vec::new());
    for py in 0..image.height {
        for px in 0..image.width {
            let Some(p) = floor_interior(s, &cam, px, py) else { continue };
            // The checker is box-filtered over the pixel's footprint: keep to pixels whose
            // footprint lies inside one tile. The footprint is measured from the neighbours' hits.
            let here = tile_coord(s, p);
            let right = floor_hit(s, &cam, px as f32 + 1.5, py as f32 + 0.5).map(|q| tile_coord(s, q));
            let below = floor_hit(s, &cam, px as f32 + 0.5, py as f32 + 1.5).map(|q| tile_coord(s, q));
            let (Some(right), Some(below)) = (right, below) else { continue };
            let footprint = (right - here).abs() + (below - here).abs();
            let to_edge = (here - here.round()).abs();
            if to_edge.x <= footprint.x + 0.01 || to_edge.y <= footprint.y + 0.01 {
                continue;
            }
            let margins: Vec<f32> = casters.iter().map(|&sphere| shadow_margin(s, p, sphere)).collect();
            let m = penumbra(s);
            let in_umbra = margins.iter().any(|&d| d < -m);
            let in_light = margins.iter().all(|&d| d > m);
            if !in_umbra && !in_light {
                continue;
            }
            let (i, j) = (here.x.floor() as i64, here.y.floor() as i64);
            let colour = s.floor.colors[(i + j).rem_euclid(2) as usize];
            let expected = if in_light { colour * (ambient + light * n_dot_l) } else { colour * ambient };
            let got = image.get(px, py);
            let ok = (0..3).all(|c| (level(got[c]) - level(expected[c])).abs() <= 2);
            if in_light {
                lit += 1
            } else {
                shadowed += 1
            }
            if !ok {
                wrong.push(((px, py), got.map(level), expected.to_array().map(level)));
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "{} of {} floor pixels off by more than 2/255, e.g. {:?}",
        wrong.len(),
        lit + shadowed,
        &wrong[..wrong.len().min(5)]
    );
    (lit, shadowed)
}

#[test]
fn floor_pixels_are_colour_times_ambient_plus_n_dot_l() {
    let s = scene();
    // The floor's normal is +Y, so N.L is the y component of the unit vector toward the light:
    // 13 / sqrt(10^2 + 13^2 + 2^2) = 0.7868 for the light at (10, 13, -2).
    let n_dot_l = s.light.to_light().y.max(0.0);
    assert!((n_dot_l - 13.0 / 273f32.sqrt()).abs() < 1e-6);
    let (lit, shadowed) = check_floor_shading(&s, &render(&s, &figure()));
    // The check must not pass by checking nothing.
    assert!(lit > 5000 && shadowed > 500, "only {lit} lit and {shadowed} shadowed pixels checked");
    // docs/scenes.md: lit tiles (207, 207, 0) / (207, 0, 0), shadowed (47, 47, 0) / (47, 0, 0).
    let (ambient, light) = (s.ambient, s.light.radiance());
    let yellow = s.floor.colors[0];
    assert_eq!((yellow * (ambient + light * n_dot_l)).to_array().map(level), [207, 207, 0]);
    assert_eq!((yellow * ambient).to_array().map(level), [47, 47, 0]);
}

/// docs/scenes.md: the clear colour written to 8 bits shows as (76, 128, 229) in the figure.
/// (scenes/whitted.toml gives it as those levels / 255: the skeleton's (0.3, 0.5, 0.9) is an exact
/// tie between two levels in every channel, which no single rounding rule breaks the figure's way.)
#[test]
fn the_background_is_76_128_229() {
    for look in Look::ALL {
        let image = render(&scene(), &Options::all_on(look));
        for (x, y) in [(0, 0), (WIDTH - 1, 0), (WIDTH / 2, 1)] {
            assert_eq!(image.get(x, y).map(level), [76, 128, 229], "look {look}, pixel ({x}, {y})");
        }
    }
}

/// Pixel coordinates (from the top-left corner) where the camera sees world point p.
fn project(cam: &Camera, p: Vec3) -> (f32, f32) {
    let b = cam.basis();
    let v = p - cam.eye;
    let depth = v.dot(b.forward);
    let x = v.dot(b.right) / (depth * b.tan_half_fov * b.aspect);
    let y = v.dot(b.up) / (depth * b.tan_half_fov);
    ((x + 1.0) * 0.5 * cam.width as f32, (1.0 - y) * 0.5 * cam.height as f32)
}

/// Where the light's ray through `center` meets the floor: the centre of that sphere's shadow
/// (a sphere's shadow under parallel light is an ellipse centred there).
fn shadow_centre(scene: &RasterScene, center: Vec3) -> Vec3 {
    let d = scene.light.direction();
    center + (scene.floor.height() - center.y) / d.y * d
}

/// Each sphere's shadow is centred on the light's projection of the sphere's centre: the pixel
/// there is ambient-only, and around it the rendered shadow (as a fraction, from the red
/// channel) has the centroid and area of the exact shadow, computed per pixel by casting the
/// ray toward the light. A displaced or shrunken shadow (too much bias: a gap under the caster)
/// moves the centroid or loses area.
fn check_shadow_placement(s: &RasterScene, label: &str) {
    let image: RgbImage32 = render(s, &figure());
    let cam = camera(s, WIDTH, HEIGHT);
    let (red, ambient, direct) = crate::floor_red_lighting(s, "the shadow fraction");
    let forward = cam.basis().forward;
    for (k, sphere) in spheres(s).into_iter().enumerate() {
        let centre = shadow_centre(s, sphere.0);
        let (px, py) = project(&cam, centre);
        assert!(
            px >= 0.0 && py >= 0.0 && px < WIDTH as f32 && py < HEIGHT as f32,
            "{label}: shadow {k} off screen"
        );
        let got = level(image.get(px as u32, py as u32)[0]);
        assert!(
            (got - level(red * ambient)).abs() <= 2,
            "{label}: shadow {k} centre pixel red {got}, not ambient-only"
        );

        let other = spheres(s)[1 - k];
        let (mut rendered, mut exact) = ((0.0f64, glam::DVec3::ZERO), (0.0f64, glam::DVec3::ZERO));
        for y in 0..HEIGHT {
            for x in 0..WIDTH {
                let Some(p) = floor_interior(s, &cam, x, y) else { continue };
                if p.distance(centre) > 2.5 || shadow_margin(s, p, other) <= penumbra(s) {
                    continue;
                }
                let dir = cam.ray_direction(x as f32 + 0.5, y as f32 + 0.5);
                let t = p.distance(cam.eye);
                let area = f64::from(dir.dot(forward).powi(3) * t * t / dir.y.abs());
                let visibility = (image.get(x, y)[0] / red - ambient) / direct;
                let shadow = f64::from((1.0 - visibility).clamp(0.0, 1.0));
                let inside = if shadow_margin(s, p, sphere) < 0.0 { 1.0 } else { 0.0 };
                let p = p.as_dvec3();
                rendered = (rendered.0 + area * shadow, rendered.1 + area * shadow * p);
                exact = (exact.0 + area * inside, exact.1 + area * inside * p);
            }
        }
        assert!(exact.0 > 0.0, "{label}: shadow {k} has no visible pixels");
        let (c_rendered, c_exact) = (rendered.1 / rendered.0, exact.1 / exact.0);
        let offset = c_rendered.distance(c_exact);
        assert!(
            offset < 0.05,
            "{label}: shadow {k} centroid {c_rendered:?}, exact {c_exact:?} ({offset:.3} apart)"
        );
        let ratio = rendered.0 / exact.0;
        assert!((ratio - 1.0).abs() < 0.07, "{label}: shadow {k} area is {ratio:.3} of the exact one");
    }
}

#[test]
fn shadows_fall_where_the_light_projects_the_sphere_centres() {
    check_shadow_placement(&scene(), "whitted.toml");
    // As a user would edit the file: another light direction and a moved metal sphere.
    let mut moved = scene();
    moved.light.direction = Vec3::new(-8.0, -14.0, -3.0).normalize();
    moved.metal.as_mut().unwrap().center = Vec3::new(1.5, 1.5, -1.0);
    check_shadow_placement(&moved, "moved light and sphere");
}

#[test]
fn the_glass_is_a_tenth_white_plus_nine_tenths_environment() {
    // Twice the reference size, so the refracted floor at the disc's rim is several pixels deep.
    let (width, height) = (2 * WIDTH, 2 * HEIGHT);
    let s = scene();
    let image = render_at(&s, &figure(), width, height);
    let cam = camera(&s, width, height);
    let mix = s.glass.unwrap().reflectivity;
    let base = (1.0 - mix) * s.glass.unwrap().color;
    let inside_glass = |x: f32, y: f32| {
        let dir = cam.ray_direction(x, y);
        ray_sphere(cam.eye, dir, s.glass.unwrap().center, s.glass.unwrap().radius).is_some()
    };
    let (mut glass, mut sky, mut floor) = (0, 0, 0);
    let sky_level = (base + mix * s.background).to_array().map(level);
    let tolerance = 2.5 / 255.0 / mix;
    for y in 0..height {
        for x in 0..width {
            let (cx, cy) = (x as f32 + 0.5, y as f32 + 0.5);
            if ![(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0), (0.0, 0.0)]
                .iter()
                .all(|(dx, dy)| inside_glass(cx + dx, cy + dy))
            {
                continue;
            }
            glass += 1;
            let p = image.get(x, y);
            // p = 0.1 + 0.9 E with E the environment: E must be a colour in [0, 1].
            let environment = [0, 1, 2].map(|c| (p[c] - base[c]) / mix);
            assert!(
                environment.iter().all(|e| (-tolerance..=1.0 + tolerance).contains(e)),
                "pixel ({x}, {y}) = {:?} is not 0.1 + 0.9 E for any E in [0, 1]",
                p.map(level)
            );
            if p.map(level) == sky_level {
                sky += 1;
            }
            // The lit floor through the glass: both tiles have red 0.8 (lit: 0.81) and blue 0,
            // so the pixel's blue is exactly the white part, 0.1.
            if environment[0] > 0.6 && (level(p[2]) - level(base.z)).abs() <= 1 {
                floor += 1;
            }
        }
    }
    assert!(glass > 20_000, "only {glass} glass pixels");
    assert!(
        sky > glass / 2,
        "the sky seen through the glass should fill most of it: {sky} of {glass} are {sky_level:?}"
    );
    assert!(floor >= 100, "only {floor} glass pixels show the refracted checkerboard");
}
