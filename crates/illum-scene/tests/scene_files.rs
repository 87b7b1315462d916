//! The shipped scene files: every one loads, the two Cornell boxes and the Whitted scene hold
//! the numbers that docs/scenes.md lists with their sources. Expected values are typed in from
//! that page, not computed by the crate.

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use illum_scene::{
    Bounces, BoxShape, Checker, Look, MaterialKind, RendererKind, Sampling, Scene, SceneError, Sequence,
    Shape,
};

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

fn load(name: &str) -> Scene {
    let path = scenes_dir().join(name);
    Scene::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

fn object<'a>(scene: &'a Scene, name: &str) -> &'a illum_scene::Object {
    scene
        .objects
        .iter()
        .find(|o| o.name == name)
        .unwrap_or_else(|| panic!("no object named {name:?} in {}", scene.name))
}

fn material_name<'a>(scene: &'a Scene, object_name: &str) -> &'a str {
    &scene.materials[object(scene, object_name).material].name
}

fn as_box(scene: &Scene, name: &str) -> BoxShape {
    match &object(scene, name).shape {
        Shape::Box(b) => *b,
        other => panic!("{name} is not a box: {other:?}"),
    }
}

fn close3(a: Vec3, b: Vec3, tol: f32) -> bool {
    (a - b).abs().max_element() <= tol
}

/// The (x, z) footprint of a block: its four bottom corners (y = min), in the order
/// local (0,0), (165,0), (165,165), (0,165), which is the order docs/scenes.md lists them in.
fn footprint(b: &BoxShape) -> [Vec2; 4] {
    let (r, t) = b.local_to_world();
    let local = [
        Vec3::new(b.min.x, b.min.y, b.min.z),
        Vec3::new(b.max.x, b.min.y, b.min.z),
        Vec3::new(b.max.x, b.min.y, b.max.z),
        Vec3::new(b.min.x, b.min.y, b.max.z),
    ];
    local.map(|p| {
        let w = r * p + t;
        Vec2::new(w.x, w.z)
    })
}

fn assert_footprint(b: &BoxShape, expected: [(f32, f32); 4], what: &str) {
    let got = footprint(b);
    for (g, (x, z)) in got.iter().zip(expected) {
        assert!(
            (g.x - x).abs() <= 0.1 && (g.y - z).abs() <= 0.1,
            "{what}: footprint {got:?}, expected {expected:?}"
        );
    }
    // world_corners must agree with local_to_world on the same corners.
    let corners = b.world_corners();
    for (g, c) in got.iter().zip([corners[0], corners[1], corners[5], corners[4]]) {
        assert!((g.x - c.x).abs() < 1e-3 && (g.y - c.z).abs() < 1e-3, "{what}: {corners:?}");
    }
}

#[test]
fn every_scene_file_loads() {
    // One format: every file loads as a Scene and names the renderer tools use by default.
    let mut loaded = Vec::new();
    for entry in std::fs::read_dir(scenes_dir()).expect("scenes/ exists") {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
            assert!(!scene.objects.is_empty());
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            let expected = match name.as_str() {
                "whitted.toml" => RendererKind::Raster,
                _ => RendererKind::PathTrace,
            };
            assert_eq!(scene.renderer, expected, "{name}");
            loaded.push(name);
        }
    }
    for required in ["cornell.toml", "cornell-classic.toml", "whitted.toml", "cornell-mesh.toml"] {
        assert!(loaded.iter().any(|n| n == required), "{required} missing: {loaded:?}");
    }
}

#[test]
fn cornell_camera_and_settings() {
    let s = load("cornell.toml");
    assert_eq!(s.name, "cornell");
    let c = s.camera;
    assert_eq!(c.eye, Vec3::new(278.0, 278.0, -724.26));
    assert_eq!(c.target, Vec3::new(278.0, 278.0, 0.0));
    assert_eq!(c.up, Vec3::Y);
    assert_eq!(c.vfov_deg, 45.0);
    assert_eq!((c.width, c.height), (512, 512));
    // 724.26 = 300 / tan(22.5 deg).
    assert!((c.eye.z.abs() - 300.0 / 22.5f32.to_radians().tan()).abs() < 0.01);
    // Screen-right is world -X, so the red wall (x = 555) is on the image's left.
    let basis = c.basis();
    assert!(close3(basis.right, Vec3::NEG_X, 1e-6), "{:?}", basis.right);
    assert_eq!(material_name(&s, "left wall"), "red");
    assert_eq!(as_box(&s, "left wall").min.x, 555.0);

    let r = s.pathtrace;
    assert_eq!(r.spp, 16);
    assert_eq!(r.bounces, Bounces::Fixed(2));
    assert_eq!(r.seed, 0);
    assert_eq!(r.sampling, Sampling::Cosine);
    assert_eq!(r.sequence, Sequence::Independent);
    // The path tracer needs no clip planes and the box has neither sky nor sun.
    assert_eq!(s.clip, None);
    assert!(s.environment.is_none() && s.directional_light.is_none());
}

#[test]
fn cornell_materials() {
    let s = load("cornell.toml");
    let names: Vec<&str> = s.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["green", "light", "red", "white"], "sorted by name");
    let m = |n: &str| s.materials.iter().find(|m| m.name == n).unwrap();
    // (143, 16, 16) / 255 and (15, 101, 22) / 255, to the four decimals docs/scenes.md gives.
    assert!(close3(m("red").diffuse_albedo().unwrap(), Vec3::new(143.0, 16.0, 16.0) / 255.0, 1e-4));
    assert!(close3(m("green").diffuse_albedo().unwrap(), Vec3::new(15.0, 101.0, 22.0) / 255.0, 1e-4));
    assert_eq!(m("white").diffuse_albedo().unwrap(), Vec3::splat(0.5));
    assert_eq!(m("light").emission(), Vec3::splat(30.0));
    assert_eq!(m("light").diffuse_albedo().unwrap(), Vec3::ZERO, "the light is not reflective");
    for n in ["red", "green", "white"] {
        assert_eq!(m(n).emission(), Vec3::ZERO, "{n} must not emit");
    }
}

#[test]
fn cornell_walls_match_the_facts_table() {
    let s = load("cornell.toml");
    // (name, centre, half-extent, material) from docs/scenes.md.
    let walls = [
        ("left wall", [556.0, 278.0, 278.0], [1.0, 278.0, 278.0], "red"),
        ("right wall", [0.0, 278.0, 278.0], [1.0, 278.0, 278.0], "green"),
        ("ceiling", [278.0, 556.0, 278.0], [278.0, 1.0, 278.0], "white"),
        ("floor", [278.0, 0.0, 278.0], [278.0, 1.0, 278.0], "white"),
        ("back wall", [278.0, 278.0, 556.0], [278.0, 278.0, 1.0], "white"),
    ];
    for (name, centre, half, material) in walls {
        let b = as_box(&s, name);
        let (c, h) = (Vec3::from(centre), Vec3::from(half));
        assert_eq!((b.min, b.max), (c - h, c + h), "{name}");
        assert_eq!(b.rotate_y_deg, 0.0, "{name}");
        assert_eq!(b.translate, Vec3::ZERO, "{name}");
        assert_eq!(material_name(&s, name), material, "{name}");
    }
    // Only the walls, the light and the two blocks: no front wall.
    assert_eq!(s.objects.len(), 8);
}

#[test]
fn cornell_light_is_the_downward_130_by_105_rectangle() {
    let s = load("cornell.toml");
    let emitters: Vec<_> = s.emitters().collect();
    assert_eq!(emitters.len(), 1);
    let (index, obj, quad) = emitters[0];
    assert_eq!(obj.name, "light");
    assert_eq!(s.objects[index].name, "light");
    assert_eq!(s.materials[obj.material].emission(), Vec3::splat(30.0));
    assert_eq!(quad.area(), 13650.0);
    assert_eq!(quad.normal(), Vec3::new(0.0, -1.0, 0.0));
    // x in [213, 343], z in [225.5, 330.5] at y = 555.
    let corners = [
        quad.corner,
        quad.corner + quad.edge_u,
        quad.corner + quad.edge_v,
        quad.corner + quad.edge_u + quad.edge_v,
    ];
    let lo = corners.iter().fold(Vec3::INFINITY, |a, &b| a.min(b));
    let hi = corners.iter().fold(Vec3::NEG_INFINITY, |a, &b| a.max(b));
    assert_eq!(lo, Vec3::new(213.0, 555.0, 225.5));
    assert_eq!(hi, Vec3::new(343.0, 555.0, 330.5));
}

#[test]
fn cornell_block_footprints() {
    let s = load("cornell.toml");
    let tall = as_box(&s, "tall block");
    assert_eq!((tall.min, tall.max), (Vec3::ZERO, Vec3::new(165.0, 330.0, 165.0)));
    assert_footprint(&tall, [(265.0, 295.0), (424.4, 252.3), (467.1, 411.7), (307.7, 454.4)], "tall block");
    let short = as_box(&s, "short block");
    assert_eq!((short.min, short.max), (Vec3::ZERO, Vec3::splat(165.0)));
    assert_footprint(&short, [(105.0, 65.0), (261.9, 116.0), (210.9, 272.9), (54.0, 221.9)], "short block");
    for name in ["tall block", "short block"] {
        assert_eq!(material_name(&s, name), "white");
        // Rotation about the vertical axis keeps the block standing on y = 0.
        let corners = as_box(&s, name).world_corners();
        assert!(corners.iter().all(|c| c.y >= -1e-4), "{name}: {corners:?}");
    }
}

#[test]
fn classic_cornell_matches_the_measured_box() {
    let s = load("cornell-classic.toml");
    assert_eq!(s.camera.eye, Vec3::new(278.0, 273.0, -800.0));
    assert_eq!(s.camera.target, Vec3::new(278.0, 273.0, 0.0));
    assert_eq!(s.camera.vfov_deg, 39.3);
    let m = |n: &str| s.materials.iter().find(|m| m.name == n).unwrap();
    assert_eq!(m("red").diffuse_albedo().unwrap(), Vec3::new(0.63, 0.065, 0.05));
    assert_eq!(m("green").diffuse_albedo().unwrap(), Vec3::new(0.14, 0.45, 0.091));
    assert_eq!(m("white").diffuse_albedo().unwrap(), Vec3::new(0.725, 0.71, 0.68));
    assert_eq!(m("light").emission(), Vec3::new(17.0, 12.0, 4.0));

    // The interior is 556 x 548.8 x 559.2: read it off the walls' inner faces.
    assert_eq!(as_box(&s, "right wall").max.x, 0.0);
    assert_eq!(as_box(&s, "left wall").min.x, 556.0);
    assert_eq!(material_name(&s, "left wall"), "red");
    assert_eq!(as_box(&s, "floor").max.y, 0.0);
    assert!((as_box(&s, "ceiling").min.y - 548.8).abs() < 1e-3);
    assert!((as_box(&s, "back wall").min.z - 559.2).abs() < 1e-3);

    let emitters: Vec<_> = s.emitters().collect();
    assert_eq!(emitters.len(), 1);
    let quad = emitters[0].2;
    assert_eq!(quad.area(), 130.0 * 105.0);
    assert_eq!(quad.normal(), Vec3::NEG_Y);
    let centre = quad.corner + 0.5 * (quad.edge_u + quad.edge_v);
    assert!(close3(centre, Vec3::new(278.0, 548.7, 559.2 / 2.0), 1e-3), "{centre:?}");

    // Same blocks as cornell.toml.
    assert_footprint(
        &as_box(&s, "tall block"),
        [(265.0, 295.0), (424.4, 252.3), (467.1, 411.7), (307.7, 454.4)],
        "classic tall block",
    );
    assert_footprint(
        &as_box(&s, "short block"),
        [(105.0, 65.0), (261.9, 116.0), (210.9, 272.9), (54.0, 221.9)],
        "classic short block",
    );
}

#[test]
fn load_reports_io_errors_with_the_path() {
    let path = scenes_dir().join("no-such-scene.toml");
    let err = Scene::load(&path).unwrap_err();
    let label = path.display().to_string();
    match &err {
        SceneError::Io { file, source } => {
            assert_eq!(file, &label);
            assert_eq!(source.kind(), std::io::ErrorKind::NotFound);
        }
        other => panic!("expected Io, got {other:?}"),
    }
    assert!(err.to_string().starts_with(&label), "{err}");
}

#[test]
fn load_names_the_scene_after_the_file_stem_and_labels_errors_with_the_path() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("illum-scene-load-test");
    std::fs::create_dir_all(&dir).unwrap();
    let text = std::fs::read_to_string(scenes_dir().join("cornell.toml")).unwrap();

    let unnamed = dir.join("my-box.toml");
    std::fs::write(&unnamed, text.replace("name = \"cornell\"", "")).unwrap();
    assert_eq!(Scene::load(&unnamed).unwrap().name, "my-box");

    let broken = dir.join("broken.toml");
    std::fs::write(&broken, text.replace("spp = 16", "spp = 0")).unwrap();
    let err = Scene::load(&broken).unwrap_err().to_string();
    let label = broken.display().to_string();
    assert_eq!(err, format!("{label}: pathtrace.spp = 0: must be at least 1"));
}

#[test]
fn whitted_is_the_physical_scene_of_the_fake() {
    let s = load("whitted.toml");
    assert_eq!(s.name, "whitted");
    assert_eq!(s.raster.look, Look::Figure);
    let c = s.camera;
    assert_eq!(c.eye, Vec3::new(7.5, 2.3, -4.2));
    assert_eq!(c.target, Vec3::new(4.2, 2.3, -4.2));
    assert_eq!(c.up, Vec3::Y);
    assert_eq!(c.vfov_deg, 60.0);
    let clip = s.clip.expect("near and far");
    assert_eq!((clip.near, clip.far), (0.1, 3000.0));
    // The camera looks along -X and screen-right is world -Z.
    let basis = c.basis();
    assert!(close3(basis.forward, Vec3::NEG_X, 1e-6), "{:?}", basis.forward);
    assert!(close3(basis.right, Vec3::NEG_Z, 1e-6), "{:?}", basis.right);

    // The sky: the figure's 8-bit levels (76, 128, 229) / 255, within 0.002 of the skeleton's
    // (0.3, 0.5, 0.9) (scenes/whitted.toml says why).
    let sky = s.environment.expect("a sky").radiance;
    assert_eq!(sky, Vec3::new(0.298039, 0.501961, 0.898039));
    assert!(close3(sky, Vec3::new(0.3, 0.5, 0.9), 0.002));
    // The light from (10, 13, -2) toward the origin, irradiance pi x intensity 1, a delta light.
    let light = s.directional_light.expect("a directional light");
    let expected = -Vec3::new(10.0, 13.0, -2.0) / 273f32.sqrt();
    assert!(close3(light.direction, expected, 1e-6), "{:?}", light.direction);
    assert_eq!(light.irradiance, Vec3::splat(std::f32::consts::PI));
    assert!(light.is_delta());
    assert_eq!(s.shading.ambient, Vec3::splat(0.23));

    // The floor: x in [-23, 7], z in [-7.5, 7.5], facing up, 1 x 1 tiles counted from the
    // minimum corner; 0xcccc00 and 0xcc0000 as linear 0xcc / 255 = 0.8, yellow on even tiles.
    let Shape::Quad(floor) = object(&s, "floor").shape else { panic!("the floor is a quad") };
    assert_eq!(floor.corner, Vec3::new(-23.0, 0.0, -7.5));
    assert_eq!(floor.corner + floor.edge_u + floor.edge_v, Vec3::new(7.0, 0.0, 7.5));
    assert_eq!(floor.normal(), Vec3::Y);
    let checker = Checker { even: Vec3::new(0.8, 0.8, 0.0), odd: Vec3::new(0.8, 0.0, 0.0), tile: 1.0 };
    assert_eq!(s.materials[object(&s, "floor").material].kind, MaterialKind::Checker(checker));

    let sphere = |name: &str| match &object(&s, name).shape {
        Shape::Sphere(sphere) => (sphere.center, sphere.radius),
        other => panic!("{name} is not a sphere: {other:?}"),
    };
    assert_eq!(sphere("glass sphere"), (Vec3::new(4.2, 2.6, -4.2), 1.0));
    assert_eq!(sphere("metal sphere"), (Vec3::new(2.0, 1.9, -2.5), 1.0));
    // Glass of index 1 / 0.7, the skeleton's refraction ratio.
    let MaterialKind::Dielectric { ior } = s.materials[object(&s, "glass sphere").material].kind else {
        panic!("the glass is a dielectric")
    };
    assert!((1.0 / ior - 0.7).abs() < 1e-7, "ior {ior}");
    // A mirror tinted by 0xcadcd9 = (202, 220, 217) / 255.
    let MaterialKind::Mirror { reflectance } = s.materials[object(&s, "metal sphere").material].kind else {
        panic!("the metal is a mirror")
    };
    assert!(close3(reflectance, Vec3::new(202.0, 220.0, 217.0) / 255.0, 1e-3), "{reflectance:?}");

    // The fake's own parameters.
    assert_eq!(s.raster.glass_color, Vec3::ONE);
    assert_eq!(s.raster.glass_reflectivity, 0.9);
    assert_eq!(s.raster.pcf_radius, 0.05);
    assert_eq!(s.raster.cube_size, 256);
    assert_eq!(s.raster.effects, illum_scene::Effects::ALL_ON);
    assert_eq!(s.shading.dielectric.shininess, 200.0);
    assert_eq!(
        (s.shading.mirror.specular, s.shading.mirror.shininess, s.shading.mirror.weight),
        (Vec3::ONE, 30.0, 0.6)
    );
}
