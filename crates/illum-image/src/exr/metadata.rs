//! The render settings an EXR file carries: [`ExrMetadata`] as `illum.<field>` text attributes,
//! and the checks on attribute names that the format imposes.

use std::collections::HashMap;
use std::path::Path;

use exr::meta::attribute::Text;

use crate::ImageError;

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

    /// Rebuilds the metadata from the text attributes [`load_exr`](super::load_exr) returns.
    /// `Ok(None)` when the file carries none of illum's fixed fields (an EXR from another
    /// program); an error when some are present but one is missing or does not parse. `path` is
    /// only used in error messages. Attributes without the `illum.` prefix are ignored.
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
pub(super) fn check_attribute_names(path: &Path, attributes: &[(String, String)]) -> Result<(), ImageError> {
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
pub(super) fn text(s: &str) -> Text {
    Text::from_slice_unchecked(s.as_bytes())
}

pub(super) fn string(t: &Text) -> String {
    String::from_utf8_lossy(t.as_slice()).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

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
