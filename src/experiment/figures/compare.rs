//! Image comparisons: reference and strategies side by side with error maps and crops, and
//! the spp progression with error numbers.

use super::{map_panel, panel_of, short, Figure, CROP_COLOURS, PANEL};
use crate::experiment::analysis::{error_of, metric_name, metric_short};
use crate::experiment::plan::{image_path, load_image, spp_tag};
use crate::experiment::results::{Results, Row};
use crate::experiment::runner::Outcome;
use crate::film::Image;
use crate::plot::colormap::LogScale;
use crate::plot::panels::{colour_bar, write_figure, Panel};

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
pub(super) fn comparison(
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

/// Rows of images at increasing spp, each with its error, ending with the reference.
pub(super) fn progression(o: &Outcome) -> Result<Option<Figure>, String> {
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
