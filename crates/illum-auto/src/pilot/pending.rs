//! What the pilot holds between steps besides its tracer: the truth once rendered, a readback
//! under way, and a denoised setting's measurements so far.

use illum_denoise::{DenoiseInput, PendingDenoise};
use illum_image::RgbImage32;
use illum_pathtrace::{Guides, PendingGuides};
use illum_raster::PendingFrame;
use illum_whitted::{PendingImage, PendingObjectIds};
use web_time::Instant;

use crate::measure::Measured;
use crate::regions::Regions;

/// The truth once rendered: its image, its own estimated relMSE and the regions.
pub(super) struct Truth {
    pub(super) image: RgbImage32,
    pub(super) rel_mse: f64,
    pub(super) regions: Regions,
}

/// A readback under way, polled on later steps.
pub(super) enum Pending {
    /// The truth's object-ID image, with the truth's image and estimated relMSE.
    Regions { ids: PendingObjectIds, image: RgbImage32, rel_mse: f64 },
    /// A raster setting's frame at the pilot's size.
    Raster(PendingFrame),
    /// A Whitted setting's image at the pilot's size, its set-up seconds and when its
    /// frame was submitted.
    Whitted { image: PendingImage, setup: f64, submitted: Instant },
    /// A denoised setting's guides of `samples` for the running tracer, and when they were
    /// submitted.
    Guides { guides: PendingGuides, samples: u32, submitted: Instant },
    /// A denoised setting's à-trous run on the running tracer's accumulation at `spp`, its
    /// input (which `DenoiseInput::finish` reads) and when it was submitted.
    Denoised { pending: PendingDenoise, input: DenoiseInput, spp: u32, submitted: Instant },
}

/// What a denoised setting has measured at the pilot's size.
#[derive(Default)]
pub(super) struct Denoising {
    /// The guides of the running tracer and their samples per pixel.
    pub(super) guides: Option<(u32, Guides)>,
    /// Seconds of the guides and of the fastest filter run (None before either ran).
    pub(super) guide_seconds: Option<f64>,
    pub(super) filter_seconds: Option<f64>,
    /// The pixels of the image they were timed on.
    pub(super) pixels: f64,
    /// The denoised image's measurement at each spp of `denoised_spps` reached so far.
    pub(super) at: Vec<(u32, Measured)>,
}

impl Denoising {
    /// Records a filter run of `seconds` (the fastest counts: the first run pays for pipelines
    /// made lazily).
    pub(super) fn filtered(&mut self, seconds: f64) {
        self.filter_seconds = Some(self.filter_seconds.map_or(seconds, |s| s.min(seconds)));
    }
}
