//! Opening scene files: from a path, from files' bytes (dropped on the window or picked in the
//! browser), into every mode that can render them; and each mode's default scene.

use std::path::{Path, PathBuf};

use illum_scene::RendererKind;

use super::ViewerApp;
use crate::pathtrace_mode::PathTraceMode;
use crate::raster_mode::RasterMode;
use crate::scene_file;
use crate::whitted_mode::WhittedMode;

impl ViewerApp {
    /// Opens a scene file in every mode that can render it and returns the mode to show (the
    /// file's `renderer`, when it can). A mode that cannot render it keeps its scene. On error
    /// nothing changes and the loader's message is returned.
    pub fn open(&mut self, path: &Path) -> Result<RendererKind, String> {
        // The path as given names the scene in the UI and in saved metadata.
        let loaded = scene_file::load(path)?;
        Ok(self.install(path.to_path_buf(), loaded))
    }

    /// As [`Self::open`], for files picked or dropped together in the browser: the scene file
    /// among them and the mesh files it names ([`scene_file::load_files`]); the scene file's
    /// name names it in errors and in the UI.
    pub fn open_files(&mut self, files: &[scene_file::GivenFile]) -> Result<RendererKind, String> {
        let (name, loaded) = scene_file::load_files(files)?;
        Ok(self.install(PathBuf::from(name), loaded))
    }

    /// Opens files dropped on the window together like the Open button (natively: the scene
    /// file's path, whose mesh files are read beside it; in the browser their bytes arrive a
    /// few frames later, through the file picker's inbox).
    pub(super) fn open_dropped(&mut self, ctx: &egui::Context, files: Vec<egui::DroppedFileHandle>) {
        #[cfg(not(target_arch = "wasm32"))]
        {
            let _ = ctx;
            // The scene file among them (a mesh file dropped with it is read from its folder).
            let scene =
                files.iter().find(|f| f.path().extension().is_some_and(|e| e.eq_ignore_ascii_case("toml")));
            if let Some(file) = scene.or(files.first()) {
                let result = self.open(file.path());
                self.opened(result);
            }
        }
        #[cfg(target_arch = "wasm32")]
        self.picker.read_dropped(ctx, files);
    }

    /// Shows the outcome of opening a scene from the UI: its mode and name, or the error.
    pub(super) fn opened(&mut self, result: Result<RendererKind, String>) {
        match result {
            Ok(mode) => {
                self.mode = mode;
                self.open_error = None;
                if let Some(current) = self.current_scene_path() {
                    self.scene_field = current;
                }
            }
            Err(e) => self.open_error = Some(e),
        }
    }

    /// Puts a loaded scene into every mode that can render it; returns the mode to show.
    /// The modes that cannot render it keep their scene, and their reasons are kept for the
    /// top bar ([`Self::refusal_of`]).
    fn install(&mut self, given: PathBuf, loaded: scene_file::LoadedScene) -> RendererKind {
        let mode = loaded.mode();
        let mut refusals = Vec::new();
        match loaded.pathtrace {
            Ok(scene) => match &mut self.pathtrace {
                Ok(mode) => mode.set_scene(given.clone(), scene),
                Err(_) => self.pathtrace = Ok(PathTraceMode::new(given.clone(), scene)),
            },
            Err(reason) => refusals.push((RendererKind::PathTrace, reason)),
        }
        match loaded.raster {
            Ok((raster, scene)) => match &mut self.raster {
                Ok(mode) => mode.set_scene(given.clone(), raster, scene),
                Err(_) => self.raster = Ok(RasterMode::new(given.clone(), raster, scene)),
            },
            Err(reason) => refusals.push((RendererKind::Raster, reason)),
        }
        match loaded.whitted {
            Ok(scene) => match &mut self.whitted {
                Ok(mode) => mode.set_scene(given.clone(), scene),
                Err(_) => self.whitted = Ok(WhittedMode::new(given.clone(), scene)),
            },
            Err(reason) => refusals.push((RendererKind::Whitted, reason)),
        }
        self.refused = (!refusals.is_empty()).then_some((given, refusals));
        mode
    }
}

pub(super) fn load_pathtrace(path: &Path) -> Result<PathTraceMode, String> {
    Ok(PathTraceMode::new(path.to_path_buf(), scene_file::load(path)?.pathtrace?))
}

pub(super) fn load_raster(path: &Path) -> Result<RasterMode, String> {
    let (raster, scene) = scene_file::load(path)?.raster?;
    Ok(RasterMode::new(path.to_path_buf(), raster, scene))
}

pub(super) fn load_whitted(path: &Path) -> Result<WhittedMode, String> {
    Ok(WhittedMode::new(path.to_path_buf(), scene_file::load(path)?.whitted?))
}
