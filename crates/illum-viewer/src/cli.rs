//! The command line: `illum-viewer [SCENE] [--mode raster|pathtrace|whitted|auto] [--screenshot FILE --frames N]`.

use std::path::PathBuf;

use clap::Parser;

use illum_scene::RendererKind;

#[derive(Parser, Debug, Clone)]
#[command(
    name = "illum-viewer",
    about = "Interactive viewer for illum's three renderers: the rasterizer, the Whitted ray tracer and the path tracer"
)]
pub struct Args {
    /// Scene file (TOML). It opens in every mode that can render it and is shown in the mode of
    /// its `renderer`; a mode that cannot render it keeps its default scene.
    #[arg(default_value = crate::scene_file::DEFAULT_PATHTRACE_SCENE)]
    pub scene: PathBuf,
    /// The mode shown first: a renderer, or `auto` (the Auto mode, which shows the renderer it
    /// picks). Default: the mode of SCENE.
    #[arg(long, value_parser = parse_start_mode)]
    pub mode: Option<StartMode>,
    /// Render `--frames` frames, save a screenshot of the window to this PNG file and exit.
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// Frames drawn before the screenshot is taken (with `--screenshot`).
    #[arg(long, default_value_t = 30)]
    pub frames: u32,
    /// A truth for the Difference view of the raster and Whitted modes: an EXR that illum wrote
    /// of the same scene (`illum.scene_hash`) at the mode's image size (the raster's is the
    /// view's, the Whitted image's half the view's each way).
    #[arg(long, value_name = "FILE.exr")]
    pub reference: Option<PathBuf>,
    /// Start the raster and Whitted modes with the Difference view on.
    #[arg(long)]
    pub difference: bool,
    /// Start the path tracer with Denoise on (the panel's toggle).
    #[arg(long)]
    pub denoise: bool,
    /// Initial window width in points.
    #[arg(long, default_value_t = 960.0)]
    pub width: f32,
    /// Initial window height in points.
    #[arg(long, default_value_t = 600.0)]
    pub height: f32,
}

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_screenshot_options() {
        let args = Args::try_parse_from([
            "illum-viewer",
            "--mode",
            "raster",
            "--screenshot",
            "a.png",
            "--frames",
            "3",
        ])
        .unwrap();
        assert_eq!(args.mode, Some(StartMode::Renderer(RendererKind::Raster)));
        let auto = Args::try_parse_from(["illum-viewer", "--mode", "auto"]).unwrap();
        assert_eq!(auto.mode, Some(StartMode::Auto));
        assert_eq!(args.frames, 3);
        assert_eq!(args.screenshot, Some(PathBuf::from("a.png")));
        let err = Args::try_parse_from(["illum-viewer", "--mode", "xyz"]).unwrap_err().to_string();
        assert!(err.contains("raster") && err.contains("pathtrace") && err.contains("auto"), "{err}");
    }
}
