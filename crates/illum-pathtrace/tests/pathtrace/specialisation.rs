//! "Model only what a scene requires": each scene's specialised pipeline contains what it uses
//! and nothing else, renders the same image as the generic one (tested in
//! statistics.rs), is cached, and refuses a scene it was not built for.

use illum_pathtrace::PathTracer;
use illum_pathtrace::gpu_scene::GpuScene;
use illum_pathtrace::specialise::{light_choice_module, traversal};
use illum_scene::{Bounces, Overrides, Sampling, Scene};

use crate::common;

fn names_of(scene: &Scene, indices: &[usize]) -> Vec<String> {
    // gpu_scene uploads non-emitters first, in file order.
    let non_emitters: Vec<&str> = scene
        .objects
        .iter()
        .filter(|o| !scene.materials[o.material].is_emitter())
        .map(|o| o.name.as_str())
        .collect();
    indices.iter().map(|&i| non_emitters[i].to_owned()).collect()
}

#[test]
fn each_scene_file_picks_the_specialisation_it_should() {
    // cornell-classic's ceiling and back wall overhang the side walls by 2 units; the overhang's
    // lit face is hidden only by the union of two boxes, which the (conservative) rule does not
    // prove, so its side walls stay in the shadow test. That costs speed, never correctness.
    let cases: [(&str, &[&str]); 2] = [
        ("cornell", &["short block", "tall block"]),
        ("cornell-classic", &["left wall", "right wall", "short block", "tall block"]),
    ];
    for (file, expected_occluders) in cases {
        let scene = common::scene(file, Overrides::default());
        let gpu_scene = GpuScene::new(&scene).expect("uploads");
        let key = traversal(&gpu_scene);
        // Walls, floor, ceiling are axis-aligned boxes, the blocks rotated boxes, the light a quad.
        assert_eq!(key.kind_names(), ["aabb", "box", "quad"], "{file}");
        assert_eq!(gpu_scene.lights.len(), 1, "{file}");
        let mut occluders = names_of(&scene, &key.occluders);
        occluders.sort();
        // A wall cannot shadow a light inside the room; only the blocks can.
        assert_eq!(occluders, expected_occluders, "{file}");
        assert!(!key.source.contains("hit_sphere("), "{file}: a scene without spheres has sphere code");
        assert!(!key.source.contains("surface_sphere("), "{file}: a scene without spheres has sphere code");
        // The path tracer rebuilds surfaces of non-emitters only, and both kinds of box with one
        // function: one reconstruction per hit instead of three.
        let scattering = &key.source[key.source.find("fn scattering_surface_at").expect("generated")..];
        let scattering = &scattering[..scattering.find("\n}\n").expect("ends")];
        assert!(
            scattering.contains("default: { return surface_box(obj, p); }") && !scattering.contains("case "),
            "{file}: {scattering}"
        );
        let choice = light_choice_module(&scene, &gpu_scene).source;
        assert!(
            choice.contains("return 0u;") && !choice.contains("pick <"),
            "{file}: one light needs no selection"
        );
    }
}

/// The Cornell box with a sphere in it and the light split in two.
fn cornell_with_sphere_and_two_lights() -> Scene {
    let text = std::fs::read_to_string(common::workspace_path("scenes/cornell.toml")).expect("readable");
    let light =
        "quad = { corner = [213.0, 555.0, 225.5], edge_u = [130.0, 0.0, 0.0], edge_v = [0.0, 0.0, 105.0] }";
    assert!(text.contains(light), "scenes/cornell.toml's light changed; update this test");
    let text = text.replace(
        light,
        "quad = { corner = [213.0, 555.0, 225.5], edge_u = [65.0, 0.0, 0.0], edge_v = [0.0, 0.0, 105.0] }\n\
         [[objects]]\nname = \"light 2\"\nmaterial = \"light\"\n\
         quad = { corner = [278.0, 555.0, 225.5], edge_u = [65.0, 0.0, 0.0], edge_v = [0.0, 0.0, 105.0] }\n\
         [[objects]]\nname = \"ball\"\nmaterial = \"white\"\nsphere = { center = [150.0, 300.0, 400.0], radius = 60.0 }",
    );
    Scene::from_toml_str(&text, "cornell with a ball and two lights").expect("parses")
}

#[test]
fn a_sphere_and_a_second_light_bring_their_code_and_nothing_else() {
    let scene = cornell_with_sphere_and_two_lights();
    let gpu_scene = GpuScene::new(&scene).expect("uploads");
    let key = traversal(&gpu_scene);
    assert!(key.kind_names().contains(&"sphere"));
    assert_eq!(gpu_scene.lights.len(), 2);
    assert!(
        key.source.contains("hit_sphere(")
            && light_choice_module(&scene, &gpu_scene).source.contains("pick <")
    );
    let occluders = names_of(&scene, &key.occluders);
    assert!(occluders.contains(&"ball".to_owned()), "the ball can shadow the floor: {occluders:?}");

    // The two half lights together give the same image as the one whole light.
    let small = Overrides { width: Some(24), height: Some(24), spp: Some(256), ..Default::default() };
    let mut split = scene.clone();
    split.apply_overrides(&small, "test").expect("valid");
    let mut whole = common::scene("cornell", small);
    // Put the ball into the one-light scene too, so the two differ only in the light's split.
    whole.objects.push(split.objects.iter().find(|o| o.name == "ball").expect("ball").clone());
    let (a, b) = (common::render(&split), common::render(&whole));
    for c in 0..3 {
        let (ma, va) = common::image_mean_and_variance(&a, c);
        let (mb, vb) = common::image_mean_and_variance(&b, c);
        let z = (ma - mb) / (va + vb).sqrt();
        assert!(z.abs() < 4.0, "channel {c}: split lights {ma} vs one light {mb} (z = {z:.2})");
    }
}

#[test]
fn pipelines_are_cached_by_specialisation() {
    let scene = common::scene("cornell", Overrides { width: Some(8), height: Some(8), ..Default::default() });
    let first = PathTracer::new(common::gpu(), &scene).expect("builds");
    // Another seed and resolution: same geometry, same pipeline.
    let other = common::scene(
        "cornell",
        Overrides { width: Some(16), height: Some(4), seed: Some(3), ..Default::default() },
    );
    let second = PathTracer::new(common::gpu(), &other).expect("builds");
    assert!(first.shares_pipeline_with(&second), "an equal specialisation was compiled again");
    // Other geometry: its own pipeline (so the check above can fail).
    let classic =
        common::scene("cornell-classic", Overrides { width: Some(8), height: Some(8), ..Default::default() });
    let third = PathTracer::new(common::gpu(), &classic).expect("builds");
    assert!(!first.shares_pipeline_with(&third), "different geometry reused a pipeline");
}

#[test]
fn a_scene_the_pipeline_was_not_built_for_is_refused() {
    let scene = common::scene(
        "cornell",
        Overrides { width: Some(8), height: Some(8), spp: Some(2), ..Default::default() },
    );
    let mut tracer = PathTracer::new(common::gpu(), &scene).expect("builds");
    tracer.render_to_spp(2).expect("renders");

    // A new camera and settings are fine and restart the accumulation.
    let mut moved = scene.clone();
    moved.camera.eye.x += 10.0;
    moved.pathtrace.seed = 9;
    tracer.update_scene(&moved).expect("camera changes need no new pipeline");
    assert_eq!(tracer.spp_done(), 0);

    // A sphere is a feature this pipeline lacks: an error, never a wrong image.
    let with_ball = cornell_with_sphere_and_two_lights();
    let mut with_ball_small = with_ball.clone();
    with_ball_small.camera = scene.camera;
    let message = match tracer.update_scene(&with_ball_small) {
        Ok(()) => panic!("a scene with a sphere must be refused by a box-only pipeline"),
        Err(e) => e.to_string(),
    };
    assert!(message.contains("sphere") && message.contains("new PathTracer"), "{message}");
}

#[test]
fn a_resize_keeps_the_submission_size_the_caller_chose() {
    // A viewer asks for short submissions; resizing its window rebuilds the buffers but must not
    // bring back the default 0.15 s ones. With a target far below one sample's cost, every
    // submission is the smallest band: one row at 2 spp (samples are traced in pairs, so a pass
    // in bands takes 2 spp, planner.rs). (A fresh planner's first submission would take 16384
    // samples.)
    let scene = common::scene("cornell", common::small(40, 30, 4));
    let mut tracer = PathTracer::new(common::gpu(), &scene).expect("builds");
    tracer.set_target_seconds(1e-9);
    tracer.render_step(None).expect("renders"); // the probe, which measures a sample's cost
    assert_eq!(tracer.render_step(None).expect("renders").samples, 2 * 40, "one row per submission");
    let mut larger = scene.clone();
    larger.camera.width = 52;
    larger.camera.height = 36;
    tracer.update_scene(&larger).expect("same geometry, new size");
    let report = tracer.render_step(None).expect("renders");
    assert_eq!(report.samples, 2 * 52, "after the resize: {} samples in one submission", report.samples);
}

#[test]
fn settings_that_choose_code_rebuild_the_pipeline_on_update() {
    // Hemisphere sampling and Russian roulette are shader defs (on lavapipe code costs time by
    // being in the shader, even where a parameter skips it). A tracer updated to other settings
    // must render exactly what a tracer built for them renders; with the first pipeline kept,
    // the uniform sampler's image would be the cosine one's.
    let base = Overrides { width: Some(16), height: Some(16), spp: Some(16), ..Default::default() };
    let scene = common::scene("cornell", base);
    let changed = common::scene(
        "cornell",
        Overrides { sampling: Some(Sampling::Uniform), bounces: Some(Bounces::Unbounded), ..base },
    );
    let mut updated = PathTracer::new(common::gpu(), &scene).expect("builds");
    updated.add_samples_in_one_pass(16).expect("renders");
    let before = updated.accumulator().mean_image();
    updated.update_scene(&changed).expect("same geometry, other settings");
    updated.add_samples_in_one_pass(16).expect("renders");
    let fresh = common::render(&changed);
    let (a, b) = (updated.accumulator().mean_image(), fresh.accumulator().mean_image());
    assert!(a.pixels == b.pixels, "the updated tracer does not render the new settings' image");
    assert!(before.pixels != a.pixels, "the two settings rendered the same image: the test proves nothing");
}

/// A specialised pipeline reconstructs axis-aligned and rotated boxes with one function,
/// `surface_box` (on lavapipe every case of a switch costs time): an axis-aligned box is
/// uploaded as a box rotated by zero with an error bound of zero. That must change nothing: on
/// the GPU, `surface_box` and `surface_aabb` give bit for bit the same point, normal and bound at
/// points on every face, edge and corner of boxes from 1e-3 to 1e5 units across, near the origin
/// and 1e5 units from it, with each point a few floats off its face as a hit point is.
#[test]
fn a_box_rotated_by_zero_rebuilds_exactly_the_axis_aligned_surface() {
    use glam::Vec3;
    use illum_rtcore::{GpuObject, GpuShape, ObjectRecord, ShapeKind};

    let boxes = [
        (Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 2.0, 3.0)),
        (Vec3::new(-1.0, 555.0, 0.0), Vec3::new(557.0, 557.0, 556.0)),
        (Vec3::new(1e5, -1e5, 1e5), Vec3::new(1e5 + 1e-3, -1e5 + 7.0, 1e5 + 0.5)),
        (Vec3::new(-3e-3, -1e-3, 2e-3), Vec3::new(-2e-3, 1e-3, 3e-3)),
        (Vec3::new(-1e5, -1e5, -1e5), Vec3::new(1e5, 1e5, 1e5)),
    ];
    let records: Vec<ObjectRecord> = boxes
        .iter()
        .map(|&(min, max)| {
            GpuObject { shape: GpuShape::Aabb { min, max }, material: 0, emitter: false }.record()
        })
        .collect();
    assert!(records.iter().all(|r| r.kind == ShapeKind::Aabb.code() && r.a[3] == 1.0 && r.b[3] == 0.0));
    // Points on the faces: the face's coordinate moved by -2..2 floats, the others at the
    // face's edges, corners or inside (a fixed LCG, so failures repeat).
    let mut state = 0x2545f491u32;
    let mut next = move || {
        state = state.wrapping_mul(1664525).wrapping_add(1013904223);
        (state >> 8) as f32 / (1u32 << 24) as f32
    };
    let mut points: Vec<[f32; 4]> = Vec::new();
    for (index, &(min, max)) in boxes.iter().enumerate() {
        for axis in 0..3 {
            for on_max in [false, true] {
                for k in 0..200 {
                    let mut p = [0.0f32; 3];
                    for a in 0..3 {
                        // Corners and edges first, then the inside of the face.
                        let u = match k {
                            0..=3 => ((k >> (a % 2)) & 1) as f32,
                            _ => next(),
                        };
                        p[a] = min[a] + u * (max[a] - min[a]);
                    }
                    let face = if on_max { max[axis] } else { min[axis] };
                    let bits = face.to_bits() as i64 + (k as i64 % 5) - 2;
                    p[axis] = if face == 0.0 { 0.0 } else { f32::from_bits(bits as u32) };
                    points.push([p[0], p[1], p[2], f32::from_bits(index as u32)]);
                }
            }
        }
    }
    let source = "#import illum::rtcore::geometry::{Object, surface_aabb, surface_box}
@group(0) @binding(0) var<storage, read> objects: array<Object>;
@group(0) @binding(1) var<storage, read> points: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> out: array<vec4<u32>>;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= arrayLength(&points)) { return; }
    let obj = objects[bitcast<u32>(points[i].w)];
    let a = surface_aabb(obj, points[i].xyz);
    let b = surface_box(obj, points[i].xyz);
    out[4u * i] = bitcast<vec4<u32>>(vec4<f32>(a.p, a.err));
    out[4u * i + 1u] = bitcast<vec4<u32>>(vec4<f32>(a.n, 0.0));
    out[4u * i + 2u] = bitcast<vec4<u32>>(vec4<f32>(b.p, b.err));
    out[4u * i + 3u] = bitcast<vec4<u32>>(vec4<f32>(b.n, 0.0));
}
";
    let bytes = common::run_compute(
        "surface harness",
        &illum_rtcore::shaders::core_modules(),
        source.into(),
        &[bytemuck::cast_slice(&records), bytemuck::cast_slice(&points)],
        points.len() as u64 * 64,
        ((points.len() as u32).div_ceil(64), 1, 1),
    );
    let words: &[u32] = bytemuck::cast_slice(&bytes);
    let mut compared = 0;
    for (i, point) in points.iter().enumerate() {
        let w = &words[16 * i..16 * i + 16];
        let (aabb, rotated) = (&w[0..8], &w[8..16]);
        assert_eq!(
            aabb,
            rotated,
            "point {:?} on box {}: surface_aabb gives p, err, n = {:?}, surface_box {:?}",
            &point[..3],
            point[3].to_bits(),
            aabb.iter().map(|b| f32::from_bits(*b)).collect::<Vec<_>>(),
            rotated.iter().map(|b| f32::from_bits(*b)).collect::<Vec<_>>()
        );
        // The bound is zero: the point lies on the face's plane exactly.
        assert_eq!(f32::from_bits(aabb[3]), 0.0);
        compared += 1;
    }
    assert_eq!(compared, boxes.len() * 6 * 200);
}
