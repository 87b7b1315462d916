//! Writing EXR files: the RGB image in f32 with its metadata, and any extra layers after it as a
//! multi-part file, to a file atomically or into memory.

use std::path::Path;

use exr::meta::attribute::AttributeValue;
use exr::meta::header::LayerAttributes;
use exr::prelude::{Image, Layer, SpecificChannels, Vec2, WritableImage};

use crate::ImageError;
use crate::atomic::write_atomically;
use crate::exr::layers::{F32Layer, U32Layer};
use crate::exr::metadata::{ExrMetadata, check_attribute_names, text};
use crate::png::check_writable;
use crate::rgb_image::RgbImage32;

/// Writes `image` as a linear EXR with channels R, G, B in f32 (ZIP, lossless), with
/// `metadata` as `illum.*` text attributes, atomically.
pub fn save_exr(
    path: impl AsRef<Path>,
    image: &RgbImage32,
    metadata: &ExrMetadata,
) -> Result<(), ImageError> {
    let path = path.as_ref();
    check_writable(path, image)?;
    let attributes = metadata.to_attributes();
    check_attribute_names(path, &attributes)?;

    let layer_attributes = rgb_layer_attributes(&attributes, None);
    let width = image.width as usize;
    let channels = SpecificChannels::rgb(|pos: Vec2<usize>| {
        let [r, g, b] = image.pixels[pos.y() * width + pos.x()];
        (r, g, b)
    });
    let layer = Layer::new(
        (width, image.height as usize),
        layer_attributes,
        exr::image::Encoding::SMALL_LOSSLESS,
        channels,
    );
    let exr_image = Image::from_layer(layer);
    write_atomically(path, |file| {
        exr_image.write().to_unbuffered(file).map_err(|e| ImageError::Encode {
            path: path.to_path_buf(),
            format: "EXR",
            source: Box::new(e),
        })
    })
}

/// The RGB layer's attributes: illum as the software, the metadata's `attributes` as text, and
/// `name` (a multi-part file needs every layer named).
fn rgb_layer_attributes(attributes: &[(String, String)], name: Option<&str>) -> LayerAttributes {
    let mut layer_attributes = LayerAttributes {
        software_name: Some(text("illum")),
        layer_name: name.map(text),
        ..LayerAttributes::default()
    };
    for (name, value) in attributes {
        layer_attributes.other.insert(text(name), AttributeValue::Text(text(value)));
    }
    layer_attributes
}

/// As [`save_exr`], plus float `layers` after the RGB image, all in one atomic write.
pub fn save_exr_with_f32_layers(
    path: impl AsRef<Path>,
    image: &RgbImage32,
    metadata: &ExrMetadata,
    layers: Vec<F32Layer>,
) -> Result<(), ImageError> {
    save_exr_with_float_layers(path, image, metadata, Vec::new(), layers)
}

/// As [`save_exr`], plus the u32 `layers` and then the f32 `float_layers` after the RGB image,
/// all in one atomic write.
pub fn save_exr_with_float_layers(
    path: impl AsRef<Path>,
    image: &RgbImage32,
    metadata: &ExrMetadata,
    layers: Vec<U32Layer>,
    float_layers: Vec<F32Layer>,
) -> Result<(), ImageError> {
    let path = path.as_ref();
    if layers.is_empty() && float_layers.is_empty() {
        return save_exr(path, image, metadata);
    }
    check_writable(path, image)?;
    let parts = layers.into_iter().map(Part::from).chain(float_layers.into_iter().map(Part::from)).collect();
    write_atomically(path, |file| encode_with_layers(path, image, metadata, parts, file))
}

/// An extra part of the file: its name and its channels.
struct Part {
    name: String,
    channels: Vec<(String, exr::prelude::FlatSamples)>,
}

impl From<U32Layer> for Part {
    fn from(layer: U32Layer) -> Self {
        Part {
            name: layer.name,
            channels: layer
                .channels
                .into_iter()
                .map(|(n, v)| (n, exr::prelude::FlatSamples::U32(v)))
                .collect(),
        }
    }
}

impl From<F32Layer> for Part {
    fn from(layer: F32Layer) -> Self {
        Part {
            name: layer.name,
            channels: layer
                .channels
                .into_iter()
                .map(|(n, v)| (n, exr::prelude::FlatSamples::F32(v)))
                .collect(),
        }
    }
}

/// As [`save_exr`], plus `layers` after the RGB image, all in one atomic write. The RGB layer
/// is named `rgb` when there are extra layers (a multi-part file needs names).
pub fn save_exr_with_layers(
    path: impl AsRef<Path>,
    image: &RgbImage32,
    metadata: &ExrMetadata,
    layers: Vec<U32Layer>,
) -> Result<(), ImageError> {
    save_exr_with_float_layers(path, image, metadata, layers, Vec::new())
}

/// [`save_exr_with_layers`] into memory: the EXR file's bytes (for a download in the browser).
/// `name` labels errors, as a path would.
pub fn exr_bytes_with_layers(
    name: &str,
    image: &RgbImage32,
    metadata: &ExrMetadata,
    layers: Vec<U32Layer>,
    float_layers: Vec<F32Layer>,
) -> Result<Vec<u8>, ImageError> {
    let path = Path::new(name);
    check_writable(path, image)?;
    let mut out = std::io::Cursor::new(Vec::new());
    let parts = layers.into_iter().map(Part::from).chain(float_layers.into_iter().map(Part::from)).collect();
    encode_with_layers(path, image, metadata, parts, &mut out)?;
    Ok(out.into_inner())
}

/// Encodes the RGB image and the extra layers (at least one) into `out`. `path` labels errors.
/// The layers are taken by value: their channels move into the encoder instead of being copied
/// (at 8192 x 8192 a statistics layer is 3.7 GB).
fn encode_with_layers<W: std::io::Write + std::io::Seek>(
    path: &Path,
    image: &RgbImage32,
    metadata: &ExrMetadata,
    layers: Vec<Part>,
    out: W,
) -> Result<(), ImageError> {
    use exr::prelude::{AnyChannel, AnyChannels, FlatSamples};
    let attributes = metadata.to_attributes();
    check_attribute_names(path, &attributes)?;
    let pixels = image.width as usize * image.height as usize;
    for layer in &layers {
        for (name, values) in &layer.channels {
            if values.len() != pixels {
                return Err(ImageError::invalid(
                    path,
                    format!(
                        "layer '{}' channel '{name}' has {} values for {pixels} pixels",
                        layer.name,
                        values.len()
                    ),
                ));
            }
        }
    }
    let layer_attributes = rgb_layer_attributes(&attributes, Some("rgb"));
    let size = (image.width as usize, image.height as usize);
    let channel = |name: &str, c: usize| {
        AnyChannel::new(name, FlatSamples::F32(image.pixels.iter().map(|p| p[c]).collect()))
    };
    let rgb = Layer::new(
        size,
        layer_attributes,
        exr::image::Encoding::SMALL_LOSSLESS,
        AnyChannels::sort([channel("B", 2), channel("G", 1), channel("R", 0)].into_iter().collect()),
    );
    let mut all = vec![rgb];
    for layer in layers {
        let channels =
            layer.channels.into_iter().map(|(name, values)| AnyChannel::new(name.as_str(), values)).collect();
        all.push(Layer::new(
            size,
            LayerAttributes::named(text(&layer.name)),
            exr::image::Encoding::SMALL_LOSSLESS,
            AnyChannels::sort(channels),
        ));
    }
    let exr_image = Image::from_layers(
        exr::prelude::ImageAttributes::new(exr::prelude::IntegerBounds::from_dimensions(size)),
        all,
    );
    exr_image.write().to_unbuffered(out).map_err(|e| ImageError::Encode {
        path: path.to_path_buf(),
        format: "EXR",
        source: Box::new(e),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_metadata_is_rejected_before_writing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("dup.exr");
        let mut meta = ExrMetadata::default();
        meta.fields.push(("scene".into(), "3".into()));
        let err = save_exr(&path, &RgbImage32::new(1, 1), &meta).unwrap_err().to_string();
        assert!(err.contains("dup.exr") && err.contains("'illum.scene' is given twice"), "{err}");
        assert!(!path.exists());

        let mut meta = ExrMetadata::default();
        meta.fields.push(("k".repeat(300), "v".into()));
        let err = save_exr(&path, &RgbImage32::new(1, 1), &meta).unwrap_err().to_string();
        assert!(err.contains("at most 255"), "{err}");
    }
}
