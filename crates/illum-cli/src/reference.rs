//! `--reference FILE.exr` for the rasterizer and the Whitted ray tracer: where a truth is at
//! hand (a converged path-traced EXR of the same scene), their EXRs get its signed difference,
//! image minus reference per pixel and channel, as the f32 layer [`DIFFERENCE_LAYER`]. These
//! renderers have no noise but a bias; the layer shows where it is.
//!
//! The reference is checked before anything is rendered, by the rule every reader of a
//! reference shares ([`Reference`]): the same size, and the same scene where the file says
//! which (`illum.scene_hash`).

use std::path::Path;

use illum_image::{F32Layer, RgbImage32};
use illum_pathtrace::reference::{Reference, SizePolicy};
use illum_scene::Scene;

/// The EXR layer of the signed difference from the reference (channels R, G, B).
pub const DIFFERENCE_LAYER: &str = "illum.difference";

/// Reads the reference at `path` and checks it against `scene` at its camera's size (see
/// [`Reference`]); prints the note of a file whose scene could not be checked.
pub fn load_reference(path: &Path, scene: &Scene) -> anyhow::Result<RgbImage32> {
    let (reference, note) = Reference::load(path, scene, SizePolicy::Flags)?;
    if let Some(note) = note {
        println!("{note}");
    }
    Ok(reference.image)
}

/// The signed difference `image - reference` (same size), as the [`DIFFERENCE_LAYER`].
pub fn difference_layer(image: &RgbImage32, reference: &RgbImage32) -> F32Layer {
    let channel = |c: usize| -> Vec<f32> {
        image.pixels.iter().zip(&reference.pixels).map(|(a, r)| a[c] - r[c]).collect()
    };
    F32Layer {
        name: DIFFERENCE_LAYER.to_owned(),
        channels: ["R", "G", "B"].iter().enumerate().map(|(c, n)| ((*n).to_owned(), channel(c))).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_difference_is_image_minus_reference_per_channel() {
        let mut a = RgbImage32::new(2, 1);
        a.pixels = vec![[1.0, 2.0, 3.0], [0.5, 0.5, 0.5]];
        let mut r = RgbImage32::new(2, 1);
        r.pixels = vec![[1.5, 2.0, 1.0], [0.0, 1.0, 0.25]];
        let layer = difference_layer(&a, &r);
        assert_eq!(layer.name, DIFFERENCE_LAYER);
        assert_eq!(layer.channels[0], ("R".to_owned(), vec![-0.5, 0.5]));
        assert_eq!(layer.channels[1], ("G".to_owned(), vec![0.0, -0.5]));
        assert_eq!(layer.channels[2], ("B".to_owned(), vec![2.0, 0.25]));
    }
}
