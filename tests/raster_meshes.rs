//! Triangle meshes in the rasterizer, against the Whitted ray tracer. A Lambertian mesh in the
//! rasterizer is shaded by the Whitted ray tracer's local model (albedo x (ambient + E x N.L x
//! visibility)), with the same rays through the pixel centres (`aa = 1`), so away from edges
//! the two images agree to the rasterizer's 8-bit output: the Whitted scene with a white
//! icosphere on its floor, flat and smooth, and a grey block mesh between it and the light, on
//! the pixels where a mesh is seen lit, facing away or in another mesh's shadow, and on the
//! floor in a mesh's shadow. And the meshes appear in the glass's and the metal's cube maps.

use std::sync::{Mutex, OnceLock};

use glam::Vec3;
use illum_gpu::testing::gpu;
use illum_image::RgbImage32;
use illum_raster::{Look, Options, RasterRenderer, RasterScene};
use illum_scene::testing::obj::{box_obj, icosphere_obj, scene_with_files};
use illum_scene::{Scene, Shape};
use illum_whitted::{ObjectIds, Shadow, WhittedTracer};

const WIDTH: u32 = 320;
const HEIGHT: u32 = 180;

/// Pixels this far (in pixels, either way) from a change of object or of shadow in the Whitted
/// tracer's object-ID image are not compared: a silhouette, a shadow's edge and the
/// rasterizer's soft shadow edge, which reaches 1.5 x pcf_radius = 0.075 units, 2.6 pixels here.
const EDGE_PIXELS: i32 = 3;

/// The most two 8-bit levels may differ: 1 for the rasterizer's rounding to 8 bits, 1 for f32
/// rounding and the rasterizer's interpolated positions.
const LEVELS: i32 = 2;

/// The Whitted scene at WIDTH x HEIGHT with one ray per pixel, and, with `meshes`, a white
/// icosphere of 320 triangles (radius 0.7) on its floor, flat or `smooth`, and a grey block
/// (0.4 units, a box mesh of 12 triangles) floating between the icosphere and the light, whose
/// shadow falls on the icosphere's top.
fn whitted_scene(meshes: bool, smooth: bool) -> Scene {
    let path = illum_scene::resolve_scene_path("scenes/whitted.toml".as_ref());
    let mut text = std::fs::read_to_string(&path).unwrap();
    text.push_str(
        "\n[materials.white]\nalbedo = [0.8, 0.8, 0.8]\n[materials.grey]\nalbedo = [0.4, 0.5, 0.6]\n",
    );
    if meshes {
        text.push_str(
            "[[objects]]\nname = \"ball\"\nmaterial = \"white\"\n\
             mesh = { file = \"ball.obj\", translate = [3.0, 0.7, -6.0], scale = 0.7 }\n\
             [[objects]]\nname = \"block\"\nmaterial = \"grey\"\nmesh = { file = \"block.obj\" }\n",
        );
    }
    let corners: [Vec3; 8] = std::array::from_fn(|i| {
        Vec3::new(
            if i & 1 == 0 { 4.0 } else { 4.4 },
            if i & 2 == 0 { 2.07 } else { 2.47 },
            if i & 4 == 0 { -6.44 } else { -6.04 },
        )
    });
    let (ball, block) = (icosphere_obj(2, smooth), box_obj(corners));
    let mut scene =
        scene_with_files(&text, &path.display().to_string(), &[("ball.obj", &ball), ("block.obj", &block)])
            .unwrap_or_else(|e| panic!("{e}"));
    scene.camera.width = WIDTH;
    scene.camera.height = HEIGHT;
    scene.whitted.aa = 1;
    scene
}

/// `scene` drawn by the rasterizer with every effect of `look` on, by one renderer for the test
/// binary (its pipelines are compiled once).
fn render_raster(scene: &Scene, look: Look) -> RgbImage32 {
    static RENDERER: OnceLock<Mutex<RasterRenderer>> = OnceLock::new();
    let raster_scene = RasterScene::from_scene(scene).unwrap_or_else(|e| panic!("{e}"));
    let mut renderer = RENDERER
        .get_or_init(|| {
            Mutex::new(
                RasterRenderer::new(gpu(), &raster_scene, WIDTH, HEIGHT).unwrap_or_else(|e| panic!("{e}")),
            )
        })
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    renderer.set_scene(&raster_scene).unwrap_or_else(|e| panic!("{e}"));
    renderer.render(&Options::all_on(look)).unwrap_or_else(|e| panic!("{e}"))
}

fn level(v: f32) -> i32 {
    (v * 255.0).round() as i32
}

/// Whether pixel (x, y) and every pixel within EDGE_PIXELS of it see the same object in the same
/// shadow.
fn interior(ids: &ObjectIds, x: i32, y: i32) -> bool {
    let at = |x: i32, y: i32| (y * ids.width as i32 + x) as usize;
    let (w, h) = (ids.width as i32, ids.height as i32);
    let here = at(x, y);
    (-EDGE_PIXELS..=EDGE_PIXELS).all(|dy| {
        (-EDGE_PIXELS..=EDGE_PIXELS).all(|dx| {
            let (u, v) = (x + dx, y + dy);
            (0..w).contains(&u)
                && (0..h).contains(&v)
                && ids.hit[at(u, v)] == ids.hit[here]
                && ids.shadow[at(u, v)] == ids.shadow[here]
        })
    })
}

/// Whether the Whitted image is the same, to a level, over pixel (x, y)'s 3 x 3 neighbourhood:
/// no border of the floor's checker runs through it (the rasterizer filters the checker over
/// the pixel, the ray tracer samples it at the centre).
fn flat_neighbourhood(image: &RgbImage32, x: i32, y: i32) -> bool {
    let value = |x: i32, y: i32| image.pixels[(y * image.width as i32 + x) as usize].map(level);
    let here = value(x, y);
    (-1..=1).all(|dy| (-1..=1).all(|dx| (0..3).all(|c| (value(x + dx, y + dy)[c] - here[c]).abs() <= 1)))
}

#[test]
fn lambertian_meshes_match_the_whitted_ray_tracer() {
    for smooth in [false, true] {
        let scene = whitted_scene(true, smooth);
        let meshes: Vec<usize> =
            (0..scene.objects.len()).filter(|&i| matches!(scene.objects[i].shape, Shape::Mesh(_))).collect();
        let floor = scene.objects.iter().position(|o| o.name == "floor").unwrap();
        let raster = render_raster(&scene, Look::Figure);
        let tracer = WhittedTracer::new(gpu(), &scene).unwrap_or_else(|e| panic!("{e}"));
        let whitted = tracer.render().unwrap();
        let ids = tracer.object_ids().unwrap();
        // lit mesh, mesh facing away, mesh in another mesh's shadow, floor in a mesh's shadow
        let mut counts = [0usize; 4];
        let mut worst = 0;
        let mut failures = Vec::new();
        for y in EDGE_PIXELS..HEIGHT as i32 - EDGE_PIXELS {
            for x in EDGE_PIXELS..WIDTH as i32 - EDGE_PIXELS {
                let p = (y * WIDTH as i32 + x) as usize;
                if !interior(&ids, x, y) {
                    continue;
                }
                let class = match (ids.hit[p], ids.shadow[p]) {
                    (Some(i), Shadow::Lit) if meshes.contains(&i) => 0,
                    (Some(i), Shadow::FacingAway) if meshes.contains(&i) => 1,
                    (Some(i), Shadow::BlockedBy(b)) if meshes.contains(&i) && meshes.contains(&b) => 2,
                    (Some(i), Shadow::BlockedBy(b)) if i == floor && meshes.contains(&b) => 3,
                    _ => continue,
                };
                if class == 3 && !flat_neighbourhood(&whitted, x, y) {
                    continue;
                }
                counts[class] += 1;
                let (a, b) = (raster.pixels[p].map(level), whitted.pixels[p].map(level));
                let difference = (0..3).map(|c| (a[c] - b[c]).abs()).max().unwrap();
                worst = worst.max(difference);
                if difference > LEVELS {
                    failures.push((x, y, a, b));
                }
            }
        }
        println!(
            "smooth {smooth}: compared {counts:?} pixels (lit mesh, mesh facing away, mesh in a mesh's \
             shadow, floor in a mesh's shadow); largest difference {worst} levels, {} beyond {LEVELS}",
            failures.len()
        );
        if !failures.is_empty() || std::env::var_os("ILLUM_SAVE_TEST_IMAGES").is_some() {
            let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/target");
            let stem = format!("raster-meshes-smooth-{smooth}");
            illum_image::save_diff_images(dir, &stem, &raster, &whitted).unwrap();
        }
        assert!(
            failures.is_empty(),
            "smooth {smooth}: {} pixels differ, first {:?}",
            failures.len(),
            &failures[..failures.len().min(5)]
        );
        assert!(
            counts[0] >= 300 && counts[1] >= 30 && counts[2] >= 30 && counts[3] >= 10,
            "smooth {smooth}: too few pixels to compare: {counts:?}"
        );
    }
}

/// The meshes are in the cube maps: the enhanced look's glass (refracting and reflecting its
/// cube map) and metal (mirroring its own) change when the meshes are added.
#[test]
fn meshes_appear_in_the_cube_maps() {
    let with = whitted_scene(true, true);
    let without = whitted_scene(false, true);
    let (a, b) = (render_raster(&with, Look::Enhanced), render_raster(&without, Look::Enhanced));
    let tracer = WhittedTracer::new(gpu(), &without).unwrap_or_else(|e| panic!("{e}"));
    let ids = tracer.object_ids().unwrap();
    let index = |name: &str| without.objects.iter().position(|o| o.name == name).unwrap();
    let (glass, metal) = (index("glass sphere"), index("metal sphere"));
    let changed = |object: usize| {
        (0..a.pixels.len())
            .filter(|&p| ids.hit[p] == Some(object))
            .filter(|&p| (0..3).any(|c| (level(a.pixels[p][c]) - level(b.pixels[p][c])).abs() > LEVELS))
            .count()
    };
    let (in_glass, in_metal) = (changed(glass), changed(metal));
    println!("pixels changed by the meshes: {in_glass} on the glass sphere, {in_metal} on the metal sphere");
    assert!(in_glass >= 20 && in_metal >= 20, "glass {in_glass}, metal {in_metal}");
}
