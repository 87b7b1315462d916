//! Every validation rule, triggered by an edited copy of a small valid scene, with the message
//! checked for file, field, value and what is allowed; plus syntax errors (line, column, key),
//! command-line overrides. (Device limits are checked by the GPU crates, with their tests.)
//!
//! Long (one test per rule) but one concept: every error of the file format and its overrides.

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

const FINITE: &str = "finite";

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
// Non-finite numbers, everywhere a number can appear.

#[test]
fn non_finite_numbers_are_rejected_in_every_field() {
    // (text to replace, replacement, field, value shown)
    let cases = [
        ("eye = [0.0, 1.0, -5.0]", "eye = [nan, 1.0, -5.0]", "camera.eye", "[nan, 1, -5]"),
        ("target = [0.0, 1.0, 0.0]", "target = [0.0, inf, 0.0]", "camera.target", "[0, inf, 0]"),
        ("up = [0.0, 1.0, 0.0]", "up = [0.0, 1.0, -inf]", "camera.up", "[0, 1, -inf]"),
        ("vfov = 45.0", "vfov = nan", "camera.vfov", "nan"),
        ("albedo = [0.5, 0.5, 0.5]", "albedo = [0.5, nan, 0.5]", "materials.grey.albedo", "[0.5, nan, 0.5]"),
        (
            "emission = [5.0, 5.0, 5.0]",
            "emission = [inf, 5.0, 5.0]",
            "materials.lamp.emission",
            "[inf, 5, 5]",
        ),
        (
            "center = [0.0, 0.0, 0.0]",
            "center = [0.0, nan, 0.0]",
            "objects[0] (\"block\").box.center",
            "[0, nan, 0]",
        ),
        (
            "half_extent = [1.0, 1.0, 1.0]",
            "half_extent = [1.0, 1.0, inf]",
            "objects[0] (\"block\").box.half_extent",
            "[1, 1, inf]",
        ),
        (
            "min = [-2.0, -1.0, -2.0]",
            "min = [-inf, -1.0, -2.0]",
            "objects[1] (\"slab\").box.min",
            "[-inf, -1, -2]",
        ),
        ("max = [2.0, -0.5, 2.0]", "max = [2.0, nan, 2.0]", "objects[1] (\"slab\").box.max", "[2, nan, 2]"),
        ("rotate_y = 30.0", "rotate_y = nan", "objects[1] (\"slab\").box.rotate_y", "nan"),
        (
            "pivot = [1.0, 0.0, 1.0]",
            "pivot = [1.0, 0.0, inf]",
            "objects[1] (\"slab\").box.pivot",
            "[1, 0, inf]",
        ),
        (
            "translate = [0.0, 0.0, 3.0]",
            "translate = [nan, 0.0, 3.0]",
            "objects[1] (\"slab\").box.translate",
            "[nan, 0, 3]",
        ),
        (
            "corner = [-0.5, 3.0, -0.5]",
            "corner = [-0.5, inf, -0.5]",
            "objects[2] (\"lamp\").quad.corner",
            "[-0.5, inf, -0.5]",
        ),
        (
            "edge_u = [1.0, 0.0, 0.0]",
            "edge_u = [nan, 0.0, 0.0]",
            "objects[2] (\"lamp\").quad.edge_u",
            "[nan, 0, 0]",
        ),
        (
            "edge_v = [0.0, 0.0, 1.0]",
            "edge_v = [0.0, 0.0, inf]",
            "objects[2] (\"lamp\").quad.edge_v",
            "[0, 0, inf]",
        ),
        ("center = [2.0, 1.0, 0.0]", "center = [2.0, nan, 0.0]", "objects[3].sphere.center", "[2, nan, 0]"),
        ("radius = 0.5", "radius = inf", "objects[3].sphere.radius", "inf"),
        // Finite in f64 but infinite once converted to the renderer's f32.
        ("radius = 0.5", "radius = 1e39", "objects[3].sphere.radius", "1e39"),
    ];
    for (from, to, field, value) in cases {
        expect_invalid(&edit(from, to), field, value, FINITE);
    }
}

// ---------------------------------------------------------------------------------------------
// Geometry.

#[test]
fn box_half_extent_must_be_positive() {
    let allowed = "every component must be > 0";
    SCENE.expect_invalid_values(
        "half_extent = [1.0, 1.0, 1.0]",
        "objects[0] (\"block\").box.half_extent",
        &[("[1.0, 0.0, 1.0]", "[1, 0, 1]", allowed), ("[-1.0, 1.0, 1.0]", "[-1, 1, 1]", allowed)],
    );
}

#[test]
fn box_max_must_exceed_min() {
    SCENE.expect_invalid_edits(&[
        // y equal to min: a flat box.
        (
            "max = [2.0, -0.5, 2.0]",
            "max = [2.0, -1.0, 2.0]",
            "objects[1] (\"slab\").box.max",
            "[2, -1, 2]",
            "must be greater than objects[1] (\"slab\").box.min = [-2, -1, -2] on every axis",
        ),
        // x below min.
        (
            "max = [2.0, -0.5, 2.0]",
            "max = [-3.0, -0.5, 2.0]",
            "objects[1] (\"slab\").box.max",
            "[-3, -0.5, 2]",
            "on every axis",
        ),
    ]);
}

#[test]
fn box_needs_one_corner_form() {
    let allowed = "give either center + half_extent or min + max (not both, not a mix)";
    let field = "objects[0] (\"block\").box";
    let block = "box = { center = [0.0, 0.0, 0.0], half_extent = [1.0, 1.0, 1.0] }";
    let cases = [
        ("box = { center = [0.0, 0.0, 0.0], max = [1.0, 1.0, 1.0] }", "{ center, max }"),
        (
            "box = { center = [0.0, 0.0, 0.0], half_extent = [1.0, 1.0, 1.0], min = [0.0, 0.0, 0.0], max = [1.0, 1.0, 1.0] }",
            "{ center, half_extent, min, max }",
        ),
        ("box = { half_extent = [1.0, 1.0, 1.0] }", "{ half_extent }"),
        ("box = { rotate_y = 10.0 }", "{  }"),
    ];
    for (to, shown) in cases {
        expect_invalid(&edit(block, to), field, shown, allowed);
    }
}

#[test]
fn sphere_radius_must_be_positive() {
    let allowed = "must be > 0";
    SCENE.expect_invalid_values(
        "radius = 0.5",
        "objects[3].sphere.radius",
        &[("0.0", "0", allowed), ("-2.5", "-2.5", allowed)],
    );
}

#[test]
fn quad_must_have_area() {
    let field = "objects[2] (\"lamp\").quad";
    let allowed = "edge_u and edge_v must be non-zero and not parallel";
    let cases = [
        // parallel edges
        (
            "edge_v = [0.0, 0.0, 1.0]",
            "edge_v = [-2.0, 0.0, 0.0]",
            "{ edge_u = [1, 0, 0], edge_v = [-2, 0, 0] }",
        ),
        // zero edge
        (
            "edge_v = [0.0, 0.0, 1.0]",
            "edge_v = [0.0, 0.0, 0.0]",
            "{ edge_u = [1, 0, 0], edge_v = [0, 0, 0] }",
        ),
        (
            "edge_u = [1.0, 0.0, 0.0]",
            "edge_u = [0.0, 0.0, 0.0]",
            "{ edge_u = [0, 0, 0], edge_v = [0, 0, 1] }",
        ),
        // sin(angle) = 1e-13 < 1e-12: degenerate relative to the edge lengths
        (
            "edge_v = [0.0, 0.0, 1.0]",
            "edge_v = [1000.0, 0.0, 1e-10]",
            "{ edge_u = [1, 0, 0], edge_v = [1000, 0, 1e-10] }",
        ),
    ];
    for (from, to, shown) in cases {
        let text = edit(from, to);
        expect_invalid(&text, field, shown, allowed);
        assert!(parse(&text).unwrap_err().to_string().contains("area"));
    }
}

// ---------------------------------------------------------------------------------------------
// Camera.

#[test]
fn camera_eye_must_differ_from_target() {
    expect_invalid(
        &edit("target = [0.0, 1.0, 0.0]", "target = [0.0, 1.0, -5.0]"),
        "camera.target",
        "[0, 1, -5]",
        "must differ from camera.eye = [0, 1, -5]",
    );
}

#[test]
fn camera_up_must_be_nonzero_and_not_parallel_to_the_view() {
    let allowed = "must be non-zero and not parallel to the view direction target - eye = [0, 0, 5]";
    let cases = [
        ("up = [0.0, 0.0, 0.0]", "[0, 0, 0]"),
        ("up = [0.0, 0.0, 1.0]", "[0, 0, 1]"),
        ("up = [0.0, 0.0, -3.0]", "[0, 0, -3]"),
        // |normalize(f) x normalize(up)| = 1e-7 < 1e-6
        ("up = [1e-7, 0.0, 1.0]", "[1e-7, 0, 1]"),
    ];
    for (to, shown) in cases {
        expect_invalid(&edit("up = [0.0, 1.0, 0.0]", to), "camera.up", shown, allowed);
    }
    // Tilted a little more than the threshold (1e-5) is accepted.
    parse(&edit("up = [0.0, 1.0, 0.0]", "up = [1e-5, 0.0, 1.0]")).unwrap();
}

#[test]
fn camera_vfov_must_be_in_the_open_interval() {
    let allowed = "must be in the open interval (0, 180) degrees";
    SCENE.expect_invalid_values(
        "vfov = 45.0",
        "camera.vfov",
        &[
            ("0.0", "0", allowed),
            ("180.0", "180", allowed),
            ("-10.0", "-10", allowed),
            ("200", "200", allowed),
        ],
    );
}

#[test]
fn camera_resolution_must_be_positive() {
    SCENE.expect_invalid_edits(&[
        ("width = 64", "width = 0", "camera.width", "0", "must be at least 1"),
        ("height = 32", "height = 0", "camera.height", "0", "must be at least 1"),
        ("width = 64", "width = -640", "camera.width", "-640", "must be at least 1"),
        ("height = 32", "height = 4294967296", "camera.height", "4294967296", "must be at most 4294967295"),
    ]);
}

// ---------------------------------------------------------------------------------------------
// Render settings.

#[test]
fn spp_must_be_at_least_one() {
    expect_invalid(&edit("spp = 4", "spp = 0"), "pathtrace.spp", "0", "must be at least 1");
    // The exact message of the design document's example.
    let err = parse(&edit("spp = 4", "spp = 0")).unwrap_err();
    assert_eq!(err.to_string(), "scenes/test.toml: pathtrace.spp = 0: must be at least 1");
}

#[test]
fn seed_must_fit_u32() {
    expect_invalid(&edit("seed = 7", "seed = -1"), "pathtrace.seed", "-1", "must be at least 0");
}

#[test]
fn bounces_must_be_in_range_or_unbounded() {
    let allowed = "must be an integer in 0..=256 or \"unbounded\"";
    let cases = [
        ("bounces = 257", "257"),
        ("bounces = -1", "-1"),
        ("bounces = \"forever\"", "\"forever\""),
        ("bounces = \"Unbounded\"", "\"Unbounded\""),
        ("bounces = \"5\"", "\"5\""),
        ("bounces = 2.5", "2.5"),
        ("bounces = true", "true"),
    ];
    for (to, shown) in cases {
        expect_invalid(&edit("bounces = 3", to), "pathtrace.bounces", shown, allowed);
    }
}

#[test]
fn sampling_must_be_cosine_or_uniform() {
    expect_invalid(
        &edit("sampling = \"uniform\"", "sampling = \"importance\""),
        "pathtrace.sampling",
        "\"importance\"",
        "must be \"cosine\" or \"uniform\"",
    );
}

// ---------------------------------------------------------------------------------------------
// Materials.

#[test]
fn albedo_channels_must_be_in_unit_range() {
    let allowed = "every channel must be in [0, 1]";
    SCENE.expect_invalid_values(
        "albedo = [0.5, 0.5, 0.5]",
        "materials.grey.albedo",
        &[("[0.5, 1.2, 0.5]", "[0.5, 1.2, 0.5]", allowed), ("[-0.1, 0.5, 0.5]", "[-0.1, 0.5, 0.5]", allowed)],
    );
    // The bounds themselves are allowed.
    parse(&edit("albedo = [0.5, 0.5, 0.5]", "albedo = [0.0, 1.0, 1.0]")).unwrap();
}

#[test]
fn emission_channels_must_be_non_negative() {
    expect_invalid(
        &edit("emission = [5.0, 5.0, 5.0]", "emission = [5.0, -1.0, 5.0]"),
        "materials.lamp.emission",
        "[5, -1, 5]",
        "every channel must be >= 0",
    );
}

#[test]
fn material_names_with_spaces_are_quoted_in_field_paths() {
    let text = edit(
        "[materials.grey]\nalbedo = [0.5, 0.5, 0.5]",
        "[materials.\"dark grey\"]\nalbedo = [2.0, 0.5, 0.5]",
    );
    expect_invalid(&text, "materials.\"dark grey\".albedo", "[2, 0.5, 0.5]", "[0, 1]");
}

// ---------------------------------------------------------------------------------------------
// Objects.

#[test]
fn unknown_material_lists_the_known_ones() {
    expect_invalid(
        &edit("material = \"grey\"\nsphere", "material = \"blue\"\nsphere"),
        "objects[3].material",
        "\"blue\"",
        "must name a material defined under [materials]; known: grey, lamp",
    );
}

#[test]
fn unknown_material_with_no_materials_defined() {
    let text = edit(
        "[materials.grey]\nalbedo = [0.5, 0.5, 0.5]\n\n[materials.lamp]\nemission = [5.0, 5.0, 5.0]\n",
        "",
    );
    expect_invalid(
        &text,
        "objects[0] (\"block\").material",
        "\"grey\"",
        "none are defined; add a [materials.NAME] table",
    );
}

#[test]
fn emission_only_on_quads() {
    let allowed = "emission is supported on quad objects only";
    expect_invalid(
        &edit("name = \"block\"\nmaterial = \"grey\"", "name = \"block\"\nmaterial = \"lamp\""),
        "objects[0] (\"block\").material",
        "\"lamp\"",
        allowed,
    );
    let err = parse(&edit("material = \"grey\"\nsphere", "material = \"lamp\"\nsphere")).unwrap_err();
    check_invalid(&err, FILE, "objects[3].material", "\"lamp\"", allowed);
    assert!(err.to_string().contains("sphere"), "{err}");
}

#[test]
fn each_object_needs_exactly_one_shape() {
    let allowed = "each object needs exactly one of box, quad, sphere";
    let text = edit(
        "sphere = { center = [2.0, 1.0, 0.0], radius = 0.5 }",
        "sphere = { center = [2.0, 1.0, 0.0], radius = 0.5 }\nquad = { corner = [0.0, 0.0, 0.0], edge_u = [1.0, 0.0, 0.0], edge_v = [0.0, 1.0, 0.0] }",
    );
    expect_invalid(&text, "objects[3]", "(both quad and sphere)", allowed);
    let text = edit("sphere = { center = [2.0, 1.0, 0.0], radius = 0.5 }\n", "");
    expect_invalid(&text, "objects[3]", "(no shape)", allowed);
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
