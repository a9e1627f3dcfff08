//! Per-pixel variance and efficiency maps, and the most efficient strategy per pixel.

use super::{map_panel, Figure, PANEL};
use crate::experiment::plan::{image_path, load_image, spp_tag};
use crate::experiment::results::Results;
use crate::experiment::runner::Outcome;
use crate::plot::colormap::LogScale;
use crate::plot::panels::{colour_bar, write_figure, Panel};

/// Per-pixel variance and efficiency maps per strategy, and which strategy is most efficient
/// where.
pub(super) fn variance_maps(o: &Outcome, spp: u32) -> Result<Option<Figure>, String> {
    let tag = spp_tag(spp);
    let eps = o.exp.exp.metrics.relmse_epsilon;
    let res = Results {
        rows: o.rows.clone(),
        dropped: 0,
    };
    let reference = &o.reference.mean;
    let mut vars = Vec::new();
    let mut effs = Vec::new();
    let mut names = Vec::new();
    for (label, name) in &o.strategies {
        let Some(row) = res.find_sweep(label, spp, 0) else {
            continue;
        };
        let (_, var) = load_image(&image_path(&o.dir, label, &tag, 0))?;
        // Variance of one sample (spp x variance of the mean, mean over RGB) shows the
        // estimator itself. Efficiency is relative, as relMSE is: 1 / (variance of the mean /
        // (r^2 + eps) x seconds), so pixels whose value is near zero do not get an absurd
        // efficiency from a near-zero variance.
        let v: Vec<f64> = var
            .data
            .iter()
            .map(|p| (p[0] + p[1] + p[2]) / 3.0)
            .collect();
        let mean = v.iter().sum::<f64>() / v.len().max(1) as f64;
        let rel: Vec<f64> = var
            .data
            .iter()
            .zip(&reference.data)
            .map(|(p, r)| (0..3).map(|c| p[c] / (r[c] * r[c] + eps)).sum::<f64>() / 3.0)
            .collect();
        vars.push(v.iter().map(|x| x * spp as f64).collect::<Vec<f64>>());
        effs.push(
            rel.iter()
                .zip(&v)
                // Rounding-level variances (every sample equal) say nothing about efficiency.
                .map(|(r, x)| {
                    if *x > 1e-10 * mean {
                        1.0 / (r * row.seconds)
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
    let mut r2 = vec![colour_bar("rel. efficiency", &es)];
    for ((n, v), e) in names.iter().zip(&vars).zip(&effs) {
        r1.push(map_panel(v, o.width, o.height, &vs, n).fit(PANEL));
        r2.push(map_panel(e, o.width, o.height, &es, n).fit(PANEL));
    }
    let mut r3 = vec![winner_panel(&effs, o.width, o.height).fit(PANEL)];
    for (i, n) in names.iter().enumerate() {
        let c = crate::plot::series_colour(i);
        r3.push(Panel::new(
            n.clone(),
            90,
            14,
            [c.0, c.1, c.2].repeat(90 * 14),
        ));
    }
    let file = "variance.png";
    write_figure(
        &o.dir.join(file),
        &format!("Per-pixel variance and efficiency at {spp} spp (seed 0)"),
        &[r1, r2, r3],
    )?;
    Ok(Some(Figure {
        file: file.into(),
        caption: format!(
            "Top: per-pixel variance of one sample (mean over RGB), log scale shared by all \
             strategies (yellow is noisier). Middle: per-pixel relative efficiency 1/(variance \
             of the pixel mean / (r^2 + {eps}) x render seconds) at {spp} spp (yellow wins). \
             Bottom: the most efficient strategy per pixel, coloured as in the plots (grey: no \
             strategy has a measurable variance there). Pixels with zero variance are at the \
             bottom of the scales. Per-pixel variances estimated from few samples are noisy, \
             and for rare-event pixels (no hit yet) too low."
        ),
    }))
}

/// The index of the most efficient strategy per pixel, in the plot colours.
fn winner_panel(effs: &[Vec<f64>], w: u32, h: u32) -> Panel {
    let rgb = (0..(w * h) as usize)
        .flat_map(|i| {
            let best = (0..effs.len())
                .filter(|&k| effs[k][i] > 0.0)
                .max_by(|&a, &b| effs[a][i].total_cmp(&effs[b][i]));
            match best {
                Some(k) => {
                    let c = crate::plot::series_colour(k);
                    [c.0, c.1, c.2]
                }
                None => [200, 200, 200],
            }
        })
        .collect();
    Panel::new("most efficient", w, h, rgb)
}
