//! Log-log line plots with plotters (text in DejaVu Sans, embedded, so no system fonts are needed).

use std::path::Path;

use plotters::prelude::*;

/// One line: a label and its (x, y) points (x, y > 0).
pub struct Line {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    pub style: Style,
}

/// How a [`Line`] is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    /// Points joined by a line, in a colour of its own.
    Joined,
    /// Crosses, not joined, in a colour of their own (single measurements).
    Markers,
    /// Crosses in the previous line's colour (estimates of that line's values).
    MarkersOfPrevious,
}

const COLOURS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular())
            .unwrap_or_else(|_| panic!("the embedded DejaVu Sans font is valid"));
    });
}

/// A short tick label: "1", "20", "0.5", "1e-4", at most 2 significant digits, no trailing
/// zeros, so that neighbouring labels on a log axis do not run into each other.
pub fn tick_label(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let magnitude = v.abs().log10().floor() as i32;
    if (-2..=4).contains(&magnitude) {
        // Round to 2 significant digits, then print without padding.
        let scale = 10f64.powi(1 - magnitude);
        let rounded = (v * scale).round() / scale;
        let decimals = (1 - magnitude).max(0) as usize;
        let text = format!("{rounded:.decimals$}");
        if text.contains('.') { text.trim_end_matches('0').trim_end_matches('.').to_owned() } else { text }
    } else {
        let text = format!("{v:.1e}");
        text.replace(".0e", "e")
    }
}

/// Writes a log-log plot to `path` (PNG). Lines of markers share the colour of the solid line
/// drawn just before them.
pub fn log_log(path: &Path, title: &str, x_label: &str, y_label: &str, lines: &[Line]) -> anyhow::Result<()> {
    register_font();
    let plottable = |(x, y): &(f64, f64)| x.is_finite() && y.is_finite() && *x > 0.0 && *y > 0.0;
    let points = lines.iter().flat_map(|l| l.points.iter()).filter(|p| plottable(p));
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in points {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    anyhow::ensure!(x0 < x1 && y0 < y1, "{title}: nothing to plot");
    // Written to a temporary name and renamed, like every other output.
    let temporary = path.with_extension("partial.png");
    {
        let root = BitMapBackend::new(&temporary, (900, 600)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d((x0 / 1.2..x1 * 1.2).log_scale(), (y0 / 1.5..y1 * 1.5).log_scale())?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .label_style(("sans-serif", 14))
            .x_labels(8)
            .y_labels(8)
            .x_label_formatter(&|x| tick_label(*x))
            .y_label_formatter(&|y| tick_label(*y))
            .draw()?;
        let mut colour_index = 0;
        for (i, line) in lines.iter().enumerate() {
            if line.style != Style::MarkersOfPrevious && i > 0 {
                colour_index += 1;
            }
            let colour = COLOURS[colour_index % COLOURS.len()];
            let pts: Vec<(f64, f64)> = line.points.iter().copied().filter(|p| plottable(p)).collect();
            if line.style != Style::Joined {
                chart
                    .draw_series(pts.iter().map(|&p| Cross::new(p, 5, colour.stroke_width(2))))?
                    .label(line.label.clone())
                    .legend(move |(x, y)| Cross::new((x + 10, y), 5, colour.stroke_width(2)));
            } else {
                chart
                    .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))?
                    .label(line.label.clone())
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
                    });
                chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, colour.filled())))?;
            }
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .position(SeriesLabelPosition::LowerLeft)
            .draw()?;
        root.present()?;
    }
    std::fs::rename(&temporary, path)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::tick_label;

    #[test]
    fn tick_labels_are_short() {
        let cases = [
            (1.0, "1"),
            (9.0, "9"),
            (10.0, "10"),
            (1000.0, "1000"),
            (0.5, "0.5"),
            (0.03, "0.03"),
            (2.5e-4, "2.5e-4"),
            (1e-5, "1e-5"),
            (3e6, "3e6"),
        ];
        for (v, want) in cases {
            assert_eq!(tick_label(v), want, "{v}");
        }
    }
}
