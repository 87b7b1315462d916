//! Scenes far from the world origin (`frame.rs`): a shipped scene file moved by up to 1e6 units
//! along each axis and diagonally loads into the same f32 scene, measured from its eye, wherever
//! it sits; its world coordinates are kept in f64 in `Scene::origin`; and a scene near the
//! origin keeps the coordinates its file gives.

use std::path::{Path, PathBuf};

use glam::{DVec3, Vec3};
use illum_scene::testing::moved;
use illum_scene::{Scene, Shape};

fn text(name: &str) -> String {
    let path: PathBuf = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes").join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn load(text: &str) -> Scene {
    Scene::from_toml_str(text, "moved.toml").unwrap_or_else(|e| panic!("{e}"))
}

/// Offsets along each axis and the diagonal, at 1e3, 1e4, 1e5 and 1e6 units, both signs.
fn offsets() -> Vec<DVec3> {
    let mut out = Vec::new();
    for magnitude in [1e3, 1e4, 1e5, 1e6] {
        for direction in [DVec3::X, DVec3::Y, DVec3::Z, DVec3::ONE.normalize(), -DVec3::ONE.normalize()] {
            out.push(direction * magnitude);
        }
    }
    out
}

/// Every point that places the scene: the eye, the target, and each object's corners (a box's
/// eight, a quad's four, a mesh's vertices) or a sphere's centre, in the scene's own frame.
fn points(scene: &Scene) -> Vec<Vec3> {
    let mut out = vec![scene.camera.eye, scene.camera.target];
    for object in &scene.objects {
        match &object.shape {
            Shape::Box(b) => out.extend(b.world_corners()),
            Shape::Quad(q) => out.extend([q.corner, q.corner + q.edge_u, q.corner + q.edge_v]),
            Shape::Sphere(s) => out.push(s.center),
            Shape::Mesh(m) => out.extend(&m.positions),
        }
    }
    out
}

/// The largest coordinate of any of the scene's points, in its own frame.
fn magnitude(scene: &Scene) -> f32 {
    points(scene).iter().map(|p| p.abs().max_element()).fold(0.0, f32::max)
}

#[test]
fn the_shipped_scenes_near_the_origin_keep_their_coordinates() {
    for name in ["whitted.toml", "cornell.toml", "cornell-classic.toml"] {
        let scene = load(&text(name));
        assert_eq!(scene.origin, DVec3::ZERO, "{name}");
        // A small move keeps the world frame too: the eye stays within the scene's own size.
        let nudged = load(&moved(&text(name), [3.0, -2.0, 1.0]));
        assert_eq!(nudged.origin, DVec3::ZERO, "{name} moved by 3 units");
    }
}

/// Moved anywhere up to 1e6 units away, a scene is measured from its eye: the eye is exactly 0,
/// `world_point` gives the file's positions back, every point is where the scene at home puts it
/// relative to its eye (to f32 rounding at the scene's own size: four steps of f32 at its
/// largest coordinate, for the home file's rounding, the rebased one and a box's rotation), and
/// the f32 numbers are the same wherever the scene sits, so every renderer gets the same input.
#[test]
fn a_scene_moved_up_to_1e6_units_loads_into_the_same_f32_scene() {
    for name in ["whitted.toml", "cornell.toml", "cornell-classic.toml"] {
        let home = load(&text(name));
        let eye = home.camera.eye.as_dvec3();
        let mut first: Option<Scene> = None;
        let mut worst_ulps = 0.0f64;
        for offset in offsets() {
            let what = format!("{name} moved by {offset:?}");
            let scene = load(&moved(&text(name), offset.to_array()));
            if scene.origin == DVec3::ZERO {
                // Still within the scene's own size of the origin (the Cornell box, 1281 units
                // with its eye, moved by 1e3): the world frame is as precise as the eye's.
                let eye_world = scene.camera.eye.abs().max_element();
                assert!(eye_world <= magnitude(&home) * 2.0, "{what}: kept the world frame {eye_world} away");
                continue;
            }
            assert_eq!(scene.camera.eye, Vec3::ZERO, "{what}");
            let expected_origin = eye + offset;
            // The home eye is the file's rounded to f32; the origin is the file's in f64.
            let tolerance = f64::from(magnitude(&home)) * 2f64.powi(-23) + 1e-9 * offset.length();
            assert!((scene.origin - expected_origin).abs().max_element() <= tolerance, "{what}");
            assert!(
                (scene.world_point(scene.camera.target) - (home.camera.target.as_dvec3() + offset)).length()
                    <= 2.0 * tolerance,
                "{what}: target"
            );
            let size = f64::from(magnitude(&scene).max(magnitude(&home)));
            let ulp = size * 2f64.powi(-23);
            for (p, q) in points(&scene).iter().zip(points(&home)) {
                let expected = q.as_dvec3() - eye;
                let error = (p.as_dvec3() - expected).abs().max_element();
                worst_ulps = worst_ulps.max(error / ulp);
                assert!(error <= 4.0 * ulp, "{what}: {p:?} against {expected:?} ({error:e} > 4 x {ulp:e})");
            }
            let rebased = magnitude(&scene);
            assert!(rebased < 2.0 * magnitude(&home), "{what}: magnitude {rebased} in the eye's frame");
            match &first {
                None => first = Some(scene),
                Some(first) => {
                    let differ = points(&scene).iter().zip(points(first)).filter(|(a, b)| **a != *b).count();
                    assert_eq!(differ, 0, "{what}: {differ} f32 points differ from the first offset's");
                    assert_eq!(scene.materials, first.materials, "{what}");
                    assert_eq!(scene.directional_light, first.directional_light, "{what}");
                }
            }
        }
        println!(
            "{name}: every point within {worst_ulps:.2} f32 steps of the home scene's, relative to the eye"
        );
    }
}

/// A box far away is re-expressed about its own centre; its corners are the file's, moved.
#[test]
fn a_rotated_box_far_away_keeps_its_corners() {
    let home = load(&text("cornell.toml"));
    let offset = DVec3::new(-7e5, 3e5, 1e6);
    let far = load(&moved(&text("cornell.toml"), offset.to_array()));
    for (h, f) in home.objects.iter().zip(&far.objects) {
        let (Shape::Box(h), Shape::Box(f)) = (&h.shape, &f.shape) else { continue };
        for (a, b) in h.world_corners().iter().zip(f.world_corners()) {
            let expected = a.as_dvec3() + offset;
            let got = far.world_point(b);
            assert!((got - expected).length() < 1e-3, "{a:?} + offset: {got:?} against {expected:?}");
        }
    }
}
