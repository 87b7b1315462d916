//! The mode a viewer starts in, as the command line's `--mode` and the page's `?mode=` name it.

use illum_scene::RendererKind;

/// A mode is named like the renderer it shows: `raster`, `pathtrace` or `whitted` (the page's
/// `?mode=` too).
pub fn parse_mode(text: &str) -> Result<RendererKind, String> {
    text.parse::<RendererKind>().map_err(|e| format!("unknown mode {text:?}: {}", e.allowed))
}

/// The command line's first mode: one of the renderers, or Auto.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StartMode {
    Renderer(RendererKind),
    Auto,
}

impl StartMode {
    /// The renderer shown first (Auto starts from the scene's and then shows its choice's).
    pub fn renderer(self) -> Option<RendererKind> {
        match self {
            StartMode::Renderer(kind) => Some(kind),
            StartMode::Auto => None,
        }
    }
}

/// `auto`, or a renderer as [`parse_mode`] reads it.
pub fn parse_start_mode(text: &str) -> Result<StartMode, String> {
    if text == "auto" {
        return Ok(StartMode::Auto);
    }
    parse_mode(text).map(StartMode::Renderer).map_err(|e| format!("{e}, or auto"))
}
