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

/// A file picked or dropped in the browser, which gives its name (no folder) and its bytes, or
/// why it could not be read.
pub type GivenFile = (String, Result<Vec<u8>, String>);

/// Loads a scene from files given together (picked or dropped in a browser page, which has no
/// file system): the one scene file among them (`.toml`, or the only file given), with each
/// mesh file it names read from the others by file name, since a page sees no folders. Returns
/// the scene file's name and the scene.
pub fn load_files(files: &[GivenFile]) -> Result<(String, LoadedScene), String> {
    let names = || files.iter().map(|(name, _)| name.as_str()).collect::<Vec<_>>().join(", ");
    let scenes: Vec<&GivenFile> = if files.len() == 1 {
        files.iter().collect()
    } else {
        files.iter().filter(|(name, _)| name.to_ascii_lowercase().ends_with(".toml")).collect()
    };
    let (scene_name, bytes) = match scenes.as_slice() {
        [one] => one,
        [] => {
            return Err(format!(
                "none of the files given ({}) is a scene file (.toml): give the scene file together with the mesh files it names",
                names()
            ));
        }
        _ => {
            return Err(format!(
                "give one scene file (.toml) at a time, with its mesh files: {} were given",
                names()
            ));
        }
    };
    let bytes = bytes.as_ref().map_err(Clone::clone)?;
    let text = std::str::from_utf8(bytes)
        .map_err(|e| format!("{scene_name}: not a text (UTF-8) scene file: {e}"))?;
    let mut read = |mesh: &str| -> Result<Vec<u8>, String> {
        let wanted =
            Path::new(mesh).file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        match files.iter().find(|(name, _)| *name == wanted) {
            Some((_, bytes)) => bytes.clone(),
            None => Err(format!(
                "cannot read {mesh}: a page reads only the files given with the scene; open {wanted} together with {scene_name}"
            )),
        }
    };
    let scene = Scene::from_toml_str_with(text, scene_name, &mut read).map_err(|e| e.to_string())?;
    Ok((scene_name.clone(), split(scene)?))
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

    /// A page's files: the scene and the mesh files it names, matched by file name; what is
    /// missing or ambiguous is named.
    #[test]
    fn files_given_together_load_their_meshes_by_name() {
        let scene = include_str!("../../../scenes/cornell-mesh.toml");
        let mesh = include_bytes!("../../../scenes/models/icosphere-3.obj").to_vec();
        let given = |files: &[(&str, &[u8])]| -> Vec<GivenFile> {
            files.iter().map(|(name, bytes)| ((*name).to_owned(), Ok(bytes.to_vec()))).collect()
        };
        let (name, loaded) =
            load_files(&given(&[("icosphere-3.obj", &mesh), ("cornell-mesh.toml", scene.as_bytes())]))
                .unwrap();
        assert_eq!(name, "cornell-mesh.toml");
        let from_disk = load(Path::new("../../scenes/cornell-mesh.toml")).unwrap();
        assert_eq!(loaded.pathtrace.unwrap().content_hash(), from_disk.pathtrace.unwrap().content_hash());

        let missing = load_files(&given(&[("cornell-mesh.toml", scene.as_bytes())])).unwrap_err();
        assert!(
            missing.contains("cornell-mesh.toml")
                && missing.contains("cannot read models/icosphere-3.obj")
                && missing.contains("open icosphere-3.obj together with cornell-mesh.toml"),
            "{missing}"
        );
        let no_scene = load_files(&given(&[("a.obj", &mesh), ("b.obj", &mesh)])).unwrap_err();
        assert!(no_scene.contains("a.obj, b.obj") && no_scene.contains("(.toml)"), "{no_scene}");
        let two =
            load_files(&given(&[("a.toml", scene.as_bytes()), ("b.toml", scene.as_bytes())])).unwrap_err();
        assert!(two.contains("one scene file") && two.contains("a.toml, b.toml"), "{two}");
        let unreadable = vec![("x.toml".to_owned(), Err("x.toml: could not be read: gone".to_owned()))];
        assert_eq!(load_files(&unreadable).unwrap_err(), "x.toml: could not be read: gone");
        // A single file is the scene whatever its name (a dropped file may have none).
        let cornell = include_str!("../../../scenes/cornell.toml");
        assert!(load_files(&given(&[("dropped file", cornell.as_bytes())])).is_ok());
    }
}
