//! Every effect toggle changes the picture where it should and nowhere else; shadows leave the
//! lit spheres untouched (no acne); anti-aliasing changes only pixels on an edge.

use illum_image::RgbImage32;
use illum_raster::RasterScene;
use illum_raster::{Look, Options};
use illum_scene::Effects;

use crate::{HEIGHT, WIDTH, camera, level, ray_sphere, render, scene};

/// Pixels whose largest channel differs by more than 2 levels.
fn changed(a: &RgbImage32, b: &RgbImage32) -> Vec<(u32, u32)> {
    let mut out = Vec::new();
    for y in 0..a.height {
        for x in 0..a.width {
            let (p, q) = (a.get(x, y), b.get(x, y));
            if (0..3).any(|c| (level(p[c]) - level(q[c])).abs() > 2) {
                out.push((x, y));
            }
        }
    }
    out
}

/// `look` with every effect on but what `change` turns off.
pub(crate) fn with(look: Look, change: impl FnOnce(&mut Effects)) -> Options {
    let mut options = Options::all_on(look);
    change(&mut options.effects);
    options
}

#[test]
fn each_toggle_changes_the_picture_or_is_documented_not_to() {
    let s = scene();
    for look in Look::ALL {
        let all = render(&s, &Options::all_on(look));
        for (name, off) in Effects::TOGGLES {
            let n = changed(&all, &render(&s, &with(look, off))).len();
            // The figure has no reflections and no Fresnel: those toggles belong to the enhanced look.
            let inert = look == Look::Figure && (name == "reflection" || name == "fresnel");
            if inert {
                assert_eq!(n, 0, "look {look}: turning {name} off changed {n} pixels");
            } else {
                assert!(n > 40, "look {look}: turning {name} off changed only {n} pixels");
            }
        }
    }
}

/// Which surface the camera ray through (x, y) meets first: 0 sky, 1 floor, 2 glass, 3 metal.
fn surface(s: &RasterScene, x: f32, y: f32) -> u8 {
    let cam = camera(s, WIDTH, HEIGHT);
    let dir = cam.ray_direction(x, y);
    let glass = ray_sphere(cam.eye, dir, s.glass.unwrap().center, s.glass.unwrap().radius);
    let metal = ray_sphere(cam.eye, dir, s.metal.unwrap().center, s.metal.unwrap().radius);
    match (glass, metal) {
        (Some(g), Some(m)) => return if g < m { 2 } else { 3 },
        (Some(_), None) => return 2,
        (None, Some(_)) => return 3,
        (None, None) => {}
    }
    if crate::floor_hit(s, &cam, x, y).is_some() { 1 } else { 0 }
}

/// True when every point of the pixel (probed at its corners and centre, slightly enlarged)
/// sees the same surface.
fn interior(s: &RasterScene, x: u32, y: u32) -> Option<u8> {
    let (cx, cy) = (x as f32 + 0.5, y as f32 + 0.5);
    let centre = surface(s, cx, cy);
    let corners = [(-0.6, -0.6), (0.6, -0.6), (-0.6, 0.6), (0.6, 0.6)];
    corners.iter().all(|(dx, dy)| surface(s, cx + dx, cy + dy) == centre).then_some(centre)
}

/// For a pixel inside a sphere's disc (`which`: 2 glass, 3 metal): whether the light reaches
/// the visible point without passing within `margin` of the other sphere (so no shadow, not even
/// a soft edge, belongs there).
fn clear_of_the_other_sphere(s: &RasterScene, x: u32, y: u32, which: u8, margin: f32) -> bool {
    let cam = camera(s, WIDTH, HEIGHT);
    let dir = cam.ray_direction(x as f32 + 0.5, y as f32 + 0.5);
    let [(c, r), (other, other_r)] = if which == 2 {
        [
            (s.glass.unwrap().center, s.glass.unwrap().radius),
            (s.metal.unwrap().center, s.metal.unwrap().radius),
        ]
    } else {
        [
            (s.metal.unwrap().center, s.metal.unwrap().radius),
            (s.glass.unwrap().center, s.glass.unwrap().radius),
        ]
    };
    let Some(t) = ray_sphere(cam.eye, dir, c, r) else { return false };
    let p = cam.eye + t * dir;
    crate::ray_distance(p, s.light.to_light(), other) > other_r + margin
}

#[test]
fn shadows_leave_the_lit_metal_untouched() {
    // A sphere casts no shadow on itself, so wherever the light reaches the metal sphere clear
    // of the glass, the shadow map must not change a pixel: the metal is tested against its own
    // depth in the map, and acne would show here. (Where the light grazes the glass, the glass's
    // soft shadow edge legitimately reaches across.) The figure look's metal is plain Phong, so
    // nothing else changes with the shadows; the glass shows the floor's shadows through its
    // cube map and cannot be checked this way. A low light makes grazing angles on the metal.
    let margin = 3.0 * scene().quality.pcf_radius + 0.05;
    // The file's light, and one from (10, 2.5, -2) toward the origin.
    for direction in [scene().light.direction, glam::Vec3::new(-10.0, -2.5, 2.0).normalize()] {
        let mut s = scene();
        s.light.direction = direction;
        let options = Options::all_on(Look::Figure);
        let on = render(&s, &options);
        let off = render(&s, &with(Look::Figure, |e| e.shadows = false));
        let changed_pixels = changed(&on, &off);
        let mut checked = 0;
        for y in 0..HEIGHT {
            for x in 0..WIDTH {
                if interior(&s, x, y) != Some(3) || !clear_of_the_other_sphere(&s, x, y, 3, margin) {
                    continue;
                }
                checked += 1;
                assert!(
                    !changed_pixels.contains(&(x, y)),
                    "light along {direction}: shadows changed metal pixel ({x}, {y})"
                );
            }
        }
        assert!(checked > 1000, "light along {direction}: only {checked} metal pixels checked");
    }
}

#[test]
fn antialiasing_changes_only_pixels_on_an_edge() {
    let s = scene();
    for look in Look::ALL {
        let on = render(&s, &Options::all_on(look));
        let off = render(&s, &with(look, |e| e.antialiasing = false));
        let differing = changed(&on, &off);
        let inside: Vec<_> = differing.iter().filter(|(x, y)| interior(&s, *x, *y).is_some()).collect();
        assert!(
            inside.is_empty(),
            "look {look}: anti-aliasing changed {} pixels away from any edge, e.g. {:?}",
            inside.len(),
            &inside[..inside.len().min(5)]
        );
        // Silhouettes of both spheres and the floor's far edge: a few hundred pixels at this size.
        assert!(
            differing.len() > 150,
            "look {look}: anti-aliasing changed only {} edge pixels",
            differing.len()
        );
    }
}
