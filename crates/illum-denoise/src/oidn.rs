//! Intel Open Image Denoise's RT filter on its CPU device (cargo feature `oidn`; the library is
//! not part of illum: docs/denoising-oidn.md says where to get it and how to link it).
//!
//! The filter reads the mean image as HDR colour and the path tracer's guides as its auxiliary
//! images: albedo in [0, 1] and the mean normal, zero where the pixel's rays left the scene
//! (OIDN's "no surface"). The guides average a few samples and are not noise-free, so
//! `clean_aux` stays off and OIDN denoises them itself. It ignores the per-pixel variance: what
//! it removes is judged by its network, not by illum's statistics; the bound
//! ([`crate::bound`], applied by [`crate::Denoiser`]) is what keeps its output within the
//! pixels' noise.

use illum_image::RgbImage32;

use crate::DenoiseError;
use crate::input::DenoiseInput;

pub struct OidnDenoiser {
    device: oidn::Device,
}

fn failed(what: &str, error: oidn::Error) -> DenoiseError {
    DenoiseError::Unsupported(format!("Open Image Denoise: {what}: {error}"))
}

impl OidnDenoiser {
    /// Creates OIDN's CPU device (fails when the library's CPU module is not beside it).
    pub fn new() -> Result<Self, DenoiseError> {
        let device = oidn::Device::cpu().map_err(|e| failed("no CPU device", e))?;
        Ok(OidnDenoiser { device })
    }

    /// The RT filter's output for `input` (its colour, albedo and normal; not its variance).
    pub fn denoise(&self, input: &DenoiseInput) -> Result<RgbImage32, DenoiseError> {
        let flat = |pixels: &[[f32; 3]]| pixels.iter().flatten().copied().collect::<Vec<f32>>();
        let color = flat(&input.image.pixels);
        let mut output = vec![0.0f32; color.len()];
        let mut filter = oidn::RayTracing::try_new(&self.device).map_err(|e| failed("no RT filter", e))?;
        filter
            .image_dimensions(input.width() as usize, input.height() as usize)
            .hdr(true)
            .albedo_normal(&flat(&input.albedo), &flat(&input.normal));
        filter.filter(&color, &mut output).map_err(|e| failed("the RT filter failed", e))?;
        self.device.get_error().map_err(|e| failed("the device reported", e))?;
        let pixels = output.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
        Ok(RgbImage32 { width: input.width(), height: input.height(), pixels })
    }
}
