//! Reading a PLY (Stanford polygon) file's triangles from its bytes (the `ply-rs-bw` crate), in
//! ASCII or binary, so that the same code serves a file read from disk and one a web page hands
//! over.
//!
//! The `vertex` element's `x`, `y`, `z` are the positions and its `nx`, `ny`, `nz`, when all
//! three are there, the vertex normals; the `face` element's list `vertex_indices` (or
//! `vertex_index`) gives each polygon, triangulated as a fan from its first vertex (as OBJ
//! polygons are). Every other element and property (colours, texture coordinates, edges) is
//! read by the crate and not used; materials come from the scene file.
//!
//! A problem with one element is named by its line in an ASCII file (the header's lines, then
//! one line per element in order) and by its element and index in a binary one.

use std::io::Cursor;

use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Encoding, Ply, Property};

use crate::mesh_file::FileMesh;

/// Where element `index` of `element` is, for messages: `FILE:LINE` in ASCII, else
/// `FILE, element NAME ENTRY` (0-based).
struct Places<'a> {
    shown: &'a str,
    ascii: bool,
    header_lines: usize,
    /// Each element's name and the count of the elements before it.
    firsts: Vec<(String, usize)>,
}

impl Places<'_> {
    fn of(&self, element: &str, index: usize) -> String {
        let first = self.firsts.iter().find(|(name, _)| name == element).map_or(0, |(_, first)| *first);
        if self.ascii {
            format!("{}:{}", self.shown, self.header_lines + first + index + 1)
        } else {
            format!("{}, element {element} {index}", self.shown)
        }
    }
}

/// The number of lines up to and including `end_header`.
fn header_lines(bytes: &[u8]) -> usize {
    let mut line = 0;
    for text in bytes.split(|&b| b == b'\n') {
        line += 1;
        if text.trim_ascii() == b"end_header" {
            break;
        }
    }
    line
}

/// The parser's error as `FILE:LINE: what (in `the line`)` where it names a line (`Line N: ...`,
/// its first line only: the rest is the grammar's detail), else `FILE: what`.
fn parse_error(bytes: &[u8], shown: &str, error: &std::io::Error) -> String {
    let message = error.to_string();
    let first = message.lines().next().unwrap_or_default();
    let located = first.strip_prefix("Line ").and_then(|rest| {
        let (number, what) = rest.split_once(':')?;
        let line: usize = number.trim().parse().ok()?;
        let text = bytes.split(|&b| b == b'\n').nth(line.checked_sub(1)?)?;
        let text: String = String::from_utf8_lossy(text).trim().chars().take(120).collect();
        Some(format!("{shown}:{line}:{what} (in `{text}`)"))
    });
    located.unwrap_or_else(|| format!("{shown}: not a PLY file this reader takes: {first}"))
}

/// A scalar property's value.
fn scalar(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(v) => f64::from(v),
        Property::UChar(v) => f64::from(v),
        Property::Short(v) => f64::from(v),
        Property::UShort(v) => f64::from(v),
        Property::Int(v) => f64::from(v),
        Property::UInt(v) => f64::from(v),
        Property::Float(v) => f64::from(v),
        Property::Double(v) => v,
        _ => return None,
    })
}

/// A list property of integers, widened.
fn indices(p: &Property) -> Option<Vec<i64>> {
    Some(match p {
        Property::ListChar(v) => v.iter().map(|&i| i64::from(i)).collect(),
        Property::ListUChar(v) => v.iter().map(|&i| i64::from(i)).collect(),
        Property::ListShort(v) => v.iter().map(|&i| i64::from(i)).collect(),
        Property::ListUShort(v) => v.iter().map(|&i| i64::from(i)).collect(),
        Property::ListInt(v) => v.iter().map(|&i| i64::from(i)).collect(),
        Property::ListUInt(v) => v.iter().map(|&i| i64::from(i)).collect(),
        _ => return None,
    })
}

/// The file's triangles, or what is wrong with it, naming the file (`shown`) and, where one
/// element is at fault, its line or its element and index.
pub(crate) fn read_ply(bytes: &[u8], shown: &str) -> Result<FileMesh, String> {
    let ply: Ply<DefaultElement> = Parser::<DefaultElement>::new()
        .read_ply(&mut Cursor::new(bytes))
        .map_err(|e| parse_error(bytes, shown, &e))?;
    let mut firsts = Vec::new();
    let mut before = 0;
    for (name, element) in &ply.header.elements {
        firsts.push((name.clone(), before));
        before += element.count;
    }
    let places = Places {
        shown,
        ascii: ply.header.encoding == Encoding::Ascii,
        header_lines: header_lines(bytes),
        firsts,
    };
    let no_faces = || {
        format!(
            "{shown}: has no faces (a mesh needs at least one triangle: a `face` element with `vertex_indices`)"
        )
    };
    let vertices = ply.payload.get("vertex").map(Vec::as_slice).unwrap_or_default();
    let faces = ply.payload.get("face").map(Vec::as_slice).unwrap_or_default();
    if faces.is_empty() {
        return Err(no_faces());
    }

    let mut positions = Vec::with_capacity(vertices.len());
    let mut normals = Vec::with_capacity(vertices.len());
    let has_normals = vertices.first().is_some_and(|v| ["nx", "ny", "nz"].iter().all(|k| v.contains_key(*k)));
    for (i, v) in vertices.iter().enumerate() {
        let read = |keys: [&str; 3], what: &str| -> Result<[f32; 3], String> {
            let mut out = [0.0f32; 3];
            for (slot, key) in out.iter_mut().zip(keys) {
                let value = v.get(key).and_then(scalar).ok_or_else(|| {
                    format!(
                        "{}: the vertex has no number `{key}` (a {what} needs x, y and z)",
                        places.of("vertex", i)
                    )
                })?;
                *slot = value as f32;
            }
            if !out.iter().all(|x| x.is_finite()) {
                return Err(format!(
                    "{}: a {what} has a non-finite coordinate {out:?}",
                    places.of("vertex", i)
                ));
            }
            Ok(out)
        };
        positions.push(read(["x", "y", "z"], "vertex")?);
        if has_normals {
            normals.push(read(["nx", "ny", "nz"], "normal")?);
        }
    }

    let mut triangles = Vec::new();
    for (i, face) in faces.iter().enumerate() {
        let corners =
            face.get("vertex_indices").or_else(|| face.get("vertex_index")).and_then(indices).ok_or_else(
                || format!("{}: the face has no integer list `vertex_indices`", places.of("face", i)),
            )?;
        if let Some(&bad) = corners.iter().find(|&&c| c < 0 || c as usize >= positions.len()) {
            return Err(format!(
                "{}: a face refers to vertex {bad} of a file with {} vertices (indices count from 0)",
                places.of("face", i),
                positions.len()
            ));
        }
        // A fan from the first corner; fewer than three corners make no triangle.
        for k in 1..corners.len().saturating_sub(1) {
            triangles.push([corners[0], corners[k], corners[k + 1]].map(|c| c as u32));
        }
    }
    if triangles.is_empty() {
        return Err(no_faces());
    }
    Ok(FileMesh { positions, normals: has_normals.then_some(normals), triangles })
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str =
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n";

    fn ascii(vertex_properties: &str, vertices: &str, faces: &str) -> String {
        let face_count = faces.lines().count();
        format!(
            "{HEADER}{vertex_properties}element face {face_count}\nproperty list uchar int vertex_indices\nend_header\n{vertices}{faces}"
        )
    }

    const SQUARE: &str = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n";

    fn read(text: &str) -> Result<FileMesh, String> {
        read_ply(text.as_bytes(), "m.ply")
    }

    #[test]
    fn a_quad_is_two_triangles_and_normals_are_read_when_given() {
        let mesh = read(&ascii("", SQUARE, "4 0 1 2 3\n")).unwrap();
        assert_eq!(mesh.triangles, [[0, 1, 2], [0, 2, 3]]);
        assert_eq!(mesh.positions[2], [1.0, 1.0, 0.0]);
        assert!(mesh.normals.is_none());
        let with = ascii(
            "property float nx\nproperty float ny\nproperty float nz\n",
            "0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n",
            "3 0 1 2\n",
        );
        assert_eq!(read(&with).unwrap().normals.as_deref(), Some(&[[0.0, 0.0, 1.0]; 4][..]));
    }

    #[test]
    fn a_binary_file_reads_as_its_ascii_twin() {
        let mut bytes = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n".to_vec();
        for v in [[0.0f32, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]] {
            for x in v {
                bytes.extend(x.to_le_bytes());
            }
        }
        bytes.push(3);
        for i in [0u32, 1, 2] {
            bytes.extend(i.to_le_bytes());
        }
        let mesh = read_ply(&bytes, "b.ply").unwrap();
        assert_eq!(mesh.triangles, [[0, 1, 2]]);
        assert_eq!(mesh.positions[1], [2.0, 0.0, 0.0]);
    }

    #[test]
    fn a_non_finite_binary_vertex_is_named_by_its_element() {
        let mut bytes = b"ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n".to_vec();
        for v in [[0.0f64, 0.0, 0.0], [2.0, f64::INFINITY, 0.0], [0.0, 2.0, 0.0]] {
            for x in v {
                bytes.extend(x.to_be_bytes());
            }
        }
        bytes.push(3);
        for i in [0i32, 1, 2] {
            bytes.extend(i.to_be_bytes());
        }
        let err = read_ply(&bytes, "b.ply").unwrap_err();
        assert!(err.starts_with("b.ply, element vertex 1: a vertex has a non-finite coordinate"), "{err}");
    }

    #[test]
    fn bad_elements_are_named_by_their_line() {
        // The header takes 9 lines: the vertices are lines 10 to 13, the faces 14 on.
        let err = read(&ascii("", "0 0 0\n1 nan 0\n1 1 0\n0 1 0\n", "3 0 1 2\n")).unwrap_err();
        assert!(err.starts_with("m.ply:11: ") && err.ends_with("(in `1 nan 0`)"), "{err}");
        let err = read(&ascii("", SQUARE, "3 0 1 2\n3 0 2 9\n")).unwrap_err();
        assert!(err.starts_with("m.ply:15: a face refers to vertex 9 of a file with 4 vertices"), "{err}");
        let err = read(&ascii("", SQUARE, "3 0 1 -1\n")).unwrap_err();
        assert!(err.contains("refers to vertex -1"), "{err}");
    }

    #[test]
    fn malformed_and_empty_files_are_refused() {
        let err =
            read("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\nnot-a-number\n")
                .unwrap_err();
        assert_eq!(err, "m.ply:6: Couldn't read element line. (in `not-a-number`)");
        let err = read("solid cube\n").unwrap_err();
        assert!(err.starts_with("m.ply:1: Expected magic number"), "{err}");
        let no_faces = format!("{HEADER}end_header\n{SQUARE}");
        assert!(read(&no_faces).unwrap_err().contains("has no faces"));
        let only_lines = ascii("", SQUARE, "2 0 1\n");
        assert!(read(&only_lines).unwrap_err().contains("has no faces"));
    }
}
