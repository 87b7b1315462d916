//! Which renderer a scene file is for.
//!
//! illum reads two scene formats from the same `scenes/` folder: the path tracer's (boxes, quads
//! and spheres with Lambertian materials; see [`Scene`](crate::Scene)) and the Whitted look-alike
//! rasterizer's (see [`WhittedScene`](crate::WhittedScene)). A rasterizer scene says so with a
//! top-level `renderer = "raster"`; a file without a `renderer` key is a path-tracer scene, so
//! every path-tracer file written before the rasterizer existed keeps its meaning.

use std::path::Path;

use serde::Deserialize;

use crate::error::SceneError;

/// The key that names the renderer, and its one accepted value.
pub(crate) const RENDERER_KEY: &str = "renderer";
pub(crate) const RASTER: &str = "raster";

/// What `renderer` accepts, for error messages.
pub(crate) const RENDERER_ALLOWED: &str = "must be \"raster\" (a Whitted look-alike scene for the \
     rasterizer) or left out (a path-tracer scene)";

/// The renderer a scene file is written for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneKind {
    /// No `renderer` key: the Cornell-box path tracer's format ([`crate::Scene`]).
    PathTrace,
    /// `renderer = "raster"`: the Whitted look-alike's format ([`crate::WhittedScene`]).
    Raster,
}

/// Only the `renderer` key; every other key is ignored here (each format checks its own).
#[derive(Deserialize)]
struct Probe {
    renderer: Option<toml::Value>,
}

impl SceneKind {
    /// The kind of the scene text. Malformed TOML is a [`SceneError::Syntax`] (the same error
    /// either loader would report); a `renderer` value other than `"raster"` is
    /// [`SceneError::Invalid`].
    pub fn from_toml_str(text: &str, file_label: &str) -> Result<SceneKind, SceneError> {
        let probe: Probe = toml::from_str(text).map_err(|e| SceneError::from_toml(&e, text, file_label))?;
        match probe.renderer {
            None => Ok(SceneKind::PathTrace),
            Some(toml::Value::String(s)) if s == RASTER => Ok(SceneKind::Raster),
            Some(other) => {
                let shown = match &other {
                    toml::Value::String(s) => format!("{s:?}"),
                    value => value.to_string(),
                };
                Err(SceneError::invalid(file_label, RENDERER_KEY, shown, RENDERER_ALLOWED))
            }
        }
    }
}

/// Reads `path` and tells which renderer it is for (see [`SceneKind::from_toml_str`]).
pub fn scene_kind(path: &Path) -> Result<SceneKind, SceneError> {
    let label = path.display().to_string();
    let text =
        std::fs::read_to_string(path).map_err(|source| SceneError::Io { file: label.clone(), source })?;
    SceneKind::from_toml_str(&text, &label)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn absence_means_path_tracer_and_raster_is_named() {
        assert_eq!(SceneKind::from_toml_str("name = \"x\"", "a.toml").unwrap(), SceneKind::PathTrace);
        assert_eq!(SceneKind::from_toml_str("renderer = \"raster\"", "a.toml").unwrap(), SceneKind::Raster);
    }

    #[test]
    fn other_values_are_rejected_with_the_allowed_forms() {
        for (text, value) in [("renderer = \"pathtrace\"", "\"pathtrace\""), ("renderer = 3", "3")] {
            let err = SceneKind::from_toml_str(text, "a.toml").unwrap_err();
            assert_eq!(err.to_string(), format!("a.toml: renderer = {value}: {RENDERER_ALLOWED}"));
        }
    }

    #[test]
    fn malformed_toml_is_a_syntax_error() {
        let err = SceneKind::from_toml_str("renderer = raster", "a.toml").unwrap_err();
        assert!(matches!(err, SceneError::Syntax { line: 1, column: 12, .. }), "{err:?}");
    }
}
