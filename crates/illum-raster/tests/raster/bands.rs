//! A large frame drawn in bands of rows (one submission each, so that a long render can report
//! progress and stop between them) is the frame one submission draws, pixel for pixel, and
//! stops after the band during which it was told to.

use std::ops::ControlFlow;

use illum_raster::{Look, Options};

use crate::{HEIGHT, WIDTH, renderer, scene};

#[test]
fn bands_draw_the_whole_frames_pixels_and_can_stop() {
    let s = scene();
    let mut r = renderer();
    // 180 rows in bands of 64: 64, 128, then a last band of 52 rows.
    if r.size() != (WIDTH, HEIGHT) {
        r.resize(WIDTH, HEIGHT).unwrap_or_else(|e| panic!("{e}"));
    }
    r.set_scene(&s).unwrap_or_else(|e| panic!("{e}"));
    for look in Look::ALL {
        for antialiasing in [true, false] {
            let mut options = Options::all_on(look);
            options.effects.antialiasing = antialiasing;
            let whole = r.render(&options).unwrap_or_else(|e| panic!("{e}"));
            let mut reported = Vec::new();
            let banded = r
                .render_in_bands(&options, 50, |rows| {
                    reported.push(rows);
                    ControlFlow::Continue(())
                })
                .unwrap_or_else(|e| panic!("{e}"))
                .expect("not stopped");
            // 50 rows round up to 64, the tile side.
            assert_eq!(reported, [64, 128, 180], "{look:?}");
            let differing = (0..HEIGHT)
                .flat_map(|y| (0..WIDTH).map(move |x| (x, y)))
                .filter(|&(x, y)| whole.get(x, y) != banded.get(x, y))
                .collect::<Vec<_>>();
            assert!(
                differing.is_empty(),
                "{look:?}, antialiasing {antialiasing}: {} pixels differ from the one-submission frame, first {:?}",
                differing.len(),
                differing.first()
            );
            // The next frame, drawn whole, is unchanged by the banded one before it.
            assert_eq!(r.render(&options).unwrap_or_else(|e| panic!("{e}")), whole);
        }
    }
    let options = Options::from_scene(&s);
    let mut bands = 0;
    let stopped = r
        .render_in_bands(&options, 64, |_| {
            bands += 1;
            ControlFlow::Break(())
        })
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(stopped.is_none(), "a stopped render returns no frame");
    assert_eq!(bands, 1, "no band after the one that stopped it");
}

/// A frame read back without waiting (polled, as a web page must) is the frame `render` returns,
/// pixel for pixel, and frames drawn while it is under way do not change it.
#[test]
fn a_polled_readback_is_the_rendered_frame() {
    let s = scene();
    let mut r = renderer();
    if r.size() != (WIDTH, HEIGHT) {
        r.resize(WIDTH, HEIGHT).unwrap_or_else(|e| panic!("{e}"));
    }
    r.set_scene(&s).unwrap_or_else(|e| panic!("{e}"));
    let figure = Options::all_on(Look::Figure);
    let enhanced = Options::all_on(Look::Enhanced);
    let whole = r.render(&enhanced).unwrap_or_else(|e| panic!("{e}"));
    r.draw(&enhanced).unwrap_or_else(|e| panic!("{e}"));
    let pending = r.read_polled().unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(pending.size(), (WIDTH, HEIGHT));
    // Another look drawn after the copy was submitted: the copy keeps the enhanced frame.
    let other = r.render(&figure).unwrap_or_else(|e| panic!("{e}"));
    assert_ne!(other, whole, "the two looks draw the same frame, so the check below proves nothing");
    let mut polls = 0;
    let polled = loop {
        polls += 1;
        if let Some(result) = pending.poll(illum_gpu::testing::gpu()) {
            break result.unwrap_or_else(|e| panic!("{e}"));
        }
        assert!(polls < 100_000, "the readback never completed");
        std::thread::yield_now();
    };
    assert_eq!(polled, whole);
}
