//! The report's figure: relMSE against spp per strategy, for the stiffest cases.

use super::Row;
use crate::plot::{register_font, series_colour, FONT};
use plotters::prelude::*;
use std::path::Path;

/// The cases drawn, one panel each.
pub const PANELS: [&str; 6] = [
    "tiny-and-huge",
    "light-edge-on",
    "gap-1e-6-edge",
    "alpha-1e-3-small-light",
    "alpha-1-small-light",
    "4096-emitters",
];

pub fn write(path: &Path, rows: &[Row]) -> Result<(), String> {
    register_font();
    let e = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    let root = BitMapBackend::new(path, (1500, 900)).into_drawing_area();
    root.fill(&WHITE).map_err(|x| e(&x))?;
    for (panel, name) in root.split_evenly((2, 3)).iter().zip(PANELS) {
        let series: Vec<&Row> = rows.iter().filter(|r| r.case == name).collect();
        let pts = series
            .iter()
            .flat_map(|r| r.m.curve.iter())
            .filter(|p| p.1 > 0.0 && p.1.is_finite());
        let (mut lo, mut hi, mut xmax) = (f64::INFINITY, 0.0f64, 2.0f64);
        for &(x, y) in pts {
            lo = lo.min(y);
            hi = hi.max(y);
            xmax = xmax.max(x as f64);
        }
        if !(hi > 0.0) {
            continue;
        }
        let mut chart = ChartBuilder::on(panel)
            .caption(name, (FONT, 20))
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(60)
            .build_cartesian_2d((1f64..xmax).log_scale(), (lo * 0.5..hi * 2.0).log_scale())
            .map_err(|x| e(&x))?;
        chart
            .configure_mesh()
            .x_desc("spp")
            .y_desc("relMSE")
            .x_label_formatter(&|x| format!("{x:.0}"))
            .y_label_formatter(&|y| format!("{y:.0e}"))
            .label_style((FONT, 12))
            .draw()
            .map_err(|x| e(&x))?;
        for (i, r) in series.iter().enumerate() {
            let c = series_colour(i);
            let data: Vec<(f64, f64)> =
                r.m.curve
                    .iter()
                    .filter(|p| p.1 > 0.0)
                    .map(|&(x, y)| (x as f64, y))
                    .collect();
            chart
                .draw_series(LineSeries::new(data, c.stroke_width(2)))
                .map_err(|x| e(&x))?
                .label(r.strategy.label())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 15, y)], c));
        }
        chart
            .configure_series_labels()
            .label_font((FONT, 10))
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::LowerLeft)
            .draw()
            .map_err(|x| e(&x))?;
    }
    root.present().map_err(|x| e(&x))
}
