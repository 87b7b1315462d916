//! Contact sheets: several labelled images tiled on one canvas, for figures and for
//! comparing renders side by side.
//!
//! Labels are drawn with the public-domain 8x8 bitmap font of the `font8x8` crate, each font
//! pixel enlarged to 2x2, in white on the dark grey background.

use font8x8::UnicodeFonts;
use image::{Rgba, RgbaImage};

/// Space between panels and around the sheet, in pixels.
pub const GAP: u32 = 8;
/// Enlargement of the 8x8 font.
pub const FONT_SCALE: u32 = 2;
/// Height of one line of label text.
pub const TEXT_HEIGHT: u32 = 8 * FONT_SCALE;
/// Space between a panel and its label.
pub const LABEL_PAD: u32 = 4;
/// Background colour of the sheet.
pub const BACKGROUND: Rgba<u8> = Rgba([40, 40, 40, 255]);
/// Colour of the label text.
pub const TEXT_COLOUR: Rgba<u8> = Rgba([255, 255, 255, 255]);

/// The 8x8 glyph of `ch`: row bytes, top row first, bit 0 the leftmost pixel. Characters
/// outside the font's Latin, Greek and box-drawing sets are drawn as '?'.
fn glyph(ch: char) -> [u8; 8] {
    font8x8::BASIC_FONTS
        .get(ch)
        .or_else(|| font8x8::LATIN_FONTS.get(ch))
        .or_else(|| font8x8::GREEK_FONTS.get(ch))
        .or_else(|| font8x8::BOX_FONTS.get(ch))
        .or_else(|| font8x8::BASIC_FONTS.get('?'))
        .unwrap_or([0; 8])
}

/// Draws `text` with its top-left corner at (x0, y0), clipped to `x0 + max_width` and to the
/// canvas.
fn draw_text(canvas: &mut RgbaImage, text: &str, x0: u32, y0: u32, max_width: u32) {
    let right = x0.saturating_add(max_width).min(canvas.width());
    for (i, ch) in text.chars().enumerate() {
        let gx = x0 as u64 + i as u64 * 8 * u64::from(FONT_SCALE);
        if gx >= u64::from(right) {
            break;
        }
        for (row, bits) in glyph(ch).iter().enumerate() {
            for col in 0..8u32 {
                if bits & (1 << col) == 0 {
                    continue;
                }
                for dy in 0..FONT_SCALE {
                    for dx in 0..FONT_SCALE {
                        let x = gx + u64::from(col * FONT_SCALE + dx);
                        let y = u64::from(y0) + row as u64 * u64::from(FONT_SCALE) + u64::from(dy);
                        if x < u64::from(right) && y < u64::from(canvas.height()) {
                            canvas.put_pixel(x as u32, y as u32, TEXT_COLOUR);
                        }
                    }
                }
            }
        }
    }
}

/// Tiles `panels` left to right, top to bottom, `columns` per row (0 counts as 1), each in a
/// cell as large as the largest panel, with [`GAP`] pixels between cells and around the
/// sheet. Under each panel, after [`LABEL_PAD`] pixels, its label is drawn in one line of
/// [`TEXT_HEIGHT`] pixels, clipped to the cell's width. Panels are centred horizontally in
/// their cells.
///
/// Size: width `GAP + c * (max_w + GAP)`, height `GAP + r * (max_h + LABEL_PAD +
/// TEXT_HEIGHT + GAP)`, with `c = min(columns, n)` and `r = ceil(n / c)`. With no panels the
/// sheet is an empty `GAP x GAP` square.
pub fn contact_sheet(panels: &[(String, RgbaImage)], columns: u32) -> RgbaImage {
    if panels.is_empty() {
        return RgbaImage::from_pixel(GAP, GAP, BACKGROUND);
    }
    let n = u32::try_from(panels.len()).unwrap_or(u32::MAX);
    let cols = columns.clamp(1, n);
    let rows = n.div_ceil(cols);
    let cell_w = panels.iter().map(|(_, p)| p.width()).max().unwrap_or(0);
    let cell_h = panels.iter().map(|(_, p)| p.height()).max().unwrap_or(0);
    let row_h = cell_h + LABEL_PAD + TEXT_HEIGHT;
    let width = GAP + cols * (cell_w + GAP);
    let height = GAP + rows * (row_h + GAP);

    let mut sheet = RgbaImage::from_pixel(width, height, BACKGROUND);
    for (i, (label, panel)) in panels.iter().enumerate() {
        let (col, row) = (i as u32 % cols, i as u32 / cols);
        let cell_x = GAP + col * (cell_w + GAP);
        let cell_y = GAP + row * (row_h + GAP);
        let px = cell_x + (cell_w - panel.width()) / 2;
        image::imageops::replace(&mut sheet, panel, i64::from(px), i64::from(cell_y));
        draw_text(&mut sheet, label, cell_x, cell_y + cell_h + LABEL_PAD, cell_w);
    }
    sheet
}

#[cfg(test)]
mod tests {
    use super::*;

    fn panel(w: u32, h: u32, v: u8) -> RgbaImage {
        RgbaImage::from_pixel(w, h, Rgba([v, v / 2, 0, 255]))
    }

    fn is_light(p: &Rgba<u8>) -> bool {
        p.0[0] > 200 && p.0[1] > 200 && p.0[2] > 200
    }

    #[test]
    fn layout_size_and_labels() {
        let panels = vec![
            ("1 spp".to_string(), panel(40, 30, 100)),
            ("16 spp".to_string(), panel(40, 30, 150)),
            ("256 spp".to_string(), panel(20, 10, 200)),
        ];
        let sheet = contact_sheet(&panels, 2);
        // 2 columns, 2 rows: width 8 + 2 * (40 + 8) = 104; height 8 + 2 * (30 + 4 + 16 + 8) = 124.
        assert_eq!(sheet.dimensions(), (104, 124));

        // First panel at (8, 8); the third, narrower one centred in the second row's first cell.
        assert_eq!(sheet.get_pixel(8, 8).0, [100, 50, 0, 255]);
        assert_eq!(sheet.get_pixel(8 + 10, 8 + 58).0, [200, 100, 0, 255]);
        assert_eq!(sheet.get_pixel(8 + 9, 8 + 58), &BACKGROUND);

        // Each label band (rows 42..58 of the first row, first two cells) holds white text.
        for cell_x in [8u32, 56] {
            let light = (42..58)
                .flat_map(|y| (cell_x..cell_x + 40).map(move |x| (x, y)))
                .filter(|&(x, y)| is_light(sheet.get_pixel(x, y)))
                .count();
            assert!(light > 20, "label under cell at x={cell_x} has {light} light pixels");
        }
        // The gaps stay background: nothing is drawn between the cells.
        assert!((0..124).all(|y| sheet.get_pixel(50, y) == &BACKGROUND));
    }

    #[test]
    fn glyph_is_drawn_left_to_right() {
        // 'L': the vertical stroke is on the left, so the leftmost font columns are lit in
        // the top rows and the right half is dark there.
        let sheet = contact_sheet(&[("L".to_string(), panel(16, 1, 0))], 1);
        let y_text = GAP + 1 + LABEL_PAD;
        let left_lit = (0..4).any(|dx| is_light(sheet.get_pixel(GAP + dx, y_text + 2)));
        let right_lit = (10..16).any(|dx| is_light(sheet.get_pixel(GAP + dx, y_text + 2)));
        assert!(left_lit && !right_lit);
    }

    #[test]
    fn degenerate_inputs_do_not_panic() {
        assert_eq!(contact_sheet(&[], 3).dimensions(), (GAP, GAP));
        // columns = 0 counts as 1; more columns than panels shrink to the panel count.
        let panels = vec![("a".to_string(), panel(10, 10, 9)), ("b".to_string(), panel(10, 10, 9))];
        assert_eq!(contact_sheet(&panels, 0).width(), GAP + 10 + GAP);
        assert_eq!(contact_sheet(&panels, 9).width(), GAP + 2 * (10 + GAP));
        // A label far longer than its cell is clipped, not drawn over the neighbour.
        let long = vec![("x".repeat(100), panel(10, 10, 9)), ("".to_string(), panel(10, 10, 9))];
        let sheet = contact_sheet(&long, 2);
        let label_y = GAP + 10 + LABEL_PAD;
        assert!((label_y..label_y + TEXT_HEIGHT).all(|y| !is_light(sheet.get_pixel(GAP + 10 + GAP + 2, y))));
    }
}
