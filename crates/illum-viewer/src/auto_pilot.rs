//! The Auto mode's pilot: what the planner needs, measured on the view's scene with the
//! viewer's own renderers, a slice of work per frame so that the window keeps drawing.
//!
//! It measures what `render --renderer auto`'s pilot measures (`illum_lab::auto::pilot`), with
//! the same settings, regions and bias rule (`illum_auto`), smaller so that it ends in seconds:
//! - a path-traced truth at [`PilotOptions::longer_side`] pixels on the longer side (the view's
//!   aspect, bounces unbounded, the caustic's light tracer where there is one), accumulated
//!   over frames to [`PilotOptions::truth_spp`];
//! - every setting of `illum_auto::settings::settings` and each path-tracer setting denoised by
//!   the à-trous filter ([`SETTINGS`]) at that size against it, one per frame (a path-tracer
//!   setting over several frames to [`PilotOptions::pilot_spp`]): its bias, its noise per
//!   sample and its worst region; a denoised setting's curve is its denoised image's error at
//!   the spp of `illum_auto::measure::denoised_spps` (the filter as the Denoise toggle runs it:
//!   its guides, then `DenoiseInput::finish`), read by `illum_auto::measure::denoised` as the
//!   CLI's pilot reads it;
//! - the throughput at the size each mode renders the view at: the rasterizer's set-up and one
//!   frame; the Whitted ray tracer's set-up and frame at the pilot's size, the frame scaled by
//!   the ratio of pixel counts (a 4x4-ray frame at the view's size held the window for 3 s);
//!   the path tracer's set-up with its first sample per pixel and its time per spp over
//!   [`PilotOptions::timing_spp`] more at its own resolution, times the wall time per second of path tracing that the window's frames leave
//!   ([`FramePacer`]: the pilot's path tracing is paced as the path-tracer mode's is, so the
//!   rest of each frame is measured while it runs); a denoised setting's guides and its fastest
//!   filter run at the pilot's size, scaled by the ratio of pixel counts, the run counted three
//!   times (a refresh of the Denoise toggle filters the whole and its two halves). The viewer's
//!   device is already set up, so no device time is added.
//!
//! Nothing in it waits for the GPU where a web page cannot: each step submits work or polls a
//! readback under way ([`RasterRenderer::read_polled`], [`WhittedTracer::render_polled`],
//! [`WhittedTracer::object_ids_polled`], the path tracer's polled bands and guides,
//! [`illum_denoise::AtrousDenoiser::start`]), so the same state
//! machine runs natively and in the browser. Natively the Whitted frame, the raster's view-size
//! frame, the guides and the filter runs are waited for, so that their time is the GPU's; in a
//! web page their time runs from the submission to the frame the image is back in, and so
//! includes the rest of that frame.

#[cfg(doc)]
use crate::pacer::FramePacer;
#[cfg(doc)]
use illum_raster::RasterRenderer;
#[cfg(doc)]
use illum_whitted::WhittedTracer;
pub use polled::ViewerPilot;

mod pending;
mod polled;
mod running;

use illum_auto::settings::Variants;
use illum_scene::DenoiserKind;

/// The variants of each path-tracer setting the viewer's pilot measures: denoised by the
/// à-trous filter, the one the path tracer's Denoise toggle runs (the low-discrepancy sequence
/// and adaptive sampling are the command line's).
pub const SETTINGS: Variants<'static> =
    Variants { low_discrepancy: false, adaptive: false, denoisers: &[DenoiserKind::Atrous] };

/// A refresh of the Denoise toggle runs the filter on the whole and on its two halves.
pub const FILTER_RUNS: f64 = 3.0;

/// How the viewer's pilot measures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PilotOptions {
    /// Pixels on the longer side of the pilot's images.
    pub longer_side: u32,
    /// Samples per pixel of the truth.
    pub truth_spp: u32,
    /// Samples per pixel of each path-tracer setting.
    pub pilot_spp: u32,
    /// Samples per pixel of each path-tracer setting's throughput at the view's size (after
    /// the first, which counts in its set-up).
    pub timing_spp: u32,
}

impl Default for PilotOptions {
    /// Half the CLI's pilot side and a quarter of its truth's spp: on lavapipe (2 cores) the
    /// Whitted scene's pilot takes about 15 s, so it is run while the user watches.
    fn default() -> Self {
        PilotOptions { longer_side: 64, truth_spp: 2048, pilot_spp: 64, timing_spp: 4 }
    }
}

/// The size, in pixels, at which each mode renders the view: what the throughput is scaled to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewSizes {
    pub raster: [u32; 2],
    pub whitted: [u32; 2],
    pub pathtrace: [u32; 2],
}
