//! CPU mirror of `shaders/spawn.wgsl`: where a ray leaving a surface starts.
//!
//! A computed surface point `p` lies within `err` of the true surface, measured along the unit
//! normal `n` (the surface routines in `shaders/geometry.wgsl` supply `err`: 0 for points
//! snapped onto an axis-aligned face, [`SPAWN_REL_ERROR`] times the magnitude of the numbers the
//! point was computed from otherwise). [`spawn_point`] moves `p` by `err` along `n` and then steps
//! every coordinate that moved one more float in the same direction (pbrt-v4's OffsetRayOrigin).
//! The rounding of `p + err n` is at most half a float step per coordinate, so after the extra step
//! each coordinate has moved strictly more than `|err n_i|` toward `n`'s side. Two guarantees
//! follow, and the tests below check both in f64 over positions from 1e-6 to 1e6:
//!
//! - **No self-intersection**: `n . (p' - p) > err`, so `p'` is strictly on `n`'s side of any
//!   plane through a point within `err` of `p` along `n`.
//! - **Bounded offset**: `|p'_i - p_i| <= err' |n_i| (1 + 2^-23) + 2^-22 max(|p_i|, |p'_i|) +
//!   2^-149`, with `err' = max(err, SPAWN_MIN_OFFSET)`: the error bound (as rounded) plus 1.5
//!   float steps. A surface farther than [`offset_bound`] from `p` is therefore never skipped.
//!
//! The function is the same, operation for operation, as the WGSL one. A GPU compiler may fuse
//! `p + err n` into a fused multiply-add, which rounds once instead of twice; both guarantees
//! hold for either rounding.

use glam::Vec3;

/// Relative error bound of a rebuilt surface point: 32 machine epsilons (2^-18). See the surface
/// functions in geometry.wgsl for the per-shape analysis (all under 8.5 epsilons of the shape's
/// magnitude, the intersection test's own error included).
pub const SPAWN_REL_ERROR: f32 = 1.0 / 262_144.0;
/// Smallest offset used (2^-100), so that `p + err n` stays clear of subnormals near zero.
pub const SPAWN_MIN_OFFSET: f32 = f32::from_bits((127 - 100) << 23);

/// The float next to `x` in the direction of `towards` (`x` itself when `towards == 0`), by the
/// same bit manipulation as the shader's `step_float`. `x` must be finite.
pub fn step_float(x: f32, towards: f32) -> f32 {
    if towards == 0.0 {
        return x;
    }
    if x == 0.0 {
        return if towards > 0.0 { f32::from_bits(1) } else { f32::from_bits(0x8000_0001) };
    }
    // A float's bits, read as an integer, grow with its magnitude.
    let bits = x.to_bits();
    let away = (x > 0.0) == (towards > 0.0);
    f32::from_bits(if away { bits + 1 } else { bits - 1 })
}

/// The origin of a ray leaving the surface at `p` toward `n`'s side (`n` unit; `err` bounds `p`'s
/// distance from the true surface along `n`).
pub fn spawn_point(p: Vec3, n: Vec3, err: f32) -> Vec3 {
    let offset = err.max(SPAWN_MIN_OFFSET) * n;
    let q = p + offset;
    Vec3::new(step_float(q.x, offset.x), step_float(q.y, offset.y), step_float(q.z, offset.z))
}

/// The error bound of a point computed from numbers of magnitude at most `magnitude`.
pub fn spawn_error(magnitude: f32) -> f32 {
    SPAWN_REL_ERROR * magnitude
}

/// The stated bound on how far [`spawn_point`] moves any coordinate of `p`: the error bound plus
/// two float steps of the largest coordinate (plus the smallest subnormal).
pub fn offset_bound(p: Vec3, err: f32) -> f64 {
    let err = f64::from(err.max(SPAWN_MIN_OFFSET));
    err * (1.0 + 2.0f64.powi(-23))
        + 2.0f64.powi(-22) * (f64::from(p.abs().max_element()) + err)
        + 2.0f64.powi(-149)
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;

    #[test]
    fn the_constants_are_the_shaders() {
        let wgsl = include_str!("../shaders/spawn.wgsl");
        let constant = |name: &str| -> f32 {
            let line = wgsl
                .lines()
                .find(|l| l.starts_with(&format!("const {name}:")))
                .expect("constant in spawn.wgsl");
            let value = line.split('=').nth(1).expect("a value").trim().trim_end_matches(';');
            value.parse().expect("a float literal")
        };
        assert_eq!(constant("SPAWN_REL_ERROR"), SPAWN_REL_ERROR);
        assert_eq!(SPAWN_REL_ERROR, 2.0f32.powi(-18));
        assert_eq!(constant("SPAWN_MIN_OFFSET"), SPAWN_MIN_OFFSET);
        assert_eq!(SPAWN_MIN_OFFSET, 2.0f32.powi(-100));
    }

    #[test]
    fn step_float_matches_the_standard_library() {
        let values = [
            0.0f32,
            -0.0,
            1.0,
            -1.0,
            2.0,
            -2.0,
            0.5,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            f32::from_bits(1),
            -f32::from_bits(1),
            f32::from_bits(0x007f_ffff),
            3.0e38,
            -3.0e38,
            1.0e-6,
            123_456.79,
            -555.0,
        ];
        for x in values {
            let (up, down) = (step_float(x, 1.0), step_float(x, -1.0));
            // next_up/next_down of -0.0 and +0.0 agree; compare bit patterns otherwise.
            assert_eq!(up.to_bits(), x.next_up().to_bits(), "step up from {x:e}");
            assert_eq!(down.to_bits(), x.next_down().to_bits(), "step down from {x:e}");
            assert_eq!(step_float(x, 0.0).to_bits(), x.to_bits());
        }
    }

    /// Unit normals along and off the axes, both signs.
    fn normals() -> Vec<Vec3> {
        let mut out = Vec::new();
        for base in [
            Vec3::X,
            Vec3::Y,
            Vec3::Z,
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(0.966, 0.0, 0.259), // a block face turned 15 degrees about +Y
            Vec3::new(1.0, 1e-4, 0.0),    // almost along an axis
            Vec3::new(1e-3, -1.0, 2e-3),
        ] {
            let n = base.normalize();
            out.push(n);
            out.push(-n);
        }
        out
    }

    /// Positions with coordinates of magnitude 1e-6 .. 1e6 (and mixtures), every sign pattern.
    fn positions() -> Vec<Vec3> {
        let mut out = Vec::new();
        let mut magnitude = 1e-6f64;
        while magnitude <= 1.0001e6 {
            let m = magnitude as f32;
            for (a, b, c) in [
                (m, m, m),
                (m, 1.37 * m, 0.71 * m),
                (m, 0.0, 0.0),
                (0.0, m, 0.0),
                (m, 1e-6, 1e6),
                (1e6, m, 1e-6),
                (1.0, m, 555.0),
            ] {
                for signs in 0..8 {
                    let s = |bit: u32| if signs >> bit & 1 == 1 { -1.0 } else { 1.0 };
                    out.push(Vec3::new(s(0) * a, s(1) * b, s(2) * c));
                }
            }
            magnitude *= 10.0f64.sqrt();
        }
        out
    }

    fn dvec(v: Vec3) -> DVec3 {
        v.as_dvec3()
    }

    /// The spawned point against the plane through `on_plane` with normal `n`, in f64: its
    /// signed distance must be strictly positive, and the move must respect the offset bound.
    fn check(p: Vec3, n: Vec3, err: f32, on_plane: DVec3, label: &str) {
        let spawned = spawn_point(p, n, err);
        let side = dvec(n).dot(dvec(spawned) - on_plane);
        assert!(
            side > 0.0,
            "{label}: p = {p:?}, n = {n}, err = {err:e}: spawned {spawned:?} is {side:e} from the plane"
        );
        let bound = offset_bound(p, err);
        for i in 0..3 {
            let moved = (f64::from(spawned[i]) - f64::from(p[i])).abs();
            let allowed =
                f64::from(err.max(SPAWN_MIN_OFFSET)) * f64::from(n[i].abs()) * (1.0 + 2.0f64.powi(-23))
                    + 2.0f64.powi(-22) * f64::from(spawned[i].abs().max(p[i].abs()))
                    + 2.0f64.powi(-149);
            assert!(
                moved <= allowed,
                "{label}: p = {p:?}, n = {n}: coordinate {i} moved {moved:e} > {allowed:e}"
            );
            assert!(
                moved <= bound,
                "{label}: p = {p:?}, n = {n}: coordinate {i} moved {moved:e} > bound {bound:e}"
            );
        }
        // Distance travelled along the normal: never more than the bound, so no surface farther
        // than the bound is skipped.
        let along = dvec(n).dot(dvec(spawned) - dvec(p));
        assert!(along <= 3.0f64.sqrt() * bound, "{label}: moved {along:e} along n, bound {bound:e}");
    }

    #[test]
    fn a_point_exactly_on_its_surface_leaves_it_with_no_error_bound() {
        // Axis-aligned faces: the point is snapped onto the face's plane, so err = 0 and the
        // one-float step alone must put it on the normal's side.
        let mut count = 0;
        for p in positions() {
            for n in normals() {
                check(p, n, 0.0, dvec(p), "exact point");
                count += 1;
            }
        }
        assert!(count > 3000, "only {count} cases");
    }

    #[test]
    fn a_point_off_its_surface_by_up_to_the_error_bound_still_leaves_it() {
        // Rebuilt points: the true surface may pass up to err above p (in n's direction), the
        // worst case for the side test. err is the bound for a shape of p's own magnitude.
        for p in positions() {
            for n in normals() {
                let err = spawn_error(p.abs().max_element());
                // The true plane passes through p + err n (1 - 4 u covers rounding of err n).
                let on_plane = dvec(p) + f64::from(err) * (1.0 - 2.5e-7) * dvec(n);
                check(p, n, err, on_plane, "point below its surface");
                let below = dvec(p) - f64::from(err) * dvec(n);
                check(p, n, err, below, "point above its surface");
            }
        }
    }

    #[test]
    fn the_error_bound_covers_points_rebuilt_from_large_shapes() {
        // A point near the origin on a shape of magnitude 1e3 (e.g. a rotated block whose face
        // passes close to the origin): its error is relative to the shape, not to p.
        for p in positions().into_iter().filter(|p| p.abs().max_element() < 1.0) {
            for n in normals() {
                let err = spawn_error(1000.0);
                let on_plane = dvec(p) + f64::from(err) * (1.0 - 2.5e-7) * dvec(n);
                check(p, n, err, on_plane, "point of a large shape");
            }
        }
    }

    #[test]
    fn the_offsets_scale_with_the_magnitude() {
        // Cornell-box scale (coordinates ~555): the offset of a rebuilt point is about 2e-3,
        // 3.8e-6 relative; an exact point moves one float (6e-5). Both shrink with the scene.
        let n = Vec3::Y;
        for (p, err, most) in [
            (Vec3::new(300.0, 555.0, 300.0), spawn_error(555.0), 2.3e-3),
            (Vec3::new(300.0, 555.0, 300.0), 0.0, 7e-5),
            (Vec3::new(0.3, 0.555, 0.3), spawn_error(0.555), 2.3e-6),
            (Vec3::new(1e5, 1e5 + 555.0, 1e5), 0.0, 1e-2),
        ] {
            let moved = f64::from(spawn_point(p, n, err).y - p.y);
            assert!(
                moved > 0.0 && moved <= most,
                "p = {p}, err = {err:e}: moved {moved:e}, expected <= {most:e}"
            );
        }
    }
}
