//! OpenEXR output and input: linear f32 RGB plus the render settings as text attributes.
//!
//! EXR is the lossless record of a render: channels R, G, B stored as 32-bit floats (not
//! half floats, whose 11-bit mantissa would add quantisation error larger than the noise of a
//! converged render), compressed with ZIP, which is lossless. The settings that produced the
//! image travel with it as custom text attributes named `illum.<field>`, so a reference image
//! says how it was made.
//!
//!
//! The module's files: `metadata.rs` (the settings as text attributes), `layers.rs` (the extra
//! layers' types), `write.rs` and `read.rs`. Writing and reading share one layout: the RGB image
//! first (named `rgb` when extra layers follow), then the u32 layers, then the f32 layers.

mod layers;
mod metadata;
mod read;
mod write;

pub use layers::{F32Layer, U32Layer};
pub use metadata::{ATTRIBUTE_PREFIX, ExrMetadata};
pub use read::{ExrHeader, load_exr, load_exr_header, load_f32_layer, load_u32_layer, load_u32_layers};
pub use write::{
    exr_bytes_with_layers, save_exr, save_exr_with_f32_layers, save_exr_with_float_layers,
    save_exr_with_layers,
};

/// Round trips: what the writers store, the readers give back exactly.
#[cfg(test)]
mod tests {
    use super::*;
    use crate::rgb_image::RgbImage32;

    fn metadata() -> ExrMetadata {
        ExrMetadata {
            renderer: "pathtrace".into(),
            scene: "scenes/cornell.toml — Ünïcode".into(),
            render_seconds: 12.345_678_901_234_5,
            fields: vec![
                ("spp".into(), (1u64 << 40).to_string()),
                ("adapter".into(), "llvmpipe (LLVM 19)".into()),
                ("a".into(), String::new()),
            ],
        }
    }

    #[test]
    fn round_trip_exact_floats_and_metadata() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sub/render.exr");
        let special = [
            0.0,
            -0.0,
            1.0e-40, // subnormal: f16 would flush it
            std::f32::consts::PI,
            -7.25,
            65_519.99, // above f16's range
            f32::MAX,
            f32::INFINITY,
        ];
        let img = RgbImage32::from_fn(5, 3, |x, y| {
            let i = (y * 5 + x) as usize;
            [special[i % special.len()], 0.1 * i as f32, 1.0 / (1.0 + i as f32)]
        });
        let meta = metadata();
        save_exr(&path, &img, &meta).unwrap();

        let (back, attrs) = load_exr(&path).unwrap();
        assert_eq!((back.width, back.height), (5, 3));
        let bits =
            |im: &RgbImage32| -> Vec<u32> { im.pixels.iter().flatten().map(|v| v.to_bits()).collect() };
        assert_eq!(bits(&back), bits(&img), "pixels are not bit-exact");

        assert!(attrs.contains(&("illum.spp".to_string(), "1099511627776".to_string())), "{attrs:?}");
        let parsed = ExrMetadata::from_attributes(&path, &attrs).unwrap().unwrap();
        let mut expected = meta;
        expected.fields.sort();
        assert_eq!(parsed.get("adapter"), Some("llvmpipe (LLVM 19)"));
        assert_eq!(parsed, expected);
    }

    #[test]
    fn extra_u32_layers_round_trip_and_the_rgb_image_still_loads() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("layers.exr");
        let img = RgbImage32::from_fn(3, 2, |x, y| [x as f32, y as f32, 0.5]);
        let layer = U32Layer {
            name: "state".into(),
            channels: vec![("a".into(), vec![0, 1, 2, u32::MAX, 4, 5]), ("b".into(), vec![7; 6])],
        };
        save_exr_with_layers(&path, &img, &metadata(), vec![layer.clone()]).unwrap();
        let (back, attrs) = load_exr(&path).unwrap();
        assert_eq!(back, img);
        assert_eq!(
            ExrMetadata::from_attributes(&path, &attrs).unwrap().unwrap().get("spp"),
            Some("1099511627776")
        );
        assert_eq!(load_u32_layer(&path, "state").unwrap(), Some(layer.clone()));
        assert_eq!(load_u32_layer(&path, "other").unwrap(), None);
        assert_eq!(load_u32_layers(&path, &["other", "state"]).unwrap(), [None, Some(layer)]);
        // The headers alone: the same size and attributes as the full read, and both layers.
        let header = load_exr_header(&path).unwrap();
        assert_eq!((header.width, header.height), (3, 2));
        assert_eq!(header.attributes, attrs);
        assert_eq!(header.layers, ["rgb", "state"]);
        let single = dir.path().join("single.exr");
        save_exr(&single, &img, &metadata()).unwrap();
        assert_eq!(load_exr_header(&single).unwrap().attributes, load_exr(&single).unwrap().1);
        std::fs::write(dir.path().join("not.exr"), b"not an exr").unwrap();
        let error = load_exr_header(dir.path().join("not.exr")).unwrap_err().to_string();
        assert!(error.contains("not.exr"), "{error}");
    }

    #[test]
    fn f32_layers_round_trip_after_the_u32_ones() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.exr");
        let mut image = RgbImage32::new(2, 1);
        image.pixels = vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]];
        let u = U32Layer { name: "u".into(), channels: vec![("n".into(), vec![7, 8])] };
        let f =
            F32Layer { name: "illum.error".into(), channels: vec![("Y".into(), vec![0.25, f32::INFINITY])] };
        save_exr_with_float_layers(&path, &image, &metadata(), vec![u.clone()], vec![f.clone()]).unwrap();
        assert_eq!(load_f32_layer(&path, "illum.error").unwrap(), Some(f));
        assert_eq!(load_u32_layer(&path, "u").unwrap(), Some(u));
        assert_eq!(load_f32_layer(&path, "missing").unwrap(), None);
        assert!(load_f32_layer(&path, "u").unwrap_err().to_string().contains("not 32-bit floats"));
        assert_eq!(load_exr(&path).unwrap().0, image);
    }
}
