//! "Model only what a scene requires" in the rasterizer: a frame records only
//! the passes its scene and options need (no shadow pass without a shadow-casting light and a
//! caster, no cube capture without a sphere that reads it), and leaving a pass out never changes
//! the picture.

use illum_image::RgbImage32;
use illum_raster::RasterScene;
use illum_raster::{Look, Options, PassTimes};

use crate::effects::with;
use crate::figure::check_floor_shading;
use illum_gpu::testing;

use crate::{HEIGHT, WIDTH, level, renderer, scene};

/// The planned pass names, the measured pass times and the image of one frame at the test size.
fn frame(s: &RasterScene, options: &Options) -> (Vec<String>, Option<PassTimes>, RgbImage32) {
    let mut r = renderer();
    if r.size() != (WIDTH, HEIGHT) {
        r.resize(WIDTH, HEIGHT).unwrap_or_else(|e| panic!("{e}"));
    }
    r.set_scene(s).unwrap_or_else(|e| panic!("{e}"));
    let names = r.plan(options).pass_names();
    let frame = r.render_timed(options).unwrap_or_else(|e| panic!("{e}"));
    assert!(!frame.image.has_non_finite());
    (names, frame.pass_times, frame.image)
}

fn count(names: &[String], prefix: &str) -> usize {
    names.iter().filter(|n| n.starts_with(prefix)).count()
}

/// Pixels whose 8-bit value differs in any channel.
fn differing(a: &RgbImage32, b: &RgbImage32) -> usize {
    let mut n = 0;
    for y in 0..a.height {
        for x in 0..a.width {
            let (p, q) = (a.get(x, y), b.get(x, y));
            n += usize::from((0..3).any(|c| level(p[c]) != level(q[c])));
        }
    }
    n
}

#[test]
fn each_scene_records_only_the_passes_it_needs() {
    let s = scene();
    // Shadows switched off in the scene file ([raster.effects] shadows = false) and read as
    // the scene's default options.
    let no_cast = {
        let mut t = s.clone();
        t.effects.shadows = false;
        t.look = Look::Enhanced;
        t
    };
    let no_mirror = {
        let mut t = s.clone();
        t.metal.as_mut().unwrap().mirror = 0.0;
        t
    };
    let no_glass = RasterScene { glass: None, ..s.clone() };
    let no_spheres = RasterScene { glass: None, metal: None, ..s.clone() };
    let (figure, enhanced) = (Options::all_on(Look::Figure), Options::all_on(Look::Enhanced));
    let shadows_off = with(Look::Enhanced, |e| e.shadows = false);
    // (case, scene, options, shadow pass, glass faces (fine + coarse), metal faces)
    let cases: [(&str, &RasterScene, Options, bool, usize, usize); 8] = [
        ("assignment, figure", &s, figure, true, 12, 0),
        ("assignment, enhanced", &s, enhanced, true, 12, 6),
        ("shadows switched off", &s, shadows_off, false, 12, 6),
        ("shadows off in the file", &no_cast, Options::from_scene(&no_cast), false, 12, 6),
        ("metal mirrors nothing", &no_mirror, enhanced, true, 12, 0),
        ("no glass, enhanced", &no_glass, enhanced, true, 0, 6),
        ("no glass, figure", &no_glass, figure, true, 0, 0),
        ("no spheres", &no_spheres, enhanced, false, 0, 0),
    ];
    for (case, scene, options, shadow, glass_faces, metal_faces) in cases {
        let (names, times, _) = frame(scene, &options);
        assert_eq!(count(&names, "shadow"), usize::from(shadow), "{case}: {names:?}");
        assert_eq!(count(&names, "cube glass"), glass_faces, "{case}: {names:?}");
        assert_eq!(count(&names, "cube metal"), metal_faces, "{case}: {names:?}");
        assert_eq!(names.last().map(String::as_str), Some("main"), "{case}: {names:?}");
        assert_eq!(names.len(), usize::from(shadow) + glass_faces + metal_faces + 1, "{case}: {names:?}");
        // The timestamps come from the passes actually recorded: a skipped pass takes no time.
        if testing::gpu().timestamps {
            let t = times.unwrap_or_else(|| panic!("{case}: no pass times"));
            assert_eq!(t.shadow_ms > 0.0, shadow, "{case}: shadow {} ms", t.shadow_ms);
            assert_eq!(t.cube_ms > 0.0, glass_faces + metal_faces > 0, "{case}: cubes {} ms", t.cube_ms);
            assert!(t.main_ms > 0.0, "{case}");
        }
    }
}

#[test]
fn shadows_off_skips_the_shadow_pass_and_lights_the_whole_floor() {
    let s = scene();
    let mut no_cast = s.clone();
    no_cast.effects.shadows = false;
    for look in Look::ALL {
        let (names, _, skipped) = frame(&s, &with(look, |e| e.shadows = false));
        assert_eq!(count(&names, "shadow"), 0, "look {look}: {names:?}");
        let (_, _, shadowed) = frame(&s, &Options::all_on(look));
        assert!(differing(&skipped, &shadowed) > 40, "look {look}: the shadows were never there");
    }
    // And against the closed form: every floor pixel lit, colour x (ambient + N.L).
    let (_, _, image) = frame(&no_cast, &with(Look::Figure, |e| e.shadows = false));
    let (lit, shadowed) = check_floor_shading(&no_cast, &image);
    assert!(lit > 5000 && shadowed == 0, "{lit} lit, {shadowed} shadowed");
}

#[test]
fn a_floor_without_spheres_is_lit_everywhere_with_no_pass_but_the_main_one() {
    let s = scene();
    let bare = RasterScene { glass: None, metal: None, ..s.clone() };
    let (names, _, image) = frame(&bare, &Options::all_on(Look::Figure));
    assert_eq!(names, vec!["main".to_owned()]);
    let (lit, shadowed) = check_floor_shading(&bare, &image);
    let (full_lit, _) = check_floor_shading(&s, &frame(&s, &Options::all_on(Look::Figure)).2);
    // More floor is checked without the spheres hiding and shadowing it.
    assert!(lit > full_lit && shadowed == 0, "{lit} lit ({full_lit} with the spheres), {shadowed} shadowed");
}

#[test]
fn a_metal_that_mirrors_nothing_looks_as_without_reflection() {
    // The metal alone (no glass, whose look also depends on the reflection toggle).
    let metal_only = RasterScene { glass: None, ..scene() };
    let mut matte = metal_only.clone();
    matte.metal.as_mut().unwrap().mirror = 0.0;
    let enhanced = Options::all_on(Look::Enhanced);
    let no_reflection = with(Look::Enhanced, |e| e.reflection = false);
    let (names, _, skipped) = frame(&matte, &enhanced);
    assert_eq!(count(&names, "cube"), 0, "{names:?}");
    let (_, _, switched_off) = frame(&matte, &no_reflection);
    assert_eq!(differing(&skipped, &switched_off), 0);
    // With its mirror the metal's cube map is captured and shows.
    let (names, _, mirrored) = frame(&metal_only, &enhanced);
    assert_eq!(count(&names, "cube metal"), 6, "{names:?}");
    assert!(differing(&mirrored, &switched_off) > 40, "the mirror shows nothing");
}

/// The shadow map and the cube maps do not depend on the camera: the frame after a camera move
/// reuses them (it records the main pass alone) and is the same picture, value for value, as a
/// fresh renderer's frame from that camera. Moving a sphere records the captures again, and
/// that frame too equals a fresh renderer's.
#[test]
fn a_camera_move_reuses_shadow_and_cube_maps_and_changes_nothing_else() {
    let gpu = testing::gpu();
    let options = Options::all_on(Look::Enhanced);
    let s = scene();
    let mut r = illum_raster::RasterRenderer::new(gpu, &s, WIDTH, HEIGHT).unwrap();
    assert!(r.plan(&options).passes().len() > 1, "the first frame makes its maps");
    r.render(&options).unwrap();
    assert_eq!(r.plan(&options).pass_names(), ["main"], "an unchanged scene reuses them");

    let fresh = |scene: &RasterScene| {
        illum_raster::RasterRenderer::new(gpu, scene, WIDTH, HEIGHT).unwrap().render(&options).unwrap()
    };
    let mut moved = s.clone();
    moved.camera.eye += glam::Vec3::new(0.4, 0.5, -0.3);
    r.set_scene(&moved).unwrap();
    assert_eq!(r.plan(&options).pass_names(), ["main"], "a camera move reuses them");
    let reused = r.render(&options).unwrap();
    assert_eq!(reused.pixels, fresh(&moved).pixels, "reused maps changed the picture");
    assert!(differing(&reused, &fresh(&s)) > 100, "the camera move changed nothing: no test");

    let mut shifted = moved.clone();
    shifted.metal.as_mut().expect("a metal sphere").center.y += 0.25;
    r.set_scene(&shifted).unwrap();
    assert!(r.plan(&options).pass_names().len() > 1, "a moved sphere needs new maps");
    assert_eq!(r.render(&options).unwrap().pixels, fresh(&shifted).pixels);
    // Other options are other maps (the figure look has no metal cube map).
    let figure = Options::all_on(Look::Figure);
    assert!(r.plan(&figure).pass_names().len() > 1);
}

/// With reduced cube maps while the scene changes (what the viewer turns on), the frame after a
/// moved sphere captures them at a quarter side, and the next frame, the scene still, captures
/// them again at full size: its picture is a fresh renderer's, bit for bit. A camera move alone
/// is not a change of the scene.
#[test]
fn a_changing_scene_gets_small_cube_maps_and_a_still_one_full_ones_again() {
    let gpu = testing::gpu();
    let options = Options::all_on(Look::Enhanced);
    let s = scene();
    let full = s.quality.cube_size;
    let small = illum_raster::moving_cube_size(full);
    assert!(small < full, "the test scene's cube maps ({full}) are too small to reduce");
    let mut r = illum_raster::RasterRenderer::new(gpu, &s, WIDTH, HEIGHT).unwrap();
    r.set_reduced_cubes_while_changing(true);
    r.render(&options).unwrap();
    let mut camera_moved = s.clone();
    camera_moved.camera.eye += glam::Vec3::new(0.4, 0.5, -0.3);
    r.set_scene(&camera_moved).unwrap();
    assert_eq!(r.scene().quality.cube_size, full, "a camera move is not a change of the scene");

    let mut shifted = camera_moved.clone();
    shifted.metal.as_mut().expect("a metal sphere").center.y += 0.25;
    r.set_scene(&shifted).unwrap();
    assert_eq!(r.scene().quality.cube_size, small);
    let moving = r.render(&options).unwrap();
    let fresh =
        illum_raster::RasterRenderer::new(gpu, &shifted, WIDTH, HEIGHT).unwrap().render(&options).unwrap();
    assert!(differing(&moving, &fresh) > 0, "small cube maps changed nothing: no test");
    // The scene stands still: full size again, and the exact picture.
    let still = r.render(&options).unwrap();
    assert_eq!(r.scene().quality.cube_size, full);
    assert_eq!(still.pixels, fresh.pixels, "the still frame after a change is not the full-quality one");
}
