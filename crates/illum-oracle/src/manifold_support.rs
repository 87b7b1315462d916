//! Where manifold next-event estimation (`manifold.rs`) is defined: a delta sun, specular
//! objects that are spheres, and no object entering a specular sphere (MNEE does not test the
//! chain's segments inside the sphere, so anything there would be ignored).
//!
//! "Enters" means meets the open ball: the distance from the sphere's centre to the object (a
//! solid box or ball, or the surface of a quad or triangle) is below the radius. An object
//! that only touches the sphere is allowed.

use glam::{DVec3, Vec3};
use illum_scene::{MaterialKind, Scene, Shape};

use crate::geometry::{OrientedBox, dvec};

/// `Ok` when MNEE is defined for `scene`; otherwise which object breaks which rule, by name:
/// a directional light that is not delta, a mirror or dielectric that is not a sphere, or an
/// object (of any material, emitters too) entering a mirror or dielectric sphere. A scene
/// without a directional light or without specular spheres is accepted (MNEE adds nothing).
pub fn manifold_supported(scene: &Scene) -> Result<(), String> {
    if let Some(light) = scene.directional_light
        && light.angular_radius_deg != 0.0
    {
        return Err(format!(
            "the directional light is a disc of angular radius {} degrees, not a delta sun",
            light.angular_radius_deg
        ));
    }
    let specular = |i: usize| {
        matches!(
            scene.material_of(&scene.objects[i]).kind,
            MaterialKind::Mirror { .. } | MaterialKind::Dielectric { .. }
        )
    };
    for (i, object) in scene.objects.iter().enumerate() {
        if !specular(i) {
            continue;
        }
        let Shape::Sphere(sphere) = object.shape else {
            return Err(format!(
                "{} is {} but not a sphere",
                scene.object_label(i),
                scene.material_of(object).kind.key()
            ));
        };
        let (centre, radius) = (dvec(sphere.center), f64::from(sphere.radius));
        for (j, other) in scene.objects.iter().enumerate() {
            if j != i && distance(&other.shape, centre) < radius {
                return Err(format!(
                    "{} enters the {} sphere {}",
                    scene.object_label(j),
                    scene.material_of(object).kind.key(),
                    scene.object_label(i)
                ));
            }
        }
    }
    Ok(())
}

/// The distance from `p` to the solid box or ball, or to the quad's or mesh's surface (zero
/// inside a box or ball).
fn distance(shape: &Shape, p: DVec3) -> f64 {
    match shape {
        Shape::Sphere(s) => ((p - dvec(s.center)).length() - f64::from(s.radius)).max(0.0),
        Shape::Box(b) => {
            let b = OrientedBox::from_shape(b);
            let local = b.rotation.transpose() * (p - b.offset);
            (local - local.clamp(b.lo, b.hi)).length()
        }
        Shape::Quad(q) => {
            let (c, u, v) = (dvec(q.corner), dvec(q.edge_u), dvec(q.edge_v));
            polygon_distance(p, &[c, c + u, c + u + v, c + v])
        }
        Shape::Mesh(m) => (0..m.triangles.len())
            .map(|t| polygon_distance(p, &m.triangle(t).map(|v: Vec3| dvec(v))))
            .fold(f64::INFINITY, f64::min),
    }
}

/// The distance from `p` to the convex planar polygon `corners` (in order): to its plane when
/// p's projection is inside every edge, else to the nearest edge.
fn polygon_distance(p: DVec3, corners: &[DVec3]) -> f64 {
    let normal = (corners[1] - corners[0]).cross(corners[2] - corners[0]).normalize();
    let height = (p - corners[0]).dot(normal);
    let projected = p - height * normal;
    let edges = corners.iter().zip(corners.iter().cycle().skip(1));
    if edges.clone().all(|(a, b)| (*b - *a).cross(projected - *a).dot(normal) >= 0.0) {
        return height.abs();
    }
    edges
        .map(|(a, b)| {
            let ab = *b - *a;
            let s = ((p - *a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
            (p - (*a + s * ab)).length()
        })
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn whitted() -> Scene {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/whitted.toml");
        Scene::load(std::path::Path::new(path)).unwrap()
    }

    /// Whitted with `extra` TOML appended (objects and materials).
    fn whitted_with(extra: &str) -> Scene {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/whitted.toml");
        let text = std::fs::read_to_string(path).unwrap() + extra;
        Scene::from_toml_str(&text, "whitted+extra.toml").unwrap_or_else(|e| panic!("{e}"))
    }

    /// Guards the acceptance of the scene MNEE is for: two balls apart over a floor below them.
    #[test]
    fn the_whitted_scene_is_supported() {
        assert_eq!(manifold_supported(&whitted()), Ok(()));
    }

    /// Guards each refusal and that it names both objects: a box, a ball and a quad entering
    /// the glass sphere, a box-shaped mirror, and a sun disc; a box only touching is allowed.
    #[test]
    fn objects_entering_a_specular_sphere_are_refused_by_name() {
        let boxed = "[materials.white]\nalbedo = [0.5, 0.5, 0.5]\n[[objects]]\nname = \"crate\"\nmaterial = \"white\"\n";
        let cases = [
            format!("{boxed}box = {{ min = [4.9, 2.0, -4.5], max = [6.0, 3.0, -4.0] }}\n"),
            format!("{boxed}sphere = {{ center = [4.2, 4.0, -4.2], radius = 0.5 }}\n"),
            format!(
                "{boxed}quad = {{ corner = [3.0, 3.3, -5.0], edge_u = [0.0, 0.0, 2.0], edge_v = [2.0, 0.0, 0.0] }}\n"
            ),
        ];
        for extra in &cases {
            let err = manifold_supported(&whitted_with(extra)).unwrap_err();
            assert!(err.contains("\"crate\"") && err.contains("\"glass sphere\""), "{err}");
        }
        // Touching from outside (the box's face 1e-3 beyond the radius) enters nothing.
        let touching = format!("{boxed}box = {{ min = [5.201, 2.0, -4.5], max = [6.0, 3.0, -4.0] }}\n");
        assert_eq!(manifold_supported(&whitted_with(&touching)), Ok(()));
        let mirror_box = "[[objects]]\nname = \"mirror box\"\nmaterial = \"metal\"\n\
            box = { min = [-3.0, 0.0, 2.0], max = [-2.0, 1.0, 3.0] }\n";
        let err = manifold_supported(&whitted_with(mirror_box)).unwrap_err();
        assert!(err.contains("\"mirror box\"") && err.contains("not a sphere"), "{err}");
        let mut disc = whitted();
        disc.directional_light.as_mut().unwrap().angular_radius_deg = 1.0;
        assert!(manifold_supported(&disc).unwrap_err().contains("not a delta sun"));
    }

    /// Guards the polygon distance: above the inside, beside an edge, beyond a corner.
    #[test]
    fn polygon_distance_is_to_the_plane_or_the_nearest_edge() {
        let square = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
        assert!((polygon_distance(DVec3::new(0.5, 0.5, 2.0), &square) - 2.0).abs() < 1e-15);
        assert!((polygon_distance(DVec3::new(1.5, 0.5, 0.0), &square) - 0.5).abs() < 1e-15);
        assert!((polygon_distance(DVec3::new(2.0, 2.0, 1.0), &square) - 3f64.sqrt()).abs() < 1e-15);
        // The other winding gives the same distances.
        let reversed = [square[3], square[2], square[1], square[0]];
        assert!((polygon_distance(DVec3::new(0.5, 0.5, -2.0), &reversed) - 2.0).abs() < 1e-15);
    }
}
