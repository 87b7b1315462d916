//! The object-ID image against a closed form computed in f64: each pixel's centre ray hits the
//! nearest of the scene's shapes (the oracle's intersection, which shares no code with WGSL), and a
//! floor point lies in a ball's shadow exactly when the ball's projection along the light
//! covers it: the line p + t L (t > 0) passes within the radius of the centre. Pixels where a
//! silhouette or a shadow edge passes within a small margin of the centre ray may fall on the
//! other side in f32; they are skipped and counted (under 2% of the image; 5% with forty small
//! spheres added).

use glam::DVec3;
use illum_gpu::testing::gpu;
use illum_oracle::closed_form::pixel_ray;
use illum_scene::{Scene, Shape};
use illum_whitted::{Shadow, WhittedTracer};

/// How far the ray (o, d) passes from the shape's outline: from a sphere's silhouette, or from
/// the nearest edge of a rectangle where it crosses its plane (a small margin means f32 may
/// decide hit or miss the other way).
fn margin(shape: &Shape, o: DVec3, d: DVec3) -> f64 {
    match shape {
        Shape::Sphere(s) => {
            let oc = o - s.center.as_dvec3();
            (f64::from(s.radius) - (oc - oc.dot(d) * d).length()).abs()
        }
        Shape::Quad(q) => {
            let (u, v) = (q.edge_u.as_dvec3(), q.edge_v.as_dvec3());
            let n = u.cross(v);
            let p = o + (q.corner.as_dvec3() - o).dot(n) / d.dot(n) * d - q.corner.as_dvec3();
            // Rectangle coordinates along each edge, in scene units.
            let (a, b) = (p.dot(u) / u.length(), p.dot(v) / v.length());
            [a, u.length() - a, b, v.length() - b].into_iter().map(f64::abs).fold(f64::MAX, f64::min)
        }
        Shape::Box(_) | Shape::Mesh(_) => panic!("the Whitted scene has no boxes or meshes"),
    }
}

#[test]
fn object_ids_match_ray_casting_and_shadows_are_the_balls_projections_along_the_light() {
    check(&illum_scene::testing::shipped_scene("whitted.toml", 160, 90), 2, 50);
}

/// With spheres past the literal limit under a BVH (illum-rtcore's analytic_bvh.rs), which puts
/// them first in the GPU's order, each pixel still names the scene's object (the order's map
/// back to the scene does not depend on the kinds under the hierarchy).
#[test]
fn object_ids_name_the_scene_objects_of_spheres_under_the_bvh() {
    let count = illum_rtcore::analytic_bvh::LITERAL_OBJECTS + 24;
    let scene = illum_scene::testing::with_small_spheres(
        illum_scene::testing::shipped_scene("whitted.toml", 160, 90),
        count,
    );
    assert!(illum_rtcore::Geometry::new(&scene).analytic.is_some());
    // Forty small outlines put more pixels within the margin of an edge: under 5%.
    check(&scene, count / 2, 20);
}

/// The object-ID image of `scene` (the Whitted scene's floor, sky and sun, with any spheres)
/// against ray casting in f64; the two balls of the Whitted scene cast shadows onto the floor,
/// and at least `spheres_seen` spheres are seen; under 1 / `edge_share` of the pixels are skipped
/// as near an edge.
fn check(scene: &Scene, spheres_seen: usize, edge_share: usize) {
    let ids = WhittedTracer::new(gpu(), scene).unwrap().object_ids().unwrap();
    let traced = illum_oracle::scene::TraceScene::new(scene).unwrap();
    assert_eq!(traced.surfaces.len(), scene.objects.len());
    let to_light = -scene.directional_light.expect("a sun").direction.as_dvec3().normalize();
    let scale = 1e-3 * scene.camera.eye.as_dvec3().length().max(1.0);
    let (mut checked, mut skipped, mut shadowed) = (0usize, 0usize, vec![0usize; scene.objects.len()]);
    let mut seen = vec![false; scene.objects.len()];
    for y in 0..ids.height {
        for x in 0..ids.width {
            let i = (y * ids.width + x) as usize;
            let (o, d) = pixel_ray(&scene.camera, f64::from(x) + 0.5, f64::from(y) + 0.5);
            // The oracle's f64 intersection (the scene has no emitters, so its surfaces are the
            // scene's objects in order).
            let nearest = traced
                .surfaces
                .iter()
                .enumerate()
                .filter_map(|(k, p)| p.surface.intersect(o, d, f64::INFINITY).map(|hit| (k, hit.t)))
                .min_by(|a, b| a.1.total_cmp(&b.1));
            let near_an_outline = scene.objects.iter().any(|obj| margin(&obj.shape, o, d) < scale);
            // The expected shadow: which balls' projections along the light cover the point.
            let (expected_hit, expected_shadow, near_edge) = match nearest {
                None => (None, Shadow::Lit, near_an_outline),
                Some((k, t)) => {
                    let p = o + t * d;
                    let mut shadow = Shadow::Lit;
                    let mut near = near_an_outline;
                    if matches!(scene.objects[k].shape, Shape::Quad(_)) {
                        // The nearest ball along the light blocks it.
                        let mut nearest_along = f64::INFINITY;
                        for (j, obj) in scene.objects.iter().enumerate() {
                            if let Shape::Sphere(s) = &obj.shape {
                                let cp = s.center.as_dvec3() - p;
                                let along = cp.dot(to_light);
                                let off_axis = (cp - along * to_light).length();
                                let r = f64::from(s.radius);
                                near |= (off_axis - r).abs() < scale;
                                if along > 0.0 && off_axis < r && along < nearest_along {
                                    nearest_along = along;
                                    shadow = Shadow::BlockedBy(j);
                                }
                            }
                        }
                    }
                    (Some(k), shadow, near)
                }
            };
            if near_edge {
                skipped += 1;
                continue;
            }
            checked += 1;
            assert_eq!(ids.hit[i], expected_hit, "pixel ({x}, {y}): the object hit");
            if let Some(k) = expected_hit {
                seen[k] = true;
            }
            if expected_hit.is_some_and(|k| matches!(scene.objects[k].shape, Shape::Quad(_))) {
                assert_eq!(ids.shadow[i], expected_shadow, "pixel ({x}, {y}): the floor's shadow");
                if let Shadow::BlockedBy(j) = expected_shadow {
                    shadowed[j] += 1;
                }
            }
        }
    }
    let total = (ids.width * ids.height) as usize;
    assert!(skipped * edge_share < total, "{skipped} of {total} pixels lie on an edge");
    // Both balls of the Whitted scene cast a shadow onto the visible floor, so both kinds of
    // region exist.
    let balls: Vec<usize> =
        (0..scene.objects.len()).filter(|&j| matches!(scene.objects[j].shape, Shape::Sphere(_))).collect();
    for &j in &balls[..2] {
        assert!(shadowed[j] > 20, "{}: shadow covers only {} pixels", scene.object_label(j), shadowed[j]);
    }
    let seen_balls = balls.iter().filter(|&&j| seen[j]).count();
    assert!(seen_balls >= spheres_seen, "{seen_balls} spheres seen, expected {spheres_seen} or more");
    assert!(checked + skipped == total);
}

/// The object-ID image read back without waiting (as a web page must) is the one read with a
/// wait, and a radiance frame rendered while it is under way does not change it.
#[test]
fn the_polled_object_ids_are_the_waited_ones() {
    let scene: Scene = illum_scene::testing::shipped_scene("whitted.toml", 160, 90);
    let tracer = WhittedTracer::new(gpu(), &scene).unwrap();
    let waited = tracer.object_ids().unwrap();
    let pending = tracer.object_ids_polled();
    tracer.render().unwrap();
    let mut polls = 0;
    let polled = loop {
        polls += 1;
        if let Some(result) = pending.poll(gpu()) {
            break result.unwrap();
        }
        assert!(polls < 100_000, "the readback never completed");
        std::thread::yield_now();
    };
    assert_eq!(polled, waited);
    assert!(polled.hit.iter().any(Option::is_some) && polled.shadow.contains(&Shadow::Lit));
}
