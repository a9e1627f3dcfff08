//! Figures: log-log line charts (PNG and SVG) and image panels (PNG).
//!
//! plotters' ab_glyph text backend cannot look up system fonts, so DejaVu Sans is registered
//! once before anything is drawn; without it PNG text fails at run time with FontUnavailable.

pub mod colormap;
pub mod panels;

use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

pub const FONT: &str = "sans-serif";

pub fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular())
            .unwrap_or_else(|_| panic!("bundled DejaVu Sans is a valid font"));
    });
}

/// Colour of the i-th series: Tableau 20, readable on white and for common colour
/// blindness: the ten strong colours first, then their light companions in the same order
/// (a sampler figure has 15 series: strategies x samplers).
pub fn series_colour(i: usize) -> RGBColor {
    const C: [(u8, u8, u8); 20] = [
        (31, 119, 180),
        (255, 127, 14),
        (44, 160, 44),
        (214, 39, 40),
        (148, 103, 189),
        (140, 86, 75),
        (227, 119, 194),
        (127, 127, 127),
        (188, 189, 34),
        (23, 190, 207),
        (174, 199, 232),
        (255, 187, 120),
        (152, 223, 138),
        (255, 152, 150),
        (197, 176, 213),
        (196, 156, 148),
        (247, 182, 210),
        (199, 199, 199),
        (219, 219, 141),
        (158, 218, 229),
    ];
    let (r, g, b) = C[i % C.len()];
    RGBColor(r, g, b)
}

/// One line: points (x, y) and, per point, the spread (low, high) drawn as a bar.
#[derive(Clone, Debug, Default)]
pub struct Line {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    pub spread: Vec<(f64, f64)>,
    /// Palette index ([`series_colour`]); None: the line's own index.
    pub colour: Option<usize>,
}

#[derive(Clone, Debug, Default)]
pub struct LogLogChart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub lines: Vec<Line>,
    /// A dashed horizontal line, e.g. the reference's noise floor.
    pub hline: Option<(f64, String)>,
}

/// Padded range over positive finite values (log axes cannot show the rest).
fn log_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !lo.is_finite() {
        return (0.1, 10.0);
    }
    let (lo, hi) = if hi / lo < 10.0 {
        let mid = (lo * hi).sqrt();
        (mid / 3.2, mid * 3.2)
    } else {
        (lo, hi)
    };
    (lo / 1.5, hi * 1.5)
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, c: &LogLogChart) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(e)?;
    let xs = log_range(c.lines.iter().flat_map(|l| l.points.iter().map(|p| p.0)));
    let ys = log_range(
        c.lines
            .iter()
            .flat_map(|l| {
                l.points
                    .iter()
                    .map(|p| p.1)
                    .chain(l.spread.iter().flat_map(|s| [s.0, s.1]))
            })
            .chain(c.hline.iter().map(|h| h.0)),
    );
    let mut chart = ChartBuilder::on(&root)
        .caption(&c.title, (FONT, 20))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(75)
        .build_cartesian_2d((xs.0..xs.1).log_scale(), (ys.0..ys.1).log_scale())
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(&c.x_label)
        .y_desc(&c.y_label)
        .label_style((FONT, 13))
        .light_line_style(RGBColor(240, 240, 240))
        .bold_line_style(RGBColor(200, 200, 200))
        .axis_desc_style((FONT, 15))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .x_label_formatter(&|v| format!("{v}"))
        .draw()
        .map_err(e)?;
    for (i, l) in c.lines.iter().enumerate() {
        let col = series_colour(l.colour.unwrap_or(i));
        let pts: Vec<(f64, f64)> = l.points.iter().cloned().filter(|p| p.1 > 0.0).collect();
        chart
            .draw_series(LineSeries::new(pts.clone(), col.stroke_width(2)))
            .map_err(e)?
            .label(&l.label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2)));
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 3, col.filled())))
            .map_err(e)?;
        let bars = l
            .points
            .iter()
            .zip(&l.spread)
            .filter(|(_, s)| s.0 > 0.0 && s.1 > 0.0)
            .map(|(p, s)| PathElement::new(vec![(p.0, s.0), (p.0, s.1)], col.stroke_width(1)));
        chart.draw_series(bars).map_err(e)?;
    }
    if let Some((y, label)) = &c.hline {
        let grey = RGBColor(90, 90, 90);
        // Dashes by hand: short segments evenly spaced in log x.
        let n = 40;
        let (lx0, lx1) = (xs.0.ln(), xs.1.ln());
        let segs = (0..n).step_by(2).map(|k| {
            let a = (lx0 + (lx1 - lx0) * k as f64 / n as f64).exp();
            let b = (lx0 + (lx1 - lx0) * (k + 1) as f64 / n as f64).exp();
            PathElement::new(vec![(a, *y), (b, *y)], grey.stroke_width(1))
        });
        chart
            .draw_series(segs)
            .map_err(e)?
            .label(label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], grey));
    }
    chart
        .configure_series_labels()
        .label_font((FONT, 13))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::LowerLeft)
        .draw()
        .map_err(e)?;
    root.present().map_err(e)
}

/// Writes `<stem>.png` and `<stem>.svg`.
pub fn write_chart(stem: &Path, c: &LogLogChart) -> Result<(), String> {
    register_font();
    if let Some(d) = stem.parent() {
        std::fs::create_dir_all(d).map_err(|e| format!("{}: {e}", d.display()))?;
    }
    let (w, h) = (760u32, 520u32);
    let png = stem.with_extension("png");
    let mut buf = vec![255u8; (w * h * 3) as usize];
    draw(
        BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area(),
        c,
    )
    .map_err(|m| format!("{}: {m}", png.display()))?;
    crate::film::write_png_rgb8(&png, w, h, &buf)?;
    let svg = stem.with_extension("svg");
    let mut text = String::new();
    draw(
        SVGBackend::with_string(&mut text, (w, h)).into_drawing_area(),
        c,
    )
    .map_err(|m| format!("{}: {m}", svg.display()))?;
    crate::output::write_atomic(&svg, |tmp| {
        std::fs::write(tmp, &text).map_err(|e| format!("{}: {e}", svg.display()))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Twenty series get twenty different colours (fig4 draws 15).
    #[test]
    fn twenty_series_colours_differ() {
        let cs: std::collections::HashSet<_> = (0..20)
            .map(|i| {
                let c = series_colour(i);
                (c.0, c.1, c.2)
            })
            .collect();
        assert_eq!(cs.len(), 20);
    }

    #[test]
    fn chart_writes_png_with_text_and_svg() {
        let dir = std::env::temp_dir().join(format!("directlab-plot-{}", std::process::id()));
        let c = LogLogChart {
            title: "error vs spp".into(),
            x_label: "spp".into(),
            y_label: "relMSE".into(),
            lines: vec![Line {
                label: "light (slope -1.00)".into(),
                points: vec![(1.0, 1.0), (4.0, 0.25), (16.0, 0.0625)],
                spread: vec![(0.8, 1.2), (0.2, 0.3), (0.05, 0.07)],
                colour: None,
            }],
            hline: Some((0.01, "reference noise".into())),
        };
        write_chart(&dir.join("conv"), &c).unwrap();
        let svg = std::fs::read_to_string(dir.join("conv.svg")).unwrap();
        assert!(svg.contains("light (slope -1.00)"));
        let png = image::open(dir.join("conv.png")).unwrap().to_rgb8();
        assert_eq!(png.dimensions(), (760, 520));
        // Text and lines make some pixels dark; a failed font would have errored above.
        assert!(png.pixels().filter(|p| p.0[0] < 60).count() > 500);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn log_range_pads_and_survives_empty_input() {
        assert_eq!(log_range(std::iter::empty()), (0.1, 10.0));
        let (lo, hi) = log_range([1.0, 1000.0, -1.0, f64::NAN].into_iter());
        assert!((lo - 1.0 / 1.5).abs() < 1e-12 && (hi - 1500.0).abs() < 1e-9);
    }
}
