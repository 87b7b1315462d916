//! GPU tests of the Cornell box path tracer, in one test binary that shares one device on
//! lavapipe. (One binary, not one per file: each test binary links wgpu, and a dozen of them
//! filled the CI machine's disk.)
//!
//! - `adaptive`: adaptive sampling gives each pixel its block's samples and stays unbiased;
//! - `caustic`: the caustic's light tracer against the oracle, a closed form (an index-1 ball
//!   vanishes), the error estimate with two estimators, extremes and its fixed point;
//! - `glint`: a sun disc of 1 degree finds the glint (E S+ L) that the delta sun's host solve
//!   adds, around its brightest pixels within a z-test, and not without it;
//! - `closed_form`: direct light at floor points against Lambert's polygon formula;
//! - `statistics`: the samplers agree, cosine sampling is less noisy, seeds, batching, no NaN;
//! - `reference`: a small Cornell box against checked-in converged references, per pixel;
//! - `oracle_agreement`: the GPU against the independent f64 CPU oracle (crates/illum-oracle);
//! - `error_estimate`: the error shown to users tracks the true error; the 1/sqrt(N) rate;
//! - `sampling`: chi-square tests of the WGSL sampling routines, run on the GPU;
//! - `extremes`: the path tracer where floats run out;
//! - `display_sum`: the viewer's GPU-resident running image agrees with the f64 statistics;
//! - `specialisation`: each scene's pipeline holds what it uses, is cached, refuses others,
//!   and keeps the caller's submission size across a resize;
//! - `overflow`: lights up to f32::MAX keep a finite image, error estimate and display sum;
//! - `pacing`: a caller that goes away between steps (a viewer) is not charged for its absence;
//! - `polled`: the web viewer's polled readback (bands, and the caustic's frames) folds the same
//!   samples as the blocking one;
//! - `random_scenes`: a few hundred random valid scenes render without NaN or dropped samples;
//! - `whitted_extremes`: the Whitted scene's sun at extreme elevations and sizes against the
//!   floor's closed form, and albedo 1 with unbounded bounces.
//!
//! naga validates the shaders without a GPU in each crate's own tests (see the workspace's
//! tests/shaders.rs).

#[path = "../common/mod.rs"]
mod common;

mod adaptive;
mod caustic;
mod closed_form;
mod display_sum;
mod error_estimate;
mod extremes;
mod furnace;
mod glint;
mod manifold;
mod meshes;
mod oracle_agreement;
mod overflow;
mod pacing;
mod polled;
mod random_scenes;
mod reference;
mod sampling;
mod specialisation;
mod statistics;
mod whitted_extremes;
