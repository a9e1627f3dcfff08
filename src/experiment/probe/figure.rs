//! The probe report's figure: error against spp per strategy, one panel per case named in
//! `figures.panels`. A strategy keeps its colour across panels.

use super::ProbeOutcome;
use crate::experiment::analysis::{metric_short, series, Series};
use crate::experiment::results::Row;
use crate::plot::{register_font, series_colour, FONT};
use plotters::prelude::*;

pub const FILE: &str = "convergence.png";

/// The panels' series, in `figures.panels` order.
pub(crate) fn panel_series(o: &ProbeOutcome) -> Vec<(String, Vec<Series>)> {
    let m = o.exp.exp.metrics.primary;
    o.exp
        .exp
        .figures
        .panels
        .iter()
        .filter_map(|name| {
            let c = o.cases.iter().find(|c| &c.case.name == name)?;
            let rows: Vec<Row> = o.rows.iter().filter(|r| &r.case == name).cloned().collect();
            let order: Vec<(String, String)> =
                c.kept.iter().map(|(n, s)| (s.label(), n.clone())).collect();
            Some((name.clone(), series(&rows, &order, m)))
        })
        .collect()
}

/// Writes the figure; `None` when the experiment names no panels.
pub(crate) fn write(o: &ProbeOutcome) -> Result<Option<String>, String> {
    let panels = panel_series(o);
    if panels.is_empty() {
        return Ok(None);
    }
    register_font();
    let path = o.dir.join(FILE);
    let e = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    let cols = panels.len().min(3);
    let rows = panels.len().div_ceil(cols);
    let size = (500 * cols as u32, 450 * rows as u32);
    let metric = metric_short(o.exp.exp.metrics.primary);
    let colour_of = |name: &str| {
        let i = o.exp.exp.strategies.iter().position(|s| s.name == name);
        series_colour(i.unwrap_or(0))
    };
    let mut buf = vec![255u8; (size.0 * size.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, size).into_drawing_area();
        root.fill(&WHITE).map_err(|x| e(&x))?;
        for (area, (name, ss)) in root.split_evenly((rows, cols)).iter().zip(&panels) {
            let pts = ss.iter().flat_map(|s| s.points.iter());
            let (mut lo, mut hi, mut xmax) = (f64::INFINITY, 0.0f64, 2.0f64);
            for p in pts.filter(|p| p.error > 0.0 && p.error.is_finite()) {
                lo = lo.min(p.error);
                hi = hi.max(p.error);
                xmax = xmax.max(p.spp as f64);
            }
            if !(hi > 0.0) {
                continue;
            }
            let mut chart = ChartBuilder::on(area)
                .caption(name, (FONT, 20))
                .margin(10)
                .x_label_area_size(35)
                .y_label_area_size(60)
                .build_cartesian_2d((1f64..xmax).log_scale(), (lo * 0.5..hi * 2.0).log_scale())
                .map_err(|x| e(&x))?;
            chart
                .configure_mesh()
                .x_desc("spp")
                .y_desc(metric)
                .x_label_formatter(&|x| format!("{x:.0}"))
                .y_label_formatter(&|y| format!("{y:.0e}"))
                .label_style((FONT, 12))
                .draw()
                .map_err(|x| e(&x))?;
            for s in ss {
                let c = colour_of(&s.name);
                let data: Vec<(f64, f64)> = s
                    .points
                    .iter()
                    .filter(|p| p.error > 0.0)
                    .map(|p| (p.spp as f64, p.error))
                    .collect();
                let slope = s.slope.map_or(String::new(), |v| format!(" ({v:.2})"));
                chart
                    .draw_series(LineSeries::new(data, c.stroke_width(2)))
                    .map_err(|x| e(&x))?
                    .label(format!("{}{slope}", s.name))
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
        root.present().map_err(|x| e(&x))?;
    }
    crate::film::write_png_rgb8(&path, size.0, size.1, &buf)?;
    Ok(Some(FILE.to_string()))
}
