//! The denoisers `render --denoise` can run, behind one call, so that the halves' error
//! estimate ([`crate::split`]) treats them alike, and so that every output passes through the
//! same bound ([`crate::bound`]). Open Image Denoise exists only in builds with
//! the cargo feature `oidn`; without it, asking for it is an error that says how to build it.

use illum_gpu::GpuContext;
#[cfg(not(target_arch = "wasm32"))]
use illum_image::RgbImage32;

use crate::atrous::{AtrousDenoiser, AtrousSettings};
#[cfg(not(target_arch = "wasm32"))]
use crate::input::DenoiseInput;
use crate::{DenoiseError, DenoiserKind};

/// How to get a build with Open Image Denoise (the refusal's advice).
pub const OIDN_BUILD_HINT: &str = "this build has no Open Image Denoise: build with \
    `--features illum-denoise/oidn` and OIDN_DIR set to a libOpenImageDenoise 2.5 \
    (docs/denoising-oidn.md), or use --denoise atrous";

/// Whether this build has Open Image Denoise (the cargo feature `oidn`).
pub const OIDN_BUILT: bool = cfg!(feature = "oidn");

pub enum Denoiser {
    Atrous {
        /// Boxed: the filter's pipelines are large beside OIDN's device handle.
        filter: Box<AtrousDenoiser>,
        settings: AtrousSettings,
    },
    #[cfg(feature = "oidn")]
    Oidn(crate::oidn::OidnDenoiser),
}

impl Denoiser {
    /// The denoiser of that kind with its default settings.
    pub fn new(gpu: &GpuContext, kind: DenoiserKind) -> Result<Self, DenoiseError> {
        match kind {
            DenoiserKind::Atrous => Ok(Denoiser::Atrous {
                filter: Box::new(AtrousDenoiser::new(gpu)?),
                settings: AtrousSettings::default(),
            }),
            #[cfg(feature = "oidn")]
            DenoiserKind::Oidn => Ok(Denoiser::Oidn(crate::oidn::OidnDenoiser::new()?)),
            #[cfg(not(feature = "oidn"))]
            DenoiserKind::Oidn => Err(DenoiseError::Unsupported(OIDN_BUILD_HINT.to_owned())),
        }
    }

    pub fn kind(&self) -> DenoiserKind {
        match self {
            Denoiser::Atrous { .. } => DenoiserKind::Atrous,
            #[cfg(feature = "oidn")]
            Denoiser::Oidn(_) => DenoiserKind::Oidn,
        }
    }

    /// The denoised image of `input`, each channel bounded to its noisy value +- 3.29 standard
    /// errors ([`crate::bound`]), with the exact radiance added back ([`DenoiseInput::finish`]).
    /// Waits for the GPU: native only.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn denoise(&self, input: &DenoiseInput) -> Result<RgbImage32, DenoiseError> {
        let mut image = match self {
            Denoiser::Atrous { filter, settings } => filter.denoise(input, settings)?.0,
            #[cfg(feature = "oidn")]
            Denoiser::Oidn(filter) => filter.denoise(input)?,
        };
        input.finish(&mut image);
        Ok(image)
    }
}
