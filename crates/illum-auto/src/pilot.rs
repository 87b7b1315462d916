//! The pilot of Auto: what the planner ([`crate::plan`]) needs, measured on this scene and this
//! machine. One pilot serves the command line (`render --renderer auto`, which loops
//! [`Pilot::step`] to the end) and the viewer, on the desktop and in a web page (which steps it
//! once per frame); what differs between them is only [`PilotOptions`], [`Sizes`] and the
//! [`Pace`] they step it with.
//!
//! - **The truth**: the converged solution ([`crate::settings::truth_scene`], bounces
//!   unbounded, the caustic's light tracer where there is one) at [`PilotOptions::longer_side`]
//!   pixels on the longer side (the scene's aspect), rendered as the measuring tools render a
//!   reference ([`illum_pathtrace::reference::reference_scene`]) to
//!   [`PilotOptions::truth_spp`], or handed in ([`Pilot::with_truth`]: the command line's cache);
//!   then its regions, from the Whitted tracer's object IDs.
//! - **Bias and noise**: every setting of [`crate::settings::settings_with_variants`] at that
//!   size, compared with the truth per region ([`crate::measure::measured`]). A path-tracer
//!   setting runs to [`PilotOptions::pilot_spp`]; its noise curve comes from its own estimate (a
//!   low-discrepancy setting's at the spp of [`crate::measure::low_discrepancy_spps`]), and a
//!   denoised setting's from its denoised image at the spp of [`crate::measure::denoised_spps`].
//!   Measurements handed in ([`Pilot::with_measured`]: the command line's cache) are not taken
//!   again.
//! - **Throughput**, every run: the rasterizer's set-up and one frame at [`Sizes::raster`]; the
//!   Whitted ray tracer's set-up and frame at the pilot's size, the frame scaled by the ratio of
//!   pixel counts to [`Sizes::whitted`]; the path tracer's set-up with its first sample per
//!   pixel, then its time per spp over [`PilotOptions::timing_spp`] more, at the size
//!   [`PilotOptions::timed_at`] names, scaled to [`Sizes::pathtrace`] and multiplied by the wall
//!   time per second of path tracing that the [`Pace`] leaves; adaptive sampling's own pilot and
//!   a denoised setting's guides and filter runs are timed at the pilot's size and scaled the
//!   same way.
//!
//! Nothing waits for the GPU where a web page cannot: each step submits work or polls a readback
//! under way, so the same state machine runs natively and in the browser. Natively every
//! submission is waited for, so that its time is the GPU's. Two variants wait in any case and
//! are measured natively only, as only the command line offers them: adaptive sampling's 16-spp
//! pilot and Open Image Denoise (a CPU library).

mod machine;
mod path_setting;
mod pending;
mod running;

use illum_scene::DenoiserKind;
use web_time::Instant;

use crate::settings::Variants;
pub use machine::Pilot;

/// How the pilot measures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PilotOptions {
    /// Pixels on the longer side of the pilot's images (never more than the scene's own).
    pub longer_side: u32,
    /// Samples per pixel of the truth.
    pub truth_spp: u32,
    /// Samples per pixel of each path-tracer setting's bias and noise measurement.
    pub pilot_spp: u32,
    /// Samples per pixel of each path-tracer setting's throughput (after the first, which
    /// counts in its set-up).
    pub timing_spp: u32,
    /// Which variants of each path-tracer setting are measured.
    pub variants: Variants<'static>,
    /// How a denoised setting is rendered.
    pub denoising: Denoising,
    /// Where the path tracer's throughput is timed.
    pub timed_at: TimedAt,
    /// Seconds every render pays before its renderer starts (setting up the device), added to
    /// every candidate's fixed cost.
    pub overhead_seconds: f64,
}

impl PilotOptions {
    /// `render --renderer auto`'s pilot: every variant the command line offers, measured at 128
    /// pixels against an 8192-spp truth.
    pub const COMMAND_LINE: PilotOptions = PilotOptions {
        longer_side: 128,
        truth_spp: 8192,
        pilot_spp: 256,
        timing_spp: 32,
        variants: Variants {
            low_discrepancy: true,
            adaptive: true,
            denoisers: if illum_denoise::OIDN_BUILT {
                &[DenoiserKind::Atrous, DenoiserKind::Oidn]
            } else {
                &[DenoiserKind::Atrous]
            },
        },
        denoising: Denoising::AsRender,
        timed_at: TimedAt::Pilot,
        overhead_seconds: 0.0,
    };

    /// The viewer's pilot: half the command line's side and a quarter of its truth's spp, so
    /// that it ends in seconds while the user watches (on lavapipe, 2 cores, about 15 s on the
    /// Whitted scene); the variants the viewer offers (the à-trous filter of its Denoise
    /// toggle); the path tracer timed at the view's size, where its frames are paced.
    pub const VIEWER: PilotOptions = PilotOptions {
        longer_side: 64,
        truth_spp: 2048,
        pilot_spp: 64,
        timing_spp: 4,
        variants: Variants { low_discrepancy: false, adaptive: false, denoisers: &[DenoiserKind::Atrous] },
        denoising: Denoising::AsToggle,
        timed_at: TimedAt::Target,
        overhead_seconds: 0.0,
    };
}

/// How a denoised setting is rendered, as the front end that shows it renders it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Denoising {
    /// As `render --denoise`: two halves of the samples (the spp in steps of 2), guides of
    /// `illum_pathtrace::guide_samples` of the spp.
    AsRender,
    /// As the viewer's Denoise toggle: one accumulation, guides of the fewest samples.
    AsToggle,
}

impl Denoising {
    /// Samples per pixel of the guides of an image of `spp`.
    pub fn guide_samples(self, spp: u32) -> u32 {
        match self {
            Denoising::AsRender => illum_pathtrace::guide_samples(spp),
            Denoising::AsToggle => illum_pathtrace::GUIDE_SAMPLES_MIN,
        }
    }

    /// The spp a denoised render takes in multiples of.
    pub fn spp_multiple(self) -> u32 {
        match self {
            Denoising::AsRender => 2,
            Denoising::AsToggle => 1,
        }
    }
}

/// A denoised render filters the whole and its two halves (the halves estimate its error).
pub const FILTER_RUNS: f64 = 3.0;

/// Where the path tracer's throughput is timed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TimedAt {
    /// At the pilot's size, scaled by the ratio of pixel counts: for a render's size, too large
    /// to time in seconds.
    Pilot,
    /// At [`Sizes::pathtrace`] itself: for a window's view, where the pilot's size would not
    /// fill the device and the frames' pacing is part of the cost.
    Target,
}

/// The size, in pixels, at which each renderer will render: what the throughput is scaled to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sizes {
    pub raster: [u32; 2],
    pub whitted: [u32; 2],
    pub pathtrace: [u32; 2],
}

impl Sizes {
    /// Every renderer at one size (a render's).
    pub fn all(width: u32, height: u32) -> Sizes {
        Sizes { raster: [width, height], whitted: [width, height], pathtrace: [width, height] }
    }
}

/// How the pilot's steps share time with whatever else runs (a window's frames).
pub trait Pace {
    /// Seconds of GPU work to submit in the step about to run.
    fn slice_seconds(&mut self) -> f64;
    /// Records that a step began at `started` and took `seconds`.
    fn stepped(&mut self, started: Instant, seconds: f64);
    /// Wall seconds per second of path tracing, once the pilot is done: what the path
    /// tracer's throughput is divided by (1 with nothing else to share with).
    fn wall_per_traced_second(&self) -> f64;
}

/// The pace of a pilot with nothing to share its time with (the command line): submissions of
/// the path tracer's own default length, and all of the wall time its own.
#[derive(Clone, Copy, Debug, Default)]
pub struct Unpaced;

impl Pace for Unpaced {
    fn slice_seconds(&mut self) -> f64 {
        UNPACED_SLICE_SECONDS
    }
    fn stepped(&mut self, _: Instant, _: f64) {}
    fn wall_per_traced_second(&self) -> f64 {
        1.0
    }
}

/// The submission length of an unpaced pilot: long enough that a submission's fixed cost is
/// small beside its work, short enough that a Ctrl-C is answered at once.
pub const UNPACED_SLICE_SECONDS: f64 = 0.15;

/// Where a pilot stands after a step.
#[derive(Clone, Debug, PartialEq)]
pub enum Progress {
    /// Still measuring: the share done (the truth counts half, the settings the other half),
    /// and what is being measured.
    Working { done: f32, what: String },
    /// Every setting measured: [`Pilot::candidates`] holds them.
    Done,
    /// Stopped on an error, which says why.
    Failed(String),
}
