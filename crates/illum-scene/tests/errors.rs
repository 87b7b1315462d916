//! Every validation rule, triggered by an edited copy of a small valid scene, with the message
//! checked for file, field, value and what is allowed; plus syntax errors (line, column, key),
//! command-line overrides. (Device limits are checked by the GPU crates, with their tests.) The
//! refusals of edits of the scene are data, `cases/errors.toml`, checked by one test; the tests
//! here check what a refusal cannot say: what is accepted next to them, exact messages, syntax
//! positions and overrides.

use glam::Vec3;
use illum_scene::testing::{Edits, check_invalid, edit_once as edit_text};
use illum_scene::{Bounces, MAX_BOUNCES, MaterialKind, Overrides, Sampling, Scene, SceneError, Shape};

const FILE: &str = "scenes/test.toml";

/// A valid scene using every construct of the format once.
const BASE: &str = include_str!("scenes/test.toml");

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

fn expect_invalid(text: &str, field: &str, value: &str, allowed: &str) {
    SCENE.expect_invalid(text, field, value, allowed);
}

/// Asserts a syntax error at 1-based (line, column) whose message contains `needle`.
fn expect_syntax(text: &str, line: usize, column: usize, needle: &str) {
    let err = parse(text).expect_err("expected a syntax error");
    let SceneError::Syntax { file, line: l, column: c, message } = &err else {
        panic!("expected Syntax, got {err:?}");
    };
    assert_eq!(file, FILE);
    assert_eq!((*l, *c), (line, column), "{err}");
    assert!(message.contains(needle), "{message:?} lacks {needle:?}");
    let shown = err.to_string();
    assert!(shown.starts_with(&format!("{FILE}:{line}:{column}: ")), "{shown}");
}

/// 1-based (line, column) of the first occurrence of `needle` in `text`, found by the test
/// itself (columns in characters; the test texts are ASCII).
fn position_of(text: &str, needle: &str) -> (usize, usize) {
    for (i, line) in text.lines().enumerate() {
        if let Some(col) = line.find(needle) {
            return (i + 1, col + 1);
        }
    }
    panic!("{needle:?} not in text");
}

// ---------------------------------------------------------------------------------------------
// The base scene itself.

#[test]
fn base_scene_loads_with_the_written_values() {
    let s = parse(BASE).unwrap();
    assert_eq!(s.name, "test");
    assert_eq!(s.camera.eye, Vec3::new(0.0, 1.0, -5.0));
    assert_eq!((s.camera.width, s.camera.height), (64, 32));
    assert_eq!(s.pathtrace.spp, 4);
    assert_eq!(s.pathtrace.bounces, Bounces::Fixed(3));
    assert_eq!(s.pathtrace.seed, 7);
    assert_eq!(s.pathtrace.sampling, Sampling::Uniform);

    let names: Vec<&str> = s.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["grey", "lamp"]);
    assert_eq!(s.materials[1].kind, MaterialKind::Emitter { radiance: Vec3::splat(5.0) });
    assert_eq!(s.materials[1].diffuse_albedo(), Some(Vec3::ZERO), "an emitter reflects nothing");
    assert_eq!(s.materials[0].emission(), Vec3::ZERO, "a Lambertian material emits nothing");

    let obj_names: Vec<&str> = s.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(obj_names, ["block", "slab", "lamp", "objects[3]"]);
    let materials: Vec<usize> = s.objects.iter().map(|o| o.material).collect();
    assert_eq!(materials, [0, 0, 1, 0]);

    let Shape::Box(block) = s.objects[0].shape else { panic!() };
    assert_eq!((block.min, block.max), (Vec3::splat(-1.0), Vec3::splat(1.0)));
    assert_eq!(block.rotate_y_deg, 0.0);
    assert_eq!(block.pivot, Vec3::ZERO);
    assert_eq!(block.translate, Vec3::ZERO);

    // world = R (local - pivot) + pivot + translate, with R the right-handed rotation about +Y:
    // x' = x cos + z sin, z' = -x sin + z cos.
    let Shape::Box(slab) = s.objects[1].shape else { panic!() };
    let (r, t) = slab.local_to_world();
    let local = Vec3::new(2.0, -1.0, -2.0);
    let (sin, cos) = 30f32.to_radians().sin_cos();
    let d = local - Vec3::new(1.0, 0.0, 1.0);
    let expected = Vec3::new(d.x * cos + d.z * sin, d.y, -d.x * sin + d.z * cos)
        + Vec3::new(1.0, 0.0, 1.0)
        + Vec3::new(0.0, 0.0, 3.0);
    assert!((r * local + t - expected).length() < 1e-5);

    let Shape::Sphere(ball) = s.objects[3].shape else { panic!() };
    assert_eq!((ball.center, ball.radius), (Vec3::new(2.0, 1.0, 0.0), 0.5));

    let emitters: Vec<_> = s.emitters().map(|(i, o, q)| (i, o.name.clone(), *q)).collect();
    assert_eq!(emitters.len(), 1);
    assert_eq!((emitters[0].0, emitters[0].1.as_str()), (2, "lamp"));
    assert_eq!(emitters[0].2.area(), 1.0);
    assert_eq!(emitters[0].2.normal(), Vec3::NEG_Y);
}

#[test]
fn optional_parts_take_their_defaults() {
    let text = edit("spp = 4\nbounces = 3\nseed = 7\nsampling = \"uniform\"\n", "");
    let text = edit_text(&text, "[pathtrace]\n", "");
    let text = edit_text(&text, "name = \"test\"\n", "");
    let s = parse(&text).unwrap();
    assert_eq!(s.name, "test", "file stem of scenes/test.toml");
    assert_eq!(s.pathtrace.spp, 16);
    assert_eq!(s.pathtrace.bounces, Bounces::Fixed(2));
    assert_eq!(s.pathtrace.seed, 0);
    assert_eq!(s.pathtrace.sampling, Sampling::Cosine);
    // Integers are accepted where numbers are expected.
    let s = parse(&edit("radius = 0.5", "radius = 2")).unwrap();
    let Shape::Sphere(ball) = s.objects[3].shape else { panic!() };
    assert_eq!(ball.radius, 2.0);
    // "unbounded" and the top of the range are accepted.
    let s = parse(&edit("bounces = 3", "bounces = \"unbounded\"")).unwrap();
    assert_eq!(s.pathtrace.bounces, Bounces::Unbounded);
    let s = parse(&edit("bounces = 3", &format!("bounces = {MAX_BOUNCES}"))).unwrap();
    assert_eq!(s.pathtrace.bounces, Bounces::Fixed(MAX_BOUNCES));
    // Nearly parallel but not degenerate quad edges (sin = 1e-6) are fine.
    parse(&edit("edge_v = [0.0, 0.0, 1.0]", "edge_v = [1.0, 0.0, 1e-6]")).unwrap();
    // Extreme but valid field of view.
    parse(&edit("vfov = 45.0", "vfov = 179.9")).unwrap();
    parse(&edit("vfov = 45.0", "vfov = 0.001")).unwrap();
}

// ---------------------------------------------------------------------------------------------
// The refusals (among them a non-finite number in every place a number can stand).

#[test]
fn every_refusal_of_the_cases_file() {
    SCENE.expect_refusals(include_str!("cases/errors.toml"), "tests/cases/errors.toml");
}

// ---------------------------------------------------------------------------------------------
// Next to the refusals: what is accepted at their edges, exact messages, and an edit that is not
// one replacement.

#[test]
fn camera_up_tilted_just_past_the_threshold_is_accepted() {
    // Tilted a little more than the threshold (1e-5) is accepted (1e-7 is refused).
    parse(&edit("up = [0.0, 1.0, 0.0]", "up = [1e-5, 0.0, 1.0]")).unwrap();
}

/// A light 1.3e10 x 1.05e10 (the Cornell box's scaled by 1e8) has an area f32 holds, though
/// the square of its cross product's length does not.
#[test]
fn a_huge_light_whose_area_f32_holds_is_accepted() {
    let scene = parse(&edit(
        "edge_u = [1.0, 0.0, 0.0], edge_v = [0.0, 0.0, 1.0]",
        "edge_u = [1.3e10, 0.0, 0.0], edge_v = [0.0, 0.0, 1.05e10]",
    ))
    .unwrap();
    let Shape::Quad(quad) = scene.objects[2].shape else { panic!("the lamp is a quad") };
    assert!((quad.area() / 1.365e20 - 1.0).abs() < 1e-6, "{}", quad.area());
    assert_eq!(quad.normal(), Vec3::new(0.0, -1.0, 0.0));
}

#[test]
fn spp_zero_gives_the_design_documents_message() {
    let err = parse(&edit("spp = 4", "spp = 0")).unwrap_err();
    assert_eq!(err.to_string(), "scenes/test.toml: pathtrace.spp = 0: must be at least 1");
}

#[test]
fn albedo_channels_take_the_bounds_of_the_unit_range() {
    parse(&edit("albedo = [0.5, 0.5, 0.5]", "albedo = [0.0, 1.0, 1.0]")).unwrap();
}

#[test]
fn a_scene_needs_objects() {
    let start = BASE.find("[[objects]]").unwrap();
    expect_invalid(&BASE[..start], "objects", "[]", "at least one object");
}

// ---------------------------------------------------------------------------------------------
// Syntax and shape errors.

/// Asserts that `BASE` with `from` replaced by `to` is a syntax error at the first occurrence of
/// `at` in the edited text, whose message contains `needle`; returns the edited text.
fn expect_syntax_at(from: &str, to: &str, at: &str, needle: &str) -> String {
    let text = edit(from, to);
    let (line, column) = position_of(&text, at);
    expect_syntax(&text, line, column, needle);
    text
}

#[test]
fn unknown_keys_are_named_at_their_position() {
    // (from, to, where the error points, message)
    for (from, to, at, needle) in [
        ("vfov = 45.0", "fov = 45.0", "fov = 45.0", "unknown field `fov`"),
        ("rotate_y = 30.0", "rotate_z = 30.0", "rotate_z", "unknown field `rotate_z`"),
        ("[pathtrace]", "[render]", "render]", "unknown field `render`"),
        (
            "albedo = [0.5, 0.5, 0.5]",
            "albedo = [0.5, 0.5, 0.5]\nroughness = 0.2",
            "roughness",
            "unknown field `roughness`",
        ),
    ] {
        expect_syntax_at(from, to, at, needle);
    }
}

#[test]
fn malformed_toml_reports_line_and_column() {
    // An unterminated array. TOML arrays may span lines, so the parser only notices at the next
    // line, where `vfov` is neither a value nor a comma nor the closing bracket.
    expect_syntax_at("up = [0.0, 1.0, 0.0]", "up = [0.0, 1.0, 0.0", "vfov = 45.0", "missing comma");
    // A bare word as a value.
    expect_syntax_at("seed = 7", "seed = seven", "seven", "must be quoted");

    // A key without a value: reported just after the `=`, at the end of the line.
    let text = edit("seed = 7", "seed =");
    let (line, column) = position_of(&text, "seed =");
    expect_syntax(&text, line, column + "seed =".len(), "");
}

#[test]
fn wrong_types_point_at_the_value_and_quote_the_line() {
    let text = expect_syntax_at("spp = 4", "spp = \"16\"", "\"16\"", "expected an integer");
    assert!(parse(&text).unwrap_err().to_string().contains("spp = \"16\""));
    expect_syntax_at("spp = 4", "spp = 1.5", "1.5", "expected an integer");
    expect_syntax_at("eye = [0.0, 1.0, -5.0]", "eye = [0.0, 1.0]", "[0.0, 1.0]", "array of three numbers");
}

#[test]
fn missing_keys_are_named() {
    let text = edit("material = \"grey\"\nsphere", "sphere");
    let err = parse(&text).unwrap_err();
    assert!(matches!(err, SceneError::Syntax { .. }), "{err:?}");
    assert!(err.to_string().contains("missing field `material`"), "{err}");

    let text = edit("vfov = 45.0\n", "");
    let err = parse(&text).unwrap_err();
    assert!(err.to_string().contains("missing field `vfov`"), "{err}");
}

// ---------------------------------------------------------------------------------------------
// Overrides.

#[test]
fn overrides_replace_file_values() {
    let mut s = parse(BASE).unwrap();
    let before = s.clone();
    s.apply_overrides(&Overrides::default(), "command line").unwrap();
    assert_eq!(s, before, "no overrides, no change");

    let o = Overrides {
        spp: Some(64),
        bounces: Some(Bounces::Unbounded),
        seed: Some(99),
        sampling: Some(Sampling::Cosine),
        sequence: Some(illum_scene::Sequence::LowDiscrepancy),
        width: Some(800),
        height: Some(600),
    };
    s.apply_overrides(&o, "command line").unwrap();
    assert_eq!(s.pathtrace.sequence, illum_scene::Sequence::LowDiscrepancy);
    assert_eq!(s.pathtrace.spp, 64);
    assert_eq!(s.pathtrace.bounces, Bounces::Unbounded);
    assert_eq!(s.pathtrace.seed, 99);
    assert_eq!(s.pathtrace.sampling, Sampling::Cosine);
    assert_eq!((s.camera.width, s.camera.height), (800, 600));
    assert_eq!(s.objects, before.objects);
}

#[test]
fn overrides_are_validated_and_leave_the_scene_unchanged_on_error() {
    let base = parse(BASE).unwrap();
    let cases = [
        (Overrides { spp: Some(0), ..Default::default() }, "--spp", "0", "must be at least 1"),
        (Overrides { width: Some(0), ..Default::default() }, "--width", "0", "must be at least 1"),
        (Overrides { height: Some(0), ..Default::default() }, "--height", "0", "must be at least 1"),
        (
            Overrides { bounces: Some(Bounces::Fixed(MAX_BOUNCES + 1)), ..Default::default() },
            "--bounces",
            "257",
            "must be an integer in 0..=256 or \"unbounded\"",
        ),
    ];
    for (o, field, value, allowed) in cases {
        // A valid override next to the bad one must not be applied either.
        let o = Overrides { seed: Some(12345), ..o };
        let mut s = base.clone();
        let err = s.apply_overrides(&o, "command line").unwrap_err();
        check_invalid(&err, "command line", field, value, allowed);
        assert_eq!(s, base, "{field}: scene changed despite the error");
    }
}

#[test]
fn caustics_is_a_boolean_off_by_default() {
    assert!(!parse(BASE).unwrap().pathtrace.caustics, "off unless the file turns it on");
    let s = parse(&edit("seed = 7\n", "seed = 7\ncaustics = true\n")).unwrap();
    assert!(s.pathtrace.caustics);
    // A string is a type error at the value, naming what was expected.
    let text = edit("seed = 7\n", "seed = 7\ncaustics = \"yes\"\n");
    let (line, column) = position_of(&text, "\"yes\"");
    expect_syntax(&text, line, column, "expected a boolean");
}
