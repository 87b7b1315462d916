//! The extra layers an EXR file can carry after its RGB image: exact integers ([`U32Layer`]) and
//! floats to look at ([`F32Layer`]).

/// An extra EXR layer of 32-bit unsigned integer channels, stored after the RGB image (a
/// multi-part file): exact data that f32 cannot hold, such as the path tracer's f64 statistics
/// split into two words (see `illum_pathtrace::checkpoint`). Other EXR readers show the RGB
/// image and ignore it.
#[derive(Clone, Debug, PartialEq)]
pub struct U32Layer {
    /// The layer's name (the part's `name` attribute).
    pub name: String,
    /// Channel names and their values, row-major like the image (one per pixel each).
    pub channels: Vec<(String, Vec<u32>)>,
}

/// An extra EXR layer of 32-bit float channels, stored after the RGB image (a multi-part file)
/// and any [`U32Layer`]s: per-pixel values to look at, such as a denoiser's guide buffers
/// (`albedo`, `normal`), the path tracer's estimated relative error (`illum.error`) or a signed
/// difference from a reference. Other EXR readers show the RGB image and list the layer.
#[derive(Clone, Debug, PartialEq)]
pub struct F32Layer {
    /// The layer's name (the part's `name` attribute).
    pub name: String,
    /// Channel names and their values, row-major like the image (one per pixel each).
    pub channels: Vec<(String, Vec<f32>)>,
}
