//! Mesh objects: an OBJ file read relative to the scene, placed, and every way a file can be
//! wrong refused with the object, the file and (where one line is at fault) the line.

use std::collections::BTreeMap;

use glam::Vec3;
use illum_scene::testing::check_invalid;
use illum_scene::{Feature, Scene, SceneError, Shape, TriangleMesh};

const FILE: &str = "scenes/mesh.toml";

/// A scene with one mesh object, `objects[0] ("ball")`, whose table ends in `MESH`.
const BASE: &str = r#"
[camera]
eye = [0.0, 0.0, -5.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 45.0
width = 8
height = 8
[materials.grey]
albedo = [0.5, 0.5, 0.5]
[materials.lamp]
emission = [1.0, 1.0, 1.0]
[[objects]]
name = "ball"
material = "grey"
mesh = { file = "models/t.obj" MESH}
"#;

/// One triangle in the plane z = 0, its front toward -z, and a square as a quad face.
const OBJ: &str = "# a triangle and a square\nv 0 0 0\nv 0 1 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nv 3 1 0\nv 2 1 0\nf 1 2 3\nf 4 5 6 7\n";

fn load_with(scene: &str, files: &[(&str, &str)]) -> Result<Scene, SceneError> {
    let files: BTreeMap<String, Vec<u8>> =
        files.iter().map(|(name, text)| (name.to_string(), text.as_bytes().to_vec())).collect();
    Scene::from_toml_str_with(scene, FILE, &mut |name: &str| {
        files.get(name).cloned().ok_or_else(|| format!("cannot read {name}: no such file"))
    })
}

fn scene(mesh_keys: &str, obj: &str) -> Result<Scene, SceneError> {
    load_with(&BASE.replace(" MESH", mesh_keys), &[("models/t.obj", obj)])
}

fn mesh(scene: &Scene) -> &TriangleMesh {
    match &scene.objects[0].shape {
        Shape::Mesh(mesh) => mesh,
        other => panic!("not a mesh: {other:?}"),
    }
}

fn expect_file_error(keys: &str, obj: &str, allowed: &str) {
    match scene(keys, obj) {
        Ok(s) => panic!("expected {allowed:?}, but the scene loaded: {:?}", mesh(&s)),
        Err(e) => check_invalid(&e, FILE, "objects[0] (\"ball\").mesh.file", "\"models/t.obj\"", allowed),
    }
}

#[test]
fn a_mesh_is_read_triangulated_and_placed() {
    let s = scene("", OBJ).unwrap();
    let m = mesh(&s);
    assert_eq!(m.triangles.len(), 3, "a triangle and a square of two");
    assert_eq!(m.triangle(0), [Vec3::ZERO, Vec3::Y, Vec3::X]);
    assert!(!m.smooth());
    assert_eq!(m.dropped_degenerate, 0);
    assert!(s.features().contains(Feature::MeshShape));
    assert!(!s.features().contains(Feature::SmoothShading));

    // world = translate + scale R local, R = R_z R_y R_x: 90 degrees about +Y takes +X to -Z.
    let placed =
        scene(", translate = [10.0, 0.0, 0.0], scale = 2.0, rotate = [0.0, 90.0, 0.0]", OBJ).unwrap();
    let [a, b, c] = mesh(&placed).triangle(0);
    for (got, want) in
        [(a, Vec3::new(10.0, 0.0, 0.0)), (b, Vec3::new(10.0, 2.0, 0.0)), (c, Vec3::new(10.0, 0.0, -2.0))]
    {
        assert!((got - want).length() < 1e-5, "{got} != {want}");
    }
}

#[test]
fn vertex_normals_shade_smoothly_unless_flat_is_asked() {
    let obj = "v 0 0 0\nv 0 1 0\nv 1 0 0\nvn 0 0 -2\nf 1//1 2//1 3//1\n";
    let smooth = scene(", rotate = [0.0, 90.0, 0.0]", obj).unwrap();
    let normals = mesh(&smooth).normals.as_ref().expect("normals");
    // Unit length, turned with the mesh: -Z under R_y(90) is -X.
    assert!(normals.iter().all(|n| (*n - Vec3::NEG_X).length() < 1e-6), "{normals:?}");
    assert!(smooth.features().contains(Feature::SmoothShading));
    let flat = scene(", flat = true", obj).unwrap();
    assert!(!mesh(&flat).smooth() && !flat.features().contains(Feature::SmoothShading));
    expect_file_error(
        "",
        "v 0 0 0\nv 0 1 0\nv 1 0 0\nvn 0 0 0\nf 1//1 2//1 3//1\n",
        "a vertex normal is zero",
    );
}

#[test]
fn a_missing_file_is_named() {
    let err = load_with(&BASE.replace(" MESH", ""), &[]).unwrap_err();
    check_invalid(
        &err,
        FILE,
        "objects[0] (\"ball\").mesh.file",
        "\"models/t.obj\"",
        "cannot read models/t.obj",
    );
}

#[test]
fn a_file_is_read_relative_to_the_scene_file() {
    let folder = std::env::temp_dir().join(format!("illum-mesh-test-{}", std::process::id()));
    std::fs::create_dir_all(folder.join("models")).unwrap();
    std::fs::write(folder.join("models/t.obj"), OBJ).unwrap();
    let path = folder.join("mesh.toml");
    std::fs::write(&path, BASE.replace(" MESH", "")).unwrap();
    let loaded = Scene::load(&path);
    std::fs::remove_dir_all(&folder).unwrap();
    assert_eq!(mesh(&loaded.unwrap()).triangles.len(), 3);
}

#[test]
fn bad_files_are_refused_with_file_and_line() {
    expect_file_error("", "v 0 0 0\nv 0 1 0\nv 1 zero 0\nf 1 2 3\n", "models/t.obj:3: ");
    expect_file_error(
        "",
        "v 0 0 0\nv 0 1 0\nv 1 0 0\nf 1 2 4\n",
        "models/t.obj:4: face vertex index out of bounds",
    );
    expect_file_error(
        "",
        "v 0 0 0\nv 0 nan 0\nv 1 0 0\nf 1 2 3\n",
        "models/t.obj:2: a vertex has a non-finite coordinate",
    );
    expect_file_error("", "v 0 0 0\nv 0 1 0\nv 1 0 0\n", "models/t.obj: has no faces");
    expect_file_error("", "v 0 0 0\nv 0 0 0\nv 1 1 1\nf 1 2 3\nf 1 3 3\n", "all 2 triangles are degenerate");
}

#[test]
fn degenerate_triangles_are_dropped_and_counted() {
    let obj = format!("{OBJ}f 1 1 2\nv 4 4 4\nv 5 5 5\nv 6 6 6\nf 8 9 10\n");
    let s = scene("", &obj).unwrap();
    assert_eq!((mesh(&s).triangles.len(), mesh(&s).dropped_degenerate), (3, 2));
    assert_eq!(
        s.notes(),
        [format!(
            "{FILE}: objects[0] (\"ball\"): \"models/t.obj\": 2 of its triangles dropped: degenerate (repeated or \
             collinear vertices, no area)"
        )]
    );
    assert!(scene("", OBJ).unwrap().notes().is_empty());
}

#[test]
fn placements_are_checked() {
    let field = "objects[0] (\"ball\").mesh.scale";
    for (keys, value) in [(", scale = 0.0", "0"), (", scale = -1.0", "-1")] {
        check_invalid(&scene(keys, OBJ).unwrap_err(), FILE, field, value, "must be > 0");
    }
    let err = scene(", rotate = [0.0, nan, 0.0]", OBJ).unwrap_err();
    check_invalid(&err, FILE, "objects[0] (\"ball\").mesh.rotate", "[0, nan, 0]", "finite");
    expect_file_error(", scale = 1e38", "v 0 0 0\nv 0 10 0\nv 10 0 0\nf 1 2 3\n", "vertex 2 of the file");
}

#[test]
fn an_emissive_mesh_is_refused_by_name() {
    let text = BASE.replace(" MESH", "").replace("material = \"grey\"", "material = \"lamp\"");
    let err = load_with(&text, &[("models/t.obj", OBJ)]).unwrap_err();
    check_invalid(&err, FILE, "objects[0] (\"ball\").material", "\"lamp\"", "this object is a mesh");
}

#[test]
fn a_mesh_with_another_shape_is_refused() {
    let text = BASE.replace(" MESH}", "}\nsphere = { center = [0.0, 0.0, 0.0], radius = 1.0 }");
    let err = load_with(&text, &[("models/t.obj", OBJ)]).unwrap_err();
    check_invalid(
        &err,
        FILE,
        "objects[0] (\"ball\")",
        "(both sphere and mesh)",
        "exactly one of box, quad, sphere, mesh",
    );
}

#[test]
fn the_content_hash_covers_the_file_bytes_and_the_placement() {
    let hash = |keys: &str, obj: &str| scene(keys, obj).unwrap().content_hash();
    let base = hash("", OBJ);
    assert_eq!(hash("", OBJ), base);
    assert_ne!(hash("", &format!("{OBJ}# one more comment\n")), base, "any byte of the file");
    assert_ne!(hash(", scale = 1.5", OBJ), base);
    assert_ne!(hash(", translate = [0.0, 0.0, 1.0]", OBJ), base);
    assert_ne!(hash(", rotate = [0.0, 0.0, 1.0]", OBJ), base);
    let obj = "v 0 0 0\nv 0 1 0\nv 1 0 0\nvn 0 0 -1\nf 1//1 2//1 3//1\n";
    assert_ne!(hash("", obj), hash(", flat = true", obj), "smooth and flat shading differ");
}

#[test]
fn a_mesh_far_from_the_world_origin_is_measured_from_the_eye() {
    // The mesh's own vertices are far out (the placement is zero): the frame follows them.
    let far = BASE
        .replace("eye = [0.0, 0.0, -5.0]", "eye = [1e6, 0.0, -5.0]")
        .replace("target = [0.0, 0.0, 0.0]", "target = [1e6, 0.0, 0.0]")
        .replace(" MESH", "");
    let obj = "v 1000000 0 0\nv 1000000 1 0\nv 1000001 0 0\nf 1 2 3\n";
    let s = load_with(&far, &[("models/t.obj", obj)]).unwrap();
    assert_eq!(s.origin, glam::DVec3::new(1e6, 0.0, -5.0));
    assert_eq!(
        mesh(&s).triangle(0),
        [Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.0, 1.0, 5.0), Vec3::new(1.0, 0.0, 5.0)]
    );
}

/// OBJ text (vertices and triangles only) as an ASCII PLY file of the same vertices and faces.
fn obj_as_ply(obj: &str) -> String {
    let vertices: Vec<&str> = obj.lines().filter_map(|l| l.strip_prefix("v ")).collect();
    let faces: Vec<Vec<usize>> = obj
        .lines()
        .filter_map(|l| l.strip_prefix("f "))
        .map(|f| f.split_whitespace().map(|i| i.parse::<usize>().unwrap() - 1).collect())
        .collect();
    let mut text = format!(
        "ply\nformat ascii 1.0\ncomment from OBJ\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        vertices.len(),
        faces.len()
    );
    for v in &vertices {
        text.push_str(&format!("{v}\n"));
    }
    for f in &faces {
        let corners: Vec<String> = f.iter().map(usize::to_string).collect();
        text.push_str(&format!("{} {}\n", f.len(), corners.join(" ")));
    }
    text
}

/// A file named `*.ply` is read as PLY: the same vertices and faces as an OBJ file give the same
/// placed triangles; a PLY file's errors name the object, the file and the line.
#[test]
fn a_ply_file_gives_the_mesh_its_obj_twin_gives() {
    let keys = ", translate = [0.5, 0.0, 1.0], scale = 2.0, rotate = [0.0, 30.0, 0.0]";
    let from_obj = scene(keys, OBJ).unwrap();
    let ply_scene = BASE.replace(" MESH", keys).replace("models/t.obj", "models/t.PLY");
    let from_ply = load_with(&ply_scene, &[("models/t.PLY", &obj_as_ply(OBJ))]).unwrap();
    let (a, b) = (mesh(&from_obj), mesh(&from_ply));
    assert_eq!((&a.positions, &a.triangles), (&b.positions, &b.triangles));
    assert_eq!(a.triangles.len(), 3);

    let broken = obj_as_ply(OBJ).replace("\n3 0 1 2\n", "\n3 0 1 7\n");
    let err = load_with(&ply_scene, &[("models/t.PLY", &broken)]).unwrap_err();
    check_invalid(
        &err,
        FILE,
        "objects[0] (\"ball\").mesh.file",
        "\"models/t.PLY\"",
        "models/t.PLY:18: a face refers to vertex 7 of a file with 7 vertices",
    );
}
