//! What differs between the desktop and the browser, in one place. Everything else in the
//! viewer is the same code on both.
//!
//! - **Reading the GPU**: natively a frame may wait for a readback; a web page cannot (the
//!   browser maps buffers only between frames), so there the path tracer and the Whitted ray
//!   tracer poll theirs ([`POLLED_READBACK`]).
//! - **Scene files**: natively read from disk; in the browser the scenes of `scenes/` are built
//!   into the page ([`BUILT_IN_SCENES`]) and other files come from the file picker or are
//!   dropped on the page ([`read_scene`]).
//! - **Saving**: natively a file written atomically; in the browser a download
//!   (`crate::browser::download`).

use std::path::Path;

use illum_scene::Scene;

/// Whether GPU readbacks are polled across frames instead of waited for.
pub const POLLED_READBACK: bool = cfg!(target_arch = "wasm32");

/// GPU time aimed at per path-tracing submission, given the desktop's `frame_budget`. Natively
/// a frame waits for its submission, so it stays short. In the browser a frame never waits:
/// the next band is already on the GPU while the page draws, and one band comes back per frame
/// or later; so each band carries more work: where drawing the page takes most of the CPU
/// (SwiftShader), a band of the desktop's size would leave the GPU idle most of the time
/// (docs/performance.md, "In the browser"). 50 ms keeps a hardware GPU's page responsive.
pub fn submission_seconds(frame_budget: f64) -> f64 {
    if POLLED_READBACK { frame_budget.max(0.05) } else { frame_budget }
}

/// What a successful save did: natively a file was written; in the browser a download started.
pub const SAVED: &str = if cfg!(target_arch = "wasm32") { "downloaded" } else { "saved" };

/// The scene files of `scenes/`, by the path a user would type, built into the binary (the web
/// page has no file system; the desktop viewer lists them too).
pub const BUILT_IN_SCENES: &[(&str, &str)] = &[
    ("scenes/cornell.toml", include_str!("../../../scenes/cornell.toml")),
    ("scenes/whitted.toml", include_str!("../../../scenes/whitted.toml")),
    ("scenes/cornell-classic.toml", include_str!("../../../scenes/cornell-classic.toml")),
    ("scenes/cornell-sphere.toml", include_str!("../../../scenes/cornell-sphere.toml")),
];

/// The built-in text of a scene path (`scenes/x.toml`, or `./scenes/x.toml`), if it is one.
pub fn built_in_scene(path: &Path) -> Option<&'static str> {
    let wanted = path.strip_prefix(".").unwrap_or(path);
    BUILT_IN_SCENES.iter().find(|(name, _)| Path::new(name) == wanted).map(|(_, text)| *text)
}

/// Reads and validates the scene file at `path`: from disk natively. The error holds its
/// causes too (for a file that cannot be read, the system's reason).
#[cfg(not(target_arch = "wasm32"))]
pub fn read_scene(path: &Path) -> Result<Scene, String> {
    Scene::load(&illum_scene::resolve_scene_path(path)).map_err(|e| {
        let mut text = e.to_string();
        let mut cause = std::error::Error::source(&e);
        while let Some(c) = cause {
            text += &format!(": {c}");
            cause = c.source();
        }
        text
    })
}

/// Reads and validates the scene file at `path`: in the browser, one of the built-in scenes.
#[cfg(target_arch = "wasm32")]
pub fn read_scene(path: &Path) -> Result<Scene, String> {
    let label = path.display().to_string();
    match built_in_scene(path) {
        Some(text) => Scene::from_toml_str(text, &label).map_err(|e| e.to_string()),
        None => Err(format!(
            "{label}: not one of the scenes built into this page ({}); open your own file with \"Open file...\" or drop it on the page",
            BUILT_IN_SCENES.iter().map(|(name, _)| *name).collect::<Vec<_>>().join(", ")
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The built-in copies are the files in `scenes/` that load from their own text (every
    /// one of them: a scene that names a mesh file is not built in), and each loads.
    #[test]
    fn built_in_scenes_are_the_scene_folder() {
        let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        let mut on_disk: Vec<String> = std::fs::read_dir(&folder)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|name| name.ends_with(".toml"))
            .map(|name| format!("scenes/{name}"))
            .filter(|name| {
                let text = std::fs::read_to_string(folder.join("..").join(name)).unwrap();
                Scene::from_toml_str(&text, name).is_ok()
            })
            .collect();
        on_disk.sort();
        let mut built_in: Vec<String> = BUILT_IN_SCENES.iter().map(|(name, _)| (*name).to_owned()).collect();
        built_in.sort();
        assert_eq!(built_in, on_disk);
        for (name, text) in BUILT_IN_SCENES {
            assert_eq!(*text, std::fs::read_to_string(folder.join("..").join(name)).unwrap());
            Scene::from_toml_str(text, name).unwrap_or_else(|e| panic!("{e}"));
        }
        assert!(built_in_scene(Path::new("./scenes/cornell.toml")).is_some());
        assert!(built_in_scene(Path::new("scenes/nope.toml")).is_none());
    }
}
