//! Reading the mesh files a scene names, before the scene is validated (their vertices count
//! toward the frame's origin, `frame.rs`): the caller's reader gives the bytes (so that a web
//! page can hand them over), `mesh_ply.rs` parses a file named `*.ply` and `mesh_obj.rs` any
//! other. Placing and checking the triangles is `validate_mesh.rs`.

use glam::{DMat3, DVec3, Vec3};

use crate::content_hash::fnv1a_64;
use crate::error::SceneError;
use crate::file::{RawMesh, RawScene};
use crate::mesh_file::FileMesh;
use crate::mesh_obj::read_obj;
use crate::mesh_ply::read_ply;
use crate::spelling::object_label;

/// Reads a mesh file named in a scene (relative to the scene file): its bytes, or why not, as a
/// sentence naming the file.
pub type ReadFile<'a> = dyn FnMut(&str) -> Result<Vec<u8>, String> + 'a;

/// A mesh file read and parsed, before it is placed.
pub(crate) struct LoadedMesh {
    pub(crate) file: FileMesh,
    pub(crate) file_hash: u64,
}

/// Parses a mesh file's bytes by its name: PLY for a name ending in `.ply` (any case), else
/// Wavefront OBJ.
pub(crate) fn read_mesh(bytes: &[u8], name: &str) -> Result<FileMesh, String> {
    let ply = std::path::Path::new(name).extension().is_some_and(|e| e.eq_ignore_ascii_case("ply"));
    if ply { read_ply(bytes, name) } else { read_obj(bytes, name) }
}

/// Reads and parses the file of every mesh object, in file order (`None` for other objects).
pub(crate) fn load_meshes(
    raw: &RawScene,
    file: &str,
    read: &mut ReadFile<'_>,
) -> Result<Vec<Option<LoadedMesh>>, SceneError> {
    let mut out = Vec::with_capacity(raw.objects.len());
    for (i, object) in raw.objects.iter().enumerate() {
        let Some(mesh) = &object.mesh else {
            out.push(None);
            continue;
        };
        let field = format!("{}.mesh.file", object_label(i, object.name.as_deref()));
        let invalid = |why: String| SceneError::invalid(file, field.clone(), format!("{:?}", mesh.file), why);
        let bytes = read(&mesh.file).map_err(invalid)?;
        let file = read_mesh(&bytes, &mesh.file).map_err(invalid)?;
        out.push(Some(LoadedMesh { file, file_hash: fnv1a_64(&bytes) }));
    }
    Ok(out)
}

/// R = R_z R_y R_x of [`MeshPlacement`](crate::MeshPlacement), in f64.
pub(crate) fn rotation(degrees: [f64; 3]) -> DMat3 {
    let [x, y, z] = degrees.map(f64::to_radians);
    DMat3::from_rotation_z(z) * DMat3::from_rotation_y(y) * DMat3::from_rotation_x(x)
}

impl LoadedMesh {
    /// The world bounds of the placed mesh as the file gives its placement (for the frame's
    /// origin), or `None` while a number of the placement is not finite.
    pub(crate) fn world_bounds(&self, raw: &RawMesh) -> Option<(DVec3, DVec3)> {
        let r = rotation(raw.rotate.0);
        let t = DVec3::from_array(raw.translate.0);
        let placed =
            self.file.positions.iter().map(|p| t + raw.scale.0 * (r * Vec3::from_array(*p).as_dvec3()));
        let (lo, hi) =
            placed.fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)));
        (lo.is_finite() && hi.is_finite()).then_some((lo, hi))
    }
}
