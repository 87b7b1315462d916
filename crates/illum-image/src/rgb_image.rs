//! The linear radiance image that every renderer in illum produces.

/// Rec. 709 / sRGB luminance weights (the Y row of the linear-RGB to XYZ matrix for the
/// Rec. 709 primaries with a D65 white point).
pub const REC709_LUMINANCE: [f64; 3] = [0.2126, 0.7152, 0.0722];

/// Luminance Y of a linear Rec. 709 RGB triple.
pub fn luminance(rgb: [f32; 3]) -> f64 {
    REC709_LUMINANCE[0] * f64::from(rgb[0])
        + REC709_LUMINANCE[1] * f64::from(rgb[1])
        + REC709_LUMINANCE[2] * f64::from(rgb[2])
}

/// Linear radiance per pixel, three f32 channels (R, G, B), row-major, row 0 is the top of the
/// picture. `pixels.len()` must equal `width * height`; the fields are public for cheap
/// construction, and the writers check the invariant and return an error when it is broken.
#[derive(Debug, Clone, PartialEq)]
pub struct RgbImage32 {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 3]>,
}

impl RgbImage32 {
    /// A black image.
    pub fn new(width: u32, height: u32) -> Self {
        Self::filled(width, height, [0.0; 3])
    }

    /// An image with every pixel set to `rgb`.
    pub fn filled(width: u32, height: u32, rgb: [f32; 3]) -> Self {
        RgbImage32 { width, height, pixels: vec![rgb; width as usize * height as usize] }
    }

    /// An image whose pixel (x, y) is `f(x, y)`.
    pub fn from_fn(width: u32, height: u32, mut f: impl FnMut(u32, u32) -> [f32; 3]) -> Self {
        let mut pixels = Vec::with_capacity(width as usize * height as usize);
        for y in 0..height {
            for x in 0..width {
                pixels.push(f(x, y));
            }
        }
        RgbImage32 { width, height, pixels }
    }

    /// Whether `pixels.len() == width * height`.
    pub fn is_consistent(&self) -> bool {
        self.pixels.len() as u64 == u64::from(self.width) * u64::from(self.height)
    }

    fn index(&self, x: u32, y: u32) -> usize {
        assert!(x < self.width && y < self.height, "pixel ({x}, {y}) outside {}x{}", self.width, self.height);
        y as usize * self.width as usize + x as usize
    }

    /// The pixel at column `x`, row `y` (row 0 at the top).
    ///
    /// # Panics
    /// When (x, y) lies outside the image.
    pub fn get(&self, x: u32, y: u32) -> [f32; 3] {
        self.pixels[self.index(x, y)]
    }

    /// Sets the pixel at column `x`, row `y`.
    ///
    /// # Panics
    /// When (x, y) lies outside the image.
    pub fn set(&mut self, x: u32, y: u32, rgb: [f32; 3]) {
        let i = self.index(x, y);
        self.pixels[i] = rgb;
    }

    /// Per-channel mean over all pixels, accumulated in f64 so that large images do not lose
    /// precision. An empty image has mean zero.
    pub fn mean(&self) -> [f64; 3] {
        if self.pixels.is_empty() {
            return [0.0; 3];
        }
        let mut sum = [0.0f64; 3];
        for p in &self.pixels {
            for c in 0..3 {
                sum[c] += f64::from(p[c]);
            }
        }
        let n = self.pixels.len() as f64;
        sum.map(|s| s / n)
    }

    /// Mean Rec. 709 luminance (0.2126 R + 0.7152 G + 0.0722 B). Luminance is linear in RGB,
    /// so this is the luminance of [`RgbImage32::mean`].
    pub fn mean_luminance(&self) -> f64 {
        let m = self.mean();
        REC709_LUMINANCE[0] * m[0] + REC709_LUMINANCE[1] * m[1] + REC709_LUMINANCE[2] * m[2]
    }

    /// Whether any channel of any pixel is NaN or infinite.
    pub fn has_non_finite(&self) -> bool {
        self.pixels.iter().flatten().any(|v| !v.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn get_set_are_row_major_from_the_top() {
        let mut img = RgbImage32::new(3, 2);
        img.set(2, 1, [1.0, 2.0, 3.0]);
        assert_eq!(img.pixels[5], [1.0, 2.0, 3.0]);
        assert_eq!(img.get(2, 1), [1.0, 2.0, 3.0]);
        assert_eq!(img.get(0, 0), [0.0; 3]);
        let f = RgbImage32::from_fn(3, 2, |x, y| [x as f32, y as f32, 0.0]);
        assert_eq!(f.pixels[4], [1.0, 1.0, 0.0]);
    }

    #[test]
    #[should_panic(expected = "outside 3x2")]
    fn get_outside_panics_with_the_size() {
        RgbImage32::new(3, 2).get(3, 0);
    }

    #[test]
    fn mean_and_luminance() {
        let mut img = RgbImage32::new(2, 1);
        img.set(0, 0, [1.0, 0.0, 0.0]);
        img.set(1, 0, [0.0, 1.0, 4.0]);
        assert_eq!(img.mean(), [0.5, 0.5, 2.0]);
        // 0.2126*0.5 + 0.7152*0.5 + 0.0722*2 = 0.6083
        assert!((img.mean_luminance() - 0.6083).abs() < 1e-12);
        assert!((luminance([1.0, 1.0, 1.0]) - 1.0).abs() < 1e-12);
        assert_eq!(RgbImage32::new(0, 0).mean(), [0.0; 3]);
    }

    #[test]
    fn non_finite_detection() {
        let mut img = RgbImage32::filled(2, 2, [0.5; 3]);
        assert!(!img.has_non_finite());
        img.set(1, 1, [0.0, f32::INFINITY, 0.0]);
        assert!(img.has_non_finite());
        img.set(1, 1, [f32::NAN, 0.0, 0.0]);
        assert!(img.has_non_finite());
    }

    #[test]
    fn consistency() {
        let mut img = RgbImage32::new(4, 3);
        assert!(img.is_consistent());
        img.pixels.pop();
        assert!(!img.is_consistent());
    }
}
