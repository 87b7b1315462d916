//! What the planner chooses among: a [`Setting`] (every choice but the samples per pixel) and
//! the [`Candidate`] the pilot measured for it.

use std::fmt;

use illum_scene::{Bounces, DenoiserKind, Effects, Look, Sequence};

use crate::plan::noise::NoiseCurve;

/// Every setting but the samples per pixel: what the pilot measures once.
#[derive(Clone, Debug, PartialEq)]
pub enum Setting {
    Raster {
        look: Look,
        effects: Effects,
    },
    Whitted {
        depth: u32,
        aa: u32,
    },
    PathTrace {
        bounces: Bounces,
        caustics: bool,
        sequence: Sequence,
        /// Adaptive sampling: the spp spread over the image's blocks by a pilot of their noise.
        adaptive: bool,
        /// The denoiser run on the render (kept as two halves for its error estimate).
        denoise: Option<DenoiserKind>,
    },
}

impl Setting {
    /// The renderer's name as `--renderer` spells it.
    pub fn renderer(&self) -> &'static str {
        match self {
            Setting::Raster { .. } => "raster",
            Setting::Whitted { .. } => "whitted",
            Setting::PathTrace { .. } => "pathtrace",
        }
    }
}

impl fmt::Display for Setting {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Setting::Raster { look, effects } => {
                let off: Vec<&str> = Effects::TOGGLES
                    .iter()
                    .filter(|(_, turn_off)| {
                        let mut e = *effects;
                        turn_off(&mut e);
                        e == *effects
                    })
                    .map(|(name, _)| *name)
                    .collect();
                let look = match look {
                    Look::Figure => "figure",
                    Look::Enhanced => "enhanced",
                };
                if off.is_empty() {
                    write!(f, "rasterizer, {look} look")
                } else {
                    write!(f, "rasterizer, {look} look, {} off", off.join(", "))
                }
            }
            Setting::Whitted { depth, aa } => {
                write!(f, "Whitted ray tracer, depth {depth}, {aa}x{aa} rays per pixel")
            }
            Setting::PathTrace { bounces, caustics, sequence, adaptive, denoise } => {
                write!(
                    f,
                    "path tracer, bounces {bounces}, caustic light tracer {}",
                    if *caustics { "on" } else { "off" }
                )?;
                if *sequence != Sequence::Independent {
                    write!(f, ", {sequence} sequence")?;
                }
                if *adaptive {
                    f.write_str(", adaptive")?;
                }
                match denoise {
                    Some(DenoiserKind::Atrous) => f.write_str(", denoised by à-trous"),
                    Some(DenoiserKind::Oidn) => f.write_str(", denoised by OIDN"),
                    None => Ok(()),
                }
            }
        }
    }
}

/// What the pilot measured for one setting, scaled to the size of the render asked for.
#[derive(Clone, Debug, PartialEq)]
pub struct Candidate {
    pub setting: Setting,
    /// relMSE against the truth that no number of samples removes (>= 0).
    pub bias_rel_mse: f64,
    /// How the path tracer's relMSE beyond its bias falls with the spp (the input of
    /// [`noise_rel_mse`](super::noise_rel_mse)); `None` for the deterministic renderers.
    pub noise: Option<NoiseCurve>,
    /// The path tracer's spp is a multiple of this (2 for a denoised render's two halves, the
    /// replicate run for the low-discrepancy sequence); 1 otherwise.
    pub spp_multiple: u32,
    /// Seconds that do not depend on the samples: device and pipeline setup, and for a
    /// deterministic renderer its whole image.
    pub fixed_seconds: f64,
    /// The path tracer's seconds per sample per pixel over the whole image (0 otherwise).
    pub seconds_per_spp: f64,
    /// The region whose mean brightness is furthest from the truth's, and that brightness
    /// relative to the truth's, to say why a setting cannot meet a target.
    pub worst_region: Option<(String, f64)>,
}
