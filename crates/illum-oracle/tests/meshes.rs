//! Meshes in the oracles: a box given as 12 triangles draws the image the analytic box draws,
//! in the path-tracing oracle and in Whitted's, with the same random numbers; a camera inside
//! a closed black mesh sees no light through its shared edges and vertices; and smooth shading
//! follows its rules (mesh_shading.wgsl in illum-rtcore states them): a file's normals decide
//! no side, no light leaks, and a smooth icosphere looks more like its sphere than a flat one.

use glam::Vec3;
use illum_oracle::{Oracle, WhittedOracle};
use illum_scene::testing::obj::{
    box_obj, icosphere_obj, scene_with_files, tilted_square, with_vertex_normals,
};
use illum_scene::testing::{edit_once, shipped_scene};
use illum_scene::{Scene, Shape};

const SHORT_BLOCK: &str = "box = { min = [0.0, 0.0, 0.0], max = [165.0, 165.0, 165.0], rotate_y = -18.0, pivot = [0.0, 0.0, 0.0], translate = [105.0, 0.0, 65.0] }";

fn cornell_text() -> String {
    std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/cornell.toml")).unwrap()
}

/// The Cornell box with its short block as an analytic box and as a mesh of the same corners,
/// with `material` on the block.
fn box_and_mesh(material: &str, width: u32) -> (Scene, Scene) {
    let cornell = shipped_scene("cornell.toml", width, width);
    let block = cornell.objects.iter().find(|o| o.name == "short block").unwrap();
    let Shape::Box(b) = &block.shape else { panic!("the short block is a box") };
    let obj = box_obj(b.world_corners());
    let materials = "[materials.glass]\ndielectric = { ior = 1.5 }\n[materials.mirror]\nmirror = { reflectance = [0.9, 0.9, 0.9] }\n";
    let text = format!("{}{materials}", cornell_text());
    let boxed = edit_once(
        &text,
        "name = \"short block\"\nmaterial = \"white\"",
        &format!("name = \"short block\"\nmaterial = \"{material}\""),
    );
    let meshed = edit_once(&boxed, SHORT_BLOCK, "mesh = { file = \"block.obj\" }");
    let load = |t: &str| {
        let mut s =
            scene_with_files(t, "cornell.toml", &[("block.obj", &obj)]).unwrap_or_else(|e| panic!("{e}"));
        s.camera.width = width;
        s.camera.height = width;
        s
    };
    let (boxed, meshed) = (load(&boxed), load(&meshed));
    let surfaces = |s: &Scene| illum_oracle::scene::TraceScene::new(s).unwrap().surfaces.len();
    assert_eq!(surfaces(&meshed), surfaces(&boxed) + 11, "the block is 12 triangles");
    (boxed, meshed)
}

/// The fraction of pixels whose values differ by more than `tolerance` (relative to the
/// image's mean), and the two images' mean values.
fn compare(a: &[[f64; 3]], b: &[[f64; 3]], tolerance: f64) -> (f64, f64, f64) {
    let mean =
        |img: &[[f64; 3]]| img.iter().map(|p| p.iter().sum::<f64>() / 3.0).sum::<f64>() / img.len() as f64;
    let (ma, mb) = (mean(a), mean(b));
    let differ =
        a.iter().zip(b).filter(|(p, q)| (0..3).any(|c| (p[c] - q[c]).abs() > tolerance * ma)).count();
    (differ as f64 / a.len() as f64, ma, mb)
}

#[test]
fn a_box_as_triangles_path_traces_as_the_box() {
    for material in ["white", "mirror", "glass"] {
        let (boxed, meshed) = box_and_mesh(material, 24);
        let render = |s: &Scene| Oracle::new(s).unwrap().render(8, 7, illum_oracle::default_threads()).mean;
        let (differ, a, b) = compare(&render(&boxed), &render(&meshed), 1e-6);
        println!("{material}: {:.2}% of pixels differ, means {a:.6} and {b:.6}", 100.0 * differ);
        // The same random numbers trace the same paths; the corners differ by f32 rounding, so
        // a path may rarely take another branch at an edge.
        assert!(differ < 0.02, "{material}: {:.2}% of pixels differ", 100.0 * differ);
        assert!((a - b).abs() < 0.01 * a, "{material}: means {a} and {b}");
    }
}

#[test]
fn a_box_as_triangles_is_drawn_by_whitted_as_the_box() {
    for material in ["white", "mirror", "glass"] {
        let (boxed, meshed) = box_and_mesh(material, 32);
        let image = |s: &Scene| {
            let o = WhittedOracle::new(s).unwrap();
            (0..32 * 32).map(|i| o.pixel(i % 32, i / 32)).collect::<Vec<_>>()
        };
        let (differ, a, b) = compare(&image(&boxed), &image(&meshed), 1e-6);
        assert!(differ < 0.02, "{material}: {:.2}% of pixels differ (means {a}, {b})", 100.0 * differ);
    }
}

/// The Cornell box at `width` x `width` with a white ball of radius 80 on its short block: the
/// analytic sphere, or the icosphere of subdivision `k` on it, flat or smooth, or smooth with
/// its normals pointing inward (`inward`).
fn cornell_with_ball(width: u32, ball: Option<(u32, bool, bool)>) -> Scene {
    let (shape, obj) = match ball {
        None => ("sphere = { center = [157.95, 245.0, 168.95], radius = 80.0 }".to_owned(), String::new()),
        Some((k, smooth, inward)) => {
            let obj = icosphere_obj(k, false);
            let obj = if !smooth {
                obj
            } else if inward {
                with_vertex_normals(&obj, |p| -p.normalize())
            } else {
                with_vertex_normals(&obj, Vec3::normalize)
            };
            (
                "mesh = { file = \"ball.obj\", translate = [157.95, 245.0, 168.95], scale = 80.0 }"
                    .to_owned(),
                obj,
            )
        }
    };
    let text = format!("{}[[objects]]\nname = \"ball\"\nmaterial = \"white\"\n{shape}\n", cornell_text());
    let mut scene =
        scene_with_files(&text, "cornell.toml", &[("ball.obj", &obj)]).unwrap_or_else(|e| panic!("{e}"));
    scene.camera.width = width;
    scene.camera.height = width;
    scene
}

/// The file's normals never decide a side: normals pointing into the icosphere shade it as the
/// outward ones do, exactly, in both oracles.
#[test]
fn inward_vertex_normals_shade_as_outward_ones() {
    let outward = cornell_with_ball(16, Some((1, true, false)));
    let inward = cornell_with_ball(16, Some((1, true, true)));
    let render = |s: &Scene| Oracle::new(s).unwrap().render(4, 3, illum_oracle::default_threads()).mean;
    assert_eq!(render(&outward), render(&inward));
    let whitted = |s: &Scene| WhittedOracle::new(s).unwrap().render(illum_oracle::default_threads());
    assert_eq!(whitted(&outward), whitted(&inward));
}

/// Smooth shading draws an icosphere of 320 triangles nearer the sphere it approximates than
/// flat shading does (Whitted's f64 copy, deterministic): over the pixels whose ray passes within
/// 0.8 of the radius of the ball's centre (inside both silhouettes), the mean absolute difference
/// from the analytic sphere's image shrinks by more than half.
#[test]
fn a_smooth_icosphere_is_nearer_the_sphere_than_a_flat_one() {
    let render = |ball| {
        let mut oracle = WhittedOracle::new(&cornell_with_ball(48, ball)).unwrap();
        oracle.aa = 1;
        oracle.render(illum_oracle::default_threads())
    };
    let camera = cornell_with_ball(48, None).camera;
    let centre = Vec3::new(157.95, 245.0, 168.95);
    let inside: Vec<usize> = (0..48 * 48)
        .filter(|&p| {
            let d = camera.ray_direction((p % 48) as f32 + 0.5, (p / 48) as f32 + 0.5);
            let to_centre = centre - camera.eye;
            (to_centre - to_centre.dot(d) * d).length() < 0.8 * 80.0
        })
        .collect();
    let sphere = render(None);
    let difference = |image: &[[f64; 3]]| {
        inside.iter().map(|&p| (0..3).map(|c| (image[p][c] - sphere[p][c]).abs()).sum::<f64>()).sum::<f64>()
            / inside.len() as f64
    };
    let flat = difference(&render(Some((2, false, false))));
    let smooth = difference(&render(Some((2, true, false))));
    println!(
        "{} pixels inside the ball: mean absolute difference from the sphere, flat {flat:.5}, smooth {smooth:.5}",
        inside.len()
    );
    assert!(inside.len() > 50, "{} pixels", inside.len());
    assert!(smooth < 0.5 * flat, "smooth {smooth} against flat {flat}");
}

/// No light leaks: a square lit from behind is black in both oracles, though its shading normals
/// face the sun; lit from the front it is not (the control).
#[test]
fn no_light_leaks_through_a_smooth_mesh() {
    for behind in [true, false] {
        let scene = tilted_square(behind);
        let path_traced = Oracle::new(&scene).unwrap().render(16, 5, illum_oracle::default_threads()).mean;
        let whitted = WhittedOracle::new(&scene).unwrap().render(illum_oracle::default_threads());
        let centre = 16 * 32 + 16;
        println!("behind {behind}: path traced {:?}, Whitted {:?}", path_traced[centre], whitted[centre]);
        if behind {
            assert!(path_traced.iter().chain(&whitted).all(|p| *p == [0.0; 3]), "light leaked");
        } else {
            assert!(path_traced[centre][0] > 0.1 && whitted[centre][0] > 0.1);
        }
    }
}

#[test]
fn inside_a_closed_black_mesh_under_a_bright_sky_nothing_is_seen() {
    // A black box around the camera under a sky of radiance 1000, with a sun: any ray that
    // slipped between two triangles would see 1000.
    let corners: [Vec3; 8] = std::array::from_fn(|i| {
        Vec3::new(
            if i & 1 == 0 { -1.3 } else { 2.1 },
            if i & 2 == 0 { -0.7 } else { 1.9 },
            if i & 4 == 0 { -2.2 } else { 0.9 },
        )
    });
    let text = "[camera]\neye = [0.0, 0.0, 0.0]\ntarget = [0.3, 0.2, 1.0]\nup = [0.0, 1.0, 0.0]\nvfov = 120.0\nwidth = 48\nheight = 48\n\
                [environment]\nradiance = [1000.0, 1000.0, 1000.0]\n\
                [directional_light]\ndirection = [0.2, -1.0, 0.1]\nirradiance = [1000.0, 1000.0, 1000.0]\n\
                [materials.black]\nalbedo = [0.0, 0.0, 0.0]\n[[objects]]\nmaterial = \"black\"\nmesh = { file = \"box.obj\" }\n";
    let scene = scene_with_files(text, "inside.toml", &[("box.obj", &box_obj(corners))]).unwrap();
    let image = Oracle::new(&scene).unwrap().render(4, 1, illum_oracle::default_threads());
    assert!(image.mean.iter().all(|p| *p == [0.0; 3]), "light got in");
    let whitted = WhittedOracle::new(&scene).unwrap();
    for i in 0..48 * 48 {
        assert_eq!(whitted.pixel(i % 48, i / 48), [0.0; 3], "pixel {i}");
    }
}

/// The f64 oracle's triangles meet every ray the GPU traversal's watertightness test aims at a
/// shared edge or vertex of a closed cube and icosphere
/// ([`closed_meshes`](illum_scene::testing::obj::closed_meshes); illum-rtcore's
/// tests/mesh_traversal.rs casts the same rays on the GPU), where aimed.
#[test]
fn rays_at_shared_edges_and_vertices_meet_the_oracle_s_triangles() {
    use illum_oracle::geometry::mesh_surfaces;
    for (n, k) in [(1, 0), (2, 1)] {
        let (scene, rays) = illum_scene::testing::obj::closed_meshes(n, k);
        let surfaces: Vec<_> = scene
            .objects
            .iter()
            .flat_map(|o| match &o.shape {
                Shape::Mesh(mesh) => mesh_surfaces(mesh).collect(),
                _ => Vec::new(),
            })
            .collect();
        for ray in &rays {
            let (o, d) = (ray.origin.as_dvec3(), ray.direction.as_dvec3());
            let t = surfaces
                .iter()
                .filter_map(|s| s.intersect(o, d, f64::INFINITY))
                .map(|hit| hit.t)
                .fold(f64::INFINITY, f64::min);
            assert!((t - f64::from(ray.t)).abs() <= 1e-3, "{} triangles: {ray:?} met at {t}", surfaces.len());
        }
        println!("{} triangles: {} rays", surfaces.len(), rays.len());
    }
}
