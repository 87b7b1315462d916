//! Reading a Wavefront OBJ file's triangles from its bytes (the `tobj` crate), so that the same
//! code serves a file read from disk and one a web page hands over.
//!
//! Polygons with more than three vertices are triangulated (a fan from their first vertex, as
//! `tobj` does); points and lines are skipped; every object and group of the file joins one
//! mesh. `usemtl`, `mtllib` and MTL files are ignored: materials come from the scene file.
//! Vertex colours and texture coordinates are read by `tobj` and not used.

use std::io::Cursor;

use crate::mesh_file::FileMesh;

fn options() -> tobj::LoadOptions {
    tobj::LoadOptions {
        // One index per corner, so that positions and normals line up.
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    }
}

fn parse(bytes: &[u8]) -> Result<Vec<tobj::Model>, tobj::LoadError> {
    let no_materials = |_: &std::path::Path| Err(tobj::LoadError::OpenFileFailed);
    tobj::load_obj_buf(&mut Cursor::new(bytes), &options(), no_materials).map(|(models, _)| models)
}

/// The file's triangles, or what is wrong with it as `FILE:LINE: problem` (`shown` names the
/// file; the line is given wherever one line is at fault).
pub(crate) fn read_obj(bytes: &[u8], shown: &str) -> Result<FileMesh, String> {
    let models = parse(bytes).map_err(|e| match first_failing_line(bytes) {
        Some(line) => format!("{shown}:{line}: {e} (in `{}`)", quoted_line(bytes, line)),
        None => format!("{shown}: {e}"),
    })?;
    let mut out = FileMesh { positions: Vec::new(), normals: Some(Vec::new()), triangles: Vec::new() };
    for model in &models {
        let mesh = &model.mesh;
        let base = out.positions.len();
        let count = mesh.positions.len() / 3;
        out.positions.extend(mesh.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
        out.normals = match out.normals.take() {
            Some(mut normals) if mesh.normals.len() == mesh.positions.len() => {
                normals.extend(mesh.normals.chunks_exact(3).map(|n| [n[0], n[1], n[2]]));
                Some(normals)
            }
            _ => None,
        };
        for corners in mesh.indices.chunks_exact(3) {
            if let Some(&bad) = corners.iter().find(|&&i| i as usize >= count) {
                return Err(format!(
                    "{shown}: a face refers to vertex {} of an object with {count} vertices",
                    bad as usize + 1
                ));
            }
            let global = |i: u32| (base + i as usize) as u32;
            out.triangles.push([global(corners[0]), global(corners[1]), global(corners[2])]);
        }
    }
    if out.triangles.is_empty() {
        return Err(format!(
            "{shown}: has no faces (a mesh needs at least one triangle; `f` lines give them)"
        ));
    }
    if let Some(i) = out.positions.iter().position(|p| !p.iter().all(|x| x.is_finite())) {
        let at = line_of_non_finite(bytes, "v").map_or(String::new(), |line| format!(":{line}"));
        return Err(format!("{shown}{at}: a vertex has a non-finite coordinate {:?}", out.positions[i]));
    }
    if let Some(normals) = &out.normals
        && let Some(i) = normals.iter().position(|n| !n.iter().all(|x| x.is_finite()))
    {
        let at = line_of_non_finite(bytes, "vn").map_or(String::new(), |line| format!(":{line}"));
        return Err(format!("{shown}{at}: a normal has a non-finite coordinate {:?}", normals[i]));
    }
    Ok(out)
}

/// The text of line `line` (1-based), trimmed and cut to 120 characters.
fn quoted_line(bytes: &[u8], line: usize) -> String {
    let text = bytes.split(|&b| b == b'\n').nth(line - 1).unwrap_or_default();
    let text = String::from_utf8_lossy(text);
    let text = text.trim();
    let shown: String = text.chars().take(120).collect();
    if text.chars().count() > 120 { format!("{shown} ...") } else { shown }
}

/// The first line at which the file stops parsing: the smallest n for which its first n lines
/// fail. `tobj` reads line by line and stops at the first line it cannot take, so a prefix fails
/// exactly when it contains that line, and bisection finds it in log2(lines) parses (only when
/// the whole file has already failed).
fn first_failing_line(bytes: &[u8]) -> Option<usize> {
    let ends: Vec<usize> =
        bytes.iter().enumerate().filter(|&(_, &b)| b == b'\n').map(|(i, _)| i + 1).collect();
    let prefix = |lines: usize| if lines < ends.len() + 1 { &bytes[..ends[lines - 1]] } else { bytes };
    let total = ends.len() + usize::from(ends.last() != Some(&bytes.len()));
    if total == 0 || parse(prefix(total)).is_ok() {
        return None;
    }
    // Invariant: the first `good` lines parse, the first `bad` lines do not.
    let (mut good, mut bad) = (0, total);
    while bad - good > 1 {
        let mid = good + (bad - good) / 2;
        if parse(prefix(mid)).is_ok() {
            good = mid;
        } else {
            bad = mid;
        }
    }
    Some(bad)
}

/// The 1-based line of the first `keyword` statement (`v`, `vn`) with a number that is not
/// finite, for an error already found in the parsed numbers.
fn line_of_non_finite(bytes: &[u8], keyword: &str) -> Option<usize> {
    let text = String::from_utf8_lossy(bytes);
    text.lines().enumerate().find_map(|(i, line)| {
        let mut words = line.split_whitespace();
        let bad = words.next() == Some(keyword)
            && words.take(3).any(|w| w.parse::<f32>().map_or(true, |x| !x.is_finite()));
        bad.then_some(i + 1)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Result<FileMesh, String> {
        read_obj(text.as_bytes(), "m.obj")
    }

    #[test]
    fn a_quad_face_is_two_triangles_and_objects_join() {
        let mesh = read(
            "o a\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\no b\nv 0 0 1\nv 1 0 1\nv 0 1 1\nf 5 6 7\n",
        )
        .unwrap();
        assert_eq!(mesh.triangles.len(), 3);
        assert_eq!(mesh.positions.len(), 7);
        assert!(mesh.normals.is_none());
        for t in &mesh.triangles {
            assert!(t.iter().all(|&i| (i as usize) < mesh.positions.len()));
        }
        // The second object's triangle is the file's vertices 5, 6, 7.
        let last = mesh.triangles[2].map(|i| mesh.positions[i as usize]);
        assert_eq!(last, [[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]]);
    }

    #[test]
    fn normals_are_kept_when_every_corner_has_one() {
        let with = read("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n").unwrap();
        assert_eq!(with.normals.as_deref(), Some(&[[0.0, 0.0, 1.0]; 3][..]));
        let mtl = read("mtllib nowhere.mtl\nusemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        assert_eq!(mtl.triangles.len(), 1, "MTL files are ignored, missing or not");
    }

    #[test]
    fn a_malformed_line_is_named_with_its_number() {
        let err = read("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 x 0\nf 1 2 3\n").unwrap_err();
        assert!(err.starts_with("m.obj:4: "), "{err}");
        assert!(err.contains("`v 1 x 0`"), "{err}");
    }

    #[test]
    fn an_index_out_of_range_is_named_with_its_line() {
        let err = read("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n").unwrap_err();
        assert!(err.starts_with("m.obj:5: "), "{err}");
        assert!(err.contains("out of bounds"), "{err}");
    }

    #[test]
    fn non_finite_vertices_and_normals_are_named_with_their_line() {
        let err = read("v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n").unwrap_err();
        assert!(err.starts_with("m.obj:2: a vertex has a non-finite coordinate"), "{err}");
        let err = read("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -inf 0\nf 1 2 4\n").unwrap_err();
        assert!(err.starts_with("m.obj:4: "), "{err}");
        let err = read("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 inf 1\nf 1//1 2//2 3//1\n").unwrap_err();
        assert!(err.starts_with("m.obj:5: a normal has a non-finite coordinate"), "{err}");
    }

    #[test]
    fn a_file_without_faces_is_refused() {
        for text in ["", "# nothing\n", "v 0 0 0\nv 1 0 0\nv 0 1 0\n", "v 0 0 0\nv 1 0 0\nl 1 2\n"] {
            let err = read(text).unwrap_err();
            assert!(err.contains("has no faces"), "{text:?}: {err}");
        }
    }
}
