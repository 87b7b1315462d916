//! Meshes in the oracles: a box given as 12 triangles draws the image the analytic box draws,
//! in the path-tracing oracle and in Whitted's, with the same random numbers; and a camera inside
//! a closed black mesh sees no light through its shared edges and vertices.

use glam::Vec3;
use illum_oracle::{Oracle, WhittedOracle};
use illum_scene::testing::obj::{box_obj, scene_with_files};
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

#[test]
fn smooth_shading_is_refused_by_name() {
    let text =
        format!("{}[[objects]]\nmaterial = \"white\"\nmesh = {{ file = \"t.obj\" }}\n", cornell_text());
    let obj = "v 100 100 100\nv 200 100 100\nv 100 200 100\nvn 0 0 -1\nf 1//1 2//1 3//1\n";
    let scene = scene_with_files(&text, "cornell.toml", &[("t.obj", obj)]).unwrap();
    for err in
        [Oracle::new(&scene).unwrap_err().to_string(), WhittedOracle::new(&scene).unwrap_err().to_string()]
    {
        assert!(err.contains("objects[8], file \"t.obj\": the"), "{err}");
        assert!(err.contains("cannot render a triangle mesh with vertex normals"), "{err}");
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
