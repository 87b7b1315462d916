//! The rules of the physical scene model: material kinds, the environment and directional
//! light, the per-renderer sections (`[pathtrace]`, `[raster]`, `[whitted]`, `[shading]`), the
//! `renderer` key, the clip planes, and `Scene::require` refusing what a renderer lacks. Each
//! rule is triggered by an edited copy of a small valid scene, with the message checked for
//! file, field, value and what is allowed; the extremes each side of every range are tried.
//! (`errors.rs` has the camera, shape and path-tracer rules shared with the old format.)
//!
//! Long (one test per rule) but one concept: every rule of the physical model.

use glam::Vec3;
use illum_scene::testing::{Edits, edit_once as edit_text, without};
use illum_scene::{
    Checker, Effects, Feature, Look, MaterialKind, RendererKind, Scene, SceneError, Sequence, Shading,
    WhittedSettings,
};

const FILE: &str = "scenes/phys.toml";

/// A valid scene using every section and every material kind once.
const BASE: &str = include_str!("scenes/phys.toml");

/// The largest finite f32, written so that it parses to exactly `f32::MAX`.
const F32_MAX: &str = "3.4028234663852886e38";

/// What the tests edit: `BASE`, loaded as a [`Scene`].
const SCENE: Edits<Scene> = Edits { base: BASE, file: FILE, load: Scene::from_toml_str };

/// `BASE` with `from` replaced by `to`; `from` must occur exactly once, so a typo in a test
/// fails loudly instead of silently testing the unedited scene.
fn edit(from: &str, to: &str) -> String {
    SCENE.edit(from, to)
}

fn parse(text: &str) -> Result<Scene, SceneError> {
    SCENE.parse(text)
}

/// Parses `BASE` edited `from` -> `to`, which must be valid.
fn accepted(from: &str, to: &str) -> Scene {
    parse(&edit(from, to)).unwrap_or_else(|e| panic!("{to:?} should be accepted: {e}"))
}

fn expect_invalid(text: &str, field: &str, value: &str, allowed: &str) {
    SCENE.expect_invalid(text, field, value, allowed);
}

/// `line` is a `KEY = "WORD"` line of `BASE`; each of `bad`, quoted, in place of its word must
/// be refused on `field` with `allowed`.
fn expect_bad_words(line: &str, field: &str, bad: &[&str], allowed: &str) {
    let (key, _) = line.split_once(" = ").unwrap();
    for word in bad {
        expect_invalid(&edit(line, &format!("{key} = {word:?}")), field, &format!("{word:?}"), allowed);
    }
}

/// Asserts a syntax error whose message contains `needle`.
fn expect_syntax(text: &str, needle: &str) {
    let err = parse(text).expect_err("expected a syntax error");
    let SceneError::Syntax { message, .. } = &err else { panic!("expected Syntax, got {err:?}") };
    assert!(message.contains(needle), "{message:?} lacks {needle:?}");
}

const FINITE: &str = "must be a finite number within f32 range";

// ---------------------------------------------------------------------------------------------
// The base scene.

#[test]
fn base_scene_loads_with_the_written_values() {
    let s = parse(BASE).unwrap();
    assert_eq!((s.name.as_str(), s.source.as_str(), s.renderer), ("phys", FILE, RendererKind::PathTrace));
    let clip = s.clip.unwrap();
    assert_eq!((clip.near, clip.far), (0.1, 100.0));
    assert_eq!(s.environment.unwrap().radiance, Vec3::new(0.3, 0.5, 0.9));

    let light = s.directional_light.unwrap();
    assert!(light.direction.abs_diff_eq(Vec3::new(-1.0, -2.0, 0.5).normalize(), 1e-6));
    assert_eq!(light.to_light(), -light.direction);
    assert_eq!((light.irradiance, light.angular_radius_deg), (Vec3::splat(3.0), 0.25));
    assert!(!light.is_delta());

    let kinds: Vec<(&str, MaterialKind)> = s.materials.iter().map(|m| (m.name.as_str(), m.kind)).collect();
    let checker = Checker { even: Vec3::new(0.8, 0.8, 0.0), odd: Vec3::new(0.8, 0.0, 0.0), tile: 0.5 };
    assert_eq!(
        kinds,
        [
            ("board", MaterialKind::Checker(checker)),
            ("glass", MaterialKind::Dielectric { ior: 1.5 }),
            ("grey", MaterialKind::Lambertian { albedo: Vec3::splat(0.5) }),
            ("lamp", MaterialKind::Emitter { radiance: Vec3::splat(5.0) }),
            ("metal", MaterialKind::Mirror { reflectance: Vec3::new(0.9, 0.8, 0.7) }),
        ]
    );
    let keys: Vec<&str> = s.materials.iter().map(|m| m.kind.key()).collect();
    assert_eq!(keys, ["checker", "dielectric", "albedo", "emission", "mirror"]);
    let emitters: Vec<usize> = s.emitters().map(|(i, _, _)| i).collect();
    assert_eq!(emitters, [4]);
    let glass_spheres: Vec<&str> = s
        .spheres_where(|m| matches!(m.kind, MaterialKind::Dielectric { .. }))
        .map(|(o, _)| o.name.as_str())
        .collect();
    assert_eq!(glass_spheres, ["ball"]);

    assert_eq!(s.pathtrace.sequence, Sequence::LowDiscrepancy);
    assert_eq!(s.raster.look, Look::Enhanced);
    assert_eq!(s.raster.effects, Effects { shadows: false, reflection: false, ..Effects::ALL_ON });
    assert_eq!((s.raster.pcf_radius, s.raster.cube_size), (0.1, 64));
    assert_eq!((s.raster.glass_color, s.raster.glass_reflectivity), (Vec3::new(0.9, 1.0, 0.9), 0.5));
    assert_eq!(s.whitted, WhittedSettings { depth: 5, aa: 3 });
    assert_eq!(s.shading.ambient, Vec3::splat(0.1));
    assert_eq!(s.shading.dielectric.shininess, 100.0);
    let mirror = s.shading.mirror;
    assert_eq!((mirror.specular, mirror.shininess, mirror.weight), (Vec3::splat(0.9), 20.0, 0.4));
}

#[test]
fn optional_sections_take_their_defaults() {
    let text = without(
        BASE,
        &[
            "renderer = \"pathtrace\"\n",
            "near = 0.1\nfar = 100.0\n",
            "[environment]\nradiance = [0.3, 0.5, 0.9]\n",
            "angular_radius = 0.25\n",
            "sequence = \"low-discrepancy\"\n",
            "[raster]\nlook = \"enhanced\"\npcf_radius = 0.1\ncube_size = 64\nglass_color = [0.9, 1.0, 0.9]\n\
         glass_reflectivity = 0.5\n",
            "[raster.effects]\nshadows = false\npcf = true\nrefraction = true\nreflection = false\n\
         fresnel = true\nmsaa = true\n",
            "[whitted]\ndepth = 5\naa = 3\n",
            "[shading]\nambient = [0.1, 0.1, 0.1]\ndielectric = { shininess = 100.0 }\n\
         mirror = { specular = [0.9, 0.9, 0.9], shininess = 20.0, weight = 0.4 }\n",
        ],
    );
    let s = parse(&text).unwrap();
    assert_eq!(s.renderer, RendererKind::PathTrace);
    assert_eq!(s.clip, None);
    assert_eq!(s.environment, None);
    let light = s.directional_light.unwrap();
    assert_eq!(light.angular_radius_deg, 0.0);
    assert!(light.is_delta(), "no angular_radius: a delta light");
    assert_eq!(s.pathtrace.sequence, Sequence::Independent);
    assert_eq!(s.raster.look, Look::Figure);
    assert_eq!(s.raster.effects, Effects::ALL_ON);
    assert_eq!((s.raster.pcf_radius, s.raster.cube_size), (0.05, 256));
    assert_eq!((s.raster.glass_color, s.raster.glass_reflectivity), (Vec3::ONE, 0.9));
    assert_eq!(s.whitted, WhittedSettings { depth: 8, aa: 2 });
    let Shading { ambient, dielectric, mirror } = s.shading;
    assert_eq!((ambient, dielectric.shininess), (Vec3::ZERO, 200.0));
    assert_eq!((mirror.specular, mirror.shininess, mirror.weight), (Vec3::ONE, 30.0, 0.6));

    // Neither light is required, and neither is any object but one.
    let text = edit_text(
        &text,
        "[directional_light]\ndirection = [-1.0, -2.0, 0.5]\nirradiance = [3.0, 3.0, 3.0]\n",
        "",
    );
    let s = parse(&text).unwrap();
    assert_eq!(s.directional_light, None);
    // A partial effects table keeps the unnamed toggles on.
    let s = parse(&edit("shadows = false\npcf = true\nrefraction = true\nreflection = false\n", "")).unwrap();
    assert_eq!(s.raster.effects, Effects::ALL_ON);
}

// ---------------------------------------------------------------------------------------------
// Materials.

const ONE_KIND: &str = "a material needs exactly one of albedo (Lambertian), checker (Lambertian \
                        checkerboard), dielectric (glass), mirror, emission (area light)";

#[test]
fn a_material_has_exactly_one_kind() {
    SCENE.expect_invalid_edits(&[
        ("albedo = [0.5, 0.5, 0.5]\n", "", "materials.grey", "{}", ONE_KIND),
        (
            "albedo = [0.5, 0.5, 0.5]\n",
            "albedo = [0.5, 0.5, 0.5]\nmirror = { reflectance = [1, 1, 1] }\n",
            "materials.grey",
            "{ albedo, mirror }",
            ONE_KIND,
        ),
        (
            "emission = [5.0, 5.0, 5.0]\n",
            "emission = [5.0, 5.0, 5.0]\nalbedo = [0.5, 0.5, 0.5]\n",
            "materials.lamp",
            "{ albedo, emission }",
            ONE_KIND,
        ),
    ]);
    let all = "albedo = [0.5, 0.5, 0.5]\nchecker = { even = [0, 0, 0], odd = [1, 1, 1], tile = 1 }\n\
               dielectric = { ior = 1.5 }\nmirror = { reflectance = [1, 1, 1] }\nemission = [1, 1, 1]\n";
    expect_invalid(
        &edit("albedo = [0.5, 0.5, 0.5]\n", all),
        "materials.grey",
        "{ albedo, checker, dielectric, mirror, emission }",
        ONE_KIND,
    );
    // A kind with a key of another kind is a syntax error, naming the key.
    expect_syntax(
        &edit("dielectric = { ior = 1.5 }", "dielectric = { ior = 1.5, reflectance = [1, 1, 1] }"),
        "unknown field `reflectance`",
    );
    expect_syntax(
        &edit("albedo = [0.5, 0.5, 0.5]\n", "lambertian = [0.5, 0.5, 0.5]\n"),
        "unknown field `lambertian`",
    );
    expect_syntax(&edit("dielectric = { ior = 1.5 }", "dielectric = {}"), "missing field `ior`");
}

#[test]
fn a_checker_needs_a_quad_and_a_positive_tile() {
    // On a sphere and on a box.
    for (from, to, field, kind) in [
        ("material = \"glass\"", "material = \"board\"", "objects[2] (\"ball\").material", "sphere"),
        ("material = \"grey\"", "material = \"board\"", "objects[1] (\"block\").material", "box"),
    ] {
        expect_invalid(
            &edit(from, to),
            field,
            "\"board\"",
            &format!("a checkerboard is supported on quad objects only (this object is a {kind}"),
        );
    }
    SCENE.expect_invalid_values(
        "tile = 0.5",
        "materials.board.checker.tile",
        &[
            ("0", "0", "must be > 0"),
            ("-0.5", "-0.5", "must be > 0"),
            ("nan", "nan", FINITE),
            ("inf", "inf", FINITE),
            ("1e39", "1e39", FINITE),
        ],
    );
    // Every tile colour is a reflectance.
    SCENE.expect_invalid_edits(&[
        (
            "even = [0.8, 0.8, 0.0]",
            "even = [0.8, 1.01, 0.0]",
            "materials.board.checker.even",
            "[0.8, 1.01, 0]",
            "every channel must be in [0, 1]",
        ),
        (
            "odd = [0.8, 0.0, 0.0]",
            "odd = [0.8, -0.0001, 0.0]",
            "materials.board.checker.odd",
            "[0.8, -0.0001, 0]",
            "every channel must be in [0, 1]",
        ),
    ]);
    // A tile larger than the quad is one tile, and a huge one is fine.
    accepted("tile = 0.5", "tile = 1000");
    accepted("tile = 0.5", &format!("tile = {F32_MAX}"));
}

#[test]
fn a_checker_has_at_most_100000_tiles_along_an_edge() {
    // The floor's longest edge is 10: tile 1.0001e-4 is 99990 tiles. (1e-4 itself is a hair
    // under 1e-4 in f32, so it gives a hair over 100000 tiles and is refused.)
    accepted("tile = 0.5", "tile = 1.0001e-4");
    assert!(parse(&edit("tile = 0.5", "tile = 1e-4")).is_err());
    // 2^-14 is exact in f32: 10 / 2^-14 = 163840 tiles.
    expect_invalid(
        &edit("tile = 0.5", "tile = 0.00006103515625"),
        "materials.board.checker.tile",
        "0.00006103515625",
        "must give at most 100000 tiles along each edge of a quad it is on (this quad gives 163840)",
    );
    // The same checker on a smaller quad is fine: the count is per quad.
    let small = "edge_u = [0.0, 0.0, 1.0], edge_v = [1.0, 0.0, 0.0]";
    let text = edit_text(
        &edit("tile = 0.5", "tile = 0.00006103515625"),
        "edge_u = [0.0, 0.0, 10.0], edge_v = [10.0, 0.0, 0.0]",
        small,
    );
    parse(&text).unwrap();
}

/// The too-many-tiles message shows the tile widened from f32 to f64 (`9.99999997475243e-7`)
/// instead of the value written (`1e-6`), unlike every other message, which shows the file's
/// number: `validate.rs` formats `f64::from(c.tile)` where it has the f32 only.
#[test]
fn the_too_many_tiles_message_shows_the_tile_as_written() {
    expect_invalid(
        &edit("tile = 0.5", "tile = 1e-6"),
        "materials.board.checker.tile",
        "1e-6",
        "at most 100000 tiles",
    );
}

#[test]
fn a_dielectric_has_a_positive_finite_ior() {
    for (ior, value) in
        [("1", 1.0), ("1.0001", 1.0001), ("4", 4.0), ("0.5", 0.5), ("1e-30", 1e-30), (F32_MAX, f32::MAX)]
    {
        let s = accepted("ior = 1.5", &format!("ior = {ior}"));
        assert_eq!(s.materials[1].kind, MaterialKind::Dielectric { ior: value }, "ior = {ior}");
    }
    let allowed = "must be > 0 (the index of refraction inside";
    SCENE.expect_invalid_values(
        "ior = 1.5",
        "materials.glass.dielectric.ior",
        &[
            ("0", "0", allowed),
            ("-0.0", "-0", allowed),
            ("-1.5", "-1.5", allowed),
            ("1e-50", "1e-50", allowed), // positive in f64, 0 in f32
            ("nan", "nan", FINITE),
            ("inf", "inf", FINITE),
            ("-inf", "-inf", FINITE),
            ("1e39", "1e39", FINITE),
            ("3.5e38", "3.5e38", FINITE),
        ],
    );
}

#[test]
fn a_mirror_reflects_between_nothing_and_everything() {
    for r in ["[0, 0, 0]", "[1, 1, 1]", "[1.0, 0.0, 0.5]"] {
        accepted("reflectance = [0.9, 0.8, 0.7]", &format!("reflectance = {r}"));
    }
    SCENE.expect_invalid_values(
        "reflectance = [0.9, 0.8, 0.7]",
        "materials.metal.mirror.reflectance",
        &[
            (
                "[1.1, 0.8, 0.7]",
                "[1.1, 0.8, 0.7]",
                "every channel must be in [0, 1] (the fraction of light reflected)",
            ),
            ("[0.9, -0.1, 0.7]", "[0.9, -0.1, 0.7]", "every channel must be in [0, 1]"),
            ("[0.9, 0.8, nan]", "[0.9, 0.8, nan]", FINITE),
            ("[1e39, 0.8, 0.7]", "[1e39, 0.8, 0.7]", FINITE),
        ],
    );
}

#[test]
fn an_emitter_emits_something_and_nothing_negative() {
    for e in ["[0, 0, 1e-30]", "[1, 0, 0]", "[1e6, 1e6, 1e6]", &format!("[{F32_MAX}, 0, 0]")] {
        let s = accepted("emission = [5.0, 5.0, 5.0]", &format!("emission = {e}"));
        assert!(s.materials[3].is_emitter());
    }
    let allowed = "every channel must be >= 0 and one > 0 (emitted radiance; for a black surface write \
                   albedo = [0, 0, 0])";
    SCENE.expect_invalid_values(
        "emission = [5.0, 5.0, 5.0]",
        "materials.lamp.emission",
        &[
            ("[0, 0, 0]", "[0, 0, 0]", allowed),
            ("[0.0, -0.0, 0.0]", "[0, -0, 0]", allowed),
            ("[5, -1, 5]", "[5, -1, 5]", allowed),
            ("[1e-50, 0, 0]", "[1e-50, 0, 0]", allowed), // positive in f64, 0 in f32
            ("[5, nan, 5]", "[5, nan, 5]", FINITE),
            ("[1e39, 0, 0]", "[1e39, 0, 0]", FINITE),
        ],
    );
    // Emission is for quads only.
    expect_invalid(
        &edit("material = \"glass\"", "material = \"lamp\""),
        "objects[2] (\"ball\").material",
        "\"lamp\"",
        "emission is supported on quad objects only (this object is a sphere and material \"lamp\" emits [5, 5, 5]",
    );
}

// ---------------------------------------------------------------------------------------------
// Lights.

#[test]
fn the_environment_radiance_is_non_negative() {
    for r in ["[0, 0, 0]", "[100, 0, 0.5]", &format!("[{F32_MAX}, 0, 0]")] {
        accepted("radiance = [0.3, 0.5, 0.9]", &format!("radiance = {r}"));
    }
    SCENE.expect_invalid_values(
        "radiance = [0.3, 0.5, 0.9]",
        "environment.radiance",
        &[
            ("[0.3, -0.5, 0.9]", "[0.3, -0.5, 0.9]", "every channel must be >= 0"),
            ("[-1e-30, 0, 0]", "[-1e-30, 0, 0]", "every channel must be >= 0"),
            ("[nan, 0.5, 0.9]", "[nan, 0.5, 0.9]", FINITE),
            ("[1e39, 0.5, 0.9]", "[1e39, 0.5, 0.9]", FINITE),
        ],
    );
    expect_syntax(&edit("radiance = [0.3, 0.5, 0.9]", "color = [0.3, 0.5, 0.9]"), "unknown field `color`");
}

#[test]
fn the_directional_light_direction_is_non_zero() {
    // Any length is fine, down to the smallest and up to the largest f32.
    for (d, expected) in [
        ("[0, -1e-30, 0]", Vec3::NEG_Y),
        ("[0, -1e-40, 0]", Vec3::NEG_Y), // subnormal in f32
        (&format!("[{F32_MAX}, 0, 0]") as &str, Vec3::X),
        (&format!("[{F32_MAX}, {F32_MAX}, 0]") as &str, Vec3::new(1.0, 1.0, 0.0).normalize()),
    ] {
        let s = accepted("direction = [-1.0, -2.0, 0.5]", &format!("direction = {d}"));
        let direction = s.directional_light.unwrap().direction;
        assert!(direction.abs_diff_eq(expected, 1e-6), "{d}: {direction}");
    }
    let allowed = "must be non-zero (the direction the light travels";
    SCENE.expect_invalid_values(
        "direction = [-1.0, -2.0, 0.5]",
        "directional_light.direction",
        &[
            ("[0, 0, 0]", "[0, 0, 0]", allowed),
            ("[0, -0.0, 0]", "[0, -0, 0]", allowed),
            ("[0, -1e-50, 0]", "[0, -1e-50, 0]", allowed), // 0 in f32
            ("[nan, -1, 0]", "[nan, -1, 0]", FINITE),
            ("[0, -1e39, 0]", "[0, -1e39, 0]", FINITE),
        ],
    );
    expect_syntax(&edit("direction = [-1.0, -2.0, 0.5]\n", ""), "missing field `direction`");
    // The old format's light had a position and a target.
    expect_syntax(&edit("direction = [-1.0, -2.0, 0.5]", "position = [1, 2, 0]"), "unknown field `position`");
}

#[test]
fn the_directional_light_irradiance_is_non_negative() {
    for (i, expected) in [
        ("[0, 0, 0]", Vec3::ZERO),
        ("[0, 1, 0]", Vec3::Y),
        (&format!("[{F32_MAX}, 0, 0]") as &str, Vec3::new(f32::MAX, 0.0, 0.0)),
    ] {
        let s = accepted("irradiance = [3.0, 3.0, 3.0]", &format!("irradiance = {i}"));
        assert_eq!(s.directional_light.unwrap().irradiance, expected, "{i}");
    }
    SCENE.expect_invalid_values(
        "irradiance = [3.0, 3.0, 3.0]",
        "directional_light.irradiance",
        &[
            ("[-1, 3, 3]", "[-1, 3, 3]", "every channel must be >= 0"),
            ("[3, 3, -inf]", "[3, 3, -inf]", FINITE),
            ("[3, nan, 3]", "[3, nan, 3]", FINITE),
            ("[1e39, 3, 3]", "[1e39, 3, 3]", FINITE),
        ],
    );
}

#[test]
fn the_angular_radius_is_in_0_to_90_degrees() {
    for (a, delta) in [("0", true), ("-0.0", true), ("1e-30", false), ("0.265", false), ("89.999", false)] {
        let s = accepted("angular_radius = 0.25", &format!("angular_radius = {a}"));
        let light = s.directional_light.unwrap();
        assert_eq!(light.is_delta(), delta, "angular_radius = {a}");
    }
    let allowed = "must be in [0, 90) degrees (the sun disc's half-angle; 0 is a delta light)";
    SCENE.expect_invalid_values(
        "angular_radius = 0.25",
        "directional_light.angular_radius",
        &[
            ("90", "90", allowed),
            ("90.0001", "90.0001", allowed),
            ("180", "180", allowed),
            ("-0.1", "-0.1", allowed),
            ("-1e-30", "-1e-30", allowed),
            ("nan", "nan", FINITE),
            ("inf", "inf", FINITE),
            ("-inf", "-inf", FINITE),
            ("1e39", "1e39", FINITE),
        ],
    );
    // 89.9999999 is below 90 in f64 but rounds to 90 in f32.
    expect_invalid(
        &edit("angular_radius = 0.25", "angular_radius = 89.9999999"),
        "directional_light.angular_radius",
        "89.9999999",
        allowed,
    );
}

// ---------------------------------------------------------------------------------------------
// The per-renderer sections.

/// The settings spelled as words (`[pathtrace] sequence`, `[raster] look`, `renderer`): each
/// takes its own words only, and its error lists them.
#[test]
fn word_settings_take_only_their_words() {
    let sequence =
        accepted("sequence = \"low-discrepancy\"", "sequence = \"independent\"").pathtrace.sequence;
    assert_eq!(sequence, Sequence::Independent);
    assert_eq!(accepted("look = \"enhanced\"", "look = \"figure\"").raster.look, Look::Figure);
    assert_eq!(accepted("renderer = \"pathtrace\"", "renderer = \"raster\"").renderer, RendererKind::Raster);
    assert_eq!(
        accepted("renderer = \"pathtrace\"", "renderer = \"whitted\"").renderer,
        RendererKind::Whitted
    );
    // (the line of BASE, its field, words it refuses, what it allows). "whitted" was the
    // enhanced look's old name; it now names the Whitted ray tracer only.
    let cases: [(&str, &str, &[&str], &str); 3] = [
        (
            "sequence = \"low-discrepancy\"",
            "pathtrace.sequence",
            &["sobol", "Independent", "low_discrepancy", ""],
            "must be \"independent\" or \"low-discrepancy\"",
        ),
        (
            "look = \"enhanced\"",
            "raster.look",
            &["whitted", "Figure", "photo"],
            "must be \"figure\" or \"enhanced\"",
        ),
        (
            "renderer = \"pathtrace\"",
            "renderer",
            &["Whitted", "Raster", "path tracer", ""],
            "must be \"raster\", \"pathtrace\" or \"whitted\"",
        ),
    ];
    for (line, field, bad, allowed) in cases {
        expect_bad_words(line, field, bad, allowed);
    }
    // A word setting given a number is a syntax error.
    expect_syntax(&edit("sequence = \"low-discrepancy\"", "sequence = 1"), "invalid type");
    expect_syntax(&edit("renderer = \"pathtrace\"", "renderer = 1"), "invalid type");
}

#[test]
fn raster_numbers_have_their_ranges() {
    for (from, to) in [
        ("pcf_radius = 0.1", "pcf_radius = 1e-30"),
        ("cube_size = 64", "cube_size = 1"),
        ("cube_size = 64", "cube_size = 4294967295"),
        ("glass_color = [0.9, 1.0, 0.9]", "glass_color = [0, 0, 0]"),
        ("glass_reflectivity = 0.5", "glass_reflectivity = 0"),
        ("glass_reflectivity = 0.5", "glass_reflectivity = 1"),
    ] {
        accepted(from, to);
    }
    SCENE.expect_invalid_edits(&[
        ("pcf_radius = 0.1", "pcf_radius = 0", "raster.pcf_radius", "0", "must be > 0"),
        ("pcf_radius = 0.1", "pcf_radius = nan", "raster.pcf_radius", "nan", FINITE),
        ("cube_size = 64", "cube_size = 0", "raster.cube_size", "0", "must be at least 1"),
        (
            "cube_size = 64",
            "cube_size = 4294967296",
            "raster.cube_size",
            "4294967296",
            "must be at most 4294967295",
        ),
        (
            "glass_color = [0.9, 1.0, 0.9]",
            "glass_color = [0.9, 1.5, 0.9]",
            "raster.glass_color",
            "[0.9, 1.5, 0.9]",
            "[0, 1]",
        ),
        (
            "glass_reflectivity = 0.5",
            "glass_reflectivity = 1.0001",
            "raster.glass_reflectivity",
            "1.0001",
            "must be in [0, 1]",
        ),
        (
            "glass_reflectivity = 0.5",
            "glass_reflectivity = -0.5",
            "raster.glass_reflectivity",
            "-0.5",
            "must be in [0, 1]",
        ),
    ]);
    expect_syntax(&edit("msaa = true", "msaa = 1"), "expected a boolean");
    expect_syntax(&edit("msaa = true", "msaa = true\nbloom = true"), "unknown field `bloom`");
}

#[test]
fn whitted_depth_and_aa_have_their_ranges() {
    for (from, to, expected) in [
        ("depth = 5", "depth = 0", WhittedSettings { depth: 0, aa: 3 }),
        ("depth = 5", "depth = 64", WhittedSettings { depth: 64, aa: 3 }),
        ("aa = 3", "aa = 1", WhittedSettings { depth: 5, aa: 1 }),
        ("aa = 3", "aa = 16", WhittedSettings { depth: 5, aa: 16 }),
    ] {
        assert_eq!(accepted(from, to).whitted, expected, "{to}");
    }
    SCENE.expect_invalid_edits(&[
        ("depth = 5", "depth = 65", "whitted.depth", "65", "must be an integer in 0..=64"),
        ("depth = 5", "depth = -1", "whitted.depth", "-1", "must be an integer in 0..=64"),
        ("depth = 5", "depth = 4294967296", "whitted.depth", "4294967296", "must be an integer in 0..=64"),
        ("aa = 3", "aa = 0", "whitted.aa", "0", "must be an integer in 1..=16"),
        ("aa = 3", "aa = 17", "whitted.aa", "17", "must be an integer in 1..=16"),
        ("aa = 3", "aa = -3", "whitted.aa", "-3", "must be an integer in 1..=16"),
    ]);
    expect_syntax(&edit("depth = 5", "depth = 2.5"), "an integer");
    expect_syntax(&edit("aa = 3", "aa = 3\nspp = 4"), "unknown field `spp`");
}

#[test]
fn shading_values_have_their_ranges() {
    for (from, to) in [
        ("ambient = [0.1, 0.1, 0.1]", "ambient = [0, 0, 0]"),
        ("ambient = [0.1, 0.1, 0.1]", "ambient = [2, 2, 2]"), // radiance, not a reflectance
        ("shininess = 100.0", "shininess = 1e-30"),
        ("shininess = 100.0", &format!("shininess = {F32_MAX}")),
        ("specular = [0.9, 0.9, 0.9]", "specular = [0, 1, 0]"),
        ("weight = 0.4", "weight = 0"),
        ("weight = 0.4", "weight = 1"),
    ] {
        accepted(from, to);
    }
    SCENE.expect_invalid_edits(&[
        (
            "ambient = [0.1, 0.1, 0.1]",
            "ambient = [0.1, -0.1, 0.1]",
            "shading.ambient",
            "[0.1, -0.1, 0.1]",
            ">= 0",
        ),
        (
            "ambient = [0.1, 0.1, 0.1]",
            "ambient = [0.1, 1e39, 0.1]",
            "shading.ambient",
            "[0.1, 1e39, 0.1]",
            FINITE,
        ),
        ("shininess = 100.0", "shininess = 0", "shading.dielectric.shininess", "0", "must be > 0"),
        ("shininess = 100.0", "shininess = inf", "shading.dielectric.shininess", "inf", FINITE),
        (
            "specular = [0.9, 0.9, 0.9]",
            "specular = [0.9, 1.1, 0.9]",
            "shading.mirror.specular",
            "[0.9, 1.1, 0.9]",
            "[0, 1]",
        ),
        ("shininess = 20.0", "shininess = -20", "shading.mirror.shininess", "-20", "must be > 0"),
        ("weight = 0.4", "weight = 1.5", "shading.mirror.weight", "1.5", "must be in [0, 1]"),
        ("weight = 0.4", "weight = nan", "shading.mirror.weight", "nan", FINITE),
    ]);
    expect_syntax(&edit("weight = 0.4 }", "weight = 0.4, roughness = 0.1 }"), "unknown field `roughness`");
    expect_syntax(&edit("[shading]", "[shadng]"), "unknown field `shadng`");
}

// ---------------------------------------------------------------------------------------------
// The clip planes.

#[test]
fn near_and_far_come_together_with_near_before_far() {
    SCENE.expect_invalid_edits(&[
        ("far = 100.0\n", "", "camera.far", "(missing)", "must be given with camera.near"),
        ("near = 0.1\n", "", "camera.near", "(missing)", "must be given with camera.far"),
    ]);
    for (near, far) in [("1e-30", "1e30"), ("0.1", "0.10001"), ("1", F32_MAX)] {
        let s = parse(&edit("near = 0.1\nfar = 100.0\n", &format!("near = {near}\nfar = {far}\n"))).unwrap();
        let clip = s.clip.unwrap();
        assert!(clip.near > 0.0 && clip.far > clip.near, "{near} {far}");
    }
    for (near, far, field, shown, allowed) in [
        ("0", "100", "camera.near", "0", "must be > 0"),
        ("-0.1", "100", "camera.near", "-0.1", "must be > 0"),
        ("nan", "100", "camera.near", "nan", FINITE),
        ("0.1", "0.1", "camera.far", "0.1", "must be greater than camera.near = 0.1"),
        ("10", "5", "camera.far", "5", "must be greater than camera.near = 10"),
        ("0.1", "-100", "camera.far", "-100", "must be greater than camera.near = 0.1"),
        // Different in f64, equal in f32.
        ("1", "1.00000001", "camera.far", "1.00000001", "must be greater than camera.near = 1"),
        ("0.1", "inf", "camera.far", "inf", FINITE),
        ("0.1", "1e39", "camera.far", "1e39", FINITE),
    ] {
        expect_invalid(
            &edit("near = 0.1\nfar = 100.0\n", &format!("near = {near}\nfar = {far}\n")),
            field,
            shown,
            allowed,
        );
    }
}

// ---------------------------------------------------------------------------------------------
// What a renderer must implement.

/// What a path tracer of Lambertian boxes, quads and spheres under area lights implements (the
/// list is the test's own: illum-scene does not depend on illum-pathtrace).
const DIFFUSE_ONLY: &[Feature] =
    &[Feature::BoxShape, Feature::QuadShape, Feature::SphereShape, Feature::Lambertian, Feature::AreaLight];

const EVERYTHING: &[Feature] = &Feature::ALL;

#[test]
fn features_list_what_the_scene_uses_where_in_file_order() {
    let s = parse(BASE).unwrap();
    let used: Vec<(Feature, String)> = s.features();
    let expected = [
        (Feature::QuadShape, "objects[0] (\"floor\")"),
        (Feature::Checker, "objects[0] (\"floor\"), material \"board\""),
        (Feature::BoxShape, "objects[1] (\"block\")"),
        (Feature::Lambertian, "objects[1] (\"block\"), material \"grey\""),
        (Feature::SphereShape, "objects[2] (\"ball\")"),
        (Feature::Dielectric, "objects[2] (\"ball\"), material \"glass\""),
        (Feature::SphereShape, "objects[3] (\"mirror ball\")"),
        (Feature::Mirror, "objects[3] (\"mirror ball\"), material \"metal\""),
        (Feature::QuadShape, "objects[4] (\"lamp\")"),
        (Feature::AreaLight, "objects[4] (\"lamp\"), material \"lamp\""),
        (Feature::SunDisc, "[directional_light]"),
        (Feature::Environment, "[environment]"),
    ];
    let expected: Vec<(Feature, String)> = expected.iter().map(|(f, p)| (*f, p.to_string())).collect();
    assert_eq!(used, expected);

    // A light of angular radius 0 is the delta light; no light, no light feature.
    let delta = accepted("angular_radius = 0.25", "angular_radius = 0");
    assert!(delta.features().contains(&(Feature::DeltaDirectionalLight, "[directional_light]".to_owned())));
    assert!(!delta.features().iter().any(|(f, _)| *f == Feature::SunDisc));
    let dark = accepted(
        "[directional_light]\ndirection = [-1.0, -2.0, 0.5]\nirradiance = [3.0, 3.0, 3.0]\nangular_radius = 0.25\n",
        "",
    );
    assert!(
        !dark.features().iter().any(|(f, _)| matches!(f, Feature::SunDisc | Feature::DeltaDirectionalLight))
    );

    // Every feature has its own description.
    let shown: Vec<String> = EVERYTHING.iter().map(Feature::to_string).collect();
    for (i, s) in shown.iter().enumerate() {
        assert!(!s.is_empty() && !shown[..i].contains(s), "{s:?}");
    }
}

#[test]
fn require_refuses_the_first_feature_a_renderer_lacks() {
    let s = parse(BASE).unwrap();
    s.require(RendererKind::PathTrace, EVERYTHING).unwrap();
    s.require(RendererKind::Raster, EVERYTHING).unwrap();

    let err = s.require(RendererKind::PathTrace, DIFFUSE_ONLY).unwrap_err();
    let SceneError::Unsupported { file, place, feature, renderer } = &err else { panic!("{err:?}") };
    assert_eq!(
        (file.as_str(), place.as_str(), feature.as_str(), renderer.as_str()),
        (FILE, "objects[0] (\"floor\"), material \"board\"", "a checkerboard material", "path tracer")
    );
    assert_eq!(
        err.to_string(),
        "scenes/phys.toml: objects[0] (\"floor\"), material \"board\": the path tracer cannot render a \
         checkerboard material"
    );

    // Each feature in turn: take it out of EVERYTHING and it is the one refused, at its place.
    for (missing, place) in [
        (Feature::BoxShape, "objects[1] (\"block\")"),
        (Feature::SphereShape, "objects[2] (\"ball\")"),
        (Feature::Dielectric, "objects[2] (\"ball\"), material \"glass\""),
        (Feature::Mirror, "objects[3] (\"mirror ball\"), material \"metal\""),
        (Feature::AreaLight, "objects[4] (\"lamp\"), material \"lamp\""),
        (Feature::SunDisc, "[directional_light]"),
        (Feature::Environment, "[environment]"),
    ] {
        let supported: Vec<Feature> = EVERYTHING.iter().copied().filter(|f| *f != missing).collect();
        let err = s.require(RendererKind::Raster, &supported).unwrap_err();
        let SceneError::Unsupported { place: p, feature, renderer, .. } = &err else { panic!("{err:?}") };
        assert_eq!(
            (p.as_str(), feature.as_str(), renderer.as_str()),
            (place, missing.to_string().as_str(), "rasterizer")
        );
        assert!(err.to_string().ends_with(&format!("the rasterizer cannot render {missing}")), "{err}");
    }
    // Supporting the delta light does not cover a sun disc, nor the other way round.
    let delta_only: Vec<Feature> = EVERYTHING.iter().copied().filter(|f| *f != Feature::SunDisc).collect();
    let delta = accepted("angular_radius = 0.25", "angular_radius = 0");
    delta.require(RendererKind::Raster, &delta_only).unwrap();
    let sun_only: Vec<Feature> =
        EVERYTHING.iter().copied().filter(|f| *f != Feature::DeltaDirectionalLight).collect();
    let err = delta.require(RendererKind::Raster, &sun_only).unwrap_err();
    assert!(
        err.to_string().contains("[directional_light]: the rasterizer cannot render a directional light"),
        "{err}"
    );
    // Nothing supported: the first object's shape.
    let err = s.require(RendererKind::PathTrace, &[]).unwrap_err();
    assert_eq!(
        err.to_string(),
        "scenes/phys.toml: objects[0] (\"floor\"): the path tracer cannot render a quad"
    );
}

#[test]
fn a_cornell_style_scene_passes_a_diffuse_path_tracer() {
    // The scene without the checker, the glass, the mirror, the sun and the sky.
    let mut text = BASE.to_owned();
    for (from, to) in [
        ("material = \"board\"", "material = \"grey\""),
        ("material = \"glass\"", "material = \"grey\""),
        ("material = \"metal\"", "material = \"grey\""),
        ("[environment]\nradiance = [0.3, 0.5, 0.9]\n", ""),
        (
            "[directional_light]\ndirection = [-1.0, -2.0, 0.5]\nirradiance = [3.0, 3.0, 3.0]\nangular_radius = 0.25\n",
            "",
        ),
    ] {
        text = edit_text(&text, from, to);
    }
    let s = parse(&text).unwrap();
    s.require(RendererKind::PathTrace, DIFFUSE_ONLY).unwrap();
    // Unused materials do not count: only what an object uses is a feature.
    assert!(s.materials.iter().any(|m| matches!(m.kind, MaterialKind::Dielectric { .. })));
    assert!(!s.features().iter().any(|(f, _)| *f == Feature::Dielectric));
}
