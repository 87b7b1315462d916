//! The rules of the physical scene model: material kinds, the environment and directional
//! light, the per-renderer sections (`[pathtrace]`, `[raster]`, `[whitted]`, `[shading]`), the
//! `renderer` key, the clip planes, and `Scene::require` refusing what a renderer lacks. Each
//! rule is triggered by an edited copy of a small valid scene, with the message checked for
//! file, field, value and what is allowed; the extremes each side of every range are tried.
//! The refusals are data, `cases/physical_rules.toml`, checked by one test; the tests here check
//! what a refusal cannot say: the values accepted up to the extremes, and what they load as.
//! (`errors.rs` has the camera, shape and path-tracer rules.)

use glam::Vec3;
use illum_scene::testing::{Edits, edit_once as edit_text, without};
use illum_scene::{
    Checker, DielectricShading, Effects, Feature, Look, MaterialKind, MirrorShading, RasterSettings,
    RendererKind, Scene, SceneError, Sequence, Shading, WhittedSettings,
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
// The refusals.

#[test]
fn every_refusal_of_the_cases_file() {
    SCENE.expect_refusals(include_str!("cases/physical_rules.toml"), "tests/cases/physical_rules.toml");
}

// ---------------------------------------------------------------------------------------------
// Materials.

#[test]
fn a_checker_tile_larger_than_its_quad_is_one_tile() {
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
    // The same checker on a smaller quad is fine: the count is per quad (2^-14 is refused on the
    // floor, 163840 tiles along its edge of 10).
    let small = "edge_u = [0.0, 0.0, 1.0], edge_v = [1.0, 0.0, 0.0]";
    let text = edit_text(
        &edit("tile = 0.5", "tile = 0.00006103515625"),
        "edge_u = [0.0, 0.0, 10.0], edge_v = [10.0, 0.0, 0.0]",
        small,
    );
    parse(&text).unwrap();
}

#[test]
fn a_dielectric_takes_any_positive_finite_ior() {
    for (ior, value) in
        [("1", 1.0), ("1.0001", 1.0001), ("4", 4.0), ("0.5", 0.5), ("1e-30", 1e-30), (F32_MAX, f32::MAX)]
    {
        let s = accepted("ior = 1.5", &format!("ior = {ior}"));
        assert_eq!(s.materials[1].kind, MaterialKind::Dielectric { ior: value }, "ior = {ior}");
    }
}

#[test]
fn a_mirror_takes_any_reflectance_from_nothing_to_everything() {
    for (r, reflectance) in
        [("[0, 0, 0]", Vec3::ZERO), ("[1, 1, 1]", Vec3::ONE), ("[1.0, 0.0, 0.5]", Vec3::new(1.0, 0.0, 0.5))]
    {
        let s = accepted("reflectance = [0.9, 0.8, 0.7]", &format!("reflectance = {r}"));
        assert_eq!(s.materials[4].kind, MaterialKind::Mirror { reflectance }, "reflectance = {r}");
    }
}

#[test]
fn an_emitter_takes_any_non_negative_emission_but_black() {
    for (e, radiance) in [
        ("[0, 0, 1e-30]", Vec3::new(0.0, 0.0, 1e-30)),
        ("[1, 0, 0]", Vec3::X),
        ("[1e6, 1e6, 1e6]", Vec3::splat(1e6)),
        (&format!("[{F32_MAX}, 0, 0]") as &str, Vec3::new(f32::MAX, 0.0, 0.0)),
    ] {
        let s = accepted("emission = [5.0, 5.0, 5.0]", &format!("emission = {e}"));
        assert!(s.materials[3].is_emitter(), "emission = {e}");
        assert_eq!(s.materials[3].kind, MaterialKind::Emitter { radiance }, "emission = {e}");
    }
}

// ---------------------------------------------------------------------------------------------
// Lights.

#[test]
fn the_environment_takes_any_non_negative_radiance() {
    for (r, radiance) in [
        ("[0, 0, 0]", Vec3::ZERO),
        ("[100, 0, 0.5]", Vec3::new(100.0, 0.0, 0.5)),
        (&format!("[{F32_MAX}, 0, 0]") as &str, Vec3::new(f32::MAX, 0.0, 0.0)),
    ] {
        let s = accepted("radiance = [0.3, 0.5, 0.9]", &format!("radiance = {r}"));
        assert_eq!(s.environment.unwrap().radiance, radiance, "radiance = {r}");
    }
}

#[test]
fn the_directional_light_takes_a_direction_of_any_length() {
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
}

#[test]
fn the_directional_light_takes_any_non_negative_irradiance() {
    for (i, expected) in [
        ("[0, 0, 0]", Vec3::ZERO),
        ("[0, 1, 0]", Vec3::Y),
        (&format!("[{F32_MAX}, 0, 0]") as &str, Vec3::new(f32::MAX, 0.0, 0.0)),
    ] {
        let s = accepted("irradiance = [3.0, 3.0, 3.0]", &format!("irradiance = {i}"));
        assert_eq!(s.directional_light.unwrap().irradiance, expected, "{i}");
    }
}

#[test]
fn the_angular_radius_takes_0_to_just_under_90_degrees() {
    for (a, delta) in [("0", true), ("-0.0", true), ("1e-30", false), ("0.265", false), ("89.999", false)] {
        let s = accepted("angular_radius = 0.25", &format!("angular_radius = {a}"));
        let light = s.directional_light.unwrap();
        assert_eq!(light.is_delta(), delta, "angular_radius = {a}");
    }
}

// ---------------------------------------------------------------------------------------------
// The per-renderer sections.

/// The settings spelled as words (`[pathtrace] sequence`, `[raster] look`, `renderer`) each take
/// their own words (the refusals of the others are in the cases file).
#[test]
fn word_settings_take_their_words() {
    let sequence =
        accepted("sequence = \"low-discrepancy\"", "sequence = \"independent\"").pathtrace.sequence;
    assert_eq!(sequence, Sequence::Independent);
    assert_eq!(accepted("look = \"enhanced\"", "look = \"figure\"").raster.look, Look::Figure);
    assert_eq!(accepted("renderer = \"pathtrace\"", "renderer = \"raster\"").renderer, RendererKind::Raster);
    assert_eq!(
        accepted("renderer = \"pathtrace\"", "renderer = \"whitted\"").renderer,
        RendererKind::Whitted
    );
}

#[test]
fn raster_numbers_take_their_whole_ranges() {
    let base = parse(BASE).unwrap().raster;
    for (from, to, expected) in [
        ("pcf_radius = 0.1", "pcf_radius = 1e-30", RasterSettings { pcf_radius: 1e-30, ..base }),
        ("cube_size = 64", "cube_size = 1", RasterSettings { cube_size: 1, ..base }),
        ("cube_size = 64", "cube_size = 4294967295", RasterSettings { cube_size: u32::MAX, ..base }),
        (
            "glass_color = [0.9, 1.0, 0.9]",
            "glass_color = [0, 0, 0]",
            RasterSettings { glass_color: Vec3::ZERO, ..base },
        ),
        (
            "glass_reflectivity = 0.5",
            "glass_reflectivity = 0",
            RasterSettings { glass_reflectivity: 0.0, ..base },
        ),
        (
            "glass_reflectivity = 0.5",
            "glass_reflectivity = 1",
            RasterSettings { glass_reflectivity: 1.0, ..base },
        ),
    ] {
        assert_eq!(accepted(from, to).raster, expected, "{to}");
    }
}

#[test]
fn whitted_depth_and_aa_take_their_whole_ranges() {
    for (from, to, expected) in [
        ("depth = 5", "depth = 0", WhittedSettings { depth: 0, aa: 3 }),
        ("depth = 5", "depth = 64", WhittedSettings { depth: 64, aa: 3 }),
        ("aa = 3", "aa = 1", WhittedSettings { depth: 5, aa: 1 }),
        ("aa = 3", "aa = 16", WhittedSettings { depth: 5, aa: 16 }),
    ] {
        assert_eq!(accepted(from, to).whitted, expected, "{to}");
    }
}

#[test]
fn shading_values_take_their_whole_ranges() {
    let base = parse(BASE).unwrap().shading;
    let mirror = base.mirror;
    for (from, to, expected) in [
        ("ambient = [0.1, 0.1, 0.1]", "ambient = [0, 0, 0]", Shading { ambient: Vec3::ZERO, ..base }),
        // Radiance, not a reflectance: above 1 is allowed.
        ("ambient = [0.1, 0.1, 0.1]", "ambient = [2, 2, 2]", Shading { ambient: Vec3::splat(2.0), ..base }),
        (
            "shininess = 100.0",
            "shininess = 1e-30",
            Shading { dielectric: DielectricShading { shininess: 1e-30 }, ..base },
        ),
        (
            "shininess = 100.0",
            &format!("shininess = {F32_MAX}"),
            Shading { dielectric: DielectricShading { shininess: f32::MAX }, ..base },
        ),
        (
            "specular = [0.9, 0.9, 0.9]",
            "specular = [0, 1, 0]",
            Shading { mirror: MirrorShading { specular: Vec3::Y, ..mirror }, ..base },
        ),
        ("weight = 0.4", "weight = 0", Shading { mirror: MirrorShading { weight: 0.0, ..mirror }, ..base }),
        ("weight = 0.4", "weight = 1", Shading { mirror: MirrorShading { weight: 1.0, ..mirror }, ..base }),
    ] {
        assert_eq!(accepted(from, to).shading, expected, "{to}");
    }
}

// ---------------------------------------------------------------------------------------------
// The clip planes.

#[test]
fn near_and_far_take_any_near_before_far() {
    for (near, far) in [("1e-30", "1e30"), ("0.1", "0.10001"), ("1", F32_MAX)] {
        let s = parse(&edit("near = 0.1\nfar = 100.0\n", &format!("near = {near}\nfar = {far}\n"))).unwrap();
        let clip = s.clip.unwrap();
        assert!(clip.near > 0.0 && clip.far > clip.near, "{near} {far}");
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
    let used: Vec<(Feature, String)> = s.feature_uses();
    let set = s.features();
    assert!(Feature::ALL.iter().all(|f| set.contains(*f) == used.iter().any(|(u, _)| u == f)), "{set:?}");
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
    assert!(
        delta.feature_uses().contains(&(Feature::DeltaDirectionalLight, "[directional_light]".to_owned()))
    );
    assert!(!delta.feature_uses().iter().any(|(f, _)| *f == Feature::SunDisc));
    let dark = accepted(
        "[directional_light]\ndirection = [-1.0, -2.0, 0.5]\nirradiance = [3.0, 3.0, 3.0]\nangular_radius = 0.25\n",
        "",
    );
    assert!(
        !dark
            .feature_uses()
            .iter()
            .any(|(f, _)| matches!(f, Feature::SunDisc | Feature::DeltaDirectionalLight))
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
    s.require(RendererKind::PathTrace.noun(), |f| EVERYTHING.contains(&f)).unwrap();
    s.require(RendererKind::Raster.noun(), |f| EVERYTHING.contains(&f)).unwrap();

    let err = s.require(RendererKind::PathTrace.noun(), |f| DIFFUSE_ONLY.contains(&f)).unwrap_err();
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
        let err = s.require(RendererKind::Raster.noun(), |f| supported.contains(&f)).unwrap_err();
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
    delta.require(RendererKind::Raster.noun(), |f| delta_only.contains(&f)).unwrap();
    let sun_only: Vec<Feature> =
        EVERYTHING.iter().copied().filter(|f| *f != Feature::DeltaDirectionalLight).collect();
    let err = delta.require(RendererKind::Raster.noun(), |f| sun_only.contains(&f)).unwrap_err();
    assert!(
        err.to_string().contains("[directional_light]: the rasterizer cannot render a directional light"),
        "{err}"
    );
    // Nothing supported: the first object's shape.
    let err = s.require(RendererKind::PathTrace.noun(), |_| false).unwrap_err();
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
    s.require(RendererKind::PathTrace.noun(), |f| DIFFUSE_ONLY.contains(&f)).unwrap();
    // Unused materials do not count: only what an object uses is a feature.
    assert!(s.materials.iter().any(|m| matches!(m.kind, MaterialKind::Dielectric { .. })));
    assert!(!s.feature_uses().iter().any(|(f, _)| *f == Feature::Dielectric));
}
