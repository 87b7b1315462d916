//! Reading EXR files: the RGB image and its text attributes, the headers alone, and the extra
//! layers by name. Any program's EXR is read; a file that is not one is named for what it is.

use std::fs::File;
use std::io::BufReader;
use std::path::Path;

use exr::meta::attribute::{AttributeValue, Text};
use exr::prelude::{ReadChannels, ReadLayers, Vec2};

use crate::ImageError;
use crate::exr::layers::{F32Layer, U32Layer};
use crate::exr::metadata::string;
use crate::rgb_image::RgbImage32;

/// Reads the layer named `name` of an EXR file as 32-bit unsigned channels: (channel name,
/// values). `Ok(None)` when the file has no such layer; an error for an unreadable file or a
/// channel of another sample type.
pub fn load_u32_layer(path: impl AsRef<Path>, name: &str) -> Result<Option<U32Layer>, ImageError> {
    Ok(load_u32_layers(path, &[name])?.pop().flatten())
}

/// The first bytes of every OpenEXR file.
const EXR_MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];

/// Opens the file at `path` for reading as an EXR, refusing one that is not (by its first
/// bytes) and naming what it is when it is a PNG, so that a PNG given where an EXR is needed
/// (`--resume`, `--reference`, `merge`) is not reported as a corrupt EXR.
fn open_exr(path: &Path) -> Result<File, ImageError> {
    use std::io::{Read as _, Seek as _};
    let mut file = File::open(path).map_err(|e| ImageError::io(path, "opening the EXR file", e))?;
    let mut magic = [0u8; 8];
    let read = file.read(&mut magic).map_err(|e| ImageError::io(path, "reading the EXR file", e))?;
    if read < 4 || magic[..4] != EXR_MAGIC {
        let what = if magic.starts_with(b"\x89PNG") {
            "a PNG image, not an OpenEXR file"
        } else {
            "not an OpenEXR file (its first bytes are not OpenEXR's magic number 76 2f 31 01)"
        };
        return Err(ImageError::BadContent { path: path.to_path_buf(), reason: what.to_owned() });
    }
    file.rewind().map_err(|e| ImageError::io(path, "reading the EXR file", e))?;
    Ok(file)
}

/// Every layer of the EXR file at `path`, with all channels and attributes (the layer loaders'
/// one read).
fn read_all_layers(
    path: &Path,
) -> Result<
    exr::prelude::Image<exr::prelude::Layers<exr::prelude::AnyChannels<exr::prelude::FlatSamples>>>,
    ImageError,
> {
    use exr::prelude::ReadLayers as _;
    let file = open_exr(path)?;
    exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .from_buffered(BufReader::new(file))
        .map_err(|e| ImageError::Decode { path: path.to_path_buf(), format: "EXR", source: Box::new(e) })
}

/// [`load_u32_layer`] for several layers in one read of the file: one entry per name, in the
/// order of `names`.
pub fn load_u32_layers(path: impl AsRef<Path>, names: &[&str]) -> Result<Vec<Option<U32Layer>>, ImageError> {
    use exr::prelude::FlatSamples;
    let path = path.as_ref();
    let image = read_all_layers(path)?;
    let mut found: Vec<Option<U32Layer>> = names.iter().map(|_| None).collect();
    // Moved out, not copied: a merge holds one part's statistics at a time, and a copy would
    // double them (56 bytes per pixel).
    for layer in image.layer_data {
        let layer_name = layer.attributes.layer_name.as_ref().map(string);
        let Some(index) = names.iter().position(|n| layer_name.as_deref() == Some(*n)) else {
            continue;
        };
        let mut channels = Vec::new();
        for channel in layer.channel_data.list {
            let channel_name = string(&channel.name);
            match channel.sample_data {
                FlatSamples::U32(values) => channels.push((channel_name, values)),
                _ => {
                    return Err(ImageError::BadContent {
                        path: path.to_path_buf(),
                        reason: format!(
                            "layer '{}' channel '{channel_name}' is not 32-bit unsigned integers",
                            names[index]
                        ),
                    });
                }
            }
        }
        found[index].get_or_insert(U32Layer { name: names[index].to_owned(), channels });
    }
    Ok(found)
}

/// Reads the layer named `name` of an EXR file as 32-bit float channels (see [`F32Layer`]).
/// `Ok(None)` when the file has no such layer; an error for an unreadable file or a channel of
/// another sample type.
pub fn load_f32_layer(path: impl AsRef<Path>, name: &str) -> Result<Option<F32Layer>, ImageError> {
    use exr::prelude::FlatSamples;
    let path = path.as_ref();
    let image = read_all_layers(path)?;
    for layer in image.layer_data {
        if layer.attributes.layer_name.as_ref().map(string).as_deref() != Some(name) {
            continue;
        }
        let mut channels = Vec::new();
        for channel in layer.channel_data.list {
            let channel_name = string(&channel.name);
            match channel.sample_data {
                FlatSamples::F32(values) => channels.push((channel_name, values)),
                _ => {
                    return Err(ImageError::BadContent {
                        path: path.to_path_buf(),
                        reason: format!("layer '{name}' channel '{channel_name}' is not 32-bit floats"),
                    });
                }
            }
        }
        return Ok(Some(F32Layer { name: name.to_owned(), channels }));
    }
    Ok(None)
}

/// What an EXR file's headers say, without reading its pixels: the size and text attributes
/// [`load_exr`] would return (the image's and its first R, G, B layer's, sorted by name) and the
/// names of its layers. A merge of many files checks them all this way before reading any.
#[derive(Clone, Debug, PartialEq)]
pub struct ExrHeader {
    pub width: u32,
    pub height: u32,
    pub attributes: Vec<(String, String)>,
    /// Every layer's name (a layer without one: the empty string), in file order.
    pub layers: Vec<String>,
}

/// Reads the headers of an EXR file (see [`ExrHeader`]). An error names the file: unreadable,
/// not an EXR, or without a layer of R, G and B channels.
pub fn load_exr_header(path: impl AsRef<Path>) -> Result<ExrHeader, ImageError> {
    let path = path.as_ref();
    let file = open_exr(path)?;
    let meta = exr::meta::MetaData::read_from_buffered(BufReader::new(file), false)
        .map_err(|e| ImageError::Decode { path: path.to_path_buf(), format: "EXR", source: Box::new(e) })?;
    let is_rgb = |header: &&exr::meta::header::Header| {
        ["R", "G", "B"].iter().all(|c| header.channels.list.iter().any(|ch| string(&ch.name) == *c))
    };
    let header = meta.headers.iter().find(is_rgb).ok_or_else(|| ImageError::BadContent {
        path: path.to_path_buf(),
        reason: "no layer has R, G and B channels".to_owned(),
    })?;
    let size = header.layer_size;
    let (width, height) = size_u32(path, size.width(), size.height())?;
    let attributes =
        text_attributes(header.shared_attributes.other.iter().chain(&header.own_attributes.other));
    let layers = meta
        .headers
        .iter()
        .map(|h| h.own_attributes.layer_name.as_ref().map_or_else(String::new, string))
        .collect();
    Ok(ExrHeader { width, height, attributes, layers })
}

/// Pixels as the reader delivers them, before the size is known to fit in `u32`.
struct ReadPixels {
    width: usize,
    height: usize,
    data: Vec<[f32; 3]>,
}

/// Reads the first layer with R, G and B channels of an EXR file (f16, f32 or u32 samples,
/// converted to f32; other channels such as A are ignored), plus every text attribute of the
/// file as (name, value), sorted by name. Use
/// [`ExrMetadata::from_attributes`](super::ExrMetadata::from_attributes) to recover illum's
/// settings.
pub fn load_exr(path: impl AsRef<Path>) -> Result<(RgbImage32, Vec<(String, String)>), ImageError> {
    let path = path.as_ref();
    let file = open_exr(path)?;
    let decode_err = |e: exr::error::Error| ImageError::Decode {
        path: path.to_path_buf(),
        format: "EXR",
        source: Box::new(e),
    };
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .rgb_channels(
            |resolution: Vec2<usize>, _| ReadPixels {
                width: resolution.width(),
                height: resolution.height(),
                data: vec![[0.0; 3]; resolution.area()],
            },
            |pixels: &mut ReadPixels, pos: Vec2<usize>, (r, g, b): (f32, f32, f32)| {
                pixels.data[pos.y() * pixels.width + pos.x()] = [r, g, b];
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(BufReader::new(file))
        .map_err(decode_err)?;

    let pixels = image.layer_data.channel_data.pixels;
    let (width, height) = size_u32(path, pixels.width, pixels.height)?;
    let rgb = RgbImage32 { width, height, pixels: pixels.data };
    let attributes = text_attributes(image.attributes.other.iter().chain(&image.layer_data.attributes.other));
    Ok((rgb, attributes))
}

/// The image's size as `u32`, or an error naming the file when a side does not fit.
fn size_u32(path: &Path, width: usize, height: usize) -> Result<(u32, u32), ImageError> {
    match (u32::try_from(width), u32::try_from(height)) {
        (Ok(width), Ok(height)) => Ok((width, height)),
        _ => Err(ImageError::BadContent {
            path: path.to_path_buf(),
            reason: format!(
                "the image is {width}x{height}; illum handles at most {} pixels per side",
                u32::MAX
            ),
        }),
    }
}

/// The text attributes among `attributes` as (name, value), sorted by name; others are skipped.
fn text_attributes<'a>(
    attributes: impl Iterator<Item = (&'a Text, &'a AttributeValue)>,
) -> Vec<(String, String)> {
    let mut text: Vec<(String, String)> = attributes
        .filter_map(|(name, value)| match value {
            AttributeValue::Text(t) => Some((string(name), string(t))),
            _ => None,
        })
        .collect();
    text.sort();
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exr::metadata::ExrMetadata;
    use crate::exr::write::save_exr;

    #[test]
    fn reads_half_float_rgba_from_other_programs() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("half.exr");
        exr::prelude::write_rgba_file(&path, 2, 2, |x, y| {
            let v = exr::prelude::f16::from_f32((x + 2 * y) as f32 * 0.5);
            (v, v, v, exr::prelude::f16::ONE)
        })
        .unwrap();
        let (img, attrs) = load_exr(&path).unwrap();
        assert_eq!(img.pixels, vec![[0.0; 3], [0.5; 3], [1.0; 3], [1.5; 3]]);
        assert_eq!(ExrMetadata::from_attributes(&path, &attrs).unwrap(), None);
    }

    #[test]
    fn errors_name_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("missing.exr");
        let err = load_exr(&missing).unwrap_err();
        assert!(matches!(err, ImageError::Io { .. }) && err.to_string().contains("missing.exr"), "{err}");

        let garbage = dir.path().join("garbage.exr");
        std::fs::write(&garbage, b"this is not an EXR file").unwrap();
        let err = load_exr(&garbage).unwrap_err();
        assert!(
            err.to_string().contains("garbage.exr") && err.to_string().contains("not an OpenEXR file"),
            "{err}"
        );

        // A PNG is named as one, by every reader, whatever its name.
        let png = dir.path().join("image.png");
        crate::save_png(&png, &RgbImage32::new(2, 2), 0.0, crate::Encoding::Srgb).unwrap();
        for err in [load_exr(&png).unwrap_err(), load_exr_header(&png).unwrap_err()] {
            assert_eq!(err.to_string(), format!("'{}': a PNG image, not an OpenEXR file", png.display()));
        }

        // An EXR cut short is still read as one (and refused by the decoder).
        let exr = dir.path().join("whole.exr");
        save_exr(&exr, &RgbImage32::new(2, 2), &ExrMetadata::default()).unwrap();
        let bytes = std::fs::read(&exr).unwrap();
        std::fs::write(&exr, &bytes[..bytes.len() / 2]).unwrap();
        assert!(matches!(load_exr(&exr).unwrap_err(), ImageError::Decode { .. }));
    }
}
