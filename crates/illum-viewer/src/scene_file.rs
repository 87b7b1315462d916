//! Opening scene files of either kind. Every failure becomes the loader's own message (which
//! names the file, the field and what is allowed), for the UI to show; nothing panics.

use std::path::{Path, PathBuf};

use illum_scene::{Scene, SceneKind, WhittedScene, scene_kind};

/// The path tracer's scene when none is given: the assignment's Cornell box.
pub const DEFAULT_PATHTRACE_SCENE: &str = "scenes/cornell.toml";
/// The raster's scene when none is given: the assignment's glass and metal spheres.
pub const DEFAULT_RASTER_SCENE: &str = "scenes/whitted.toml";

/// A loaded scene, by kind.
#[derive(Clone, Debug)]
pub enum LoadedScene {
    PathTrace(Scene),
    Raster(WhittedScene),
}

/// `path` as given when it exists; a relative path that does not exist from the working
/// directory is tried from the workspace root too, so `scenes/cornell.toml` works from
/// `cargo run` anywhere in the workspace and from the crate's tests.
pub fn resolve(path: &Path) -> PathBuf {
    if path.is_relative() && !path.exists() {
        let from_root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(path);
        if from_root.exists() {
            return from_root;
        }
    }
    path.to_path_buf()
}

/// Loads a scene file of either kind (told apart by its `renderer` key).
pub fn load(path: &Path) -> Result<LoadedScene, String> {
    let resolved = resolve(path);
    let kind = scene_kind(&resolved).map_err(|e| e.to_string())?;
    match kind {
        SceneKind::PathTrace => Scene::load(&resolved).map(LoadedScene::PathTrace),
        SceneKind::Raster => WhittedScene::load(&resolved).map(LoadedScene::Raster),
    }
    .map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_scenes_load_as_their_kind() {
        assert!(matches!(load(Path::new(DEFAULT_PATHTRACE_SCENE)), Ok(LoadedScene::PathTrace(_))));
        assert!(matches!(load(Path::new(DEFAULT_RASTER_SCENE)), Ok(LoadedScene::Raster(_))));
    }

    #[test]
    fn bad_files_are_messages() {
        let missing = load(Path::new("no/such/scene.toml")).unwrap_err();
        assert!(missing.contains("no/such/scene.toml"), "{missing}");
        let dir = tempfile::tempdir().unwrap();
        let bad = dir.path().join("bad.toml");
        std::fs::write(&bad, "[camera]\nvfov = \"wide\"\n").unwrap();
        let message = load(&bad).unwrap_err();
        assert!(message.contains("bad.toml"), "{message}");
    }
}
