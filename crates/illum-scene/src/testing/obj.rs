//! Meshes for tests: OBJ text of simple closed shapes, and scenes loaded with their mesh files
//! from memory.

use std::collections::BTreeMap;

use glam::{DVec3, Vec3};

use crate::error::SceneError;
use crate::scene::Scene;

/// OBJ text of the closed box with these corners (bit 0, 1, 2 of the index pick the max side in
/// x, y, z, as [`BoxShape::world_corners`](crate::BoxShape::world_corners) gives them): 12
/// triangles, each wound counter-clockwise seen from outside (its front normal points out).
pub fn box_obj(corners: [Vec3; 8]) -> String {
    let mut text: String = corners.iter().map(|c| format!("v {:?} {:?} {:?}\n", c.x, c.y, c.z)).collect();
    let centre: DVec3 = corners.iter().map(|c| c.as_dvec3()).sum::<DVec3>() / 8.0;
    for axis in 0..3 {
        let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
        for side in 0..2 {
            // The face's corners in a cycle around it.
            let ring = [(0, 0), (1, 0), (1, 1), (0, 1)].map(|(i, j)| side << axis | i << b | j << c);
            let p = ring.map(|i| corners[i].as_dvec3());
            let outward = (p[1] - p[0]).cross(p[2] - p[0]).dot((p[0] + p[2]) / 2.0 - centre) > 0.0;
            let order = if outward { [0, 1, 2, 3] } else { [0, 3, 2, 1] };
            let [a, b, c, d] = order.map(|k| ring[k] + 1);
            text.push_str(&format!("f {a} {b} {c}\nf {a} {c} {d}\n"));
        }
    }
    text
}

/// `obj` (OBJ text whose faces name vertices only, `f a b c`) with one normal per vertex,
/// `normal(position)`, each face's corners naming their vertex's normal (`f a//a b//b c//c`).
pub fn with_vertex_normals(obj: &str, normal: impl Fn(Vec3) -> Vec3) -> String {
    let mut vertices = String::new();
    let mut normals = String::new();
    let mut faces = String::new();
    for line in obj.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let p: Vec<f32> = words.map(|w| w.parse().expect("a number")).collect();
                let n = normal(Vec3::new(p[0], p[1], p[2]));
                vertices.push_str(line);
                vertices.push('\n');
                normals.push_str(&format!("vn {:?} {:?} {:?}\n", n.x, n.y, n.z));
            }
            Some("f") => {
                let corners: Vec<String> = words.map(|i| format!("{i}//{i}")).collect();
                faces.push_str(&format!("f {}\n", corners.join(" ")));
            }
            _ => {}
        }
    }
    format!("{vertices}{normals}{faces}")
}

/// The shipped icosphere of subdivision `k` (scenes/models/icosphere-K.obj, on the unit sphere,
/// wound counter-clockwise from outside), with its outward unit normals when `smooth`.
pub fn icosphere_obj(k: u32, smooth: bool) -> String {
    let path = crate::resolve_scene_path(std::path::Path::new(&format!("scenes/models/icosphere-{k}.obj")));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    if smooth { with_vertex_normals(&text, Vec3::normalize) } else { text }
}

/// A two-triangle square facing the camera, its vertex normals tilted 70 degrees toward +x,
/// lit only by a sun from behind the square (`behind`) or in front of it, up and to the +x
/// side: the shading normals face the sun either way.
pub fn tilted_square(behind: bool) -> Scene {
    let n = Vec3::new(70f32.to_radians().sin(), 0.0, 70f32.to_radians().cos());
    let obj = format!(
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvn {} {} {}\nf 1//1 2//1 3//1\nf 1//1 3//1 4//1\n",
        n.x, n.y, n.z
    );
    let z = if behind { 1.0 } else { -0.2 };
    let text = format!(
        "[camera]\neye = [0.0, 0.0, 4.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\nvfov = 30.0\nwidth = 32\nheight = 32\n\
         [directional_light]\ndirection = [-1.0, -0.3, {z:?}]\nirradiance = [3.0, 3.0, 3.0]\n\
         [materials.white]\nalbedo = [0.8, 0.8, 0.8]\n[[objects]]\nmaterial = \"white\"\nmesh = {{ file = \"square.obj\" }}\n"
    );
    scene_with_files(&text, "square.toml", &[("square.obj", &obj)]).unwrap_or_else(|e| panic!("{e}"))
}

/// Loads scene `text` (labelled `file`) with its mesh files from `files` (name as the scene
/// gives it, then the file's text).
pub fn scene_with_files(text: &str, file: &str, files: &[(&str, &str)]) -> Result<Scene, SceneError> {
    let files: BTreeMap<&str, &str> = files.iter().copied().collect();
    Scene::from_toml_str_with(text, file, &mut |name: &str| {
        files
            .get(name)
            .map(|t| t.as_bytes().to_vec())
            .ok_or_else(|| format!("cannot read {name}: no such file"))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vertex_normals_are_added_to_every_corner() {
        let text = with_vertex_normals("v 0 0 0\nv 2 0 0\nv 0 2 0\nf 1 2 3\n", |p| p + Vec3::Z);
        assert_eq!(
            text,
            "v 0 0 0\nv 2 0 0\nv 0 2 0\nvn 0.0 0.0 1.0\nvn 2.0 0.0 1.0\nvn 0.0 2.0 1.0\nf 1//1 2//2 3//3\n"
        );
        let smooth = icosphere_obj(1, true);
        assert_eq!(smooth.lines().filter(|l| l.starts_with("vn ")).count(), 42);
        assert_eq!(smooth.lines().filter(|l| l.starts_with("f ")).count(), 80);
    }

    #[test]
    fn a_box_is_closed_and_faces_out() {
        let corners: [Vec3; 8] = std::array::from_fn(|i| {
            Vec3::new((i & 1) as f32, (i >> 1 & 1) as f32 * 2.0, (i >> 2 & 1) as f32 * 3.0)
        });
        let text = box_obj(corners);
        let faces: Vec<[usize; 3]> = text
            .lines()
            .filter_map(|l| l.strip_prefix("f "))
            .map(|f| {
                let v: Vec<usize> = f.split(' ').map(|i| i.parse::<usize>().unwrap() - 1).collect();
                [v[0], v[1], v[2]]
            })
            .collect();
        assert_eq!(faces.len(), 12);
        // Closed and consistently wound: every directed edge appears once, and its reverse once.
        let mut edges = BTreeMap::new();
        for f in &faces {
            for k in 0..3 {
                *edges.entry((f[k], f[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        assert!(edges.iter().all(|(&(a, b), &n)| n == 1 && edges.get(&(b, a)) == Some(&1)));
        // Outward: the signed volume (divergence theorem) is the box's, 6.
        let p = |i: usize| corners[i].as_dvec3();
        let volume: f64 = faces.iter().map(|f| p(f[0]).dot(p(f[1]).cross(p(f[2]))) / 6.0).sum();
        assert!((volume - 6.0).abs() < 1e-9, "{volume}");
    }
}
