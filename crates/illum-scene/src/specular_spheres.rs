//! Whether a scene's specular light can be solved sphere by sphere: the condition under which
//! manifold next-event estimation through one sphere (illum-pathtrace's `manifold.wgsl` and the
//! oracle's twin) owns every path whose specular chain stays on one sphere. The one home of that
//! rule: the path tracer's choice of estimators and the oracle's both ask it.
//!
//! The solve follows a chain inside a sphere without looking for other objects there, so no
//! other object may enter a specular sphere (touching is allowed). It needs a delta sun, and
//! every mirror or dielectric must be a sphere, a dielectric of index at least 1 (inside a
//! sphere every internal angle equals the refraction angle, below the critical angle, so no
//! chain meets total internal reflection; below 1 the entry itself can). Its cost grows with the number of specular
//! spheres at every diffuse vertex, so past [`MAX_SPHERES`] the light tracer is the cheaper
//! estimator.

use glam::Vec3;

use crate::{MaterialKind, Quad, Scene, Shape};

/// The bound on the solve's concentration C = b / (|dg/db| r), which diverges at a chain's fold
/// and on a sphere's axis (docs/caustics-manifold.md, "The bound"): the GPU's and the oracle's.
pub const MAX_CONCENTRATION: f32 = 64.0;

/// The most specular spheres the solve takes: each adds its chains' root search to every diffuse
/// vertex of every path.
pub const MAX_SPHERES: usize = 8;

/// Why the scene's specular light cannot be solved sphere by sphere, or `Ok` with the indices of
/// its specular spheres (in `scene.objects`).
pub fn solvable_spheres(scene: &Scene) -> Result<Vec<usize>, String> {
    match scene.directional_light {
        Some(light) if light.is_delta() => {}
        Some(_) => return Err("the sun has an angular radius: the solve needs a delta sun".to_owned()),
        None => return Err("the scene has no directional light".to_owned()),
    }
    let mut spheres = Vec::new();
    for (i, object) in scene.objects.iter().enumerate() {
        let specular = matches!(
            scene.material_of(object).kind,
            MaterialKind::Mirror { .. } | MaterialKind::Dielectric { .. }
        );
        if let MaterialKind::Dielectric { ior } = scene.material_of(object).kind
            && ior < 1.0
        {
            return Err(format!(
                "object {:?} has index {ior}, below 1: the solve takes dielectrics denser than their \
                 surroundings (below 1 light meets total internal reflection on entering)",
                object.name
            ));
        }
        match (&object.shape, specular) {
            (Shape::Sphere(_), true) => spheres.push(i),
            (shape, true) => {
                return Err(format!("object {:?} is a specular {}, not a sphere", object.name, shape.kind()));
            }
            _ => {}
        }
    }
    if spheres.len() > MAX_SPHERES {
        return Err(format!(
            "{} specular spheres, more than the {MAX_SPHERES} the solve takes at every diffuse vertex",
            spheres.len()
        ));
    }
    for &k in &spheres {
        let Shape::Sphere(sphere) = scene.objects[k].shape else { unreachable!("pushed as a sphere") };
        for (j, other) in scene.objects.iter().enumerate() {
            if j != k && enters(&other.shape, sphere.center, sphere.radius) {
                return Err(format!(
                    "object {:?} enters the specular sphere {:?}",
                    other.name, scene.objects[k].name
                ));
            }
        }
    }
    Ok(spheres)
}

/// Whether `shape` has points strictly inside the ball (centre, radius), up to a relative
/// tolerance that lets shapes touch it. Meshes count as entering (the caustic's estimators are
/// off with a mesh anyway).
fn enters(shape: &Shape, centre: Vec3, radius: f32) -> bool {
    let inside = |distance: f32| distance < radius * (1.0 - 1e-5);
    match shape {
        Shape::Sphere(s) => inside(s.center.distance(centre) - s.radius),
        Shape::Quad(q) => inside(quad_distance(q, centre)),
        Shape::Box(b) => {
            let (rotation, offset) = b.local_to_world();
            let local = rotation.transpose() * (centre - offset);
            inside(local.clamp(b.min, b.max).distance(local))
        }
        Shape::Mesh(_) => true,
    }
}

/// The distance from p to the parallelogram q.
fn quad_distance(q: &Quad, p: Vec3) -> f32 {
    let n = q.edge_u.cross(q.edge_v);
    let h = p - q.corner;
    // (s, t) of p's projection, from the dual basis of (edge_u, edge_v) in their plane.
    let nn = n.length_squared();
    let s = h.cross(q.edge_v).dot(n) / nn;
    let t = q.edge_u.cross(h).dot(n) / nn;
    if (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t) {
        return (h.dot(n) / nn.sqrt()).abs();
    }
    let segment = |a: Vec3, d: Vec3| {
        let along = ((p - a).dot(d) / d.length_squared()).clamp(0.0, 1.0);
        (a + along * d).distance(p)
    };
    let (c, u, v) = (q.corner, q.edge_u, q.edge_v);
    segment(c, u).min(segment(c, v)).min(segment(c + u, v)).min(segment(c + v, u))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn whitted() -> Scene {
        crate::testing::shipped_scene("whitted.toml", 64, 36)
    }

    #[test]
    fn the_whitted_scene_is_solvable_and_an_intruder_or_a_disc_is_named() {
        let scene = whitted();
        assert_eq!(solvable_spheres(&scene), Ok(vec![1, 2]));
        // The metal sphere moved against the glass, then into it.
        let Shape::Sphere(glass) = scene.objects[1].shape else { panic!("glass sphere") };
        let moved = |dx: f32| {
            let mut moved = scene.clone();
            let Shape::Sphere(ref mut metal) = moved.objects[2].shape else { panic!("metal sphere") };
            metal.center = glass.center + Vec3::new(dx, 0.0, 0.0);
            moved
        };
        assert_eq!(solvable_spheres(&moved(2.0)), Ok(vec![1, 2]), "touching spheres are allowed");
        let refused = solvable_spheres(&moved(1.9)).unwrap_err();
        assert!(
            refused.contains("\"metal sphere\" enters the specular sphere \"glass sphere\""),
            "{refused}"
        );
        // The floor raised through the glass sphere.
        let mut floor = scene.clone();
        let Shape::Quad(ref mut q) = floor.objects[0].shape else { panic!("floor") };
        q.corner.y = 2.0;
        let refused = solvable_spheres(&floor).unwrap_err();
        assert!(refused.contains("\"floor\" enters"), "{refused}");
        let mut thin = scene.clone();
        thin.materials.iter_mut().for_each(|m| {
            if let MaterialKind::Dielectric { ior } = &mut m.kind {
                *ior = 0.7;
            }
        });
        assert!(solvable_spheres(&thin).unwrap_err().contains("\"glass sphere\" has index 0.7, below 1"));
        let mut disc = scene.clone();
        disc.directional_light.as_mut().expect("a sun").angular_radius_deg = 0.5;
        assert!(solvable_spheres(&disc).unwrap_err().contains("delta sun"));
    }

    /// Whitted with `extra` TOML appended (objects and materials).
    fn whitted_with(extra: &str) -> Scene {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/whitted.toml");
        let text = std::fs::read_to_string(path).expect("whitted.toml") + extra;
        Scene::from_toml_str(&text, "whitted+extra.toml").unwrap_or_else(|e| panic!("{e}"))
    }

    /// Each kind of intruder is named with the sphere it enters; a box touching from outside
    /// enters nothing; a mirror box is not a sphere; more than MAX_SPHERES are refused by count.
    #[test]
    fn intruders_of_every_kind_and_other_specular_shapes_are_named() {
        let boxed = "[materials.white]\nalbedo = [0.5, 0.5, 0.5]\n[[objects]]\nname = \"crate\"\nmaterial = \"white\"\n";
        let cases = [
            format!("{boxed}box = {{ min = [4.9, 2.0, -4.5], max = [6.0, 3.0, -4.0] }}\n"),
            format!(
                "{boxed}box = {{ min = [4.9, 2.0, -4.5], max = [6.0, 3.0, -4.0], rotate_y = 30.0, pivot = [5.45, 2.5, -4.25] }}\n"
            ),
            format!("{boxed}sphere = {{ center = [4.2, 4.0, -4.2], radius = 0.5 }}\n"),
            format!(
                "{boxed}quad = {{ corner = [3.0, 3.3, -5.0], edge_u = [0.0, 0.0, 2.0], edge_v = [2.0, 0.0, 0.0] }}\n"
            ),
        ];
        for extra in &cases {
            let refused = solvable_spheres(&whitted_with(extra)).unwrap_err();
            assert!(refused.contains("\"crate\" enters the specular sphere \"glass sphere\""), "{refused}");
        }
        let touching = format!("{boxed}box = {{ min = [5.201, 2.0, -4.5], max = [6.0, 3.0, -4.0] }}\n");
        assert_eq!(solvable_spheres(&whitted_with(&touching)), Ok(vec![1, 2]));
        let mirror_box = "[[objects]]\nname = \"mirror box\"\nmaterial = \"metal\"\n\
            box = { min = [-3.0, 0.0, 2.0], max = [-2.0, 1.0, 3.0] }\n";
        let refused = solvable_spheres(&whitted_with(mirror_box)).unwrap_err();
        assert!(refused.contains("\"mirror box\" is a specular box, not a sphere"), "{refused}");
        let many: String = (0..MAX_SPHERES)
            .map(|i| {
                format!(
                    "[[objects]]\nname = \"ball {i}\"\nmaterial = \"metal\"\nsphere = {{ center = [{}, 0.5, 5.0], radius = 0.4 }}\n",
                    -20.0 + i as f32
                )
            })
            .collect();
        let refused = solvable_spheres(&whitted_with(&many)).unwrap_err();
        assert!(
            refused.contains(&format!("{} specular spheres, more than the {MAX_SPHERES}", MAX_SPHERES + 2)),
            "{refused}"
        );
    }

    #[test]
    fn the_distance_to_a_quad_is_exact_inside_and_beyond_its_edges() {
        let q =
            Quad { corner: Vec3::ZERO, edge_u: Vec3::new(2.0, 0.0, 0.0), edge_v: Vec3::new(1.0, 0.0, 1.0) };
        assert!((quad_distance(&q, Vec3::new(1.5, 3.0, 0.5)) - 3.0).abs() < 1e-6);
        // Beyond the edge from (2, 0, 0) to (3, 0, 1): the perpendicular from (4, 0, 0).
        let expected = (2.0f32).sqrt();
        assert!((quad_distance(&q, Vec3::new(4.0, 0.0, 0.0)) - expected).abs() < 1e-6);
        // Beyond the corner (0, 0, 0).
        assert!((quad_distance(&q, Vec3::new(-3.0, 4.0, 0.0)) - 5.0).abs() < 1e-6);
    }
}
