//! Every validation rule of the Whitted scene format, triggered by an edited copy of a small
//! valid scene, with the message checked for file, field, value and what is allowed; plus the
//! format detection between the two loaders, resolution overrides and device limits.

use glam::Vec3;
use illum_scene::{Effects, Look, RasterLimits, Scene, SceneError, SceneKind, WhittedScene};

const FILE: &str = "scenes/w.toml";

/// A valid scene with every optional key written out.
const BASE: &str = r#"renderer = "raster"
name = "w"
look = "whitted"

[camera]
eye = [7.5, 2.3, -4.2]
target = [4.2, 2.3, -4.2]
up = [0.0, 1.0, 0.0]
vfov = 60.0
near = 0.1
far = 3000.0
width = 64
height = 36

[background]
color = [0.3, 0.5, 0.9]

[light]
position = [10.0, 13.0, -2.0]
target = [0.0, 0.0, 0.0]
color = [1.0, 1.0, 1.0]
intensity = 1.0

[ambient]
color = [1.0, 1.0, 1.0]
intensity = 0.23

[floor]
center = [-8.0, 0.0, 0.0]
size = [30.0, 15.0]
tile = 1.0
colors = [[0.8, 0.8, 0.0], [0.8, 0.0, 0.0]]

[glass]
center = [4.2, 2.6, -4.2]
radius = 1.0
color = [1.0, 1.0, 1.0]
refraction_ratio = 0.7
reflectivity = 0.9
shininess = 200.0

[metal]
center = [2.0, 1.9, -2.5]
radius = 1.0
color = [0.792, 0.863, 0.851]
specular = [1.0, 1.0, 1.0]
shininess = 30.0
mirror = 0.6

[effects]
shadows = true
pcf = false
refraction = true
reflection = true
fresnel = true
msaa = false

[quality]
pcf_radius = 0.05
cube_size = 128
"#;

fn edit(from: &str, to: &str) -> String {
    assert_eq!(BASE.matches(from).count(), 1, "{from:?} must occur once");
    BASE.replacen(from, to, 1)
}

fn parse(text: &str) -> Result<WhittedScene, SceneError> {
    WhittedScene::from_toml_str(text, FILE)
}

fn check_invalid(err: &SceneError, file: &str, field: &str, value: &str, allowed: &str) {
    let SceneError::Invalid { file: f, field: fd, value: v, allowed: a } = err else {
        panic!("expected Invalid on {field}, got {err:?}");
    };
    assert_eq!((f.as_str(), fd.as_str(), v.as_str()), (file, field, value), "{err}");
    assert!(a.contains(allowed), "allowed {a:?} lacks {allowed:?}");
    assert!(err.to_string().starts_with(&format!("{file}: {field} = {value}: ")), "{err}");
}

fn expect_invalid(text: &str, field: &str, value: &str, allowed: &str) {
    match parse(text) {
        Ok(_) => panic!("expected an error on {field} = {value}, but the scene loaded"),
        Err(e) => check_invalid(&e, FILE, field, value, allowed),
    }
}

#[test]
fn base_scene_loads_with_the_written_values() {
    let s = parse(BASE).unwrap();
    assert_eq!(s.name, "w");
    assert_eq!(s.look, Look::Whitted);
    assert_eq!((s.camera.width, s.camera.height), (64, 36));
    assert_eq!(s.effects, Effects { pcf: false, msaa: false, ..Effects::ALL_ON });
    assert_eq!(s.quality.cube_size, 128);
    assert_eq!(s.quality.pcf_radius, 0.05);
    assert_eq!(s.metal.unwrap().mirror, 0.6);
    assert_eq!(s.glass.unwrap().shininess, 200.0);
}

#[test]
fn optional_parts_take_their_defaults() {
    let mut text = BASE.to_owned();
    for cut in [
        "look = \"whitted\"\n",
        "name = \"w\"\n",
        "target = [0.0, 0.0, 0.0]\ncolor = [1.0, 1.0, 1.0]\nintensity = 1.0\n",
        "[ambient]\ncolor = [1.0, 1.0, 1.0]\nintensity = 0.23\n",
        "color = [1.0, 1.0, 1.0]\nrefraction_ratio",
        "reflectivity = 0.9\nshininess = 200.0\n",
        "specular = [1.0, 1.0, 1.0]\nshininess = 30.0\nmirror = 0.6\n",
        "[effects]\nshadows = true\npcf = false\nrefraction = true\nreflection = true\nfresnel = true\nmsaa = false\n",
        "[quality]\npcf_radius = 0.05\ncube_size = 128\n",
    ] {
        assert_eq!(text.matches(cut).count(), 1, "{cut:?}");
        let keep = if cut.ends_with("refraction_ratio") { "refraction_ratio" } else { "" };
        text = text.replacen(cut, keep, 1);
    }
    let s = parse(&text).unwrap();
    assert_eq!(s.name, "w", "file stem of scenes/w.toml");
    assert_eq!(s.look, Look::Figure);
    assert_eq!(s.light.target, Vec3::ZERO);
    assert_eq!(s.light.radiance(), Vec3::ONE);
    assert!(s.light.casts_shadows, "a light casts shadows unless the file says otherwise");
    assert_eq!(s.ambient.radiance(), Vec3::ZERO, "no ambient table, no ambient light");
    assert_eq!(s.glass.unwrap().color, Vec3::ONE);
    assert_eq!((s.glass.unwrap().reflectivity, s.glass.unwrap().shininess), (0.9, 200.0));
    assert_eq!(
        (s.metal.unwrap().specular, s.metal.unwrap().shininess, s.metal.unwrap().mirror),
        (Vec3::ONE, 30.0, 0.6)
    );
    assert_eq!(s.effects, Effects::ALL_ON);
    assert_eq!((s.quality.pcf_radius, s.quality.cube_size), (0.05, 256));
}

#[test]
fn the_two_formats_refuse_each_other() {
    let without = edit("renderer = \"raster\"\n", "");
    check_invalid(&parse(&without).unwrap_err(), FILE, "renderer", "(missing)", "path-tracer scene");
    let err = Scene::from_toml_str(BASE, FILE).unwrap_err();
    check_invalid(&err, FILE, "renderer", "\"raster\"", "WhittedScene::load");
    assert_eq!(SceneKind::from_toml_str(BASE, FILE).unwrap(), SceneKind::Raster);
    let other = edit("renderer = \"raster\"", "renderer = \"vulkan\"");
    check_invalid(&parse(&other).unwrap_err(), FILE, "renderer", "\"vulkan\"", "must be \"raster\"");
}

#[test]
fn non_finite_numbers_are_rejected() {
    let cases = [
        ("eye = [7.5, 2.3, -4.2]", "eye = [nan, 2.3, -4.2]", "camera.eye"),
        ("near = 0.1", "near = inf", "camera.near"),
        ("far = 3000.0", "far = 1e39", "camera.far"),
        ("position = [10.0, 13.0, -2.0]", "position = [10.0, inf, -2.0]", "light.position"),
        ("intensity = 0.23", "intensity = nan", "ambient.intensity"),
        ("center = [-8.0, 0.0, 0.0]", "center = [-8.0, nan, 0.0]", "floor.center"),
        ("size = [30.0, 15.0]", "size = [30.0, inf]", "floor.size[1]"),
        ("radius = 1.0\ncolor = [1.0", "radius = nan\ncolor = [1.0", "glass.radius"),
        ("refraction_ratio = 0.7", "refraction_ratio = nan", "glass.refraction_ratio"),
        ("center = [2.0, 1.9, -2.5]", "center = [2.0, -inf, -2.5]", "metal.center"),
        ("pcf_radius = 0.05", "pcf_radius = nan", "quality.pcf_radius"),
    ];
    for (from, to, field) in cases {
        let err = parse(&edit(from, to)).unwrap_err();
        let SceneError::Invalid { field: f, allowed, .. } = &err else { panic!("{field}: {err:?}") };
        assert_eq!(f, field, "{err}");
        assert!(allowed.contains("finite"), "{err}");
    }
}

#[test]
fn camera_rules_are_the_path_tracers() {
    expect_invalid(&edit("vfov = 60.0", "vfov = 180.0"), "camera.vfov", "180", "open interval (0, 180)");
    expect_invalid(&edit("width = 64", "width = 0"), "camera.width", "0", "at least 1");
    expect_invalid(&edit("height = 36", "height = -3"), "camera.height", "-3", "at least 1");
    expect_invalid(
        &edit("target = [4.2, 2.3, -4.2]", "target = [7.5, 2.3, -4.2]"),
        "camera.target",
        "[7.5, 2.3, -4.2]",
        "must differ from camera.eye",
    );
    expect_invalid(
        &edit("up = [0.0, 1.0, 0.0]", "up = [-1.0, 0.0, 0.0]"),
        "camera.up",
        "[-1, 0, 0]",
        "not parallel",
    );
    expect_invalid(&edit("near = 0.1", "near = 0.0"), "camera.near", "0", "must be > 0");
    expect_invalid(&edit("far = 3000.0", "far = 0.1"), "camera.far", "0.1", "greater than camera.near = 0.1");
}

#[test]
fn geometry_and_material_ranges() {
    expect_invalid(
        &edit("radius = 1.0\ncolor = [1.0", "radius = 0.0\ncolor = [1.0"),
        "glass.radius",
        "0",
        "> 0",
    );
    expect_invalid(
        &edit("radius = 1.0\ncolor = [0.792", "radius = -1\ncolor = [0.792"),
        "metal.radius",
        "-1",
        "> 0",
    );
    expect_invalid(&edit("size = [30.0, 15.0]", "size = [0.0, 15.0]"), "floor.size[0]", "0", "> 0");
    expect_invalid(&edit("tile = 1.0", "tile = 0.0"), "floor.tile", "0", "> 0");
    expect_invalid(
        &edit("size = [30.0, 15.0]", "size = [30.0, 15.0, 1.0]"),
        "floor.size",
        "[30, 15, 1]",
        "two numbers",
    );
    expect_invalid(
        &edit("colors = [[0.8, 0.8, 0.0], [0.8, 0.0, 0.0]]", "colors = [[0.8, 0.8, 0.0]]"),
        "floor.colors",
        "[[0.8, 0.8, 0]]",
        "two colours",
    );
    expect_invalid(&edit("tile = 1.0", "tile = 1e-6"), "floor.tile", "1e-6", "at most 100000 tiles");
    expect_invalid(
        &edit("[0.8, 0.0, 0.0]]", "[1.5, 0.0, 0.0]]"),
        "floor.colors[1]",
        "[1.5, 0, 0]",
        "every channel must be in [0, 1]",
    );
    expect_invalid(
        &edit("refraction_ratio = 0.7", "refraction_ratio = 1.5"),
        "glass.refraction_ratio",
        "1.5",
        "(0, 1]",
    );
    expect_invalid(
        &edit("refraction_ratio = 0.7", "refraction_ratio = 0"),
        "glass.refraction_ratio",
        "0",
        "(0, 1]",
    );
    expect_invalid(&edit("reflectivity = 0.9", "reflectivity = 1.1"), "glass.reflectivity", "1.1", "[0, 1]");
    expect_invalid(&edit("mirror = 0.6", "mirror = -0.1"), "metal.mirror", "-0.1", "[0, 1]");
    expect_invalid(&edit("shininess = 30.0", "shininess = 0"), "metal.shininess", "0", "> 0");
    expect_invalid(
        &edit("color = [0.3, 0.5, 0.9]", "color = [0.3, -0.5, 0.9]"),
        "background.color",
        "[0.3, -0.5, 0.9]",
        ">= 0",
    );
    expect_invalid(&edit("intensity = 1.0", "intensity = -1.0"), "light.intensity", "-1", ">= 0");
    expect_invalid(
        &edit("target = [0.0, 0.0, 0.0]", "target = [10.0, 13.0, -2.0]"),
        "light.target",
        "[10, 13, -2]",
        "must differ from light.position",
    );
    expect_invalid(&edit("cube_size = 128", "cube_size = 0"), "quality.cube_size", "0", "at least 1");
    expect_invalid(&edit("pcf_radius = 0.05", "pcf_radius = 0"), "quality.pcf_radius", "0", "> 0");
    expect_invalid(
        &edit("look = \"whitted\"", "look = \"photo\""),
        "look",
        "\"photo\"",
        "\"figure\" or \"whitted\"",
    );
}

#[test]
fn the_camera_must_be_outside_the_spheres_and_the_spheres_apart() {
    expect_invalid(
        &edit("eye = [7.5, 2.3, -4.2]", "eye = [4.5, 2.6, -4.2]"),
        "camera.eye",
        "[4.5, 2.6, -4.2]",
        "outside the glass sphere",
    );
    expect_invalid(
        &edit("center = [2.0, 1.9, -2.5]", "center = [3.5, 2.6, -4.2]"),
        "metal.center",
        "[3.5, 2.6, -4.2]",
        "must not touch or overlap",
    );
}

/// The `[glass]` section of BASE, whole.
const GLASS_SECTION: &str = "[glass]\ncenter = [4.2, 2.6, -4.2]\nradius = 1.0\ncolor = [1.0, 1.0, 1.0]\n\
                             refraction_ratio = 0.7\nreflectivity = 0.9\nshininess = 200.0\n";
/// The `[metal]` section of BASE, whole.
const METAL_SECTION: &str = "[metal]\ncenter = [2.0, 1.9, -2.5]\nradius = 1.0\ncolor = [0.792, 0.863, 0.851]\n\
                             specular = [1.0, 1.0, 1.0]\nshininess = 30.0\nmirror = 0.6\n";

#[test]
fn spheres_are_optional_and_a_light_may_cast_no_shadows() {
    let glassless = parse(&edit(GLASS_SECTION, "")).unwrap();
    assert!(glassless.glass.is_none() && glassless.metal.is_some());
    assert_eq!(glassless.spheres(), vec![(Vec3::new(2.0, 1.9, -2.5), 1.0)]);
    let metalless = parse(&edit(METAL_SECTION, "")).unwrap();
    assert!(metalless.glass.is_some() && metalless.metal.is_none());
    let bare = parse(&edit(GLASS_SECTION, "").replacen(METAL_SECTION, "", 1)).unwrap();
    assert!(bare.spheres().is_empty(), "a floor under a light is a scene too");

    // The remaining sphere is still checked: the eye inside the metal, with no glass.
    let eye_in_metal =
        edit(GLASS_SECTION, "").replacen("eye = [7.5, 2.3, -4.2]", "eye = [2.0, 1.9, -2.4]", 1);
    let err = parse(&eye_in_metal).unwrap_err();
    check_invalid(&err, FILE, "camera.eye", "[2, 1.9, -2.4]", "outside the metal sphere");

    let unshadowed = parse(&edit("intensity = 1.0\n", "intensity = 1.0\ncasts_shadows = false\n")).unwrap();
    assert!(!unshadowed.light.casts_shadows);
    let err = parse(&edit("intensity = 1.0\n", "intensity = 1.0\ncasts_shadows = 0\n")).unwrap_err();
    assert!(err.to_string().contains("expected a boolean"), "{err}");
}

#[test]
fn unknown_and_mistyped_keys_are_syntax_errors() {
    for (from, to, needle) in [
        ("mirror = 0.6", "mirror = 0.6\nroughness = 0.1", "unknown field `roughness`"),
        ("msaa = false", "msaa = false\nbloom = true", "unknown field `bloom`"),
        ("msaa = false", "msaa = \"no\"", "expected a boolean"),
        ("cube_size = 128", "cube_size = 12.5", "expected an integer"),
    ] {
        let err = parse(&edit(from, to)).unwrap_err();
        assert!(matches!(err, SceneError::Syntax { .. }), "{err:?}");
        assert!(err.to_string().contains(needle), "{err}");
    }
    let err = parse(&edit("[glass]\n", "[glas]\n")).unwrap_err();
    assert!(err.to_string().contains("unknown field `glas`"), "{err}");
}

#[test]
fn resolution_overrides_are_checked_and_leave_the_scene_unchanged_on_error() {
    let base = parse(BASE).unwrap();
    let mut s = base.clone();
    s.set_resolution(Some(320), None, "command line").unwrap();
    assert_eq!((s.camera.width, s.camera.height), (320, 36));
    for (w, h, field) in [(Some(0), Some(10), "--width"), (Some(10), Some(0), "--height")] {
        let mut s = base.clone();
        let err = s.set_resolution(w, h, "command line").unwrap_err();
        check_invalid(&err, "command line", field, "0", "must be at least 1");
        assert_eq!(s, base);
    }
}

#[test]
fn device_limits_name_the_limit() {
    let limits = RasterLimits { max_texture_dimension_2d: 16384, max_buffer_size: 1 << 28 };
    let mut s = parse(BASE).unwrap();
    s.check_device_limits(&limits).unwrap();
    s.camera.width = 16385;
    let err = s.check_device_limits(&limits).unwrap_err();
    let label = "scene \"w\"";
    check_invalid(
        &err,
        label,
        "camera.width",
        "16385",
        "at most 16384, the device's max_texture_dimension_2d",
    );
    s.camera.width = 64;
    s.quality.cube_size = 20000;
    let err = s.check_device_limits(&limits).unwrap_err();
    check_invalid(&err, label, "quality.cube_size", "20000", "max_texture_dimension_2d");
    s.quality.cube_size = 256;
    // 8192 x 8192 x 4 bytes = 2^28: exactly at the limit; one more row is over it.
    s.camera.width = 8192;
    s.camera.height = 8192;
    s.check_device_limits(&limits).unwrap();
    s.camera.height = 8193;
    let err = s.check_device_limits(&limits).unwrap_err();
    check_invalid(
        &err,
        "scene \"w\"",
        "camera.width x camera.height",
        "8192 x 8193 (268468224 bytes to read back)",
        "must fit in 268435456 bytes, the device's max_buffer_size",
    );
}
