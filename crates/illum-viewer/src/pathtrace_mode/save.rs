//! Saving the path tracer's image: a PNG of the image shown (denoised when Denoise is on) or an
//! EXR checkpoint that `render --resume` continues; natively to a file, in the browser as a
//! download.

use std::path::{Path, PathBuf};

use illum_image::{Encoding, RgbImage32};

use super::PathTraceMode;

impl PathTraceMode {
    /// Writes the mean image to `save_path` with the given extension ("png" or "exr"),
    /// atomically (illum-image writes a temporary file and renames it). Returns the path.
    pub fn save(&mut self, extension: &str) -> Result<PathBuf, String> {
        let tracer = self.tracer.as_ref().ok_or("nothing rendered yet")?;
        if tracer.accumulator().total_samples() == 0 {
            return Err("nothing rendered yet".to_owned());
        }
        let path = Path::new(self.save_path.trim()).with_extension(extension);
        if path.as_os_str().is_empty() || path.file_stem().is_none() {
            return Err(format!("{:?} is not a file name", self.save_path));
        }
        // With Denoise on, the PNG is the denoised image shown; the EXR stays the raw samples'
        // checkpoint (which `render --resume` continues) and records the denoised estimate.
        let denoised = self.denoise.image().filter(|_| self.settings.denoise);
        let denoise_fields = crate::denoise_view::exr_fields(&self.denoise).filter(|_| self.settings.denoise);
        let metadata = || {
            let mut metadata = illum_pathtrace::metadata::exr_metadata(
                tracer,
                self.progressive.clock().elapsed().as_secs_f64(),
                self.progressive.stopped(),
                "illum-viewer",
            );
            metadata.fields.extend(denoise_fields.clone().unwrap_or_default());
            metadata
        };
        #[cfg(not(target_arch = "wasm32"))]
        if extension == "exr" {
            // With the statistics layer, so that `render --resume` can continue it (at the size
            // the viewer rendered).
            illum_pathtrace::checkpoint::save_checkpoint(&path, tracer, &metadata())?;
        } else {
            // The PNG is the image as rendered (or denoised): gamma 2.2, no display exposure.
            let image: RgbImage32 = denoised.cloned().unwrap_or_else(|| tracer.accumulator().mean_image());
            illum_image::save_png(&path, &image, 0.0, Encoding::Gamma22).map_err(|e| error_chain(&e))?;
        }
        // In the browser the same file, made in memory, is downloaded under the field's file name.
        #[cfg(target_arch = "wasm32")]
        {
            let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            let (bytes, mime) = if extension == "exr" {
                (illum_pathtrace::checkpoint::checkpoint_bytes(&name, tracer, &metadata())?, "image/x-exr")
            } else {
                let image: RgbImage32 =
                    denoised.cloned().unwrap_or_else(|| tracer.accumulator().mean_image());
                let bytes = illum_image::png_bytes(&name, &image, 0.0, Encoding::Gamma22)
                    .map_err(|e| error_chain(&e))?;
                (bytes, "image/png")
            };
            crate::browser::download(&name, &bytes, mime)?;
            Ok(PathBuf::from(name))
        }
        #[cfg(not(target_arch = "wasm32"))]
        Ok(path)
    }
}

/// An error with its causes, "outer: inner: ...", so a failed save says why.
fn error_chain(error: &dyn std::error::Error) -> String {
    let mut text = error.to_string();
    let mut source = error.source();
    while let Some(cause) = source {
        text.push_str(": ");
        text.push_str(&cause.to_string());
        source = cause.source();
    }
    text
}
