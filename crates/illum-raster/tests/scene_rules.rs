//! Every rule a scene must pass for the rasterizer to draw it, triggered by an edited copy of a
//! small valid scene, with the message checked for file, field, value and what is allowed: the
//! physical scene's own validation (as the rasterizer sees it), `Scene::require` refusing what
//! the rasterizer does not implement, and `RasterScene::from_scene` refusing arrangements it
//! cannot draw; plus resolution overrides and device limits.
//!
//! The refusals of edits of the scene are data, `cases/scene_rules.toml`, checked by one test; the
//! tests here check what a refusal cannot say: what is accepted next to them, what the physical
//! scene accepts and the rasterizer refuses, and edits that are not one replacement.

use glam::{Vec2, Vec3};
use illum_gpu::wgpu;
use illum_raster::{Effects, Look, RasterScene, check_device_limits};
use illum_scene::testing::{Edits, check_invalid, edit_once as edit_text, without};
use illum_scene::{Feature, RendererKind, Scene, SceneError};

const FILE: &str = "scenes/w.toml";

/// A valid scene with every optional key written out: the light's irradiance pi (a Lambertian
/// floor facing it then has radiance albedo), `[shading] ambient`, the `enhanced` look.
const BASE: &str = include_str!("scenes/w.toml");

/// The glass sphere's `[[objects]]` table of BASE, whole.
const GLASS_OBJECT: &str = "[[objects]]\nname = \"glass sphere\"\nmaterial = \"glass\"\n\
                            sphere = { center = [4.2, 2.6, -4.2], radius = 1.0 }\n\n";
/// The metal sphere's `[[objects]]` table of BASE, whole.
const METAL_OBJECT: &str = "[[objects]]\nname = \"metal sphere\"\nmaterial = \"metal\"\n\
                            sphere = { center = [2.0, 1.9, -2.5], radius = 1.0 }\n\n";
/// The floor's quad line of BASE.
const FLOOR_QUAD: &str =
    "quad = { corner = [-23.0, 0.0, -7.5], edge_u = [0.0, 0.0, 15.0], edge_v = [30.0, 0.0, 0.0] }";

/// What the tests edit: `BASE`, loaded as the rasterizer sees it.
const SCENE: Edits<RasterScene> = Edits { base: BASE, file: FILE, load: RasterScene::from_toml_str };

/// `BASE` with `from` replaced by `to`; `from` must occur exactly once.
fn edit(from: &str, to: &str) -> String {
    SCENE.edit(from, to)
}

/// `BASE` with `table` (TOML text ending in a newline) appended after the last object.
fn with_object(table: &str) -> String {
    edit("[shading]\n", &format!("{table}\n[shading]\n"))
}

fn parse(text: &str) -> Result<RasterScene, SceneError> {
    SCENE.parse(text)
}

fn expect_invalid(text: &str, field: &str, value: &str, allowed: &str) {
    SCENE.expect_invalid(text, field, value, allowed);
}

/// Asserts `text` is a valid scene that the rasterizer refuses because `place` uses `feature`.
fn expect_unsupported(text: &str, place: &str, feature: Feature) {
    Scene::from_toml_str(text, FILE).expect("the scene itself is valid");
    let err = parse(text).expect_err("expected the rasterizer to refuse the scene");
    let SceneError::Unsupported { file, place: p, feature: f, renderer } = &err else {
        panic!("expected Unsupported at {place}, got {err:?}");
    };
    assert_eq!(
        (file.as_str(), p.as_str(), f.as_str(), renderer.as_str()),
        (FILE, place, feature.to_string().as_str(), "rasterizer"),
        "{err}"
    );
    assert_eq!(err.to_string(), format!("{FILE}: {place}: the rasterizer cannot render {feature}"));
}

/// A scene file of the repository, by its path from the workspace root.
fn repo_file(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(name)
}

// ---------------------------------------------------------------------------------------------
// Loading.

#[test]
fn base_scene_loads_with_the_written_values() {
    let s = parse(BASE).unwrap();
    assert_eq!(s.name, "w");
    assert_eq!(s.source, FILE);
    assert_eq!(s.look, Look::Enhanced);
    assert_eq!((s.camera.width, s.camera.height), (64, 36));
    assert_eq!((s.clip.near, s.clip.far), (0.1, 3000.0));
    assert_eq!(s.effects, Effects { pcf: false, antialiasing: false, ..Effects::ALL_ON });
    assert_eq!(s.quality.cube_size, 128);
    assert_eq!(s.quality.pcf_radius, 0.05);
    assert_eq!(s.background, Vec3::new(0.3, 0.5, 0.9));
    assert_eq!(s.ambient, Vec3::splat(0.23));
    let direction = Vec3::new(-10.0, -13.0, 2.0).normalize();
    assert!(s.light.direction().abs_diff_eq(direction, 1e-6), "{:?}", s.light.direction());
    assert!((s.light.direction().length() - 1.0).abs() < 1e-6);
    assert_eq!(s.light.to_light(), -s.light.direction());
    assert_eq!(s.light.radiance(), Vec3::ONE, "irradiance pi is the old intensity 1");

    let floor = s.floor;
    assert_eq!(floor.center, Vec3::new(-8.0, 0.0, 0.0));
    assert_eq!(floor.size, Vec2::new(30.0, 15.0));
    assert_eq!((floor.min_corner(), floor.max_corner()), (Vec2::new(-23.0, -7.5), Vec2::new(7.0, 7.5)));
    assert_eq!((floor.height(), floor.tile), (0.0, 1.0));
    assert_eq!(floor.colors, [Vec3::new(0.8, 0.8, 0.0), Vec3::new(0.8, 0.0, 0.0)]);

    let glass = s.glass.unwrap();
    assert_eq!((glass.center, glass.radius), (Vec3::new(4.2, 2.6, -4.2), 1.0));
    assert_eq!((glass.color, glass.reflectivity, glass.shininess), (Vec3::ONE, 0.9, 200.0));
    // 1.4285715 is the shortest decimal of the f32 nearest 1 / 0.7, whose reciprocal is 0.7f32.
    assert_eq!(glass.refraction_ratio, 0.7f32);
    let metal = s.metal.unwrap();
    assert_eq!((metal.center, metal.radius), (Vec3::new(2.0, 1.9, -2.5), 1.0));
    assert_eq!(metal.color, Vec3::new(0.792, 0.863, 0.851));
    assert_eq!((metal.specular, metal.shininess, metal.mirror), (Vec3::ONE, 30.0, 0.6));
    assert_eq!(s.spheres(), vec![(glass.center, 1.0), (metal.center, 1.0)]);
}

#[test]
fn whitted_toml_gives_the_skeletons_numbers_exactly() {
    let s = RasterScene::load(&repo_file("scenes/whitted.toml")).unwrap();
    assert_eq!(s.name, "whitted");
    assert_eq!(s.look, Look::Figure);
    assert!((s.glass.unwrap().refraction_ratio - 0.7).abs() < 1e-7);
    // irradiance = 3.14159265 rounds to f32 pi, so irradiance / pi is the skeleton's intensity 1.
    assert_eq!(s.light.radiance(), Vec3::ONE);
    assert_eq!(s.ambient, Vec3::splat(0.23));
    assert_eq!(s.floor.min_corner(), Vec2::new(-23.0, -7.5));
    assert_eq!(s.floor.size, Vec2::new(30.0, 15.0));
    assert_eq!(s.metal.unwrap().mirror, 0.6);
    assert_eq!(s.effects, Effects::ALL_ON);
    assert_eq!((s.quality.pcf_radius, s.quality.cube_size), (0.05, 256));
}

/// The skeleton's refraction ratio is 0.7; whitted.toml's `ior = 1.4285714` parses to the f32
/// 1.4285713, whose reciprocal is 0.70000005. `ior = 1.4285715` (or 1.4285714285714286) would
/// give 0.7f32 exactly.
#[test]
fn whitted_toml_refraction_ratio_is_exactly_the_skeletons() {
    let s = RasterScene::load(&repo_file("scenes/whitted.toml")).unwrap();
    assert_eq!(s.glass.unwrap().refraction_ratio, 0.7f32);
}

#[test]
fn optional_parts_take_their_defaults() {
    let text = without(
        BASE,
        &[
            "name = \"w\"\n",
            "angular_radius = 0.0\n",
            "[environment]\nradiance = [0.3, 0.5, 0.9]\n",
            "[shading]\nambient = [0.23, 0.23, 0.23]\ndielectric = { shininess = 200.0 }\n\
         mirror = { specular = [1.0, 1.0, 1.0], shininess = 30.0, weight = 0.6 }\n",
            "[raster]\nlook = \"enhanced\"\npcf_radius = 0.05\ncube_size = 128\n\
         glass_color = [1.0, 1.0, 1.0]\nglass_reflectivity = 0.9\n",
            "[raster.effects]\nshadows = true\npcf = false\nrefraction = true\nreflection = true\n\
         fresnel = true\nmsaa = false\n",
        ],
    );
    let s = parse(&text).unwrap();
    assert_eq!(s.name, "w", "file stem of scenes/w.toml");
    assert_eq!(s.look, Look::Figure);
    assert_eq!(s.light.radiance(), Vec3::ONE);
    assert_eq!(s.background, Vec3::ZERO, "no environment, black background");
    assert_eq!(s.ambient, Vec3::ZERO, "no [shading] ambient, no ambient light");
    let glass = s.glass.unwrap();
    assert_eq!((glass.color, glass.reflectivity, glass.shininess), (Vec3::ONE, 0.9, 200.0));
    let metal = s.metal.unwrap();
    assert_eq!((metal.specular, metal.shininess, metal.mirror), (Vec3::ONE, 30.0, 0.6));
    // Shadows are an effect toggle, on by default.
    assert_eq!(s.effects, Effects::ALL_ON);
    assert_eq!((s.quality.pcf_radius, s.quality.cube_size), (0.05, 256));
}

/// `renderer` is only the tools' default renderer, so the same text loads as a
/// `Scene` and as a `RasterScene` whatever it says, and only its spelling is checked.
#[test]
fn the_renderer_key_is_only_a_default() {
    assert_eq!(Scene::from_toml_str(BASE, FILE).unwrap().renderer, RendererKind::Raster);
    let without = edit("renderer = \"raster\"\n", "");
    assert_eq!(Scene::from_toml_str(&without, FILE).unwrap().renderer, RendererKind::PathTrace);
    assert_eq!(parse(&without).unwrap(), parse(BASE).unwrap());
    let pathtrace = edit("renderer = \"raster\"", "renderer = \"pathtrace\"");
    assert_eq!(parse(&pathtrace).unwrap(), parse(BASE).unwrap());
    let other = edit("renderer = \"raster\"", "renderer = \"vulkan\"");
    expect_invalid(&other, "renderer", "\"vulkan\"", "must be \"raster\", \"pathtrace\" or \"whitted\"");
    // "whitted" names the Whitted ray tracer: a default renderer
    // like the others, which does not change what the rasterizer draws.
    let whitted = edit("renderer = \"raster\"", "renderer = \"whitted\"");
    assert_eq!(parse(&whitted).unwrap(), parse(BASE).unwrap());
}

// ---------------------------------------------------------------------------------------------
// The refusals: the scene's own validation, at the fields the rasterizer reads, and
// the rasterizer's arrangements.

#[test]
fn every_refusal_of_the_cases_file() {
    SCENE.expect_refusals(include_str!("cases/scene_rules.toml"), "tests/cases/scene_rules.toml");
}

// ---------------------------------------------------------------------------------------------
// The rasterizer's own rules: what it implements and how the scene must be arranged.

/// The physical scene allows any ior > 0; the rasterizer refracts only into a denser medium, so it asks for ior >= 1.
#[test]
fn the_glass_must_be_denser_than_air_for_the_rasterizer() {
    for (ior, ratio) in [("1", 1.0), ("1.0001", 1.0 / 1.0001f32), ("4", 0.25)] {
        let s = parse(&edit("ior = 1.4285715", &format!("ior = {ior}"))).unwrap();
        assert_eq!(s.glass.unwrap().refraction_ratio, ratio, "ior = {ior}");
    }
    let text = edit("ior = 1.4285715", "ior = 0.5");
    Scene::from_toml_str(&text, FILE).expect("ior 0.5 is a valid scene for the path tracer");
    let err = parse(&text).unwrap_err();
    let SceneError::Invalid { field, value, allowed, .. } = &err else { panic!("{err:?}") };
    assert_eq!(value, "0.5", "{err}");
    assert!(allowed.contains("ior must be >= 1"), "{err}");
    assert!(field.ends_with(".dielectric.ior") && field.contains("glass"), "{err}");
}

#[test]
fn spheres_are_optional_and_shadows_are_an_effect() {
    let glassless = parse(&edit(GLASS_OBJECT, "")).unwrap();
    assert!(glassless.glass.is_none() && glassless.metal.is_some());
    assert_eq!(glassless.spheres(), vec![(Vec3::new(2.0, 1.9, -2.5), 1.0)]);
    let metalless = parse(&edit(METAL_OBJECT, "")).unwrap();
    assert!(metalless.glass.is_some() && metalless.metal.is_none());
    let bare = parse(&edit(GLASS_OBJECT, "").replacen(METAL_OBJECT, "", 1)).unwrap();
    assert!(bare.spheres().is_empty(), "a floor under a light is a scene too");

    // The remaining sphere is still checked: the eye inside the metal, with no glass (the metal
    // is then objects[1]).
    let eye_in_metal = edit_text(&edit(GLASS_OBJECT, ""), "eye = [7.5, 2.3, -4.2]", "eye = [2.0, 1.9, -2.4]");
    let err = parse(&eye_in_metal).unwrap_err();
    check_invalid(&err, FILE, "camera.eye", "[2, 1.9, -2.4]", "outside objects[1] (\"metal sphere\")");

    // Shadows off: `[raster.effects] shadows = false`.
    let unshadowed = parse(&edit("shadows = true", "shadows = false")).unwrap();
    assert!(!unshadowed.effects.shadows);
    let err = parse(&edit("shadows = true", "shadows = 0")).unwrap_err();
    assert!(err.to_string().contains("expected a boolean"), "{err}");
    let err =
        parse(&edit("angular_radius = 0.0\n", "angular_radius = 0.0\ncasts_shadows = false\n")).unwrap_err();
    assert!(err.to_string().contains("unknown field `casts_shadows`"), "{err}");
}

#[test]
fn the_cornell_box_is_refused_by_the_rasterizer() {
    let path = repo_file("scenes/cornell.toml");
    let scene = Scene::load(&path).unwrap();
    let err = RasterScene::from_scene(&scene).unwrap_err();
    let SceneError::Unsupported { place, feature, renderer, .. } = &err else { panic!("{err:?}") };
    assert_eq!(renderer, "rasterizer", "{err}");
    assert!(err.to_string().contains("the rasterizer cannot render"), "{err}");
    // `Scene::require` names the first feature the rasterizer lacks, in file order: the walls
    // (boxes) come before the light.
    assert_eq!((place.as_str(), feature.as_str()), ("objects[0] (\"left wall\")", "a box"), "{err}");
    // The area light is among what it cannot render; alone, it is what the refusal names.
    let light = scene.feature_uses().into_iter().find(|(f, _)| *f == Feature::AreaLight).unwrap();
    assert_eq!(light.1, "objects[5] (\"light\"), material \"light\"");
    assert!(!illum_raster::scene::implements(Feature::AreaLight));
    let mut lit = scene.clone();
    lit.objects.retain(|o| !matches!(o.shape, illum_scene::Shape::Box(_)));
    let err = RasterScene::from_scene(&lit).unwrap_err();
    let SceneError::Unsupported { place, feature, renderer, .. } = &err else { panic!("{err:?}") };
    assert_eq!(
        (place.as_str(), feature.as_str(), renderer.as_str()),
        (
            "objects[0] (\"light\"), material \"light\"",
            "an area light (a quad with an emitting material)",
            "rasterizer"
        ),
        "{err}"
    );
}

#[test]
fn features_the_rasterizer_lacks_are_refused_by_name() {
    let crate_ = "[[objects]]\nname = \"crate\"\nmaterial = \"grey\"\n\
                  box = { center = [-5.0, 1.0, 3.0], half_extent = [1.0, 1.0, 1.0] }\n";
    expect_unsupported(&with_object(crate_), "objects[3] (\"crate\")", Feature::BoxShape);

    let lamp = "[materials.lamp]\nemission = [5.0, 5.0, 5.0]\n\n[[objects]]\nname = \"lamp\"\n\
                material = \"lamp\"\nquad = { corner = [-5.0, 8.0, -1.0], edge_u = [1.0, 0.0, 0.0], \
                edge_v = [0.0, 0.0, 1.0] }\n";
    // The lamp's quad is a quad (which the rasterizer has), its material an area light.
    expect_unsupported(&with_object(lamp), "objects[3] (\"lamp\"), material \"lamp\"", Feature::AreaLight);

    let sun = edit("angular_radius = 0.0", "angular_radius = 0.5");
    expect_unsupported(&sun, "[directional_light]", Feature::SunDisc);

    let ball = repo_file("scenes/models/icosphere-0.obj");
    let ball = format!(
        "[[objects]]\nname = \"ball\"\nmaterial = \"grey\"\nmesh = {{ file = {:?}, translate = [-5.0, 1.0, 3.0] }}\n",
        ball.display().to_string()
    );
    assert!(Feature::SunDisc.to_string().contains("sun disc"));
    // A Lambertian mesh is drawn (tests/raster/meshes.rs); a glass or mirror one is refused by
    // name: the rasterizer's glass and mirror are spheres, each read through a cube map.
    let drawn = parse(&with_object(&ball)).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(drawn.meshes.len(), 1);
    for material in ["glass", "metal"] {
        let shiny = ball.replace("material = \"grey\"", &format!("material = \"{material}\""));
        expect_invalid(
            &with_object(&shiny),
            "objects[3] (\"ball\").material",
            &format!("{material:?}"),
            "the rasterizer draws a mesh only with a Lambertian material (glass and mirrors are spheres only, each drawn through a cube map)",
        );
    }
}

#[test]
fn the_floor_may_face_down_for_the_scene_and_stand_off_the_ground() {
    // Facing down (the edges swapped, edge_u x edge_v = -Y) is a valid quad, which the
    // rasterizer refuses as a floor (see the cases file).
    let down = "quad = { corner = [-23.0, 0.0, -7.5], edge_u = [30.0, 0.0, 0.0], edge_v = [0.0, 0.0, 15.0] }";
    Scene::from_toml_str(&edit(FLOOR_QUAD, down), FILE).expect("a valid quad, facing down");
    // A floor off the ground is fine.
    let lower = edit("corner = [-23.0, 0.0, -7.5]", "corner = [-23.0, -1.0, -7.5]");
    let s = parse(&lower).unwrap();
    assert_eq!((s.floor.height(), s.floor.min_corner()), (-1.0, Vec2::new(-23.0, -7.5)));
}

#[test]
fn the_floor_tiles_range_from_one_plain_tile_to_the_finest_checker() {
    let plain = parse(&edit("material = \"floor\"", "material = \"grey\"")).unwrap();
    assert_eq!(plain.floor.colors, [Vec3::splat(0.5); 2], "a Lambertian floor is one colour");
    assert_eq!(plain.floor.tile, 30.0, "one tile covers it");
    // 30 / 3e-4 = 100000 tiles exactly (in f64 of the f32 tile: just under), the limit itself.
    parse(&edit("tile = 1.0", "tile = 0.0003")).unwrap();
}

/// The rasterizer needs clip planes and a directional light (refused without them: see the cases
/// file), which the path tracer does without.
#[test]
fn clip_planes_and_a_light_are_optional_for_the_scene() {
    let no_clip = edit("near = 0.1\nfar = 3000.0\n", "");
    assert_eq!(Scene::from_toml_str(&no_clip, FILE).unwrap().clip, None, "the path tracer needs none");
    // A black light is still a light.
    let dark =
        parse(&edit("irradiance = [3.14159265, 3.14159265, 3.14159265]", "irradiance = [0, 0, 0]")).unwrap();
    assert_eq!(dark.light.radiance(), Vec3::ZERO);
}

#[test]
fn antialiasing_is_read_under_its_name_and_its_former_one() {
    // tests/scenes/w.toml says `msaa = false`, the key's former name, which is still read with
    // the same meaning (anti-aliased edges or not).
    for (key, on) in [("msaa = false", false), ("msaa = true", true), ("antialiasing = false", false)] {
        let s = parse(&edit("msaa = false", key)).unwrap_or_else(|e| panic!("{key}: {e}"));
        assert_eq!(s.effects.antialiasing, on, "{key}");
    }
    assert!(parse(&edit("msaa = false\n", "")).unwrap().effects.antialiasing, "on when absent");
}

// ---------------------------------------------------------------------------------------------
// After loading.

#[test]
fn resolution_overrides_are_checked_and_leave_the_scene_unchanged_on_error() {
    let base = parse(BASE).unwrap();
    let mut s = base.clone();
    s.set_resolution(Some(320), None, "command line").unwrap();
    assert_eq!((s.camera.width, s.camera.height), (320, 36));
    s.set_resolution(None, Some(200), "command line").unwrap();
    assert_eq!((s.camera.width, s.camera.height), (320, 200));
    for (w, h, field) in [(Some(0), Some(10), "--width"), (Some(10), Some(0), "--height")] {
        let mut s = base.clone();
        let err = s.set_resolution(w, h, "command line").unwrap_err();
        check_invalid(&err, "command line", field, "0", "must be at least 1");
        assert_eq!(s, base);
    }
}

fn device_limits(max_texture_dimension_2d: u32, max_buffer_size: u64) -> wgpu::Limits {
    wgpu::Limits { max_texture_dimension_2d, max_buffer_size, ..wgpu::Limits::default() }
}

/// The meshes' vertex buffer (three 48-byte corners a triangle, mesh.rs) fits a max_buffer_size
/// of its size and not a byte less, refused by a message that names the mesh file, the bytes it
/// needs and the limit. At 1 x 1 the readback needs 256 bytes, so the vertices decide.
#[test]
fn the_meshes_vertex_buffer_is_held_to_max_buffer_size() {
    let ball = repo_file("scenes/models/icosphere-0.obj").display().to_string();
    let mesh = format!(
        "[[objects]]\nname = \"ball\"\nmaterial = \"grey\"\nmesh = {{ file = {ball:?}, translate = [-5.0, 1.0, 3.0] }}\n"
    );
    let mut s = parse(&with_object(&mesh)).unwrap_or_else(|e| panic!("{e}"));
    (s.camera.width, s.camera.height) = (1, 1);
    let bytes = (20 * 3 * std::mem::size_of::<illum_raster::mesh::MeshVertex>()) as u64;
    check_device_limits(&s, &device_limits(16384, bytes)).unwrap_or_else(|e| panic!("{bytes} bytes: {e}"));
    let err = check_device_limits(&s, &device_limits(16384, bytes - 1)).unwrap_err();
    check_invalid(
        &err,
        "scene \"w\"",
        "objects (meshes)",
        &format!("20 triangles of {ball:?} ({bytes} bytes of vertices)"),
        &format!("must fit in {} bytes, the device's max_buffer_size", bytes - 1),
    );
}

#[test]
fn device_limits_name_the_limit() {
    let limits = device_limits(16384, 1 << 28);
    let mut s = parse(BASE).unwrap();
    check_device_limits(&s, &limits).unwrap();
    s.camera.width = 16385;
    let err = check_device_limits(&s, &limits).unwrap_err();
    let label = "scene \"w\"";
    check_invalid(
        &err,
        label,
        "camera.width",
        "16385",
        "at most 16384, the device's max_texture_dimension_2d",
    );
    s.camera.width = 64;
    s.camera.height = 16385;
    let err = check_device_limits(&s, &limits).unwrap_err();
    check_invalid(&err, label, "camera.height", "16385", "max_texture_dimension_2d");
    s.camera.height = 36;
    s.quality.cube_size = 20000;
    let err = check_device_limits(&s, &limits).unwrap_err();
    check_invalid(&err, label, "raster.cube_size", "20000", "max_texture_dimension_2d");
    s.quality.cube_size = 16384;
    check_device_limits(&s, &limits).unwrap();
    // The readback: exactly at the buffer limit, then one row over it. 8192 x 8192 x 4 bytes =
    // 2^28; rows are padded to 256 bytes, so width 1 reads back 256 bytes per row.
    let over = "must fit in 268435456 bytes, the device's max_buffer_size";
    let cases = [
        (limits, 8192, 8192, "8192 x 8193 (268468224 bytes to read back)", over),
        (device_limits(16384, 256 * 36), 1, 36, "1 x 37 (9472 bytes to read back)", "9216 bytes"),
    ];
    for (limits, width, height, shown, allowed) in cases {
        (s.camera.width, s.camera.height) = (width, height);
        check_device_limits(&s, &limits).unwrap_or_else(|e| panic!("{width} x {height}: {e}"));
        s.camera.height = height + 1;
        let err = check_device_limits(&s, &limits).unwrap_err();
        check_invalid(&err, label, "camera.width x camera.height", shown, allowed);
    }
}
