//! illum-pathtrace: the Cornell box path tracer (the assignment's task 2).
//!
//! A WGSL compute shader (`shaders/pathtrace.wgsl`) traces paths over the scene's
//! analytic boxes, quads and spheres with next-event estimation on rectangular lights and the
//! sun; a second compute shader (`caustic.wgsl`, only with `[pathtrace] caustics = true`) traces
//! the caustic from the sun (`tracer/caustic.rs`, docs/caustics.md); which estimators run for a
//! scene is decided in one place ([`estimators`]). The host
//! side here uploads the scene ([`gpu_scene`]), composes the pipeline ([`shaders`], with a
//! traversal generated per scene by [`specialise`]), checks the device's limits ([`limits`]),
//! plans short GPU submissions ([`planner`]), and folds each batch's f32 sums into f64
//! per-pixel statistics ([`accumulator`]). For viewers,
//! an opt-in running image stays on the GPU ([`display_sum`]) so that showing it needs no copy
//! through the CPU.

pub mod accumulator;
pub mod allocation;
mod batch;
mod bindings;
pub mod checkpoint;
mod display_sum;
mod error;
pub mod error_map;
mod estimators;
pub mod glint;
pub mod gpu_scene;
mod limits;
mod manifold;
pub mod metadata;
mod options;
mod planner;
pub mod progressive;
pub mod reference;
pub mod replicates;
mod scene_code;
mod shaders;
pub mod specialise;
mod tracer;

pub use accumulator::{Accumulator, ExactPart, ImageParts};
pub use allocation::SampleAllocation;
pub use batch::{CHUNK_SAMPLES, SLOT_BYTES};
pub use display_sum::{DISPLAY_PIXEL_BYTES, DISPLAY_SUM_SHADER};
pub use error::PathTraceError;
pub use estimators::{Estimator, Estimators};
pub use gpu_scene::implements;
pub use illum_scene::Sequence;
pub use manifold::MANIFOLD_MODULE;
pub use options::{TracerOptions, Traversal};
pub use progressive::{
    Progress, Progressive, RenderClock, Rule, Status, StopReason, StopRules, parse_target_error,
    parse_time_budget,
};
#[cfg(not(target_arch = "wasm32"))]
pub use progressive::{render_progressive, render_progressive_over};
pub use shaders::{
    CAUSTIC_BUFFERS_MODULE, CAUSTIC_SHADER, CAUSTIC_WALK_MODULE, GATHER_SHADER, GENERIC_LIGHT_CHOICE,
    GENERIC_MATERIALS, GENERIC_TRAVERSAL, GUIDES_SHADER, PATHTRACE_SHADER, SAMPLING_MODULES, SCENE_MODULE,
    SURFACES_MODULE, shader_modules,
};
pub use tracer::{
    CausticParams, CausticParts, GUIDE_SAMPLES_MAX, GUIDE_SAMPLES_MIN, Guides, PathTracer, PendingGuides,
    Readback, StepReport, bounding_sphere, fixed_point, guide_samples,
};
