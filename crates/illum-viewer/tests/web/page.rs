//! What `web/tests/browser.mjs` left of each page: its status lines and its screenshot.

use std::collections::HashMap;
use std::path::Path;

pub(crate) fn status(out: &Path, case: &str) -> HashMap<String, String> {
    let path = out.join(format!("{case}.status"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.lines().filter_map(|l| l.split_once('=')).map(|(k, v)| (k.to_owned(), v.to_owned())).collect()
}

pub(crate) fn get<'a>(status: &'a HashMap<String, String>, key: &str) -> &'a str {
    status.get(key).map_or("", String::as_str)
}

pub(crate) fn screenshot(out: &Path, case: &str) -> image::RgbaImage {
    let path = out.join(format!("{case}.png"));
    image::open(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgba8()
}

/// Pixels of `image` within one level of `rgb` in each channel.
pub(crate) fn count(image: &image::RgbaImage, rgb: [u8; 3]) -> usize {
    image.pixels().filter(|p| (0..3).all(|c| p.0[c].abs_diff(rgb[c]) <= 1)).count()
}

/// Distinct colours: a blank or flat canvas has a handful, a rendered picture thousands.
pub(crate) fn distinct_colours(image: &image::RgbaImage) -> usize {
    let mut colours: Vec<[u8; 3]> = image.pixels().map(|p| [p.0[0], p.0[1], p.0[2]]).collect();
    colours.sort_unstable();
    colours.dedup();
    colours.len()
}
