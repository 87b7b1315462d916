//! Ray-triangle intersection in f64, for meshes: every triangle of a mesh is its own surface,
//! tested one by one (brute force, no acceleration structure), so the oracle shares nothing
//! with the GPU's BVH or its watertight test.

use glam::DVec3;
use illum_scene::TriangleMesh;

use crate::geometry::{Surface, SurfaceHit, dvec};

/// The triangle {a + s e1 + r e2 : s, r >= 0, s + r <= 1}, front normal normalize(e1 x e2).
#[derive(Clone, Copy, Debug)]
pub struct Triangle {
    pub a: DVec3,
    pub e1: DVec3,
    pub e2: DVec3,
    pub normal: DVec3,
}

impl Triangle {
    pub fn new(a: DVec3, b: DVec3, c: DVec3) -> Triangle {
        let (e1, e2) = (b - a, c - a);
        Triangle { a, e1, e2, normal: e1.cross(e2).normalize() }
    }

    /// Solves o + t d = a + s e1 + r e2 by Cramer's rule with scalar triple products (as for a
    /// parallelogram, geometry.rs), with the triangle's bound s + r <= 1. Edges are closed
    /// (s = 0, r = 0 and s + r = 1 count as inside); in f64 a ray through a shared edge of two
    /// f32 triangles is found by at least one of them but for rounding of order 1e-16.
    pub fn intersect(&self, o: DVec3, d: DVec3, t_max: f64) -> Option<SurfaceHit> {
        let dv = d.cross(self.e2);
        let det = self.e1.dot(dv);
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let inv_det = 1.0 / det;
        let q = o - self.a;
        let s = q.dot(dv) * inv_det;
        if !(0.0..=1.0).contains(&s) {
            return None;
        }
        let qu = q.cross(self.e1);
        let r = d.dot(qu) * inv_det;
        if !(r >= 0.0 && s + r <= 1.0) {
            return None;
        }
        let t = self.e2.dot(qu) * inv_det;
        (t > 0.0 && t < t_max).then_some(SurfaceHit { t, normal: self.normal })
    }

    /// The centre and radius of a sphere around the triangle (about its centroid).
    pub fn bounding_sphere(&self) -> (DVec3, f64) {
        let centre = self.a + (self.e1 + self.e2) / 3.0;
        let corners = [self.a, self.a + self.e1, self.a + self.e2];
        (centre, corners.iter().map(|c| (*c - centre).length()).fold(0.0, f64::max))
    }
}

/// The surfaces of a mesh: one per triangle, each shaded with its own normal.
pub fn mesh_surfaces(mesh: &TriangleMesh) -> impl Iterator<Item = Surface> + '_ {
    (0..mesh.triangles.len()).map(|i| {
        let [a, b, c] = mesh.triangle(i).map(dvec);
        Surface::Triangle(Triangle::new(a, b, c))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_triangle_is_hit_inside_and_missed_outside() {
        let tri =
            Triangle::new(DVec3::new(1.0, 0.0, 0.0), DVec3::new(3.0, 0.0, 0.0), DVec3::new(1.0, 2.0, 0.0));
        assert_eq!(tri.normal, DVec3::Z);
        let o = DVec3::new(0.0, 0.0, 5.0);
        for (s, r, hit) in [(0.2, 0.2, true), (0.49, 0.49, true), (0.6, 0.6, false), (-0.01, 0.5, false)] {
            let target = tri.a + s * tri.e1 + r * tri.e2;
            let d = (target - o).normalize();
            let h = tri.intersect(o, d, f64::INFINITY);
            assert_eq!(h.is_some(), hit, "(s, r) = ({s}, {r})");
            if let Some(h) = h {
                assert!((o + h.t * d - target).length() < 1e-12);
                assert!(tri.intersect(o, d, h.t * 0.999).is_none(), "t_max cuts the hit");
            }
        }
        // From behind (the back side is hit too) and parallel to the plane.
        assert!(tri.intersect(DVec3::new(1.5, 0.5, -1.0), DVec3::Z, f64::INFINITY).is_some());
        assert!(tri.intersect(DVec3::new(0.0, 0.5, 0.0), DVec3::X, f64::INFINITY).is_none());
    }

    #[test]
    fn a_ray_through_a_shared_edge_or_vertex_hits_a_triangle() {
        // The unit square as two triangles sharing the diagonal (0,0)-(1,1).
        let (p00, p10, p11, p01) =
            (DVec3::ZERO, DVec3::new(1.0, 0.0, 0.0), DVec3::new(1.0, 1.0, 0.0), DVec3::new(0.0, 1.0, 0.0));
        let halves = [Triangle::new(p00, p10, p11), Triangle::new(p00, p11, p01)];
        for k in 0..=16 {
            let x = f64::from(k) / 16.0;
            let o = DVec3::new(x, x, 3.0);
            let hits =
                halves.iter().filter(|t| t.intersect(o, DVec3::NEG_Z, f64::INFINITY).is_some()).count();
            assert!(hits >= 1, "the diagonal at {x}");
        }
    }
}
