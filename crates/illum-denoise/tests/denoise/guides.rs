//! The path tracer's guide buffers (illum-pathtrace's tracer/guides.rs) on the Cornell box.

use illum_pathtrace::GUIDE_SAMPLES;

use crate::common;

/// Pixels that see one wall with all their samples hold its albedo and its normal facing the
/// camera exactly (every sample's value is the same f32); every pixel's albedo lies in [0, 1]
/// and its mean normal is at most unit length.
#[test]
fn cornell_guides_hold_each_walls_albedo_and_normal() {
    let tracer = common::render(&common::cornell(4, 1));
    let guides = tracer.guides(1000).expect("guides");
    assert_eq!(guides.samples, GUIDE_SAMPLES, "the request is capped");
    let size = common::SIZE as usize;
    let at = |x: usize, y: usize| (guides.albedo[y * size + x], guides.normal[y * size + x]);
    // The red wall (x = 555) is on the image's left, the green one on its right, the floor at
    // the bottom, the back wall above the blocks (row 20; the ceiling meets it near row 15); the outermost 2 or 3 pixels
    // see past the box's open front.
    let cases = [
        ("red wall", at(5, size / 2), [0.5608, 0.0627, 0.0627], [-1.0, 0.0, 0.0]),
        ("green wall", at(size - 6, size / 2), [0.0588, 0.3961, 0.0863], [1.0, 0.0, 0.0]),
        ("floor", at(size / 2, size - 6), [0.5, 0.5, 0.5], [0.0, 1.0, 0.0]),
        ("back wall", at(size / 2, 20), [0.5, 0.5, 0.5], [0.0, 0.0, -1.0]),
    ];
    for (what, (albedo, normal), want_albedo, want_normal) in cases {
        for c in 0..3 {
            assert!(
                (albedo[c] - want_albedo[c]).abs() <= 1e-6,
                "{what}: albedo {albedo:?}, want {want_albedo:?}"
            );
            assert!(
                (normal[c] - want_normal[c]).abs() <= 1e-6,
                "{what}: normal {normal:?}, want {want_normal:?}"
            );
        }
    }
    for (a, n) in guides.albedo.iter().zip(&guides.normal) {
        assert!(a.iter().all(|v| (0.0..=1.0).contains(v)), "albedo {a:?}");
        assert!(n.iter().map(|v| v * v).sum::<f32>() <= 1.0 + 1e-5, "normal {n:?}");
    }
}
