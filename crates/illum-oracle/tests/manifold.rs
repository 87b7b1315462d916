//! Manifold next-event estimation in the oracle (`manifold.rs`) as an estimator: closed forms it
//! must reproduce exactly, its path-length rule, its bound, that it replaces the light tracer,
//! and that its image agrees with the light tracer's where both count the same paths.

use glam::DVec3;
use illum_oracle::{Chain, ManifoldSettings, Oracle};
use illum_scene::{Bounces, Scene};

/// A floor seen from above and a ball of `material` at (3, 3, 0), radius 0.5, under a sun of
/// irradiance 3 along (-1, -1, 0): its shadow is centred on the origin.
fn ball_scene(material: &str) -> Scene {
    let text = format!(
        "[camera]\neye = [0.0, 5.0, 0.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 0.0, 1.0]\nvfov = 40.0\n\
         width = 24\nheight = 16\n[directional_light]\ndirection = [-1.0, -1.0, 0.0]\n\
         irradiance = [3.0, 3.0, 3.0]\n[materials.floor]\nalbedo = [0.6, 0.6, 0.6]\n\
         [materials.ball]\n{material}\n[[objects]]\nname = \"floor\"\nmaterial = \"floor\"\n\
         quad = {{ corner = [-50.0, 0.0, -50.0], edge_u = [0.0, 0.0, 100.0], edge_v = [100.0, 0.0, 0.0] }}\n\
         [[objects]]\nname = \"ball\"\nmaterial = \"ball\"\nsphere = {{ center = [3.0, 3.0, 0.0], radius = 0.5 }}\n"
    );
    Scene::from_toml_str(&text, "manifold.toml").unwrap_or_else(|e| panic!("{e}"))
}

fn mnee(scene: &Scene, bounces: Bounces, settings: ManifoldSettings) -> Oracle {
    illum_scene::specular_spheres::solvable_spheres(scene).unwrap();
    Oracle::new(scene).unwrap().with_bounces(bounces).with_manifold(Some(settings))
}

/// Guards the concentration's normalisation (C = 1 with no deflection) and the weights at
/// index 1: a ball of index 1 is invisible, so at every floor point in its shadow MNEE must
/// find exactly one path, TT with C = 1, carrying E cos 45 degrees; outside it nothing.
#[test]
fn an_index_1_ball_passes_the_sun_unchanged() {
    let oracle =
        mnee(&ball_scene("dielectric = { ior = 1.0 }"), Bounces::Unbounded, ManifoldSettings::default());
    let expected = 3.0 * 0.5f64.sqrt();
    let mut inside = 0;
    for i in 0..41 {
        for j in 0..41 {
            // Off the axis point (0, 0), where C = |b| / (|dg/db| r_x) is 0 / 0 in floating point.
            let (x, z) = (-0.987 + 0.05 * f64::from(i), -0.991 + 0.05 * f64::from(j));
            let p = DVec3::new(x, 1e-9, z);
            // Paths of weight ~1e-32 (F at index 1 is zero but for rounding) do not count.
            let paths: Vec<_> = oracle
                .manifold_paths(p, DVec3::Y, DVec3::Y, 0)
                .into_iter()
                .filter(|p| p.irradiance.x > 1e-12)
                .collect();
            // The shadow: |p - axis| < 0.5 across the axis through (3, 3, 0) along (-1, -1, 0).
            let across = ((x * x / 2.0) + z * z).sqrt();
            if across < 0.49 {
                inside += 1;
                assert_eq!(paths.len(), 1, "({x}, {z}): {paths:?}");
                let path = paths[0];
                assert_eq!(path.chain, Chain::TT);
                assert!((path.concentration - 1.0).abs() < 1e-9, "({x}, {z}): C = {}", path.concentration);
                assert!((path.irradiance.x - expected).abs() < 1e-8 * expected, "{path:?}");
            } else if across > 0.51 {
                assert!(paths.is_empty(), "({x}, {z}): {paths:?}");
            }
        }
    }
    assert!(inside > 200, "{inside} points in the shadow");
}

/// Guards the path-length rule d + k + 1 <= n (k the chain's events, d the vertex's depth) and
/// the bound on C, on a glass ball's shadow point that R does not reach but TT does.
#[test]
fn chains_count_by_path_length_and_the_bound_clamps_c() {
    let scene = ball_scene("dielectric = { ior = 1.5 }");
    let p = DVec3::new(0.05, 1e-9, 0.02);
    let chains = |bounces: Bounces, depth: u32| {
        let oracle = mnee(&scene, bounces, ManifoldSettings::with_internal_reflections(1));
        let mut found: Vec<u32> =
            oracle.manifold_paths(p, DVec3::Y, DVec3::Y, depth).iter().map(|p| p.chain.chords).collect();
        found.dedup();
        found
    };
    assert_eq!(chains(Bounces::Unbounded, 0), vec![1]);
    assert_eq!(chains(Bounces::Fixed(3), 0), vec![1]);
    assert_eq!(chains(Bounces::Fixed(2), 0), Vec::<u32>::new());
    assert_eq!(chains(Bounces::Fixed(4), 1), vec![1]);
    assert_eq!(chains(Bounces::Fixed(3), 1), Vec::<u32>::new());
    // A bound of half the largest C met clamps that path's C and scales its irradiance alike.
    let free = mnee(&scene, Bounces::Unbounded, ManifoldSettings::default());
    let paths = free.manifold_paths(p, DVec3::Y, DVec3::Y, 0);
    let top = paths.iter().max_by(|a, b| a.concentration.total_cmp(&b.concentration)).unwrap();
    let bound = 0.5 * top.concentration;
    let settings = ManifoldSettings { max_concentration: Some(bound), ..ManifoldSettings::default() };
    let limited = mnee(&scene, Bounces::Unbounded, settings).manifold_paths(p, DVec3::Y, DVec3::Y, 0);
    assert_eq!(limited.len(), paths.len());
    let same = limited.iter().find(|q| q.theta1 == top.theta1).unwrap();
    assert_eq!(same.concentration, bound);
    assert!(
        (same.irradiance.x - 0.5 * top.irradiance.x).abs() < 1e-12 * top.irradiance.x,
        "{same:?} vs {top:?}"
    );
}

/// Guards the ownership rule: MNEE on turns the caustic's light tracer and photon gather off,
/// and asking for the light tracer again while MNEE is on changes nothing.
#[test]
fn mnee_replaces_the_light_tracer() {
    let scene = ball_scene("dielectric = { ior = 1.5 }");
    let oracle = Oracle::new(&scene).unwrap().with_caustics(true);
    assert!(oracle.caustics() && oracle.gathers());
    let oracle = oracle.with_manifold(Some(ManifoldSettings::default()));
    assert!(oracle.manifold() && !oracle.caustics() && !oracle.gathers());
    let oracle = oracle.with_caustics(true);
    assert!(!oracle.caustics(), "the light tracer came back while MNEE is on");
}

/// Guards the integration into the camera paths: the glass ball's shadow seen directly (paths
/// L S+ D E, which both estimators count completely but for chains of two or more internal
/// reflections, under 0.2% of the light here) must have the same mean with MNEE as with the
/// light tracer, within their standard errors.
#[test]
fn the_shadow_through_glass_matches_the_light_tracer() {
    let scene = ball_scene("dielectric = { ior = 1.5 }");
    let threads = illum_oracle::default_threads();
    let tracer = Oracle::new(&scene)
        .unwrap()
        .with_bounces(Bounces::Fixed(4))
        .with_caustics(true)
        .render(256, 3, threads);
    let manifold = mnee(&scene, Bounces::Fixed(4), ManifoldSettings::default()).render(64, 4, threads);
    let (mut n, mut a, mut b, mut var) = (0.0, 0.0, 0.0, 0.0);
    let t = 20f64.to_radians().tan();
    for y in 0..16 {
        for x in 0..24 {
            // The floor point the pixel's centre sees (right = -x, up = +z, at height 5).
            let sx = (2.0 * (f64::from(x) + 0.5) / 24.0 - 1.0) * 1.5 * t;
            let sy = (1.0 - 2.0 * (f64::from(y) + 0.5) / 16.0) * t;
            let (px, pz) = (-5.0 * sx, 5.0 * sy);
            if (px * px / 2.0 + pz * pz).sqrt() < 0.4 {
                let i = tracer.index(x, y);
                n += 1.0;
                a += tracer.mean[i][0];
                b += manifold.mean[i][0];
                var += tracer.variance_of_mean[i][0] + manifold.variance_of_mean[i][0];
            }
        }
    }
    assert!(n >= 8.0, "{n} shadow pixels");
    let (a, b, se) = (a / n, b / n, var.sqrt() / n);
    assert!(b > 20.0 * se, "the shadow is dark with MNEE: {b} +- {se}");
    assert!((a - b).abs() < 4.0 * se, "light tracer {a}, MNEE {b}, +- {se}");
}
