//! The path tracer's guide buffers (illum-pathtrace's tracer/guides.rs) on the Cornell box.

use illum_pathtrace::{GUIDE_SAMPLES_MAX, GUIDE_SAMPLES_MIN};

use crate::common;

/// Pixels that see one wall with all their samples hold its albedo and its normal facing the
/// camera exactly (every sample's value is the same f32); every pixel's albedo lies in [0, 1]
/// and its mean normal is at most unit length.
#[test]
fn cornell_guides_hold_each_walls_albedo_and_normal() {
    let tracer = common::render(&common::cornell(4, 1));
    let guides = tracer.guides(GUIDE_SAMPLES_MAX + 1).expect("guides");
    assert_eq!(guides.samples, GUIDE_SAMPLES_MAX, "the request is capped");
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

/// A ball between two walls, the camera between the ball and the near wall: the ray through
/// the image's centre meets the ball head-on. A mirror ball (reflectance 0.5) sends it straight
/// back to the near wall (albedo 0.8): the guide is 0.5 x 0.8 with the near wall's normal,
/// whatever the sample. A glass ball (index 1.5) reflects ((1.5 - 1) / (1.5 + 1))^2 = 4% at
/// normal incidence: the guide follows the likelier refraction in and out, on to the far wall
/// (albedo 0.6), weighted by its probability at each crossing: 0.96^2 x 0.6 = 0.553, within
/// 1e-3 (the pixel's rays meet the ball up to 9 degrees off normal, where the reflectance is
/// 0.0401). A guide that sampled the branch would mix in the near wall (0.8) in about 8% of
/// samples and lie near 0.57; one that stopped at the glass would be 0.
#[test]
fn guides_follow_mirrors_and_the_likelier_branch_of_glass_to_the_next_diffuse_surface() {
    let scene = |ball: &str| {
        let text = format!(
            "[camera]\neye = [0.0, 0.0, 0.0]\ntarget = [0.0, 0.0, 5.0]\nup = [0.0, 1.0, 0.0]\nvfov = 30.0\n\
             width = 9\nheight = 9\n[environment]\nradiance = [1.0, 1.0, 1.0]\n\
             [materials.ball]\n{ball}\n[materials.far]\nalbedo = [0.6, 0.6, 0.6]\n[materials.near]\nalbedo = [0.8, 0.8, 0.8]\n\
             [[objects]]\nmaterial = \"ball\"\nsphere = {{ center = [0.0, 0.0, 5.0], radius = 1.0 }}\n\
             [[objects]]\nmaterial = \"far\"\nquad = {{ corner = [-50.0, -50.0, 10.0], edge_u = [100.0, 0.0, 0.0], edge_v = [0.0, 100.0, 0.0] }}\n\
             [[objects]]\nmaterial = \"near\"\nquad = {{ corner = [-50.0, -50.0, -3.0], edge_u = [100.0, 0.0, 0.0], edge_v = [0.0, 100.0, 0.0] }}\n\
             [pathtrace]\nspp = 1\nbounces = 16\n"
        );
        illum_scene::Scene::from_toml_str(&text, "mirror-and-glass.toml").unwrap_or_else(|e| panic!("{e}"))
    };
    let centre = 4 * 9 + 4;
    let mirror =
        common::render(&scene("mirror = { reflectance = [0.5, 0.5, 0.5] }")).guides(16).expect("guides");
    for c in 0..3 {
        assert!((mirror.albedo[centre][c] - 0.4).abs() <= 1e-6, "mirror: albedo {:?}", mirror.albedo[centre]);
    }
    assert!((mirror.normal[centre][2] - 1.0).abs() <= 1e-3, "mirror: normal {:?}", mirror.normal[centre]);
    let glass = common::render(&scene("dielectric = { ior = 1.5 }")).guides(64).expect("guides");
    let (a, want) = (glass.albedo[centre], 0.96f32 * 0.96 * 0.6);
    assert!(a.iter().all(|&v| (v - want).abs() <= 1e-3), "glass: albedo {a:?}, want {want}");
    assert!(
        (glass.normal[centre][2] + 1.0).abs() <= 1e-2,
        "glass: the far wall's normal, {:?}",
        glass.normal[centre]
    );
}

/// The guides read back without waiting (`start_guides`, the viewer's) are the blocking
/// readback's, bit for bit.
#[test]
fn polled_guides_are_the_blocking_ones() {
    let tracer = common::render(&common::cornell(2, 5));
    let blocking = tracer.guides(GUIDE_SAMPLES_MIN).expect("guides");
    let pending = tracer.start_guides(GUIDE_SAMPLES_MIN).expect("submitted");
    let polled = loop {
        if let Some(result) = pending.poll(common::gpu()) {
            break result.expect("read back");
        }
        std::thread::sleep(std::time::Duration::from_millis(1));
    };
    assert!(polled == blocking, "the polled guides differ from the blocking ones");
}
