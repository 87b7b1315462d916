//! Validation of a mesh object: its file, read and parsed by `mesh_load.rs`, placed in the
//! scene's frame in f64 and rounded to f32 once, as every other position (`frame.rs`).
//!
//! Errors name the object, the file as the scene gives it, and the line of the file where one
//! line is at fault. Degenerate triangles (no f32 normal) are dropped and counted, since they
//! cover no area; a mesh left with none is refused.

use std::sync::Arc;

use glam::{DVec3, Vec3};

use crate::camera::robust_normalize;
use crate::error::SceneError;
use crate::file::RawMesh;
use crate::mesh::{MeshPlacement, MeshRef, TriangleMesh};
use crate::mesh_load::{LoadedMesh, rotation};
use crate::spelling::{fmt_num, fmt_vec};
use crate::validate::Check;

impl Check<'_> {
    /// The mesh of object `label`, placed in the scene's frame.
    pub(crate) fn mesh(
        &self,
        label: &str,
        raw: &RawMesh,
        loaded: &LoadedMesh,
    ) -> Result<MeshRef, SceneError> {
        let path = format!("{label}.mesh");
        let translate = self.position(&format!("{path}.translate"), raw.translate)?;
        let scale_path = format!("{path}.scale");
        let scale = self.number(&scale_path, raw.scale)?;
        if scale <= 0.0 {
            return Err(self.invalid(scale_path, fmt_num(raw.scale.0), "must be > 0 (a uniform scale)"));
        }
        let rotate_deg = self.vec3(&format!("{path}.rotate"), raw.rotate)?;
        let r = rotation(raw.rotate.0);
        let t = DVec3::from_array(raw.translate.0) - self.origin;
        let file_field = format!("{path}.file");
        let shown_file = format!("{:?}", raw.file);

        let mut positions = Vec::with_capacity(loaded.file.positions.len());
        for (i, p) in loaded.file.positions.iter().enumerate() {
            let placed = (t + raw.scale.0 * (r * Vec3::from_array(*p).as_dvec3())).as_vec3();
            if !placed.is_finite() {
                return Err(self.invalid(
                    &file_field,
                    &shown_file,
                    format!(
                        "vertex {} of the file, {}, placed by scale {} and translate {}, {}",
                        i + 1,
                        fmt_vec(p.map(f64::from)),
                        fmt_num(raw.scale.0),
                        fmt_vec(raw.translate.0),
                        self.beyond_f32_from_eye()
                    ),
                ));
            }
            positions.push(placed);
        }
        let normals = match (&loaded.file.normals, raw.flat) {
            (Some(normals), false) => Some(
                normals
                    .iter()
                    .map(|n| {
                        robust_normalize((r * Vec3::from_array(*n).as_dvec3()).as_vec3()).ok_or_else(|| {
                            self.invalid(
                                &file_field,
                                &shown_file,
                                format!(
                                    "a vertex normal is zero ({}): give every normal a direction, or set \
                                     flat = true to shade with the triangles' own normals",
                                    fmt_vec(n.map(f64::from))
                                ),
                            )
                        })
                    })
                    .collect::<Result<Vec<_>, _>>()?,
            ),
            _ => None,
        };
        let has_normal = |t: &[u32; 3]| {
            let [a, b, c] = t.map(|v| positions[v as usize]);
            robust_normalize((b - a).cross(c - a)).is_some()
        };
        let triangles: Vec<[u32; 3]> = loaded.file.triangles.iter().copied().filter(has_normal).collect();
        let dropped_degenerate = loaded.file.triangles.len() - triangles.len();
        if triangles.is_empty() {
            return Err(self.invalid(
                file_field,
                shown_file,
                format!(
                    "all {} triangles are degenerate (repeated or collinear vertices, once placed \
                     and rounded to f32): the mesh has no area",
                    dropped_degenerate
                ),
            ));
        }
        Ok(Arc::new(TriangleMesh {
            file: raw.file.clone(),
            file_hash: loaded.file_hash,
            placement: MeshPlacement { translate, scale, rotate_deg },
            positions,
            normals,
            triangles,
            dropped_degenerate,
        }))
    }
}
