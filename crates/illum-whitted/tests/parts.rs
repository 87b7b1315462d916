//! A long render dispatched in parts (bands of rows, or tiles when a band of 8 rows holds too
//! many rays) is the one-dispatch render bit for bit, reports each part as it ends, and stops
//! after the part during which it was told to.

use std::ops::ControlFlow;

use illum_whitted::WhittedTracer;

fn bits(image: &illum_image::RgbImage32) -> Vec<u32> {
    image.pixels.iter().flatten().map(|v| v.to_bits()).collect()
}

#[test]
fn parts_give_the_same_image_report_their_pixels_and_can_stop() {
    let gpu = illum_gpu::testing::gpu();
    // 40 x 45: the last band has 13 rows and a tile row 5, not multiples of the workgroup's 8;
    // 40 columns in tiles of 24 leave a last tile of 16.
    for name in ["whitted.toml", "cornell.toml"] {
        let scene = illum_scene::testing::shipped_scene(name, 40, 45);
        let tracer = WhittedTracer::new(gpu, &scene).unwrap();
        let whole = bits(&tracer.render().unwrap());
        for (per_part, expected) in [
            // 16 rows of 40 pixels per part.
            (40 * 16 + 5, vec![640, 1280, 1800]),
            // Tiles of 8 rows x 24 columns (200 / 8 = 25, down to 24), then 8 x 16; the last
            // band's are 5 rows high.
            (200, (1..=5).flat_map(|band| [band * 320 - 128, band * 320]).chain([1720, 1800]).collect()),
        ] {
            let mut reported = Vec::new();
            let image = tracer
                .render_in_parts(per_part, |done| {
                    reported.push(done);
                    ControlFlow::Continue(())
                })
                .unwrap()
                .expect("not stopped");
            assert_eq!(reported, expected, "{name}, {per_part} pixels per part");
            assert!(bits(&image) == whole, "{name}, {per_part} pixels per part: differs from one dispatch");
        }
    }

    let scene = illum_scene::testing::shipped_scene("whitted.toml", 16, 64);
    let tracer = WhittedTracer::new(gpu, &scene).unwrap();
    let mut parts = 0;
    let stopped = tracer
        .render_in_parts(16 * 8, |_| {
            parts += 1;
            if parts == 3 { ControlFlow::Break(()) } else { ControlFlow::Continue(()) }
        })
        .unwrap();
    assert!(stopped.is_none(), "a stopped render returns no image");
    assert_eq!(parts, 3, "no part after the one that stopped it");
    // Told to stop after the last part: the image is complete and returned.
    let complete = tracer.render_in_parts(16 * 64, |_| ControlFlow::Break(())).unwrap();
    assert!(complete.is_some_and(|image| bits(&image) == bits(&tracer.render().unwrap())));
}
