//! PNG output: tone-mapped 8-bit RGB, written atomically.

use std::io::{BufWriter, Write};
use std::path::Path;

use image::ImageEncoder;
use image::codecs::png::PngEncoder;

use crate::ImageError;
use crate::atomic::write_atomically;
use crate::rgb_image::RgbImage32;
use crate::tonemap::{Encoding, to_rgb8};

/// Checks what every writer needs: a non-empty image whose pixel count matches its size.
pub(crate) fn check_writable(path: &Path, image: &RgbImage32) -> Result<(), ImageError> {
    if !image.is_consistent() {
        return Err(ImageError::invalid(
            path,
            format!(
                "the image is {}x{} but holds {} pixels (width * height = {} expected)",
                image.width,
                image.height,
                image.pixels.len(),
                u64::from(image.width) * u64::from(image.height)
            ),
        ));
    }
    if image.width == 0 || image.height == 0 {
        return Err(ImageError::invalid(
            path,
            format!("the image is {}x{}; both sides must be at least 1", image.width, image.height),
        ));
    }
    Ok(())
}

/// Tone-maps `image` (exposure in stops, then `encoding`, see [`crate::tonemap`]) and writes
/// it as an 8-bit RGB PNG, atomically.
pub fn save_png(
    path: impl AsRef<Path>,
    image: &RgbImage32,
    exposure: f32,
    encoding: Encoding,
) -> Result<(), ImageError> {
    let path = path.as_ref();
    check_writable(path, image)?;
    let rgb = to_rgb8(image, exposure, encoding);
    write_png_bytes(path, rgb.as_raw(), rgb.width(), rgb.height(), image::ExtendedColorType::Rgb8)
}

/// [`save_png`] into memory: the PNG file's bytes (for a download in the browser). `name`
/// labels errors, as a path would.
pub fn png_bytes(
    name: &str,
    image: &RgbImage32,
    exposure: f32,
    encoding: Encoding,
) -> Result<Vec<u8>, ImageError> {
    let path = Path::new(name);
    check_writable(path, image)?;
    let rgb = to_rgb8(image, exposure, encoding);
    let mut out = Vec::new();
    PngEncoder::new(&mut out)
        .write_image(rgb.as_raw(), rgb.width(), rgb.height(), image::ExtendedColorType::Rgb8)
        .map_err(|e| ImageError::Encode { path: path.to_path_buf(), format: "PNG", source: Box::new(e) })?;
    Ok(out)
}

/// Writes an 8-bit RGBA image (a contact sheet, a diff picture) as PNG, atomically.
pub fn save_rgba8_png(path: impl AsRef<Path>, image: &image::RgbaImage) -> Result<(), ImageError> {
    let path = path.as_ref();
    if image.width() == 0 || image.height() == 0 {
        return Err(ImageError::invalid(
            path,
            format!("the image is {}x{}; both sides must be at least 1", image.width(), image.height()),
        ));
    }
    write_png_bytes(path, image.as_raw(), image.width(), image.height(), image::ExtendedColorType::Rgba8)
}

fn write_png_bytes(
    path: &Path,
    bytes: &[u8],
    width: u32,
    height: u32,
    color: image::ExtendedColorType,
) -> Result<(), ImageError> {
    write_atomically(path, |file| {
        let mut out = BufWriter::new(file);
        PngEncoder::new(&mut out).write_image(bytes, width, height, color).map_err(|e| {
            ImageError::Encode { path: path.to_path_buf(), format: "PNG", source: Box::new(e) }
        })?;
        // Flush explicitly: BufWriter's drop would swallow a write error.
        out.flush().map_err(|e| ImageError::io(path, "writing the PNG data", e))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gradient() -> RgbImage32 {
        RgbImage32::from_fn(7, 5, |x, y| [x as f32 / 6.0, y as f32 / 4.0, 0.5 + 0.1 * x as f32])
    }

    #[test]
    fn round_trips_through_image_open() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out/grad.png");
        let img = gradient();
        save_png(&path, &img, 0.0, Encoding::Srgb).unwrap();
        let back = image::open(&path).unwrap().to_rgb8();
        assert_eq!(back.dimensions(), (7, 5));
        assert_eq!(back, to_rgb8(&img, 0.0, Encoding::Srgb));
        // Spot check one pixel by hand: (0, 0) is [0, 0, 0.5] -> sRGB [0, 0, 188].
        assert_eq!(back.get_pixel(0, 0).0, [0, 0, 188]);
        // Row 0 is the top of the picture: (0, 4) has green 1.0.
        assert_eq!(back.get_pixel(0, 4).0[1], 255);
    }

    #[test]
    fn rgba_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("rgba.png");
        let img = image::RgbaImage::from_fn(3, 2, |x, y| image::Rgba([x as u8 * 80, y as u8 * 100, 7, 200]));
        save_rgba8_png(&path, &img).unwrap();
        assert_eq!(image::open(&path).unwrap().to_rgba8(), img);
    }

    #[test]
    fn inconsistent_or_empty_image_is_an_error_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.png");
        let mut img = gradient();
        img.pixels.pop();
        let msg = save_png(&path, &img, 0.0, Encoding::Gamma22).unwrap_err().to_string();
        assert!(msg.contains("bad.png") && msg.contains("34 pixels"), "{msg}");
        let msg = save_png(&path, &RgbImage32::new(0, 3), 0.0, Encoding::Gamma22).unwrap_err().to_string();
        assert!(msg.contains("0x3"), "{msg}");
        assert!(!path.exists());
    }
}
