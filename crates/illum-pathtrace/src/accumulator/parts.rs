//! The image as the two parts it is made of: the **sampled** part, each pixel's mean of its
//! samples with the variance of that mean, and the **exact** part, radiance solved rather than
//! sampled (the sun's glint, `glint.rs`), which has no variance. The accumulator owns both;
//! [`ImageParts`] is the one view every consumer takes (the saved and shown image, the
//! denoiser, the metrics of the samples alone), so that the rule joining them lives here only:
//! **a pixel's estimate is its sampled mean plus its exact part once it has a sample** (before
//! that it has no estimate, and shows 0).
//!
//! A consumer that forgot the exact part would be wrong by a factor of a thousand in a glint
//! pixel; one that filtered or bounded it as if it were noisy would spread it. The view gives
//! each what it needs: [`ImageParts::mean`] whole, [`ImageParts::sampled_mean`] and
//! [`ImageParts::variance`] for filters and statistics of the samples, and
//! [`ImageParts::shown_exact`] to put the exact part back on a filtered image.

use illum_image::RgbImage32;

use super::Accumulator;

/// Radiance solved exactly, per pixel: (pixel, rgb) sorted by pixel, at most one entry per
/// pixel, every value finite.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ExactPart {
    entries: Vec<(usize, [f64; 3])>,
}

impl ExactPart {
    /// The exact part of an image of `pixels` pixels from (pixel, radiance) entries in any
    /// order; entries of one pixel add. Refused for a pixel outside the image or a value that is
    /// not finite.
    pub fn new(entries: &[(usize, [f64; 3])], pixels: usize) -> Result<Self, String> {
        if let Some(&(p, _)) = entries.iter().find(|e| e.0 >= pixels) {
            return Err(format!("exact radiance at pixel {p}, outside the image's {pixels} pixels"));
        }
        if let Some(&(p, v)) = entries.iter().find(|e| e.1.iter().any(|c| !c.is_finite())) {
            return Err(format!("exact radiance {v:?} at pixel {p} is not finite"));
        }
        let mut sorted = entries.to_vec();
        sorted.sort_by_key(|e| e.0);
        let mut merged: Vec<(usize, [f64; 3])> = Vec::with_capacity(sorted.len());
        for (p, v) in sorted {
            match merged.last_mut() {
                Some((q, w)) if *q == p => (0..3).for_each(|c| w[c] += v[c]),
                _ => merged.push((p, v)),
            }
        }
        Ok(ExactPart { entries: merged })
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// The entries, (pixel, radiance) in pixel order.
    pub fn entries(&self) -> &[(usize, [f64; 3])] {
        &self.entries
    }

    /// The pixel's exact radiance, if it has any.
    pub fn at(&self, pixel: usize) -> Option<[f64; 3]> {
        self.entries.binary_search_by_key(&pixel, |e| e.0).ok().map(|i| self.entries[i].1)
    }

    /// Adds each entry to its pixel of `image` (of the same size).
    pub fn add_to(&self, image: &mut RgbImage32) {
        for &(p, v) in &self.entries {
            for (value, exact) in image.pixels[p].iter_mut().zip(v) {
                *value = (f64::from(*value) + exact) as f32;
            }
        }
    }

    /// Per pixel of an image of `pixels` pixels, rgb x `scale` and 0 (a `vec4<f32>` each), zero
    /// where there is no exact part: what a GPU consumer uploads (the viewer's display, which
    /// adds it where the pixel has a sample, as [`ImageParts`] does).
    pub fn dense(&self, pixels: usize, scale: f32) -> Vec<[f32; 4]> {
        let mut values = vec![[0.0f32; 4]; pixels];
        for &(p, v) in self.entries.iter().filter(|e| e.0 < pixels) {
            values[p] = [v[0] as f32 * scale, v[1] as f32 * scale, v[2] as f32 * scale, 0.0];
        }
        values
    }

    /// A digest of the entries (a checkpoint's `illum.glint_hash`, whose values are in its
    /// `illum.exact` layer): `none`, or 16 hex digits of the 64-bit FNV-1a of each entry's pixel
    /// index and radiances (little-endian bits). Parts to be merged must agree on it, from their
    /// headers alone.
    pub fn digest(&self) -> String {
        if self.entries.is_empty() {
            return "none".to_owned();
        }
        let mut bytes = Vec::with_capacity(self.entries.len() * 32);
        for (p, v) in &self.entries {
            bytes.extend((*p as u64).to_le_bytes());
            for c in v {
                bytes.extend(c.to_bits().to_le_bytes());
            }
        }
        format!("{:016x}", illum_scene::fnv1a_64(&bytes))
    }
}

/// The accumulator's image as its two parts (see the module's documentation).
#[derive(Clone, Copy, Debug)]
pub struct ImageParts<'a> {
    accumulator: &'a Accumulator,
}

impl<'a> ImageParts<'a> {
    pub(super) fn of(accumulator: &'a Accumulator) -> Self {
        ImageParts { accumulator }
    }

    /// The pixel's estimate: its sampled mean, plus its exact part once it has a sample.
    pub fn pixel_mean(&self, pixel: usize) -> [f64; 3] {
        let mean = self.pixel_sampled_mean(pixel);
        match self.accumulator.exact().at(pixel) {
            Some(exact) if self.accumulator.pixel_count(pixel) > 0 => [0, 1, 2].map(|c| mean[c] + exact[c]),
            _ => mean,
        }
    }

    /// The mean of the pixel's samples alone (0 before its first).
    pub fn pixel_sampled_mean(&self, pixel: usize) -> [f64; 3] {
        let n = self.accumulator.pixel_count(pixel);
        self.accumulator.pixel_sum(pixel).map(|s| s / n.max(1) as f64)
    }

    /// The whole image: what is saved and shown.
    pub fn mean(&self) -> RgbImage32 {
        self.image_of(|p| clamp_to_f32(self.pixel_mean(p)))
    }

    /// The sampled part alone: what a filter reads, and what a reference made of samples only
    /// (the f64 oracle) is compared with.
    pub fn sampled_mean(&self) -> RgbImage32 {
        self.image_of(|p| clamp_to_f32(self.pixel_sampled_mean(p)))
    }

    /// The variance of each pixel's mean: the sampled part's (the exact part has none);
    /// infinite where it is unknown (fewer than 2 samples).
    pub fn variance(&self) -> RgbImage32 {
        self.image_of(|p| self.accumulator.pixel_variance_of_mean(p).map(|v| v as f32))
    }

    /// The exact part where the image shows it (pixels with a sample): what goes back onto an
    /// image made from [`Self::sampled_mean`], such as a filter's output.
    pub fn shown_exact(&self) -> ExactPart {
        let entries =
            self.accumulator.exact().entries.iter().filter(|e| self.accumulator.pixel_count(e.0) > 0);
        ExactPart { entries: entries.copied().collect() }
    }

    fn image_of(&self, value: impl Fn(usize) -> [f32; 3]) -> RgbImage32 {
        let mut image = RgbImage32::new(self.accumulator.width, self.accumulator.height);
        for (p, px) in image.pixels.iter_mut().enumerate() {
            *px = value(p);
        }
        image
    }
}

/// A mean as f32: one beyond f32's range (a light near f32::MAX seen through noise) is stored as
/// f32::MAX rather than infinity, since EXR and PNG hold f32 at most.
fn clamp_to_f32(mean: [f64; 3]) -> [f32; 3] {
    mean.map(|v| v.min(f32::MAX as f64) as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exact part joins a pixel's mean once the pixel has a sample, and nothing else: not
    /// the sampled mean, not the variance, not the statistics.
    #[test]
    fn the_exact_part_adds_to_the_mean_of_sampled_pixels_and_to_nothing_else() {
        let mut acc = Accumulator::new(3, 1);
        acc.set_exact(ExactPart::new(&[(1, [5.0, 6.0, 7.0]), (1, [1.0, 1.0, 1.0])], 3).unwrap());
        assert_eq!(acc.exact().entries(), &[(1, [6.0, 7.0, 8.0])], "entries of one pixel add");
        assert_eq!(acc.parts().pixel_mean(1), [0.0; 3], "no sample yet: no exact part");
        assert!(acc.parts().shown_exact().is_empty(), "none shown before a sample");
        let sums = [[2.0, 2.0, 2.0, 2.0]; 3];
        let squares = [[2.0, 2.0, 2.0, 0.0]; 3];
        acc.fold(0, &sums, &squares);
        let parts = acc.parts();
        assert_eq!(parts.pixel_mean(0), [1.0; 3]);
        assert_eq!(parts.pixel_mean(1), [7.0, 8.0, 9.0]);
        assert_eq!(parts.mean().pixels[1], [7.0, 8.0, 9.0]);
        assert_eq!(parts.sampled_mean().pixels[1], [1.0; 3]);
        assert_eq!(parts.variance().pixels[1], parts.variance().pixels[0], "no variance of its own");
        assert!(Accumulator::new(1, 1).parts().variance().pixels[0][0].is_infinite(), "unknown: infinite");
        assert_eq!(acc.pixel_sum(1), [2.0; 3], "the statistics hold the samples alone");
        let mut rebuilt = parts.sampled_mean();
        parts.shown_exact().add_to(&mut rebuilt);
        assert_eq!(rebuilt, parts.mean(), "sampled part + shown exact part = the image");
        acc.reset();
        acc.fold(0, &sums, &squares);
        assert_eq!(acc.parts().pixel_mean(1), [7.0, 8.0, 9.0], "kept across a reset");
    }

    #[test]
    fn an_exact_part_outside_the_image_or_not_finite_is_refused() {
        assert!(ExactPart::new(&[(3, [1.0; 3])], 3).unwrap_err().contains("outside the image's 3 pixels"));
        assert!(ExactPart::new(&[(0, [1.0, f64::NAN, 0.0])], 3).unwrap_err().contains("not finite"));
        assert!(ExactPart::new(&[(0, [f64::INFINITY, 0.0, 0.0])], 3).unwrap_err().contains("not finite"));
    }

    /// The digest tells exact parts apart by any bit of any entry, and says `none` for none.
    #[test]
    fn the_digest_changes_with_every_entry() {
        let entries = vec![(3, [0.1, 1.0 / 3.0, 2e-300]), (40, [6.02e23, 0.0, 1.0])];
        let digest = |e: &[(usize, [f64; 3])]| ExactPart::new(e, 48).unwrap().digest();
        let hash = digest(&entries);
        assert_eq!(hash.len(), 16);
        assert_eq!(digest(&entries.clone()), hash, "stable");
        assert_eq!(digest(&[]), "none");
        let mut moved = entries.clone();
        moved[1].0 = 41;
        let mut nudged = entries.clone();
        nudged[0].1[2] = f64::from_bits(nudged[0].1[2].to_bits() + 1);
        for other in [moved, nudged, entries[..1].to_vec()] {
            assert_ne!(digest(&other), hash, "{other:?}");
        }
    }

    /// The GPU's copy: scaled, at its pixels, zero elsewhere.
    #[test]
    fn the_dense_copy_scales_each_entry_into_its_pixel() {
        let exact = ExactPart::new(&[(2, [4.0, 8.0, 16.0])], 4).unwrap();
        assert_eq!(exact.dense(4, 0.5), vec![[0.0; 4], [0.0; 4], [2.0, 4.0, 8.0, 0.0], [0.0; 4]]);
    }
}
