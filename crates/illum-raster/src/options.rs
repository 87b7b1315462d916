//! What a frame should look like: the look and the effect toggles.

use illum_scene::{Effects, Look};

use crate::scene::RasterScene;

/// The choices a caller makes per frame. The scene file supplies defaults
/// ([`Options::from_scene`]); code, the command line or a viewer may change any of them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Options {
    pub look: Look,
    pub effects: Effects,
}

impl Options {
    /// The look and effects written in the scene file.
    pub fn from_scene(scene: &RasterScene) -> Self {
        Options { look: scene.look, effects: scene.effects }
    }

    /// `look` with every effect on.
    pub fn all_on(look: Look) -> Self {
        Options { look, effects: Effects::ALL_ON }
    }
}
