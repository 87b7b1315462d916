//! The light tracer's parameters: what the shaders read (`CausticParams`), the bounding spheres
//! particles start from, and the fixed point its splats are added in. Pure arithmetic, tested
//! without a GPU.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use illum_rtcore::GpuShape;

/// Mirrors `struct CausticParams` in caustic.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct CausticParams {
    pub particles: u32,
    pub row_stride: u32,
    pub frame_base: u32,
    pub frame_count: u32,
    pub num_discs: u32,
    pub seed: u32,
    pub pixel_area: f32,
    pub area_per_particle: f32,
    pub scene_centre: [f32; 3],
    pub scene_radius: f32,
    pub fixed_scale: f32,
    pub fixed_cap: f32,
    pub disc_area: f32,
    /// r_1 of the photon gather (0 without it).
    pub gather_radius: f32,
    /// Photon-grid buckets per frame (a power of two; 1 without the gather).
    pub buckets: u32,
    /// The dispatch's particles (or pixels, in the gather): `first_index..index_end` (a frame's
    /// pieces are ranges of them, see `schedule.rs`).
    pub first_index: u32,
    pub index_end: u32,
    /// The sample index the gather's radius counts from: the render's first (see
    /// `gather_radius` in caustic_buffers.wgsl).
    pub radius_origin: u32,
}

/// Mixed into the scene's seed for the particles, so that particle i of frame k never draws
/// the random numbers of sample k of pixel i.
pub(super) const PARTICLE_SEED_KEY: u32 = 0x5ca0_571c;
/// Words per pixel of a frame: (lo, hi) for each of three channels.
pub(super) const WORDS_PER_PIXEL: u64 = 6;
/// The most bytes one dispatch's frames take (and the most host memory one pass's chunk
/// statistics may take, below).
pub(super) const SPLAT_BYTES: u64 = 64 << 20;
/// Bytes per photon: three vec4 (caustic_buffers.wgsl).
pub(super) const PHOTON_BYTES: u64 = 48;
/// Host bytes per pixel and slot layer of a pass: S1 and S2, three f64 each.
pub(crate) const PASS_BYTES_PER_PIXEL_LAYER: u64 = 48;
/// The most host memory one pass's caustic statistics may take.
pub(crate) const PASS_BYTES: u64 = 256 << 20;

/// The bounding sphere (centre, radius) of a shape, in f32 (what the GPU tests against).
pub fn bounding_sphere(shape: &GpuShape) -> (Vec3, f32) {
    match *shape {
        GpuShape::Aabb { min, max } => (0.5 * (min + max), 0.5 * (max - min).length()),
        GpuShape::Box { local_min, local_max, cos, sin, offset } => {
            let c = 0.5 * (local_min + local_max);
            let centre = Vec3::new(cos * c.x + sin * c.z, c.y, -sin * c.x + cos * c.z) + offset;
            (centre, 0.5 * (local_max - local_min).length())
        }
        GpuShape::Quad { corner, edge_u, edge_v } => {
            let radius = 0.5 * (edge_u + edge_v).length().max((edge_u - edge_v).length());
            (corner + 0.5 * (edge_u + edge_v), radius)
        }
        GpuShape::Sphere { center, radius } => (center, radius),
    }
}

/// The fixed-point scale S (a power of two) and cap for frames of `particles` particles whose
/// typical splat is `reference` (in the GPU's scaled radiance).
///
/// Each particle adds to one pixel once, as q = round(v S) < cap, cap = 2^(64 - ceil(log2 N))
/// (particles at or above it are dropped and counted). A frame's pixel sum is then below
/// N cap <= 2^64: the two-word (64-bit) sum cannot overflow, for any scene, sun or particle.
/// S puts the reference splat at cap / 2^24: a particle may be 2^24 times brighter than the
/// reference (the floor 4096 times nearer the eye, say) before it is dropped, and the reference
/// splat has 64 - ceil(log2 N) - 24 bits (22 at 512 x 512: relative rounding 2^-23, below f32's
/// own). The scale follows the sun's irradiance, so a very bright sun changes nothing but S.
pub fn fixed_point(particles: u64, reference: f64) -> (f32, f32) {
    let bits = 64 - (particles.max(1) as f64).log2().ceil() as i32;
    let cap = 2f64.powi(bits);
    let exponent = if reference > 0.0 && reference.is_finite() {
        ((cap / 2f64.powi(24) / reference).log2().floor() as i32).clamp(-120, 120)
    } else {
        0
    };
    (2f32.powi(exponent), cap as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The no-overflow argument: N particles, each below the cap, sum below 2^64; the reference
    /// splat sits 2^24 below the cap (within a factor 2, S being a power of two), for one pixel
    /// up to 2^28 particles and references from a dim to a blinding sun.
    #[test]
    fn the_fixed_point_cannot_overflow_and_keeps_headroom() {
        for particles in [1u64, 2, 3, 1000, 512 * 512, 1 << 24, (1 << 28) - 1] {
            for reference in [1e-30, 1e-6, 0.37, 3.0, 1e6, 1e20] {
                let (scale, cap) = fixed_point(particles, reference);
                assert_eq!(scale.to_bits() & 0x007f_ffff, 0, "{scale} is a power of two");
                assert_eq!(cap.to_bits() & 0x007f_ffff, 0, "{cap} is a power of two");
                // N cap <= 2^64: the largest total of a frame's pixel fits the two words.
                assert!(particles as f64 * f64::from(cap) <= 2f64.powi(64), "N {particles}, cap {cap}");
                // Every q below the cap splits exactly into two words.
                assert!(f64::from(cap) <= 2f64.powi(64));
                let q = reference * f64::from(scale);
                let target = f64::from(cap) / 2f64.powi(24);
                // (S is an f32: beyond 2^120 it stops growing, and a light of 1e-30 keeps
                // fewer bits, still about 20.)
                let clamped = scale == 2f32.powi(120);
                assert!(
                    q <= target && (q > 0.5 * target || clamped),
                    "N {particles}, reference {reference}: q {q}, target {target}"
                );
            }
        }
        // A reference of zero (no light) or not a number gives scale 1, not infinity.
        assert_eq!(fixed_point(100, 0.0).0, 1.0);
        assert_eq!(fixed_point(100, f64::NAN).0, 1.0);
    }

    #[test]
    fn bounding_spheres_contain_their_shapes() {
        let quad = GpuShape::Quad {
            corner: Vec3::ZERO,
            edge_u: Vec3::new(2.0, 0.0, 0.0),
            edge_v: Vec3::new(1.0, 0.0, 3.0),
        };
        let (c, r) = bounding_sphere(&quad);
        for p in [Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 3.0), Vec3::new(3.0, 0.0, 3.0)] {
            assert!((p - c).length() <= r * (1.0 + 1e-6), "{p} outside ({c}, {r})");
        }
        let (cos, sin) = (0.5f32.sqrt(), 0.5f32.sqrt());
        let boxed = GpuShape::Box {
            local_min: Vec3::ZERO,
            local_max: Vec3::new(1.0, 2.0, 3.0),
            cos,
            sin,
            offset: Vec3::new(5.0, 0.0, 1.0),
        };
        let (c, r) = bounding_sphere(&boxed);
        for i in 0..8 {
            let l = Vec3::new((i & 1) as f32, 2.0 * ((i >> 1) & 1) as f32, 3.0 * ((i >> 2) & 1) as f32);
            let p = Vec3::new(cos * l.x + sin * l.z, l.y, -sin * l.x + cos * l.z) + Vec3::new(5.0, 0.0, 1.0);
            assert!((p - c).length() <= r * (1.0 + 1e-6), "corner {p} outside ({c}, {r})");
        }
    }
}
