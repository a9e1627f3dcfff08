//! Convergence charts: error against spp, against time and against counted cost, and
//! efficiency.

use super::Figure;
use crate::experiment::analysis::{metric_label, metric_name, metric_short, series, Point, Series};
use crate::experiment::costs::Costs;
use crate::experiment::results::Row;
use crate::experiment::runner::Outcome;
use crate::experiment::schema::ErrorMetric;
use crate::plot::{write_chart, Line, LogLogChart};

/// The charts of `o`; the error-vs-cost chart where its runs have a cost model (`costs`).
pub fn charts(o: &Outcome, costs: Option<&Costs>) -> Result<(Vec<Series>, Vec<Figure>), String> {
    let m = o.exp.exp.metrics.primary;
    let eps = o.exp.exp.metrics.relmse_epsilon;
    let what = metric_name(m, eps);
    let ss = series(&o.rows, &o.strategies, m);
    let floor = match m {
        ErrorMetric::Mse => o.reference.info.mse_floor,
        _ => o.reference.info.relmse_floor,
    };
    let line = |s: &Series, f: &dyn Fn(&Point) -> (f64, f64)| Line {
        label: match s.slope {
            Some(k) => format!("{} (slope {k:.2})", s.name),
            None => s.name.clone(),
        },
        points: s.points.iter().map(f).collect(),
        spread: s.points.iter().map(|p| (p.min, p.max)).collect(),
        colour: None,
    };
    let mut figs = Vec::new();
    let mut chart = |file: &str, c: LogLogChart, caption: String| -> Result<(), String> {
        write_chart(&o.dir.join(file), &c)?;
        figs.push(Figure {
            file: format!("{file}.png"),
            caption: format!("{caption} ([SVG]({file}.svg))"),
        });
        Ok(())
    };
    chart(
        "convergence",
        LogLogChart {
            title: format!("{what} vs samples per pixel"),
            x_label: "samples per pixel".into(),
            y_label: what.clone(),
            lines: ss
                .iter()
                .map(|s| line(s, &|p| (p.spp as f64, p.error)))
                .collect(),
            hline: Some((floor, "reference noise floor".into())),
        },
        format!(
            "{what} (corrected for the reference noise) against spp, mean over {} seeds; bars span \
             the seeds' minimum to maximum; slopes are least-squares fits in log-log, from points \
             clear of the noise floor (a 1/N estimator has slope -1).",
            o.exp.exp.seeds
        ),
    )?;
    chart(
        "error_vs_time",
        LogLogChart {
            title: format!("{what} vs render time"),
            x_label: "render seconds".into(),
            y_label: what.clone(),
            lines: ss
                .iter()
                .map(|s| line(s, &|p| (p.seconds, p.error)))
                .collect(),
            hline: Some((floor, "reference noise floor".into())),
        },
        "Error against render time (the same runs): lower-left is better.".into(),
    )?;
    if let Some(costs) = costs {
        // Each point at its runs' mean modelled seconds; a point without a model value
        // (rows from before counts were recorded) is left out with its bar.
        let costed = |s: &Series| -> Line {
            let at: Vec<(&Point, f64)> = s
                .points
                .iter()
                .filter_map(|p| {
                    let pick = |r: &Row| r.is_sweep() && r.strategy == s.label && r.spp == p.spp;
                    Some((p, costs.mean(&o.rows, pick)?))
                })
                .collect();
            Line {
                points: at.iter().map(|(p, x)| (*x, p.error)).collect(),
                spread: at.iter().map(|(p, _)| (p.min, p.max)).collect(),
                ..line(s, &|p| (p.seconds, p.error))
            }
        };
        chart(
            "error_vs_cost",
            LogLogChart {
                title: format!("{what} vs counted cost"),
                x_label: "modelled seconds (counted rays and evaluations)".into(),
                y_label: what.clone(),
                lines: ss.iter().map(costed).collect(),
                hline: Some((floor, "reference noise floor".into())),
            },
            format!(
                "Error against counted cost (the same runs): each run's rays and evaluations \
                 weighed by the cost per unit fitted on this experiment's {} runs \
                 (see Counted cost), so two estimators compare by the work they do rather than \
                 by how fast their code or sampler happens to run.",
                costs.model.runs
            ),
        )?;
    }
    let eff: Vec<Line> = ss
        .iter()
        .map(|s| Line {
            label: s.name.clone(),
            points: s
                .points
                .iter()
                .map(|p| (p.spp as f64, p.efficiency()))
                .collect(),
            spread: vec![],
            colour: None,
        })
        .collect();
    chart(
        "efficiency",
        LogLogChart {
            title: "efficiency 1 / (error x time)".into(),
            x_label: "samples per pixel".into(),
            y_label: format!("1 / ({what} x seconds)"),
            lines: eff,
            hline: None,
        },
        "Efficiency 1/(error x time) against spp: higher is better; flat for a 1/N estimator \
         whose cost grows linearly with spp."
            .into(),
    )?;
    let x = &o.exp.exp;
    for &m in &x.metrics.report {
        let what = metric_label(
            m,
            x.metrics.relmse_epsilon,
            x.metrics.mape_epsilon,
            x.figures.exposure.unwrap_or(1.0),
        );
        let ms = series(&o.rows, &o.strategies, m);
        if ms.iter().all(|s| s.points.iter().all(|p| !(p.error > 0.0))) {
            continue;
        }
        chart(
            &format!("convergence-{}", m.slug()),
            LogLogChart {
                title: format!("{} vs samples per pixel", metric_short(m)),
                x_label: "samples per pixel".into(),
                y_label: what.clone(),
                lines: ms
                    .iter()
                    .map(|s| line(s, &|p| (p.spp as f64, p.error)))
                    .collect(),
                hline: None,
            },
            format!(
                "{what} against spp, mean over the seeds (raw: not corrected for the \
                 reference's noise); slopes fitted as above."
            ),
        )?;
    }
    Ok((ss, figs))
}
