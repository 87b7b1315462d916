//! Contact sheets: several labelled images tiled on one canvas, for figures and for
//! comparing renders side by side.
//!
//! Labels are set in DejaVu Sans (the `dejavu` crate's embedded font, rasterized with
//! `ab_glyph`, anti-aliased), white on the dark grey background. Every label is shown whole: it
//! wraps at spaces to its panel's width, and a cell is widened when one word of a label is wider
//! than the panel, so small panels never cut a label ("Fig. 2b: 1 bounc").

use ab_glyph::{Font, FontRef, PxScale, ScaleFont, point};
use image::{Rgba, RgbaImage};

/// Space between panels and around the sheet, in pixels.
pub const GAP: u32 = 8;
/// Font size of the labels, in pixels (the font's em height).
pub const FONT_PX: f32 = 16.0;
/// Space between a panel and its label.
pub const LABEL_PAD: u32 = 4;
/// Background colour of the sheet.
pub const BACKGROUND: Rgba<u8> = Rgba([40, 40, 40, 255]);
/// Colour of the label text.
pub const TEXT_COLOUR: Rgba<u8> = Rgba([255, 255, 255, 255]);

fn font() -> FontRef<'static> {
    FontRef::try_from_slice(dejavu::sans::regular()).expect("the embedded DejaVu Sans parses")
}

/// Height of one line of label text, in pixels (ascent - descent + line gap, rounded up).
pub fn line_height() -> u32 {
    let font = font();
    let scaled = font.as_scaled(PxScale::from(FONT_PX));
    (scaled.ascent() - scaled.descent() + scaled.line_gap()).ceil() as u32
}

/// Width of `text` set in one line, in pixels (advances and kerning, rounded up).
pub fn text_width(text: &str) -> u32 {
    let font = font();
    let scaled = font.as_scaled(PxScale::from(FONT_PX));
    let mut width = 0.0;
    let mut previous = None;
    for ch in text.chars() {
        let id = scaled.glyph_id(ch);
        if let Some(p) = previous {
            width += scaled.kern(p, id);
        }
        width += scaled.h_advance(id);
        previous = Some(id);
    }
    width.ceil() as u32
}

/// `text` broken at spaces into lines at most `max_width` pixels wide; a word wider than that
/// stays whole on its own line (the caller widens the cell for it: see [`contact_sheet`]).
pub fn wrap(text: &str, max_width: u32) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for word in text.split(' ').filter(|w| !w.is_empty()) {
        match lines.last_mut() {
            Some(line) if text_width(&format!("{line} {word}")) <= max_width => {
                line.push(' ');
                line.push_str(word);
            }
            _ => lines.push(word.to_owned()),
        }
    }
    lines
}

/// Draws one line of `text` with its top-left corner at (x0, y0), blending the glyphs'
/// coverage over what is there, clipped to the canvas.
fn draw_text(canvas: &mut RgbaImage, text: &str, x0: u32, y0: u32) {
    let font = font();
    let scale = PxScale::from(FONT_PX);
    let scaled = font.as_scaled(scale);
    let mut x = x0 as f32;
    let baseline = y0 as f32 + scaled.ascent();
    let mut previous = None;
    for ch in text.chars() {
        let id = scaled.glyph_id(ch);
        if let Some(p) = previous {
            x += scaled.kern(p, id);
        }
        let glyph = id.with_scale_and_position(scale, point(x, baseline));
        x += scaled.h_advance(id);
        previous = Some(id);
        let Some(outline) = font.outline_glyph(glyph) else { continue };
        let bounds = outline.px_bounds();
        outline.draw(|gx, gy, coverage| {
            let px = bounds.min.x as i64 + i64::from(gx);
            let py = bounds.min.y as i64 + i64::from(gy);
            if px < 0 || py < 0 || px >= i64::from(canvas.width()) || py >= i64::from(canvas.height()) {
                return;
            }
            let pixel = canvas.get_pixel_mut(px as u32, py as u32);
            let a = coverage.clamp(0.0, 1.0);
            for c in 0..3 {
                let mixed = f32::from(pixel.0[c]) * (1.0 - a) + f32::from(TEXT_COLOUR.0[c]) * a;
                pixel.0[c] = mixed.round() as u8;
            }
        });
    }
}

/// Tiles `panels` left to right, top to bottom, `columns` per row (0 counts as 1), each in a
/// cell as wide as the widest panel (or the widest word of any label, if wider) and as tall as
/// the tallest panel, with [`GAP`] pixels between cells and around the sheet. Under each panel,
/// after [`LABEL_PAD`] pixels, its label is drawn whole, wrapped at spaces to the cell's width;
/// every row of cells leaves room for the most lines any label needs. Panels and label lines
/// are centred horizontally in their cells.
///
/// Size: width `GAP + c * (cell_w + GAP)`, height `GAP + r * (max_h + LABEL_PAD + lines *
/// line_height() + GAP)`, with `c = min(columns, n)` and `r = ceil(n / c)`. With no panels the
/// sheet is an empty `GAP x GAP` square.
pub fn contact_sheet(panels: &[(String, RgbaImage)], columns: u32) -> RgbaImage {
    if panels.is_empty() {
        return RgbaImage::from_pixel(GAP, GAP, BACKGROUND);
    }
    let n = u32::try_from(panels.len()).unwrap_or(u32::MAX);
    let cols = columns.clamp(1, n);
    let rows = n.div_ceil(cols);
    let widest_word =
        panels.iter().flat_map(|(label, _)| label.split(' ')).map(text_width).max().unwrap_or(0);
    let cell_w = panels.iter().map(|(_, p)| p.width()).max().unwrap_or(0).max(widest_word);
    let cell_h = panels.iter().map(|(_, p)| p.height()).max().unwrap_or(0);
    let labels: Vec<Vec<String>> = panels.iter().map(|(label, _)| wrap(label, cell_w)).collect();
    let lines = labels.iter().map(Vec::len).max().unwrap_or(0).max(1) as u32;
    let line_h = line_height();
    let row_h = cell_h + LABEL_PAD + lines * line_h;
    let width = GAP + cols * (cell_w + GAP);
    let height = GAP + rows * (row_h + GAP);

    let mut sheet = RgbaImage::from_pixel(width, height, BACKGROUND);
    for (i, ((_, panel), label)) in panels.iter().zip(&labels).enumerate() {
        let (col, row) = (i as u32 % cols, i as u32 / cols);
        let cell_x = GAP + col * (cell_w + GAP);
        let cell_y = GAP + row * (row_h + GAP);
        let px = cell_x + (cell_w - panel.width()) / 2;
        image::imageops::replace(&mut sheet, panel, i64::from(px), i64::from(cell_y));
        for (k, line) in label.iter().enumerate() {
            let x = cell_x + cell_w.saturating_sub(text_width(line)) / 2;
            draw_text(&mut sheet, line, x, cell_y + cell_h + LABEL_PAD + k as u32 * line_h);
        }
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
        p.0[0] > 128 && p.0[1] > 128 && p.0[2] > 128
    }

    /// Columns of `sheet` between x0 and x1 that hold text in rows y0..y1.
    fn lit_columns(sheet: &RgbaImage, x0: u32, x1: u32, y0: u32, y1: u32) -> Vec<u32> {
        (x0..x1).filter(|&x| (y0..y1).any(|y| is_light(sheet.get_pixel(x, y)))).collect()
    }

    #[test]
    fn layout_size_and_labels() {
        let panels = vec![
            ("1 spp".to_string(), panel(80, 30, 100)),
            ("16 spp".to_string(), panel(80, 30, 150)),
            ("256 spp".to_string(), panel(20, 10, 200)),
        ];
        let sheet = contact_sheet(&panels, 2);
        let line = line_height();
        assert_eq!(sheet.dimensions(), (8 + 2 * (80 + 8), 8 + 2 * (30 + 4 + line + 8)));
        assert_eq!(sheet.get_pixel(8, 8).0, [100, 50, 0, 255]);
        // The third, narrower panel centred in the second row's first cell.
        let row2 = 8 + 30 + 4 + line + 8;
        assert_eq!(sheet.get_pixel(8 + 30, row2).0, [200, 100, 0, 255]);
        assert_eq!(sheet.get_pixel(8 + 29, row2), &BACKGROUND);
        for cell_x in [8u32, 96] {
            assert!(
                !lit_columns(&sheet, cell_x, cell_x + 80, 42, 42 + line).is_empty(),
                "no label at {cell_x}"
            );
        }
        assert!((0..sheet.height()).all(|y| sheet.get_pixel(92, y) == &BACKGROUND), "drawn into the gap");
    }

    #[test]
    fn every_label_is_whole_at_every_panel_size() {
        // The figures example's labels, on panels from 1 to 512 pixels wide.
        let label = "Fig. 2b: 1 bounce";
        for width in [1u32, 16, 40, 64, 100, 512] {
            let panels = vec![
                (label.to_string(), panel(width, 8, 50)),
                ("Fig. 3c: 16 spp".to_string(), panel(width, 8, 50)),
            ];
            let sheet = contact_sheet(&panels, 2);
            let cell_w = (sheet.width() - GAP) / 2 - GAP;
            let lines = wrap(label, cell_w);
            assert_eq!(lines.join(" "), label, "width {width}: the label lost text");
            assert!(
                lines.iter().all(|l| text_width(l) <= cell_w),
                "width {width}: {lines:?} wider than {cell_w}"
            );
            // The text stays inside its cell: nothing lit in the gap between the two cells.
            let gap_x = GAP + cell_w;
            assert!(lit_columns(&sheet, gap_x, gap_x + GAP, 0, sheet.height()).is_empty(), "width {width}");
        }
        // At the figures' panel size the label is one line, and its last letter is drawn.
        let sheet = contact_sheet(&[(label.to_string(), panel(256, 8, 50))], 1);
        let lit = lit_columns(&sheet, GAP, GAP + 256, 8 + 8 + LABEL_PAD, sheet.height());
        let (first, last) = (lit[0], *lit.last().unwrap());
        assert!(last - first + 2 >= text_width(label) - 2, "drawn {first}..{last} of {}", text_width(label));
    }

    #[test]
    fn glyphs_are_drawn_left_to_right() {
        // 'L': the vertical stroke is on the left, so near the top only the left part is lit.
        let sheet = contact_sheet(&[("L".to_string(), panel(16, 1, 0))], 1);
        let cell_w = sheet.width() - 2 * GAP;
        let x0 = GAP + (cell_w - text_width("L")) / 2;
        let top = GAP + 1 + LABEL_PAD + 5;
        let left_lit = (0..5).any(|dx| is_light(sheet.get_pixel(x0 + dx, top)));
        let right_lit = (7..10).any(|dx| is_light(sheet.get_pixel(x0 + dx, top)));
        assert!(left_lit && !right_lit);
    }

    #[test]
    fn degenerate_inputs_do_not_panic() {
        assert_eq!(contact_sheet(&[], 3).dimensions(), (GAP, GAP));
        let panels = vec![("a".to_string(), panel(10, 10, 9)), ("b".to_string(), panel(10, 10, 9))];
        let one = contact_sheet(&panels, 0).width();
        assert_eq!(contact_sheet(&panels, 9).width(), 2 * one - GAP);
        let _ = contact_sheet(&[(String::new(), panel(0, 0, 0)), ("  x  ".into(), panel(1, 1, 1))], 2);
        let _ = contact_sheet(&[("\u{1F600} \u{0} \t".into(), panel(3, 3, 3))], 1);
    }
}
