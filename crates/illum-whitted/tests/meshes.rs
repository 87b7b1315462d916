//! Meshes in the GPU Whitted ray tracer (BVH traversal, watertight triangle test) against the
//! f64 copy of the algorithm with its brute-force triangles (`illum_oracle::whitted`), pixel by
//! pixel by `illum_oracle::whitted_agreement`'s criterion: the Whitted scene with a diffuse, a
//! glass and a mirror icosphere added, at depths 0, 2 and 8, flat and smoothly shaded; a camera
//! inside a closed black mesh under a bright sky sees nothing; and no light leaks through a
//! smooth mesh whose shading normals face a light behind it.

use illum_gpu::testing::gpu;
use illum_oracle::WhittedOracle;
use illum_oracle::whitted_agreement::compare;
use illum_scene::testing::obj::{box_obj, icosphere_obj, scene_with_files, tilted_square};
use illum_scene::{Scene, resolve_scene_path};
use illum_whitted::WhittedTracer;

/// The Whitted scene with three icospheres on its floor: white (subdivision 1), glass and mirror
/// (subdivision 2), flat (the shipped files have no normals) or `smooth` (with their vertex
/// normals).
fn whitted_with_meshes(width: u32, height: u32, smooth: bool) -> Scene {
    let path = resolve_scene_path("scenes/whitted.toml".as_ref());
    let text = std::fs::read_to_string(&path).unwrap();
    let meshes = [
        ("white", 1, [3.0, 0.7, -6.0], 0.7),
        ("glass", 2, [3.2, 0.6, -2.6], 0.6),
        ("metal", 2, [1.5, 0.8, -4.5], 0.8),
    ];
    let added: String = meshes
        .iter()
        .map(|(material, k, [x, y, z], r)| {
            format!(
                "\n[[objects]]\nname = \"{material} icosphere\"\nmaterial = \"{material}\"\n\
                 mesh = {{ file = \"models/icosphere-{k}.obj\", translate = [{x:?}, {y:?}, {z:?}], scale = {r:?} }}\n"
            )
        })
        .collect();
    let text = format!("{text}\n[materials.white]\nalbedo = [0.8, 0.8, 0.8]\n{added}");
    let file = path.display().to_string();
    let mut scene = if smooth {
        let files = [1, 2].map(|k| (format!("models/icosphere-{k}.obj"), icosphere_obj(k, true)));
        let files: Vec<(&str, &str)> =
            files.iter().map(|(name, text)| (name.as_str(), text.as_str())).collect();
        scene_with_files(&text, &file, &files)
    } else {
        Scene::from_toml_str(&text, &file)
    }
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.features().contains(illum_scene::Feature::SmoothShading), smooth);
    scene.camera.width = width;
    scene.camera.height = height;
    scene
}

fn check(name: &str, scene: &Scene) {
    let depth = scene.whitted.depth;
    let image = WhittedTracer::new(gpu(), scene).unwrap_or_else(|e| panic!("{e}")).render().unwrap();
    let oracle = WhittedOracle::new(scene).unwrap_or_else(|e| panic!("{e}"));
    let reference = oracle.render(2);
    if std::env::var_os("ILLUM_SAVE_TEST_IMAGES").is_some() {
        let path = format!("{}/../../target/{name}-depth-{depth}.png", env!("CARGO_MANIFEST_DIR"));
        illum_image::save_png(path, &image, 0.0, illum_image::Encoding::default()).unwrap();
    }
    let comparison = compare(&image, &reference, &oracle, depth);
    println!("{name}, depth {depth}: {}", comparison.summary(depth));
    assert!(comparison.passes(), "{name}, depth {depth}: {comparison:?}");
}

#[test]
fn diffuse_glass_and_mirror_meshes_match_the_f64_copy() {
    for depth in [0, 2, 8] {
        let mut scene = whitted_with_meshes(160, 90, false);
        scene.whitted.depth = depth;
        check("whitted-meshes", &scene);
    }
}

#[test]
fn smooth_diffuse_glass_and_mirror_meshes_match_the_f64_copy() {
    for depth in [0, 2, 8] {
        let mut scene = whitted_with_meshes(160, 90, true);
        scene.whitted.depth = depth;
        check("whitted-smooth-meshes", &scene);
    }
}

/// No light leaks: lit from behind, the square is black, though its shading normals face the
/// sun; lit from the front, its middle is lit (the test's control), as the f64 copy says.
#[test]
fn no_light_leaks_through_a_smooth_mesh() {
    for behind in [true, false] {
        let scene = tilted_square(behind);
        let image = WhittedTracer::new(gpu(), &scene).unwrap_or_else(|e| panic!("{e}")).render().unwrap();
        let centre = image.pixels[16 * 32 + 16];
        let expected = WhittedOracle::new(&scene).unwrap().pixel(16, 16);
        println!("lit from behind: {behind}: centre {centre:?}, f64 copy {expected:?}");
        if behind {
            assert!(image.pixels.iter().all(|p| *p == [0.0; 3]), "light leaked: centre {centre:?}");
            assert_eq!(expected, [0.0; 3]);
        } else {
            assert!(centre[0] > 0.1, "the control is not lit: {centre:?}");
            assert!(
                (f64::from(centre[0]) - expected[0]).abs() < 1e-4 * expected[0],
                "{centre:?} vs {expected:?}"
            );
        }
    }
}

#[test]
fn inside_a_closed_black_mesh_nothing_is_seen() {
    let corners: [glam::Vec3; 8] = std::array::from_fn(|i| {
        glam::Vec3::new(
            if i & 1 == 0 { -1.3 } else { 2.1 },
            if i & 2 == 0 { -0.7 } else { 1.9 },
            if i & 4 == 0 { -2.2 } else { 0.9 },
        )
    });
    let text = "[camera]\neye = [0.0, 0.0, 0.0]\ntarget = [0.3, 0.2, 1.0]\nup = [0.0, 1.0, 0.0]\nvfov = 150.0\nwidth = 96\nheight = 96\n\
                [environment]\nradiance = [1000.0, 1000.0, 1000.0]\n\
                [directional_light]\ndirection = [0.2, -1.0, 0.1]\nirradiance = [1000.0, 1000.0, 1000.0]\n\
                [materials.black]\nalbedo = [0.0, 0.0, 0.0]\n[[objects]]\nmaterial = \"black\"\nmesh = { file = \"box.obj\" }\n";
    let scene = scene_with_files(text, "inside.toml", &[("box.obj", &box_obj(corners))]).unwrap();
    let image = WhittedTracer::new(gpu(), &scene).unwrap().render().unwrap();
    let lit = image.pixels.iter().filter(|p| p.iter().any(|&c| c != 0.0)).count();
    assert_eq!(lit, 0, "{lit} of {} pixels see light through the box", image.pixels.len());
}

/// The module's text without its source spans, which number the composed modules' texts and so
/// move when a module is added to the list.
fn without_spans(module: &str) -> String {
    let mut parts = module.split("Span { start: ");
    let mut out = parts.next().unwrap_or_default().to_owned();
    for part in parts {
        out.push_str("Span");
        out.push_str(part.split_once('}').map_or(part, |(_, rest)| rest));
    }
    out
}

/// A scene without a mesh compiles no BVH code: its pipeline's module is the same, but for
/// source spans, whether the BVH module is on the list of modules it may import or not (as
/// before meshes existed).
#[test]
fn scenes_without_a_mesh_compose_the_same_shader_as_without_the_bvh_module() {
    for name in ["whitted.toml", "cornell.toml"] {
        let scene = illum_scene::testing::shipped_scene(name, 64, 64);
        let geometry = illum_rtcore::Geometry::new(&scene);
        let with = illum_whitted::shader_modules(&scene, &geometry);
        let without: Vec<_> =
            with.iter().filter(|m| m.path != illum_rtcore::shaders::BVH_MODULE.path).cloned().collect();
        assert_eq!(without.len() + 1, with.len());
        let defs = illum_whitted::shader_defs(&scene);
        let compose = |modules: &[illum_gpu::shader::ShaderFile]| {
            let module = illum_gpu::shader::compose(modules, &illum_whitted::WHITTED_SHADER, &defs).unwrap();
            without_spans(&format!("{module:?}"))
        };
        let composed = compose(&with);
        assert!(!composed.contains("bvh"), "{name}");
        assert_eq!(composed, compose(&without), "{name}");
    }
}

/// The object-ID image names a mesh's object for its triangles' pixels: every pixel labelled
/// with an icosphere has its centre ray passing within the icosphere's radius of its centre
/// (its vertices lie on that sphere), and each icosphere labels pixels.
#[test]
fn object_ids_name_the_mesh_a_triangle_belongs_to() {
    let scene = whitted_with_meshes(160, 90, false);
    let ids = WhittedTracer::new(gpu(), &scene).unwrap().object_ids().unwrap();
    let camera = &scene.camera;
    for (index, object) in scene.objects.iter().enumerate() {
        let illum_scene::Shape::Mesh(mesh) = &object.shape else { continue };
        let (centre, radius) = (mesh.placement.translate, mesh.placement.scale);
        let mut labelled = 0;
        for (p, hit) in ids.hit.iter().enumerate() {
            if *hit != Some(index) {
                continue;
            }
            labelled += 1;
            let (x, y) = ((p as u32 % ids.width) as f32 + 0.5, (p as u32 / ids.width) as f32 + 0.5);
            let d = camera.ray_direction(x, y);
            let to_centre = centre - camera.eye;
            let miss = (to_centre - to_centre.dot(d) * d).length();
            assert!(miss <= radius * 1.001, "{}: pixel {p} passes {miss} from its centre", object.name);
        }
        assert!(labelled > 20, "{}: {labelled} pixels", object.name);
    }
}
