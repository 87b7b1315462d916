//! OpenEXR output and input: linear f32 RGB plus the render settings as text attributes.
//!
//! EXR is the lossless record of a render: channels R, G, B stored as 32-bit floats (not
//! half floats, whose 11-bit mantissa would add quantisation error larger than the noise of a
//! converged render), compressed with ZIP, which is lossless. The settings that produced the
//! image travel with it as custom text attributes named `illum.<field>`, so a reference image
//! says how it was made.
//!
//! Over 450 lines with its tests: writing and reading share one layout of parts and channels.

use std::collections::HashMap;
use std::fs::File;
use std::io::BufReader;
use std::path::Path;

use exr::meta::attribute::{AttributeValue, Text};
use exr::meta::header::LayerAttributes;
use exr::prelude::{Image, Layer, ReadChannels, ReadLayers, SpecificChannels, Vec2, WritableImage};

use crate::ImageError;
use crate::atomic::write_atomically;
use crate::png::check_writable;
use crate::rgb_image::RgbImage32;

/// Prefix of every attribute illum writes.
pub const ATTRIBUTE_PREFIX: &str = "illum.";

/// Names (without [`ATTRIBUTE_PREFIX`]) of the fields every illum EXR has.
const FIELD_NAMES: [&str; 3] = ["renderer", "scene", "render_seconds"];

/// What made an image, stored in its EXR file: the fields every renderer has, and the
/// renderer's own settings and results (a path tracer's spp and bounces mean nothing for a
/// rasterized image, so they are not fixed fields).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ExrMetadata {
    /// The renderer that made the image (`pathtrace`, `raster`).
    pub renderer: String,
    /// The scene's name.
    pub scene: String,
    /// Wall-clock render time in seconds (a record, never asserted on).
    pub render_seconds: f64,
    /// The renderer's settings and results, each stored as `illum.<key>`. Read back sorted by
    /// key.
    pub fields: Vec<(String, String)>,
}

impl ExrMetadata {
    /// The value of one of [`Self::fields`].
    pub fn get(&self, key: &str) -> Option<&str> {
        self.fields.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
    }

    /// The attributes this metadata is stored as: full names (with [`ATTRIBUTE_PREFIX`]) and
    /// text values. Numbers are written in Rust's shortest round-trip form, so they parse
    /// back to the same value.
    pub fn to_attributes(&self) -> Vec<(String, String)> {
        let fixed = [self.renderer.clone(), self.scene.clone(), self.render_seconds.to_string()];
        FIELD_NAMES
            .iter()
            .zip(fixed)
            .map(|(name, value)| (format!("{ATTRIBUTE_PREFIX}{name}"), value))
            .chain(self.fields.iter().map(|(k, v)| (format!("{ATTRIBUTE_PREFIX}{k}"), v.clone())))
            .collect()
    }

    /// Rebuilds the metadata from the text attributes [`load_exr`] returns. `Ok(None)` when
    /// the file carries none of illum's fixed fields (an EXR from another program); an error
    /// when some are present but one is missing or does not parse. `path` is only used in
    /// error messages. Attributes without the `illum.` prefix are ignored.
    pub fn from_attributes(
        path: impl AsRef<Path>,
        attributes: &[(String, String)],
    ) -> Result<Option<ExrMetadata>, ImageError> {
        let path = path.as_ref();
        let ours: HashMap<&str, &str> = attributes
            .iter()
            .filter_map(|(k, v)| k.strip_prefix(ATTRIBUTE_PREFIX).map(|k| (k, v.as_str())))
            .collect();
        if !FIELD_NAMES.iter().any(|f| ours.contains_key(f)) {
            return Ok(None);
        }
        let get = |field: &str| {
            ours.get(field).copied().ok_or_else(|| ImageError::BadContent {
                path: path.to_path_buf(),
                reason: format!(
                    "attribute '{ATTRIBUTE_PREFIX}{field}' is missing (illum writes all of {})",
                    FIELD_NAMES.join(", ")
                ),
            })
        };
        let seconds = get("render_seconds")?;
        let render_seconds = seconds.trim().parse().map_err(|_| ImageError::BadContent {
            path: path.to_path_buf(),
            reason: format!(
                "attribute '{ATTRIBUTE_PREFIX}render_seconds' is '{seconds}'; expected a number of seconds"
            ),
        })?;
        let mut fields: Vec<(String, String)> = ours
            .iter()
            .filter(|(k, _)| !FIELD_NAMES.contains(k))
            .map(|(k, v)| ((*k).to_owned(), (*v).to_owned()))
            .collect();
        fields.sort();
        Ok(Some(ExrMetadata {
            renderer: get("renderer")?.to_owned(),
            scene: get("scene")?.to_owned(),
            render_seconds,
            fields,
        }))
    }
}

/// Checks the attribute names the writer would produce: unique, no NUL byte (names are
/// NUL-terminated in the file), and shorter than 256 bytes (the format's limit).
fn check_attribute_names(path: &Path, attributes: &[(String, String)]) -> Result<(), ImageError> {
    let mut seen = std::collections::HashSet::new();
    for (name, _) in attributes {
        if !seen.insert(name.as_str()) {
            let hint = match name.strip_prefix(ATTRIBUTE_PREFIX) {
                Some(f) if FIELD_NAMES.contains(&f) => " (a fixed field of ExrMetadata)",
                _ => "",
            };
            return Err(ImageError::invalid(
                path,
                format!("metadata key '{name}' is given twice{hint}; each key must be unique"),
            ));
        }
        if name.contains('\0') {
            return Err(ImageError::invalid(
                path,
                format!("metadata key {name:?} contains a NUL character, which EXR does not allow"),
            ));
        }
        if name.len() >= 256 {
            return Err(ImageError::invalid(
                path,
                format!("metadata key '{name}' is {} bytes long; EXR allows at most 255", name.len()),
            ));
        }
    }
    Ok(())
}

/// EXR text attributes are byte strings; illum stores UTF-8 (which is what OpenEXR itself
/// assumes), so any Rust string survives the round trip.
fn text(s: &str) -> Text {
    Text::from_slice_unchecked(s.as_bytes())
}

fn string(t: &Text) -> String {
    String::from_utf8_lossy(t.as_slice()).into_owned()
}

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

    let mut layer_attributes =
        LayerAttributes { software_name: Some(text("illum")), ..LayerAttributes::default() };
    for (name, value) in &attributes {
        layer_attributes.other.insert(text(name), AttributeValue::Text(text(value)));
    }
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

/// An extra EXR layer of 32-bit unsigned integer channels, stored after the RGB image (a
/// multi-part file): exact data that f32 cannot hold, such as the path tracer's f64 statistics
/// split into two words (see `illum_pathtrace::checkpoint`). Other EXR readers show the RGB
/// image and ignore it.
#[derive(Clone, Debug, PartialEq)]
pub struct U32Layer {
    /// The layer's name (the part's `name` attribute).
    pub name: String,
    /// Channel names and their values, row-major like the image (one per pixel each).
    pub channels: Vec<(String, Vec<u32>)>,
}

/// An extra EXR layer of 32-bit float channels, stored after the RGB image (a multi-part file)
/// and any [`U32Layer`]s: per-pixel values to look at, such as a denoiser's guide buffers
/// (`albedo`, `normal`), the path tracer's estimated relative error (`illum.error`) or a signed
/// difference from a reference. Other EXR readers show the RGB image and list the layer.
#[derive(Clone, Debug, PartialEq)]
pub struct F32Layer {
    /// The layer's name (the part's `name` attribute).
    pub name: String,
    /// Channel names and their values, row-major like the image (one per pixel each).
    pub channels: Vec<(String, Vec<f32>)>,
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
    let mut layer_attributes = LayerAttributes {
        software_name: Some(text("illum")),
        layer_name: Some(text("rgb")),
        ..LayerAttributes::default()
    };
    for (name, value) in &attributes {
        layer_attributes.other.insert(text(name), AttributeValue::Text(text(value)));
    }
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
    let (Ok(width), Ok(height)) = (u32::try_from(size.width()), u32::try_from(size.height())) else {
        return Err(ImageError::BadContent {
            path: path.to_path_buf(),
            reason: format!(
                "the image is {}x{}; illum handles at most {} pixels per side",
                size.width(),
                size.height(),
                u32::MAX
            ),
        });
    };
    let mut attributes: Vec<(String, String)> = header
        .shared_attributes
        .other
        .iter()
        .chain(header.own_attributes.other.iter())
        .filter_map(|(name, value)| match value {
            AttributeValue::Text(t) => Some((string(name), string(t))),
            _ => None,
        })
        .collect();
    attributes.sort();
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
/// file as (name, value), sorted by name. Use [`ExrMetadata::from_attributes`] to recover
/// illum's settings.
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
    let (Ok(width), Ok(height)) = (u32::try_from(pixels.width), u32::try_from(pixels.height)) else {
        return Err(ImageError::BadContent {
            path: path.to_path_buf(),
            reason: format!(
                "the image is {}x{}; illum handles at most {} pixels per side",
                pixels.width,
                pixels.height,
                u32::MAX
            ),
        });
    };
    let rgb = RgbImage32 { width, height, pixels: pixels.data };

    let mut attributes: Vec<(String, String)> = image
        .attributes
        .other
        .iter()
        .chain(image.layer_data.attributes.other.iter())
        .filter_map(|(name, value)| match value {
            AttributeValue::Text(t) => Some((string(name), string(t))),
            _ => None,
        })
        .collect();
    attributes.sort();
    Ok((rgb, attributes))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn metadata() -> ExrMetadata {
        ExrMetadata {
            renderer: "pathtrace".into(),
            scene: "scenes/cornell.toml — Ünïcode".into(),
            render_seconds: 12.345_678_901_234_5,
            fields: vec![
                ("spp".into(), (1u64 << 40).to_string()),
                ("adapter".into(), "llvmpipe (LLVM 19)".into()),
                ("a".into(), String::new()),
            ],
        }
    }

    #[test]
    fn round_trip_exact_floats_and_metadata() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sub/render.exr");
        let special = [
            0.0,
            -0.0,
            1.0e-40, // subnormal: f16 would flush it
            std::f32::consts::PI,
            -7.25,
            65_519.99, // above f16's range
            f32::MAX,
            f32::INFINITY,
        ];
        let img = RgbImage32::from_fn(5, 3, |x, y| {
            let i = (y * 5 + x) as usize;
            [special[i % special.len()], 0.1 * i as f32, 1.0 / (1.0 + i as f32)]
        });
        let meta = metadata();
        save_exr(&path, &img, &meta).unwrap();

        let (back, attrs) = load_exr(&path).unwrap();
        assert_eq!((back.width, back.height), (5, 3));
        let bits =
            |im: &RgbImage32| -> Vec<u32> { im.pixels.iter().flatten().map(|v| v.to_bits()).collect() };
        assert_eq!(bits(&back), bits(&img), "pixels are not bit-exact");

        assert!(attrs.contains(&("illum.spp".to_string(), "1099511627776".to_string())), "{attrs:?}");
        let parsed = ExrMetadata::from_attributes(&path, &attrs).unwrap().unwrap();
        let mut expected = meta;
        expected.fields.sort();
        assert_eq!(parsed.get("adapter"), Some("llvmpipe (LLVM 19)"));
        assert_eq!(parsed, expected);
    }

    #[test]
    fn extra_u32_layers_round_trip_and_the_rgb_image_still_loads() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("layers.exr");
        let img = RgbImage32::from_fn(3, 2, |x, y| [x as f32, y as f32, 0.5]);
        let layer = U32Layer {
            name: "state".into(),
            channels: vec![("a".into(), vec![0, 1, 2, u32::MAX, 4, 5]), ("b".into(), vec![7; 6])],
        };
        save_exr_with_layers(&path, &img, &metadata(), vec![layer.clone()]).unwrap();
        let (back, attrs) = load_exr(&path).unwrap();
        assert_eq!(back, img);
        assert_eq!(
            ExrMetadata::from_attributes(&path, &attrs).unwrap().unwrap().get("spp"),
            Some("1099511627776")
        );
        assert_eq!(load_u32_layer(&path, "state").unwrap(), Some(layer.clone()));
        assert_eq!(load_u32_layer(&path, "other").unwrap(), None);
        assert_eq!(load_u32_layers(&path, &["other", "state"]).unwrap(), [None, Some(layer)]);
        // The headers alone: the same size and attributes as the full read, and both layers.
        let header = load_exr_header(&path).unwrap();
        assert_eq!((header.width, header.height), (3, 2));
        assert_eq!(header.attributes, attrs);
        assert_eq!(header.layers, ["rgb", "state"]);
        let single = dir.path().join("single.exr");
        save_exr(&single, &img, &metadata()).unwrap();
        assert_eq!(load_exr_header(&single).unwrap().attributes, load_exr(&single).unwrap().1);
        std::fs::write(dir.path().join("not.exr"), b"not an exr").unwrap();
        let error = load_exr_header(dir.path().join("not.exr")).unwrap_err().to_string();
        assert!(error.contains("not.exr"), "{error}");
    }

    #[test]
    fn f32_layers_round_trip_after_the_u32_ones() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.exr");
        let mut image = RgbImage32::new(2, 1);
        image.pixels = vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]];
        let u = U32Layer { name: "u".into(), channels: vec![("n".into(), vec![7, 8])] };
        let f =
            F32Layer { name: "illum.error".into(), channels: vec![("Y".into(), vec![0.25, f32::INFINITY])] };
        save_exr_with_float_layers(&path, &image, &metadata(), vec![u.clone()], vec![f.clone()]).unwrap();
        assert_eq!(load_f32_layer(&path, "illum.error").unwrap(), Some(f));
        assert_eq!(load_u32_layer(&path, "u").unwrap(), Some(u));
        assert_eq!(load_f32_layer(&path, "missing").unwrap(), None);
        assert!(load_f32_layer(&path, "u").unwrap_err().to_string().contains("not 32-bit floats"));
        assert_eq!(load_exr(&path).unwrap().0, image);
    }

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

    #[test]
    fn bad_metadata_is_rejected_before_writing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("dup.exr");
        let mut meta = metadata();
        meta.fields.push(("scene".into(), "3".into()));
        let err = save_exr(&path, &RgbImage32::new(1, 1), &meta).unwrap_err().to_string();
        assert!(err.contains("dup.exr") && err.contains("'illum.scene' is given twice"), "{err}");
        assert!(!path.exists());

        let mut meta = metadata();
        meta.fields.push(("k".repeat(300), "v".into()));
        let err = save_exr(&path, &RgbImage32::new(1, 1), &meta).unwrap_err().to_string();
        assert!(err.contains("at most 255"), "{err}");
    }

    #[test]
    fn unparsable_or_missing_fields_are_reported() {
        let attrs = ExrMetadata::default().to_attributes();
        let mut bad = attrs.clone();
        bad.iter_mut().find(|(k, _)| k == "illum.render_seconds").unwrap().1 = "many".into();
        let err = ExrMetadata::from_attributes("x.exr", &bad).unwrap_err().to_string();
        assert!(err.contains("x.exr") && err.contains("'illum.render_seconds' is 'many'"), "{err}");

        let partial: Vec<_> = attrs.into_iter().filter(|(k, _)| k != "illum.renderer").collect();
        let err = ExrMetadata::from_attributes("x.exr", &partial).unwrap_err().to_string();
        assert!(err.contains("'illum.renderer' is missing"), "{err}");
    }
}
