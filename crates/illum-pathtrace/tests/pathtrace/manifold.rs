//! Manifold next-event estimation on the GPU (`shaders/manifold.wgsl`, `--caustic-method
//! manifold`) against the f64 oracle's own solve (illum-oracle's `manifold.rs`, written apart:
//! a dense grid of 4096 intervals with a search for root pairs hidden near folds, where the GPU
//! takes 24 intervals and keeps the first and last root of a chain on each side). Both renderers
//! then leave the light tracer and its gather out and solve the chains R, T T and T R T through
//! each sphere, with the same bound on the concentration, so their images agree in expectation
//! pixel by pixel (the criterion, its false-alarm rate and its power check: oracle_agreement.rs).
//! Each path class the solve owns is compared: the caustic seen directly (bounces 3 and 8), the
//! caustic seen in the mirror ball, and the caustic's light scattered again.

use illum_pathtrace::{Estimator, Estimators, PathTracer};
use illum_scene::{CausticMethod, Scene};

use crate::caustic::{caustic_view, mirror_view, wall_view};
use crate::common;
use crate::oracle_agreement::compare_render;

fn solved(mut scene: Scene) -> Scene {
    scene.pathtrace.caustic_method = CausticMethod::Manifold;
    let estimators = Estimators::of(&scene);
    assert!(estimators.manifold() && !estimators.light_tracer(), "{}", estimators.key());
    assert!(estimators.list().contains(&Estimator::ManifoldNee));
    scene
}

fn compare(label: &str, scene: &Scene) -> PathTracer {
    let gpu = common::render(scene);
    compare_render(label, &gpu, scene.pathtrace.spp);
    gpu
}

#[test]
fn the_solved_caustic_agrees_with_the_oracle_at_bounces_3_and_8() {
    for bounces in [3, 8] {
        compare(&format!("whitted caustic view solved, bounces {bounces}"), &solved(caustic_view(bounces)));
    }
}

#[test]
fn the_solved_caustic_seen_in_the_mirror_agrees_with_the_oracle() {
    compare("whitted mirror view solved, bounces 8", &solved(mirror_view()));
}

#[test]
fn the_solved_caustic_scattered_again_agrees_with_the_oracle() {
    compare("wall view solved, bounces 8", &solved(wall_view()));
}
