//! Loading a scene: the file's text, parsed into the raw structs of `file.rs`, then validated
//! into a [`Scene`] (`validate.rs`).

use std::path::Path;

use crate::error::SceneError;
use crate::file::RawScene;
use crate::scene::Scene;
use crate::validate::scene_from_raw;

impl Scene {
    /// Reads and validates a scene file. Errors name the file as `path` was given.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let label = path.display().to_string();
        let text =
            std::fs::read_to_string(path).map_err(|source| SceneError::Io { file: label.clone(), source })?;
        Self::from_toml_str(&text, &label)
    }

    /// Parses and validates scene text. `file_label` names the source in errors, and its file
    /// stem is the scene's name when the text has no `name`.
    pub fn from_toml_str(text: &str, file_label: &str) -> Result<Scene, SceneError> {
        let raw: RawScene = toml::from_str(text).map_err(|e| SceneError::from_toml(&e, text, file_label))?;
        let default_name = Path::new(file_label)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .filter(|s| !s.is_empty())
            .unwrap_or_else(|| "scene".to_owned());
        scene_from_raw(raw, file_label, &default_name)
    }
}
