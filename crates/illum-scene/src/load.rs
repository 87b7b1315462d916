//! Loading a scene: the file's text, parsed into the raw structs of `file.rs`, then validated
//! into a [`Scene`] (`validate.rs`), with the mesh files it names.

use std::path::Path;

use crate::error::SceneError;
use crate::file::RawScene;
use crate::mesh_load::ReadFile;
use crate::scene::Scene;
use crate::validate::scene_from_raw;

impl Scene {
    /// Reads and validates a scene file and the mesh files it names (relative to its folder).
    /// Errors name the file as `path` was given.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let label = path.display().to_string();
        let text =
            std::fs::read_to_string(path).map_err(|source| SceneError::Io { file: label.clone(), source })?;
        Self::from_toml_str(&text, &label)
    }

    /// Parses and validates scene text. `file_label` names the source in errors, and its file
    /// stem is the scene's name when the text has no `name`. Mesh files are read from the file
    /// system, relative to `file_label`'s folder (where a browser has no file system, use
    /// [`Scene::from_toml_str_with`]).
    pub fn from_toml_str(text: &str, file_label: &str) -> Result<Scene, SceneError> {
        let folder = Path::new(file_label).parent().unwrap_or(Path::new("")).to_path_buf();
        Self::from_toml_str_with(text, file_label, &mut |name: &str| {
            let path = folder.join(name);
            std::fs::read(&path).map_err(|e| format!("cannot read {}: {e}", path.display()))
        })
    }

    /// [`Scene::from_toml_str`], with each mesh file's bytes from `read`, which is given the
    /// file's name as the scene writes it and says why it has no bytes in a sentence naming it.
    pub fn from_toml_str_with(
        text: &str,
        file_label: &str,
        read: &mut ReadFile<'_>,
    ) -> Result<Scene, SceneError> {
        let raw: RawScene = toml::from_str(text).map_err(|e| SceneError::from_toml(&e, text, file_label))?;
        let default_name = Path::new(file_label)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .filter(|s| !s.is_empty())
            .unwrap_or_else(|| "scene".to_owned());
        scene_from_raw(raw, file_label, &default_name, read)
    }
}
