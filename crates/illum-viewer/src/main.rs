//! `cargo run --release -p illum-viewer -- [SCENE] [--mode raster|pathtrace|whitted|auto]
//! [--screenshot FILE --frames N]`
//!
//! Built for `wasm32-unknown-unknown` it is the web viewer instead (`scripts/build-web.sh`):
//! `main` starts it on the page's canvas.

#[cfg(not(target_arch = "wasm32"))]
fn main() {
    native::main();
}

#[cfg(target_arch = "wasm32")]
fn main() {
    illum_viewer::web::start();
}

#[cfg(not(target_arch = "wasm32"))]
mod native {
    use std::sync::Arc;

    use clap::Parser;
    use illum_viewer::cli::Args;
    use illum_viewer::gpu_setup::wgpu_setup;
    use illum_viewer::screenshot::{Outcome, ScreenshotJob};
    use illum_viewer::{StartOptions, ViewerApp};

    pub fn main() {
        env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
        let args = Args::parse();
        // A screenshot run is a check (the smoke test's): a scene that does not open must fail it,
        // not draw a window with the error in it and exit 0. Without --screenshot the window opens
        // and shows the error, so that another file can be opened.
        if args.screenshot.is_some()
            && let Err(e) = illum_viewer::scene_file::load(&args.scene)
        {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
        if let Some(why) = illum_viewer::cli::no_display(|name| std::env::var_os(name)) {
            eprintln!("error: {why}");
            std::process::exit(1);
        }
        let outcome: Outcome = Arc::default();
        let screenshot =
            args.screenshot.clone().map(|path| ScreenshotJob::new(path, args.frames, outcome.clone()));
        let start = StartOptions {
            scene: args.scene.clone(),
            mode: args.mode.and_then(illum_viewer::start_mode::StartMode::renderer),
            screenshot,
            clear_is_backdrop: true,
        };
        let auto = args.mode == Some(illum_viewer::start_mode::StartMode::Auto);

        let mut native = eframe::NativeOptions {
            viewport: egui::ViewportBuilder::default()
                .with_title("illum viewer")
                .with_inner_size([args.width, args.height]),
            ..Default::default()
        };
        // Under CI (as in the tests) prefer lavapipe, as illum_gpu::GpuContext::new does.
        native.wgpu_options.wgpu_setup = wgpu_setup(illum_gpu::policy::prefer_software_from_env());
        // No vsync: the frame rate is bounded by the work (path-tracing slices, raster frames), and
        // on software drivers FIFO presentation adds a wait to every frame.
        native.wgpu_options.surface.present_mode = egui_wgpu::wgpu::PresentMode::AutoNoVsync;

        let result = eframe::run_native(
            "illum viewer",
            native,
            Box::new(move |cc| {
                let mut app = ViewerApp::new(cc, start);
                if auto {
                    app.show_auto();
                }
                if let Some(pathtrace) = app.pathtrace_mut() {
                    pathtrace.settings.denoise = args.denoise;
                }
                // Both noise-free modes: each takes the file as its truth when the sizes fit
                // (its panel says why not otherwise).
                let on = args.difference || args.reference.is_some();
                if let Some(whitted) = app.whitted_mut() {
                    whitted.difference.on = on;
                    if let Some(path) = &args.reference {
                        whitted.difference.load_reference(path).map_err(|e| format!("error: {e}"))?;
                    }
                }
                if let Some(raster) = app.raster_mut() {
                    raster.difference.on = on;
                    if let Some(path) = &args.reference {
                        raster.difference.load_reference(path).map_err(|e| format!("error: {e}"))?;
                    }
                }
                Ok(Box::new(app))
            }),
        );
        if let Err(e) = result {
            eprintln!("error: the window could not run: {e}");
            std::process::exit(1);
        }
        if args.screenshot.is_some() {
            match outcome.lock().unwrap_or_else(|p| p.into_inner()).take() {
                Some(Ok(path)) => println!("screenshot saved to {}", path.display()),
                Some(Err(e)) => {
                    eprintln!("error: {e}");
                    std::process::exit(1);
                }
                None => {
                    eprintln!("error: the window closed before the screenshot was taken");
                    std::process::exit(1);
                }
            }
        }
    }
}
