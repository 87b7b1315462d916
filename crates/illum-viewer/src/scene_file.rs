//! Opening scene files. One scene file can be shown by every mode whose renderer can render
//! it; each failure becomes the loader's own message (which names the file, the field and what
//! is allowed, or the feature a renderer lacks), for the UI to show; nothing panics.

use std::path::Path;

use illum_raster::RasterScene;
use illum_scene::{RendererKind, Scene};

/// The path tracer's scene when none is given: the assignment's Cornell box.
pub const DEFAULT_PATHTRACE_SCENE: &str = "scenes/cornell.toml";
/// The raster's scene when none is given: the assignment's glass and metal spheres.
pub const DEFAULT_RASTER_SCENE: &str = "scenes/whitted.toml";

/// A scene file as each mode sees it: the scene, or why that mode's renderer cannot render it.
#[derive(Clone, Debug)]
pub struct LoadedScene {
    pub pathtrace: Result<Scene, String>,
    /// The raster's scene, with the scene file's own (what the Difference view compares a
    /// truth's scene with).
    pub raster: Result<(RasterScene, Scene), String>,
    pub whitted: Result<Scene, String>,
    /// The file's `renderer`.
    pub preferred: RendererKind,
}

impl LoadedScene {
    /// The mode to show: the file's own when it can render the scene, else the first of path
    /// tracer, raster and Whitted that can.
    pub fn mode(&self) -> RendererKind {
        let can = |mode: RendererKind| match mode {
            RendererKind::PathTrace => self.pathtrace.is_ok(),
            RendererKind::Raster => self.raster.is_ok(),
            RendererKind::Whitted => self.whitted.is_ok(),
        };
        [self.preferred, RendererKind::PathTrace, RendererKind::Raster, RendererKind::Whitted]
            .into_iter()
            .find(|&m| can(m))
            .unwrap_or(self.preferred)
    }
}

/// Loads a scene file for every mode. An error when the file does not load, or when no mode
/// can render it (with each renderer's reason). In the browser the path names one of the
/// scenes built into the page ([`crate::platform::read_scene`]).
pub fn load(path: &Path) -> Result<LoadedScene, String> {
    split(crate::platform::read_scene(path)?)
}

/// Loads scene text that did not come from a path the viewer can read (a file dropped on the
/// window or picked in the browser). `label` names it in errors, as a path would.
pub fn load_text(label: &str, text: &str) -> Result<LoadedScene, String> {
    split(Scene::from_toml_str(text, label).map_err(|e| e.to_string())?)
}

/// The scene as each mode sees it.
fn split(scene: Scene) -> Result<LoadedScene, String> {
    let pathtrace = scene
        .require(RendererKind::PathTrace.noun(), illum_pathtrace::implements)
        .map(|()| scene.clone())
        .map_err(|e| e.to_string());
    let raster = RasterScene::from_scene(&scene).map(|r| (r, scene.clone())).map_err(|e| e.to_string());
    let whitted = scene
        .require(RendererKind::Whitted.noun(), illum_whitted::implements)
        .map(|()| scene.clone())
        .map_err(|e| e.to_string());
    if let (Err(p), Err(r), Err(w)) = (&pathtrace, &raster, &whitted) {
        return Err(format!("no mode can show it: {p}; {r}; {w}"));
    }
    let preferred = scene.renderer;
    Ok(LoadedScene { pathtrace, raster, whitted, preferred })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_scenes_open_in_the_modes_that_can_render_them() {
        let cornell = load(Path::new(DEFAULT_PATHTRACE_SCENE)).unwrap();
        assert_eq!(cornell.mode(), RendererKind::PathTrace);
        assert!(cornell.pathtrace.is_ok());
        let why = cornell.raster.unwrap_err();
        assert!(why.contains("rasterizer cannot render"), "{why}");
        // The Whitted scene opens in both modes (the path tracer renders its glass, mirror, sun
        // and sky), shown in its file's mode.
        let whitted = load(Path::new(DEFAULT_RASTER_SCENE)).unwrap();
        assert_eq!(whitted.mode(), RendererKind::Raster);
        assert!(whitted.raster.is_ok() && whitted.pathtrace.is_ok() && whitted.whitted.is_ok());
    }

    #[test]
    fn bad_files_are_messages() {
        let missing = load(Path::new("no/such/scene.toml")).unwrap_err();
        assert!(missing.contains("no/such/scene.toml"), "{missing}");
        // The system's reason, as the OS words it.
        let reason = std::fs::read("no/such/scene.toml").unwrap_err().to_string();
        assert!(missing.ends_with(&format!(": {reason}")), "{missing}");
        let dir = tempfile::tempdir().unwrap();
        let bad = dir.path().join("bad.toml");
        std::fs::write(&bad, "[camera]\nvfov = \"wide\"\n").unwrap();
        let message = load(&bad).unwrap_err();
        assert!(message.contains("bad.toml"), "{message}");
    }

    /// Text from a dropped or picked file gives the same messages as the file read from disk,
    /// naming it by its label.
    #[test]
    fn text_loads_like_the_file() {
        let text = "[camera]\nvfov = \"wide\"\n";
        let from_text = load_text("dropped/bad.toml", text).unwrap_err();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.toml");
        std::fs::write(&path, text).unwrap();
        let from_disk = load(&path).unwrap_err();
        assert_eq!(from_text, from_disk.replace(&path.display().to_string(), "dropped/bad.toml"));
        let cornell = include_str!("../../../scenes/cornell.toml");
        assert_eq!(load_text("cornell.toml", cornell).unwrap().mode(), RendererKind::PathTrace);
    }
}
