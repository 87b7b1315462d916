//! The desktop's command line (the page reads its mode from the URL, `start_mode`): `illum-viewer [SCENE] [--mode raster|pathtrace|whitted|auto] [--screenshot FILE --frames N]`.

use std::path::PathBuf;

use clap::Parser;

use illum_scene::RendererKind;

use crate::start_mode::{StartMode, parse_start_mode};

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
    #[arg(long, value_parser = StartModeParser)]
    pub mode: Option<StartMode>,
    /// Render `--frames` frames, save a screenshot of the window to this PNG file and exit.
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// Frames drawn before the screenshot is taken (with `--screenshot`), at least 1.
    #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u32).range(1..))]
    pub frames: u32,
    /// A truth for the Difference view of the raster and Whitted modes: an EXR of the same scene
    /// (by its `illum.scene_hash`; a file without one, from another renderer, is taken as given
    /// and said so) at the mode's image size (the raster's is the view's, the Whitted image's
    /// half the view's each way).
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

/// Why no window can open, before trying: on Linux, none of the variables through which a
/// window reaches a display (winit's: `WAYLAND_DISPLAY`, `WAYLAND_SOCKET`, `DISPLAY`) is set
/// (`env` reads one). The message suggests a virtual display.
pub fn no_display(env: impl Fn(&str) -> Option<std::ffi::OsString>) -> Option<String> {
    const DISPLAYS: [&str; 3] = ["WAYLAND_DISPLAY", "WAYLAND_SOCKET", "DISPLAY"];
    let none =
        cfg!(target_os = "linux") && DISPLAYS.iter().all(|name| env(name).is_none_or(|v| v.is_empty()));
    none.then(|| {
        format!(
            "no display to open the viewer's window on ({} unset); on a machine without a screen, run it under \
             a virtual one: xvfb-run -a cargo run --release -p illum-viewer -- [ARGS]",
            DISPLAYS.join(", ")
        )
    })
}

/// `--mode`'s parser ([`parse_start_mode`]), which lists the values in `--help` and in the
/// refusal of an unknown one.
#[derive(Clone, Copy, Debug)]
struct StartModeParser;

impl clap::builder::TypedValueParser for StartModeParser {
    type Value = StartMode;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<StartMode, clap::Error> {
        let text = clap::builder::StringValueParser::new().parse_ref(cmd, arg, value)?;
        parse_start_mode(&text)
            .map_err(|e| clap::Error::raw(clap::error::ErrorKind::InvalidValue, format!("--mode: {e}\n")))
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = clap::builder::PossibleValue> + '_>> {
        let names = RendererKind::ALL.iter().map(|kind| kind.as_str()).chain(["auto"]);
        Some(Box::new(names.map(clap::builder::PossibleValue::new)))
    }
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

    #[test]
    #[cfg(target_os = "linux")]
    fn without_a_display_the_viewer_says_so_and_suggests_xvfb_run() {
        let why = no_display(|_| None).expect("no display");
        assert!(why.contains("DISPLAY") && why.contains("xvfb-run -a"), "{why}");
        assert!(no_display(|name| (name == "DISPLAY").then(|| ":99".into())).is_none());
        assert!(no_display(|name| (name == "DISPLAY").then(|| "".into())).is_some(), "an empty DISPLAY");
    }

    #[test]
    fn help_lists_every_mode_and_frames_must_be_at_least_one() {
        use clap::CommandFactory as _;
        let help = Args::command().render_long_help().to_string();
        for mode in RendererKind::ALL.iter().map(|k| k.as_str()).chain(["auto"]) {
            assert!(help.contains(mode), "--help does not list mode {mode}: {help}");
        }
        let err =
            Args::try_parse_from(["illum-viewer", "--screenshot", "a.png", "--frames", "0"]).unwrap_err();
        let text = err.to_string();
        assert!(text.contains("--frames") && text.contains("'0'") && text.contains("1.."), "{text}");
    }
}
