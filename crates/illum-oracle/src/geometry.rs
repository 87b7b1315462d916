//! Ray-shape intersection in f64.
//!
//! A mesh is one surface per triangle, tested one by one (brute force, no acceleration
//! structure), so the oracle shares nothing with the GPU's BVH or its watertight test.
//!
//! Every routine returns the smallest root t in (0, t_max) of `o + t d` on the shape's surface,
//! together with the surface's geometric unit normal there (outward for boxes and spheres, the
//! front normal for parallelograms and triangles) and its shading normal: the geometric one but
//! on a smooth mesh's triangle (see [`Triangle::shading_normal`]). Orientation toward the ray is
//! the integrator's business.
//! A ray starting inside a box or a sphere hits its inner surface on the way out.

use glam::{DMat3, DVec3, Vec3};
use illum_scene::TriangleMesh;

/// A scene's f32 vector in the oracle's f64 (exact: every f32 is an f64).
pub(crate) fn dvec(v: Vec3) -> DVec3 {
    v.as_dvec3()
}

/// A ray-surface intersection: distance along the ray (in units of |d|), geometric normal and
/// shading normal (unit, on the geometric normal's side of the surface).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    pub t: f64,
    pub normal: DVec3,
    pub shading: DVec3,
}

impl SurfaceHit {
    /// A hit shaded with its geometric normal.
    fn flat(t: f64, normal: DVec3) -> SurfaceHit {
        SurfaceHit { t, normal, shading: normal }
    }
}

/// An oriented box: the axis-aligned box [lo, hi] of its local frame, mapped to the world by
/// `world = rotation * local + offset`.
#[derive(Clone, Copy, Debug)]
pub struct OrientedBox {
    pub lo: DVec3,
    pub hi: DVec3,
    pub rotation: DMat3,
    pub offset: DVec3,
}

/// The parallelogram {corner + s u + r v : s, r in [0, 1]}, front normal normalize(u x v).
#[derive(Clone, Copy, Debug)]
pub struct Parallelogram {
    pub corner: DVec3,
    pub u: DVec3,
    pub v: DVec3,
    pub normal: DVec3,
    pub area: f64,
}

#[derive(Clone, Copy, Debug)]
pub struct Ball {
    pub center: DVec3,
    pub radius: f64,
}

#[derive(Clone, Copy, Debug)]
pub enum Surface {
    Box(OrientedBox),
    Parallelogram(Parallelogram),
    Ball(Ball),
    Triangle(Triangle),
}

impl Surface {
    pub fn intersect(&self, o: DVec3, d: DVec3, t_max: f64) -> Option<SurfaceHit> {
        match self {
            Surface::Box(b) => b.intersect(o, d, t_max),
            Surface::Parallelogram(p) => p.intersect(o, d, t_max),
            Surface::Ball(s) => s.intersect(o, d, t_max),
            Surface::Triangle(t) => t.intersect(o, d, t_max),
        }
    }
}

impl Parallelogram {
    pub fn new(corner: DVec3, u: DVec3, v: DVec3) -> Parallelogram {
        let n = u.cross(v);
        let area = n.length();
        Parallelogram { corner, u, v, normal: n / area, area }
    }

    /// Solves o + t d = corner + s u + r v for (t, s, r) by Cramer's rule, written with scalar
    /// triple products: with q = o - corner and det = u . (d x v),
    ///     s = q . (d x v) / det,   r = d . (q x u) / det,   t = v . (q x u) / det.
    /// det = 0 means d is parallel to the plane (no single crossing).
    pub fn intersect(&self, o: DVec3, d: DVec3, t_max: f64) -> Option<SurfaceHit> {
        let inside = |s: f64, r: f64| (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&r);
        let (t, _, _) = plane_crossing(o, d, self.corner, self.u, self.v, t_max, inside)?;
        Some(SurfaceHit::flat(t, self.normal))
    }

    /// The point with parameters (s, r) in [0, 1]^2; uniform (s, r) gives a uniform point.
    pub fn point(&self, s: f64, r: f64) -> DVec3 {
        self.corner + s * self.u + r * self.v
    }
}

/// Where o + t d crosses corner + s e1 + r e2, for a parallelogram's and a triangle's test: Cramer's
/// rule with scalar triple products, with q = o - corner and det = e1 . (d x e2),
///     s = q . (d x e2) / det,   r = d . (q x e1) / det,   t = e2 . (q x e1) / det;
/// `(t, s, r)` when (s, r) is `inside` the shape and 0 < t < t_max. det = 0 means d is parallel
/// to the plane (no single crossing).
fn plane_crossing(
    o: DVec3,
    d: DVec3,
    corner: DVec3,
    e1: DVec3,
    e2: DVec3,
    t_max: f64,
    inside: impl Fn(f64, f64) -> bool,
) -> Option<(f64, f64, f64)> {
    let dv = d.cross(e2);
    let det = e1.dot(dv);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv_det = 1.0 / det;
    let q = o - corner;
    let s = q.dot(dv) * inv_det;
    let qu = q.cross(e1);
    let r = d.dot(qu) * inv_det;
    if !inside(s, r) {
        return None;
    }
    let t = e2.dot(qu) * inv_det;
    (t > 0.0 && t < t_max).then_some((t, s, r))
}

impl Ball {
    /// |o + t d - c|^2 = R^2 with m = o - c is t^2 |d|^2 + 2 t (m.d) + |m|^2 - R^2 = 0. The roots
    /// are formed as q / a and c / q with q = -(b + sign(b) sqrt(disc)), which avoids the
    /// cancellation of the textbook formula when one root is near zero (a ray leaving the
    /// surface).
    pub fn intersect(&self, o: DVec3, d: DVec3, t_max: f64) -> Option<SurfaceHit> {
        let m = o - self.center;
        let a = d.length_squared();
        let half_b = m.dot(d);
        let c = m.length_squared() - self.radius * self.radius;
        let disc = half_b * half_b - a * c;
        if disc.is_nan() || disc < 0.0 {
            return None;
        }
        let q = -(half_b + half_b.signum() * disc.sqrt());
        let (mut t0, mut t1) = if q == 0.0 { (0.0, 0.0) } else { (q / a, c / q) };
        if t0 > t1 {
            std::mem::swap(&mut t0, &mut t1);
        }
        let t = if t0 > 0.0 { t0 } else { t1 };
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        let normal = (o + t * d - self.center) / self.radius;
        Some(SurfaceHit::flat(t, normal))
    }
}

impl OrientedBox {
    pub fn from_shape(shape: &illum_scene::BoxShape) -> OrientedBox {
        let rotation = DMat3::from_rotation_y(f64::from(shape.rotate_y_deg).to_radians());
        let pivot = dvec(shape.pivot);
        let offset = pivot + dvec(shape.translate) - rotation * pivot;
        OrientedBox { lo: dvec(shape.min), hi: dvec(shape.max), rotation, offset }
    }

    /// The box is the intersection of three slabs lo_i <= x_i <= hi_i in its local frame. The
    /// ray is inside slab i for t between its two crossings, so it is inside the box on
    /// [max of entries, min of exits]; the axis that sets the entry (or the exit, for a ray
    /// starting inside) is the face that was hit.
    pub fn intersect(&self, o: DVec3, d: DVec3, t_max: f64) -> Option<SurfaceHit> {
        // The rotation is orthonormal: its transpose is its inverse.
        let to_local = self.rotation.transpose();
        let ol = to_local * (o - self.offset);
        let dl = to_local * d;
        let (mut t_in, mut axis_in) = (f64::NEG_INFINITY, usize::MAX);
        let (mut t_out, mut axis_out) = (f64::INFINITY, usize::MAX);
        for axis in 0..3 {
            let (oi, di, lo, hi) = (ol[axis], dl[axis], self.lo[axis], self.hi[axis]);
            if di == 0.0 {
                // Parallel to this slab: inside it for all t, or never.
                if oi < lo || oi > hi {
                    return None;
                }
                continue;
            }
            let (ta, tb) = ((lo - oi) / di, (hi - oi) / di);
            let (enter, exit) = if ta < tb { (ta, tb) } else { (tb, ta) };
            if enter > t_in {
                t_in = enter;
                axis_in = axis;
            }
            if exit < t_out {
                t_out = exit;
                axis_out = axis;
            }
        }
        if t_in > t_out || (axis_in == usize::MAX && axis_out == usize::MAX) {
            return None;
        }
        // Entering face: its outward normal opposes the direction; leaving face: follows it.
        let (t, axis, outward_sign) = if t_in > 0.0 {
            (t_in, axis_in, -dl[axis_in].signum())
        } else {
            (t_out, axis_out, dl[axis_out].signum())
        };
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        let mut local_normal = DVec3::ZERO;
        local_normal[axis] = outward_sign;
        Some(SurfaceHit::flat(t, self.rotation * local_normal))
    }
}

/// The triangle {a + s e1 + r e2 : s, r >= 0, s + r <= 1}, front normal normalize(e1 x e2),
/// with the unit vertex normals at a, b, c of a smooth mesh (`None`: flat).
#[derive(Clone, Copy, Debug)]
pub struct Triangle {
    pub a: DVec3,
    pub e1: DVec3,
    pub e2: DVec3,
    pub normal: DVec3,
    pub vertex_normals: Option<[DVec3; 3]>,
}

impl Triangle {
    /// A flat triangle.
    pub fn new(a: DVec3, b: DVec3, c: DVec3) -> Triangle {
        let (e1, e2) = (b - a, c - a);
        Triangle { a, e1, e2, normal: e1.cross(e2).normalize(), vertex_normals: None }
    }

    /// The shading normal at the point a + s e1 + r e2: the vertex normals weighted by the
    /// point's barycentric coordinates (1 - s - r, s, r), normalised, and turned onto the front
    /// normal's side when they point the other way (the winding decides sides; a file's normals
    /// never do). The front normal itself on a flat triangle, or where the weighted sum is
    /// shorter than 1e-6 (vertex normals that nearly cancel).
    pub fn shading_normal(&self, s: f64, r: f64) -> DVec3 {
        let Some([na, nb, nc]) = self.vertex_normals else { return self.normal };
        let n = (1.0 - s - r) * na + s * nb + r * nc;
        let length = n.length();
        // Also a NaN length (a NaN normal cannot pass validation, but nothing is left to chance).
        if length.is_nan() || length <= 1e-6 {
            return self.normal;
        }
        let n = n / length;
        if n.dot(self.normal) < 0.0 { -n } else { n }
    }

    /// Solves o + t d = a + s e1 + r e2 by Cramer's rule with scalar triple products (as for a
    /// parallelogram, geometry.rs), with the triangle's bound s + r <= 1. Edges are closed
    /// (s = 0, r = 0 and s + r = 1 count as inside); in f64 a ray through a shared edge of two
    /// f32 triangles is found by at least one of them but for rounding of order 1e-16.
    pub fn intersect(&self, o: DVec3, d: DVec3, t_max: f64) -> Option<SurfaceHit> {
        let inside = |s: f64, r: f64| (0.0..=1.0).contains(&s) && r >= 0.0 && s + r <= 1.0;
        let (t, s, r) = plane_crossing(o, d, self.a, self.e1, self.e2, t_max, inside)?;
        Some(SurfaceHit { t, normal: self.normal, shading: self.shading_normal(s, r) })
    }

    /// The centre and radius of a sphere around the triangle (about its centroid).
    pub fn bounding_sphere(&self) -> (DVec3, f64) {
        let centre = self.a + (self.e1 + self.e2) / 3.0;
        let corners = [self.a, self.a + self.e1, self.a + self.e2];
        (centre, corners.iter().map(|c| (*c - centre).length()).fold(0.0, f64::max))
    }
}

/// The surfaces of a mesh: one per triangle, with its vertex normals when the mesh is smooth.
pub fn mesh_surfaces(mesh: &TriangleMesh) -> impl Iterator<Item = Surface> + '_ {
    (0..mesh.triangles.len()).map(|i| {
        let [a, b, c] = mesh.triangle(i).map(dvec);
        let vertex_normals =
            mesh.normals.as_ref().map(|normals| mesh.triangles[i].map(|v| dvec(normals[v as usize])));
        Surface::Triangle(Triangle { vertex_normals, ..Triangle::new(a, b, c) })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: DVec3, b: DVec3, tol: f64) -> bool {
        (a - b).length() <= tol
    }

    #[test]
    fn parallelogram_hits_inside_and_misses_outside() {
        let p = Parallelogram::new(
            DVec3::new(1.0, 2.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 3.0),
        );
        assert!((p.area - 6.0).abs() < 1e-12);
        assert!(close(p.normal, DVec3::NEG_Y, 1e-12));
        // Aim at the point (s, r) = (0.3, 0.6) from below and from above.
        let target = p.point(0.3, 0.6);
        for o in [DVec3::new(0.0, -5.0, 1.0), DVec3::new(4.0, 9.0, -2.0)] {
            let d = (target - o).normalize();
            let hit = p.intersect(o, d, f64::INFINITY).expect("hit");
            assert!(close(o + hit.t * d, target, 1e-12));
            assert!(p.intersect(o, d, hit.t * 0.999).is_none(), "t_max must cut the hit");
            assert!(p.intersect(o, -d, f64::INFINITY).is_none(), "behind the origin");
        }
        for (s, r) in [(-0.01, 0.5), (1.01, 0.5), (0.5, -0.01), (0.5, 1.01)] {
            let o = DVec3::new(0.0, -5.0, 1.0);
            assert!(p.intersect(o, (p.point(s, r) - o).normalize(), f64::INFINITY).is_none());
        }
        // Parallel to the plane.
        assert!(p.intersect(DVec3::new(0.0, 2.0, 0.0), DVec3::X, f64::INFINITY).is_none());
    }

    #[test]
    fn ball_from_outside_and_inside() {
        let s = Ball { center: DVec3::new(1.0, 0.0, 0.0), radius: 2.0 };
        let h = s.intersect(DVec3::new(-5.0, 0.0, 0.0), DVec3::X, f64::INFINITY).unwrap();
        assert!((h.t - 4.0).abs() < 1e-12 && close(h.normal, DVec3::NEG_X, 1e-12));
        // From the centre: the inner surface, outward normal.
        let h = s.intersect(DVec3::new(1.0, 0.0, 0.0), DVec3::Y, f64::INFINITY).unwrap();
        assert!((h.t - 2.0).abs() < 1e-12 && close(h.normal, DVec3::Y, 1e-12));
        // From just inside the surface, heading in: the far side, not the near one.
        let o = DVec3::new(1.0 + 2.0 - 1e-9, 0.0, 0.0);
        let h = s.intersect(o, DVec3::NEG_X, f64::INFINITY).unwrap();
        assert!((h.t - (4.0 - 1e-9)).abs() < 1e-9, "{h:?}");
        assert!(s.intersect(DVec3::new(-5.0, 2.5, 0.0), DVec3::X, f64::INFINITY).is_none());
        assert!(s.intersect(DVec3::new(5.0, 0.0, 0.0), DVec3::X, f64::INFINITY).is_none());
    }

    #[test]
    fn rotated_box_agrees_with_its_world_corners() {
        // The tall Cornell block: local [0,165] x [0,330] x [0,165], rotated +15 deg about its
        // corner, moved to (265, 0, 295).
        let shape = illum_scene::BoxShape {
            min: glam::Vec3::ZERO,
            max: glam::Vec3::new(165.0, 330.0, 165.0),
            rotate_y_deg: 15.0,
            pivot: glam::Vec3::ZERO,
            translate: glam::Vec3::new(265.0, 0.0, 295.0),
        };
        let b = OrientedBox::from_shape(&shape);
        // The corners in f64 from the box's own transform; they agree with the scene crate's f32
        // corners to f32 precision.
        let corners: [DVec3; 8] = std::array::from_fn(|i| {
            let pick = |bit: usize| if i >> bit & 1 == 1 { b.hi[bit] } else { b.lo[bit] };
            b.rotation * DVec3::new(pick(0), pick(1), pick(2)) + b.offset
        });
        for (ours, theirs) in corners.iter().zip(shape.world_corners()) {
            assert!(close(*ours, dvec(theirs), 1e-3), "{ours:?} vs {theirs:?}");
        }
        // docs/scenes.md: the footprint corner with local (165, 0, 0) lands at (424.4, 0, 252.3).
        assert!(close(corners[1], DVec3::new(424.4, 0.0, 252.3), 0.06), "{:?}", corners[1]);
        // Each face's centre is hit head-on from outside with that face's normal.
        let faces = [
            (1usize, 3usize, 5usize, 7usize),
            (0, 2, 4, 6),
            (2, 3, 6, 7),
            (0, 1, 4, 5),
            (4, 5, 6, 7),
            (0, 1, 2, 3),
        ];
        let centre: DVec3 = corners.iter().sum::<DVec3>() / 8.0;
        for (a, bb, c, dd) in faces {
            let fc = (corners[a] + corners[bb] + corners[c] + corners[dd]) / 4.0;
            let outward = (fc - centre).normalize();
            let o = fc + 50.0 * outward;
            let hit = b.intersect(o, -outward, f64::INFINITY).expect("face hit");
            assert!((hit.t - 50.0).abs() < 1e-9, "{hit:?}");
            assert!(close(hit.normal, outward, 1e-9), "{:?} vs {outward:?}", hit.normal);
            // From the centre outward: the same face from inside, outward normal.
            let hit = b.intersect(centre, outward, f64::INFINITY).expect("inside hit");
            assert!(close(centre + hit.t * outward, fc, 1e-9));
            assert!(close(hit.normal, outward, 1e-9));
        }
        // A ray passing beside the block, and one pointing away from it.
        assert!(b.intersect(DVec3::new(0.0, 400.0, 0.0), DVec3::X, f64::INFINITY).is_none());
        assert!(b.intersect(centre + DVec3::new(0.0, 0.0, 500.0), DVec3::Z, f64::INFINITY).is_none());
    }

    #[test]
    fn axis_parallel_rays_on_a_box() {
        let b =
            OrientedBox { lo: DVec3::ZERO, hi: DVec3::ONE, rotation: DMat3::IDENTITY, offset: DVec3::ZERO };
        let h = b.intersect(DVec3::new(0.5, 0.5, -1.0), DVec3::Z, f64::INFINITY).unwrap();
        assert_eq!(h.t, 1.0);
        assert_eq!(h.normal, DVec3::NEG_Z);
        assert!(b.intersect(DVec3::new(1.5, 0.5, -1.0), DVec3::Z, f64::INFINITY).is_none());
        // A ray starting on the top face going up leaves at t = 0: no hit.
        assert!(b.intersect(DVec3::new(0.5, 1.0, 0.5), DVec3::Y, f64::INFINITY).is_none());
    }

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
