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

/// OBJ text of the cube [-1, 1]^3 with each face cut into `n` x `n` squares of two triangles
/// each (12 n^2 triangles), wound counter-clockwise from outside. For n a power of two every
/// vertex, and the midpoint of every edge, is exact in f32.
pub fn grid_cube_obj(n: u32) -> String {
    let mut index = BTreeMap::new();
    let mut text = String::new();
    let mut vertex = |p: [i64; 3], text: &mut String| {
        let next = index.len() + 1;
        *index.entry(p).or_insert_with(|| {
            let c = p.map(|k| 2.0 * k as f64 / f64::from(n) - 1.0);
            text.push_str(&format!("v {:?} {:?} {:?}\n", c[0], c[1], c[2]));
            next
        })
    };
    let n = i64::from(n);
    let mut faces = String::new();
    for axis in 0..3 {
        let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
        for side in [0, n] {
            for i in 0..n {
                for j in 0..n {
                    let corner = |di: i64, dj: i64| {
                        let mut p = [0; 3];
                        (p[axis], p[b], p[c]) = (side, i + di, j + dj);
                        p
                    };
                    // (b, c, axis) is right-handed: the ring below runs counter-clockwise seen
                    // from +axis, so the far side keeps it and the near side reverses it.
                    let mut ring = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)];
                    if side == 0 {
                        ring.reverse();
                    }
                    let [p, q, r, t] = ring.map(|corner| vertex(corner, &mut text));
                    faces.push_str(&format!("f {p} {q} {r}\nf {p} {r} {t}\n"));
                }
            }
        }
    }
    text + &faces
}

/// A ray aimed at a point of a mesh: from `origin` along the unit `direction`, reaching the
/// point after `t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AimedRay {
    pub origin: Vec3,
    pub direction: Vec3,
    pub t: f32,
}

/// Rays aimed at every vertex of `mesh` and at the f32 midpoint of every edge, for a closed
/// convex mesh around `centre`: from `centre` out; from 3 units outside in, toward `centre` and
/// tilted off that line, each entering every face that meets the point at more than 3 degrees
/// from grazing (so the point is where the ray first meets the mesh); and, where one coordinate
/// of the point's offset from `centre` is strictly the largest in magnitude (inside a face of a
/// cube), along that axis, exactly as f32 holds it. Each ray meets the mesh, and first at the
/// point: one that misses passed between the triangles that share the point.
pub fn rays_at_edges_and_vertices(mesh: &crate::TriangleMesh, centre: Vec3) -> Vec<AimedRay> {
    let mut faces_at: BTreeMap<[u32; 3], Vec<Vec3>> = BTreeMap::new();
    let key = |p: Vec3| p.to_array().map(f32::to_bits);
    for (i, corners) in mesh.triangles.iter().enumerate() {
        let [a, b, c] = mesh.triangle(i);
        let normal = (b - a).cross(c - a).normalize();
        let mut at = |p: Vec3| faces_at.entry(key(p)).or_default().push(normal);
        for k in 0..3 {
            let (u, v) = (corners[k], corners[(k + 1) % 3]);
            let (p, q) = (mesh.positions[u as usize], mesh.positions[v as usize]);
            at(p);
            // Both triangles of an edge round its midpoint alike (f32 addition commutes).
            at((p + q) * 0.5);
        }
    }
    let mut rays = Vec::new();
    for (bits, normals) in &faces_at {
        let point = Vec3::from_array(bits.map(f32::from_bits));
        let offset = point - centre;
        rays.push(AimedRay { origin: centre, direction: offset.normalize(), t: offset.length() });
        let radial = offset.normalize();
        let (t1, t2) = radial.any_orthonormal_pair();
        let entering = |d: Vec3| normals.iter().all(|n| n.dot(d) < -(3f32.to_radians().sin()));
        for (a, b) in [(0.0, 0.0), (0.6, 0.0), (0.0, -0.6), (-0.4, 0.45), (0.3, 0.3)] {
            let direction = -(radial + a * t1 + b * t2).normalize();
            if entering(direction) {
                rays.push(AimedRay { origin: point - 3.0 * direction, direction, t: 3.0 });
            }
        }
        let magnitude = offset.abs();
        let axis = magnitude.max_position();
        if (0..3).all(|k| k == axis || magnitude[k] < magnitude[axis]) {
            let mut direction = Vec3::ZERO;
            direction[axis] = -offset[axis].signum();
            if entering(direction) {
                rays.push(AimedRay { origin: point - 3.0 * direction, direction, t: 3.0 });
            }
        }
    }
    rays
}

/// Two closed meshes: the cube [`grid_cube_obj`]`(n)` at the origin and the icosphere of
/// subdivision `k` at (10, 0, 0), under a sun (so that every object can block a light), with
/// [`rays_at_edges_and_vertices`] of each about its own centre.
pub fn closed_meshes(n: u32, k: u32) -> (Scene, Vec<AimedRay>) {
    let text = "[camera]\neye = [5.0, 0.0, -8.0]\ntarget = [5.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\nvfov = 45.0\n\
                width = 8\nheight = 8\n[directional_light]\ndirection = [0.2, -1.0, 0.3]\nirradiance = [1.0, 1.0, 1.0]\n\
                [materials.grey]\nalbedo = [0.5, 0.5, 0.5]\n\
                [[objects]]\nmaterial = \"grey\"\nmesh = { file = \"cube.obj\" }\n\
                [[objects]]\nmaterial = \"grey\"\nmesh = { file = \"ball.obj\", translate = [10.0, 0.0, 0.0] }\n";
    let files = [("cube.obj", grid_cube_obj(n)), ("ball.obj", icosphere_obj(k, false))];
    let files: Vec<(&str, &str)> = files.iter().map(|(name, text)| (*name, text.as_str())).collect();
    let scene = scene_with_files(text, "closed.toml", &files).unwrap_or_else(|e| panic!("{e}"));
    let rays = scene
        .objects
        .iter()
        .flat_map(|o| match &o.shape {
            crate::Shape::Mesh(mesh) => {
                let (lo, hi) = mesh.bounds();
                rays_at_edges_and_vertices(mesh, (lo + hi) * 0.5)
            }
            _ => Vec::new(),
        })
        .collect();
    (scene, rays)
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

    /// The vertices and faces (0-based) of OBJ text with plain `v x y z` and `f a b c` lines.
    fn parse(text: &str) -> (Vec<DVec3>, Vec<[usize; 3]>) {
        let vertices = text
            .lines()
            .filter_map(|l| l.strip_prefix("v "))
            .map(|v| {
                let c: Vec<f64> = v.split(' ').map(|x| x.parse().unwrap()).collect();
                DVec3::new(c[0], c[1], c[2])
            })
            .collect();
        let faces = text
            .lines()
            .filter_map(|l| l.strip_prefix("f "))
            .map(|f| {
                let v: Vec<usize> = f.split(' ').map(|i| i.parse::<usize>().unwrap() - 1).collect();
                [v[0], v[1], v[2]]
            })
            .collect();
        (vertices, faces)
    }

    /// Closed and consistently wound (every directed edge once, and its reverse once), and
    /// outward: the signed volume (divergence theorem) is `volume`.
    fn assert_closed_and_outward(text: &str, volume: f64) {
        let (p, faces) = parse(text);
        let mut edges = BTreeMap::new();
        for f in &faces {
            for k in 0..3 {
                *edges.entry((f[k], f[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        assert!(edges.iter().all(|(&(a, b), &n)| n == 1 && edges.get(&(b, a)) == Some(&1)));
        let signed: f64 = faces.iter().map(|f| p[f[0]].dot(p[f[1]].cross(p[f[2]])) / 6.0).sum();
        assert!((signed - volume).abs() < 1e-9, "{signed}");
    }

    #[test]
    fn a_box_is_closed_and_faces_out() {
        let corners: [Vec3; 8] = std::array::from_fn(|i| {
            Vec3::new((i & 1) as f32, (i >> 1 & 1) as f32 * 2.0, (i >> 2 & 1) as f32 * 3.0)
        });
        let text = box_obj(corners);
        assert_eq!(parse(&text).1.len(), 12);
        assert_closed_and_outward(&text, 6.0);
    }

    #[test]
    fn a_grid_cube_is_closed_and_faces_out() {
        for n in [1, 2, 4] {
            let text = grid_cube_obj(n);
            let (vertices, faces) = parse(&text);
            assert_eq!((vertices.len(), faces.len()), (6 * (n * n) as usize + 2, 12 * (n * n) as usize));
            assert_closed_and_outward(&text, 8.0);
        }
    }
}
