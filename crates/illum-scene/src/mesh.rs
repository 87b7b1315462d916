//! A triangle mesh object: its triangles in the scene's frame, where they came from, and how
//! they were placed. Every value here has passed validation (`validate_mesh.rs`): vertices
//! are finite, every index is in range, and every triangle has a finite, non-zero f32 normal.

use std::fmt;
use std::sync::Arc;

use glam::Vec3;

/// How a mesh file's coordinates are placed in the scene: `world = translate + scale R local`,
/// with R the rotation by `rotate_deg.x` about +X, then `.y` about +Y, then `.z` about +Z
/// (right-handed, R = R_z R_y R_x). `translate` is measured from the scene's origin
/// ([`Scene::origin`](crate::Scene::origin)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshPlacement {
    pub translate: Vec3,
    pub scale: f32,
    pub rotate_deg: Vec3,
}

/// The triangles of one mesh object, in the scene's frame.
#[derive(Clone, PartialEq)]
pub struct TriangleMesh {
    /// The file as the scene names it (relative to the scene file), for messages.
    pub file: String,
    /// 64-bit FNV-1a of the file's bytes: the scene's content hash covers the file through it.
    pub file_hash: u64,
    pub placement: MeshPlacement,
    /// Vertex positions, placed ([`MeshPlacement`]) and rounded to f32 once.
    pub positions: Vec<Vec3>,
    /// Unit shading normals, one per position, when the file gives every vertex one and the
    /// object does not ask for flat shading; otherwise `None`, and each triangle is shaded with
    /// its geometric normal.
    pub normals: Option<Vec<Vec3>>,
    /// Each triangle's three indices into `positions`, counter-clockwise seen from the front
    /// (the front normal is `(b - a) x (c - a)`).
    pub triangles: Vec<[u32; 3]>,
    /// Triangles of the file dropped because they have no normal in f32 (repeated or collinear
    /// vertices): they have no area, so they hide nothing.
    pub dropped_degenerate: usize,
}

impl TriangleMesh {
    /// The corners of triangle `i`.
    pub fn triangle(&self, i: usize) -> [Vec3; 3] {
        self.triangles[i].map(|v| self.positions[v as usize])
    }

    /// The bounds of every vertex: (min, max).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.positions
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)))
    }

    /// Whether the mesh is shaded with interpolated vertex normals.
    pub fn smooth(&self) -> bool {
        self.normals.is_some()
    }
}

/// A mesh of many triangles would fill a screen: its summary instead.
impl fmt::Debug for TriangleMesh {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("TriangleMesh")
            .field("file", &self.file)
            .field("file_hash", &format_args!("{:016x}", self.file_hash))
            .field("placement", &self.placement)
            .field("vertices", &self.positions.len())
            .field("triangles", &self.triangles.len())
            .field("smooth", &self.smooth())
            .field("dropped_degenerate", &self.dropped_degenerate)
            .finish()
    }
}

/// A mesh object's shape: shared, since a scene is cloned (overrides, tests) far more often
/// than its meshes change.
pub type MeshRef = Arc<TriangleMesh>;
