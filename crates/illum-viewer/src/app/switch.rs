//! Which mode is shown: switching between the modes, and the camera that follows a switch
//! between two modes showing the same scene file.

use illum_scene::RendererKind;

use super::ViewerApp;
use crate::camera::OrbitCamera;

impl ViewerApp {
    /// The scene file of the mode shown, as it was given.
    pub(super) fn current_scene_path(&self) -> Option<String> {
        self.scene_path_of(self.mode)
    }

    /// The scene file of `mode`, as it was given.
    pub(super) fn scene_path_of(&self, mode: RendererKind) -> Option<String> {
        self.mode_ref(mode).ok().map(|m| m.scene_path().display().to_string())
    }

    /// The orbit camera of `mode`, when it has a scene.
    pub(super) fn camera_of(&mut self, mode: RendererKind) -> Option<&mut OrbitCamera> {
        self.mode_of(mode).ok().map(|m| m.camera())
    }

    /// Gives the mode now shown the camera of `from` if both show the same scene file (the
    /// renderer then draws the same view; each one redraws when its camera changes).
    fn carry_camera(&mut self, from: RendererKind) {
        let same_scene =
            self.scene_path_of(from).is_some() && self.scene_path_of(from) == self.current_scene_path();
        let Some(camera) = self.camera_of(from).copied() else { return };
        if let (true, Some(to)) = (same_scene, self.camera_of(self.mode)) {
            *to = camera;
        }
    }

    /// Switches to `mode` as the top bar's buttons do (the camera follows, see
    /// `carry_camera`).
    pub fn switch_to(&mut self, mode: RendererKind) {
        let before = std::mem::replace(&mut self.mode, mode);
        if mode != before {
            self.carry_camera(before);
            if let Some(current) = self.current_scene_path() {
                // The field follows the mode: it names the scene now shown.
                self.scene_field = current;
                self.open_error = None;
            }
        }
    }
}
