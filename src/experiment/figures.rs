//! The figures of one experiment: convergence charts and image comparisons, written beside
//! its report. Returns what the report lists.

use super::analysis::{error_of, metric_name, metric_short, series, Series};
use super::results::{Results, Row};
use super::runner::{image_path, load_image, spp_tag, time_tag, Outcome};
use crate::film::{to_srgb8, Image};
use crate::plot::colormap::LogScale;
use crate::plot::panels::{colour_bar, write_figure, Panel};
use crate::plot::{write_chart, Line, LogLogChart};

/// A figure file (relative to the experiment folder) with its caption.
pub struct Figure {
    pub file: String,
    pub caption: String,
}

const PANEL: u32 = 320;
const CROP_COLOURS: [[u8; 3]; 4] = [[255, 60, 60], [60, 200, 255], [255, 210, 0], [255, 80, 255]];

fn short(v: f64) -> String {
    format!("{v:.2e}")
}

pub fn charts(o: &Outcome) -> Result<(Vec<Series>, Vec<Figure>), String> {
    let m = o.exp.exp.metrics.primary;
    let eps = o.exp.exp.metrics.relmse_epsilon;
    let what = metric_name(m, eps);
    let ss = series(&o.rows, &o.strategies, m);
    let floor = match m {
        super::schema::ErrorMetric::Mse => o.reference.info.mse_floor,
        super::schema::ErrorMetric::Relmse => o.reference.info.relmse_floor,
    };
    let line = |s: &Series, f: &dyn Fn(&super::analysis::Point) -> (f64, f64)| Line {
        label: match s.slope {
            Some(k) => format!("{} (slope {k:.2})", s.name),
            None => s.name.clone(),
        },
        points: s.points.iter().map(f).collect(),
        spread: s.points.iter().map(|p| (p.min, p.max)).collect(),
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
    Ok((ss, figs))
}

fn panel_of(img: &Image, exposure: f64, title: &str) -> Panel {
    Panel::new(title, img.width, img.height, to_srgb8(img, exposure))
}

fn map_panel(values: &[f64], w: u32, h: u32, s: &LogScale, title: &str) -> Panel {
    let rgb = values.iter().flat_map(|&v| s.colour(v)).collect();
    Panel::new(title, w, h, rgb)
}

/// Per-pixel relMSE: mean over channels of (x - r)^2 / (r^2 + eps).
fn rel_error_map(img: &Image, r: &Image, eps: f64) -> Vec<f64> {
    img.data
        .iter()
        .zip(&r.data)
        .map(|(a, b)| {
            (0..3)
                .map(|c| (a[c] - b[c]).powi(2) / (b[c] * b[c] + eps))
                .sum::<f64>()
                / 3.0
        })
        .collect()
}

/// Crops in pixels: (x, y, w, h).
fn crop_rects(o: &Outcome) -> Vec<(String, u32, u32, u32, u32)> {
    let (w, h) = (o.width as f64, o.height as f64);
    o.exp
        .exp
        .figures
        .crops
        .iter()
        .map(|c| {
            let x = (c.x * w) as u32;
            let y = (c.y * h) as u32;
            let cw = ((c.width * w) as u32).clamp(1, o.width - x);
            let ch = ((c.height * h) as u32).clamp(1, o.height - y);
            (c.name.clone(), x, y, cw, ch)
        })
        .collect()
}

/// Reference and each strategy side by side (with crops marked), their error maps, and the
/// zoomed crops, for the runs picked by `find` (one image per strategy).
fn comparison(
    o: &Outcome,
    file: &str,
    title: &str,
    tag: &str,
    find: &dyn Fn(&str) -> Option<Row>,
) -> Result<Option<Figure>, String> {
    let x = &o.exp.exp;
    let exposure = x.figures.exposure.unwrap_or(1.0);
    let eps = x.metrics.relmse_epsilon;
    let m = x.metrics.primary;
    let what = metric_name(m, eps);
    let mut renders = Vec::new();
    for (label, name) in &o.strategies {
        let Some(row) = find(label) else { continue };
        let (img, _) = load_image(&image_path(&o.dir, label, tag, 0))?;
        renders.push((name.clone(), row, img));
    }
    if renders.is_empty() {
        return Ok(None);
    }
    let crops = crop_rects(o);
    let mark = |mut p: Panel| {
        for (i, (_, x, y, w, h)) in crops.iter().enumerate() {
            p.outline(*x, *y, *w, *h, CROP_COLOURS[i % CROP_COLOURS.len()]);
        }
        p.fit(PANEL)
    };
    let r = &o.reference;
    let mut top =
        vec![mark(panel_of(&r.mean, exposure, "reference")).caption(format!("{} spp", r.info.spp))];
    let maps: Vec<Vec<f64>> = renders
        .iter()
        .map(|(_, _, img)| rel_error_map(img, &r.mean, eps))
        .collect();
    let scale = LogScale::from_values(maps.iter().flatten().cloned());
    let mut second = vec![colour_bar(&format!("per-pixel relMSE (eps {eps})"), &scale)];
    for ((name, row, img), map) in renders.iter().zip(&maps) {
        top.push(mark(panel_of(img, exposure, name)).caption(format!(
            "{} spp, {:.2} s, {} {}",
            row.spp,
            row.seconds,
            metric_short(m),
            short(error_of(row, m))
        )));
        second.push(map_panel(map, o.width, o.height, &scale, name).fit(PANEL));
    }
    let mut rows = vec![top, second];
    for (i, (cname, cx, cy, cw, ch)) in crops.iter().enumerate() {
        // Enlarged to about 160 px tall, but no wider than a panel.
        let k = (160 / ch).min(PANEL / cw).max(1);
        let mut row = vec![panel_of(&r.mean, exposure, "")
            .crop(*cx, *cy, *cw, *ch)
            .enlarge(k)];
        row[0].title = format!("{}. {cname}: reference", i + 1);
        for (name, _, img) in &renders {
            let mut p = panel_of(img, exposure, "")
                .crop(*cx, *cy, *cw, *ch)
                .enlarge(k);
            p.title = name.clone();
            row.push(p);
        }
        rows.push(row);
    }
    write_figure(&o.dir.join(file), &format!("{title} ({what})"), &rows)?;
    Ok(Some(Figure {
        file: file.into(),
        caption: format!(
            "{title}: top, the reference and each strategy (seed 0) with its {what}; middle, \
             per-pixel relMSE on one log colour scale (yellow is worse); below, zoomed crops \
             (outlined in the top row)."
        ),
    }))
}

/// Per-pixel variance and efficiency maps per strategy, from the equal-spp runs.
fn variance_maps(o: &Outcome, spp: u32) -> Result<Option<Figure>, String> {
    let tag = spp_tag(spp);
    let res = Results {
        rows: o.rows.clone(),
        dropped: 0,
    };
    let mut vars = Vec::new();
    let mut effs = Vec::new();
    let mut names = Vec::new();
    for (label, name) in &o.strategies {
        let Some(row) = res.find_sweep(label, spp, 0) else {
            continue;
        };
        let (_, var) = load_image(&image_path(&o.dir, label, &tag, 0))?;
        // Variance of one sample (spp x variance of the mean) shows the estimator itself;
        // efficiency 1 / (variance of the mean x seconds) charges it for its cost.
        let v: Vec<f64> = var
            .data
            .iter()
            .map(|p| (p[0] + p[1] + p[2]) / 3.0)
            .collect();
        vars.push(v.iter().map(|x| x * spp as f64).collect::<Vec<f64>>());
        effs.push(
            v.iter()
                .map(|x| {
                    if *x > 0.0 {
                        1.0 / (x * row.seconds)
                    } else {
                        0.0
                    }
                })
                .collect::<Vec<f64>>(),
        );
        names.push(name.clone());
    }
    if names.is_empty() || spp < 2 {
        return Ok(None);
    }
    let vs = LogScale::from_values(vars.iter().flatten().cloned());
    let es = LogScale::from_values(effs.iter().flatten().cloned());
    let mut r1 = vec![colour_bar("per-sample variance", &vs)];
    let mut r2 = vec![colour_bar("efficiency 1/(var x s)", &es)];
    for ((n, v), e) in names.iter().zip(&vars).zip(&effs) {
        r1.push(map_panel(v, o.width, o.height, &vs, n).fit(PANEL));
        r2.push(map_panel(e, o.width, o.height, &es, n).fit(PANEL));
    }
    let file = "variance.png";
    write_figure(
        &o.dir.join(file),
        &format!("Per-pixel variance and efficiency at {spp} spp"),
        &[r1, r2],
    )?;
    Ok(Some(Figure {
        file: file.into(),
        caption: format!(
            "Top: per-pixel variance of one sample (mean over RGB), log scale shared by all \
             strategies (yellow is noisier). Bottom: per-pixel efficiency 1/(variance of the \
             pixel mean x render seconds) at {spp} spp (yellow wins). Pixels with zero variance \
             (background, or every sample equal) are at the bottom of both scales."
        ),
    }))
}

/// Rows of images at increasing spp, each with its error, ending with the reference.
fn progression(o: &Outcome) -> Result<Option<Figure>, String> {
    let x = &o.exp.exp;
    let spps: Vec<u32> = x
        .figures
        .progression
        .iter()
        .cloned()
        .filter(|s| x.spp.contains(s))
        .collect();
    if spps.is_empty() {
        return Ok(None);
    }
    let exposure = x.figures.exposure.unwrap_or(1.0);
    let m = x.metrics.primary;
    let what = metric_name(m, x.metrics.relmse_epsilon);
    let res = Results {
        rows: o.rows.clone(),
        dropped: 0,
    };
    let target = (1800 / (spps.len() as u32 + 1)).clamp(96, PANEL);
    let mut rows = Vec::new();
    for (label, name) in &o.strategies {
        let mut row = Vec::new();
        for &spp in &spps {
            let Some(r) = res.find_sweep(label, spp, 0) else {
                continue;
            };
            let (img, _) = load_image(&image_path(&o.dir, label, &spp_tag(spp), 0))?;
            row.push(
                panel_of(&img, exposure, &format!("{name}, {spp} spp"))
                    .fit(target)
                    .caption(format!("{} {}", metric_short(m), short(error_of(r, m)))),
            );
        }
        row.push(
            panel_of(&o.reference.mean, exposure, "reference")
                .fit(target)
                .caption(format!("{} spp", o.reference.info.spp)),
        );
        rows.push(row);
    }
    let file = "progression.png";
    write_figure(
        &o.dir.join(file),
        &format!("Convergence to the reference ({what}, seed 0)"),
        &rows,
    )?;
    Ok(Some(Figure {
        file: file.into(),
        caption: format!(
            "Seed-0 renders at increasing spp with their {what} against the reference (right)."
        ),
    }))
}

/// All image figures of an experiment.
pub fn images(o: &Outcome) -> Result<Vec<Figure>, String> {
    let mut figs = Vec::new();
    let res = Results {
        rows: o.rows.clone(),
        dropped: 0,
    };
    let spp = o.exp.equal_spp();
    figs.extend(progression(o)?);
    figs.extend(comparison(
        o,
        "equal_spp.png",
        &format!("Equal samples: {spp} spp"),
        &spp_tag(spp),
        &|label| res.find_sweep(label, spp, 0).cloned(),
    )?);
    if let Some(et) = &o.exp.exp.equal_time {
        for &b in &et.seconds {
            figs.extend(comparison(
                o,
                &format!("equal_time_{b}s.png"),
                &format!("Equal time: {b} s"),
                &time_tag(b),
                &|label| res.find_equal_time(label, b, 0).cloned(),
            )?);
        }
    }
    figs.extend(variance_maps(o, o.exp.variance_spp())?);
    Ok(figs)
}
