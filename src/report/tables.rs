//! Report tables: error per spp, the reading of each curve, equal-time runs, image-mean
//! variance.

use super::e;
use crate::cost::per_camera_sample;
use crate::experiment::analysis::{
    error_of, metric_label, metric_name, metric_short, predicted_of, Series,
};
use crate::experiment::costs::Costs;
use crate::experiment::results::{Row, EQUAL_TIME};
use crate::experiment::runner::Outcome;
use crate::experiment::schema::ErrorMetric;
use std::fmt::Write;

pub(super) fn error_table(md: &mut String, o: &Outcome, series: &[Series]) {
    let x = &o.exp.exp;
    let what = metric_name(x.metrics.primary, x.metrics.relmse_epsilon);
    let _ = writeln!(md, "## Error per spp\n\n{what}, mean over seeds (corrected for the reference noise; * marks runs within 2x of the floor).\n");
    let mut head = "| strategy | label | slope |".to_string();
    let mut rule = "|---|---|---|".to_string();
    for spp in &x.spp {
        let _ = write!(head, " {spp} spp |");
        rule.push_str("---|");
    }
    let _ = writeln!(md, "{head} samples/s |\n{rule}---|");
    for s in series {
        let mut line = format!(
            "| {} | `{}` | {} |",
            s.name,
            s.label,
            s.slope.map_or("-".into(), |k| format!("{k:.2}"))
        );
        for spp in &x.spp {
            match s.points.iter().find(|p| p.spp == *spp) {
                Some(p) => {
                    let _ = write!(
                        line,
                        " {}{} |",
                        e(p.error),
                        if p.near_floor { "*" } else { "" }
                    );
                }
                None => line.push_str(" - |"),
            }
        }
        let (n, t) = o
            .rows
            .iter()
            .filter(|r| r.is_sweep() && r.strategy == s.label)
            .fold((0.0, 0.0), |(n, t), r| {
                (n + r.samples_per_s * r.seconds, t + r.seconds)
            });
        let _ = writeln!(line, " {:.2e} |", if t > 0.0 { n / t } else { 0.0 });
        md.push_str(&line);
    }
    md.push('\n');
}

/// The metrics beside the primary one at the figures' comparison spp, mean over seeds: one
/// column each, named with its epsilon and tone mapping in the caption.
pub(super) fn metrics_table(md: &mut String, o: &Outcome) {
    let x = &o.exp.exp;
    let spp = o.exp.equal_spp();
    let (metrics, table) = metric_means(o);
    let (eps, meps, exposure) = (
        x.metrics.relmse_epsilon,
        x.metrics.mape_epsilon,
        x.figures.exposure.unwrap_or(1.0),
    );
    let _ = writeln!(
        md,
        "## Metrics at {spp} spp\n\nMean over seeds, raw (not corrected for the reference noise); \
         every value per run and metric is in `metrics.csv`. {}.\n",
        metrics
            .iter()
            .map(|&m| metric_label(m, eps, meps, exposure))
            .collect::<Vec<_>>()
            .join("; ")
    );
    let mut head = "| strategy |".to_string();
    let mut rule = "|---|".to_string();
    for m in &metrics {
        let _ = write!(head, " {} |", metric_short(*m));
        rule.push_str("---|");
    }
    let _ = writeln!(md, "{head}\n{rule}");
    for (name, values) in table {
        let mut line = format!("| {name} |");
        for v in values {
            let _ = write!(line, " {} |", e(v));
        }
        let _ = writeln!(md, "{line}");
    }
    md.push('\n');
}

/// The raw value of metric `m` in row `r` (MSE and relMSE as measured).
pub(crate) fn raw_metric(r: &Row, m: ErrorMetric) -> f64 {
    match m {
        ErrorMetric::Mse => r.mse,
        ErrorMetric::Relmse => r.relmse,
        _ => error_of(r, m),
    }
}

/// The experiment's metrics (MSE, relMSE, then `report`) and, per strategy with runs at the
/// comparison spp, each one's mean over seeds.
pub(crate) fn metric_means(o: &Outcome) -> (Vec<ErrorMetric>, Vec<(String, Vec<f64>)>) {
    let spp = o.exp.equal_spp();
    let mut metrics = vec![ErrorMetric::Mse, ErrorMetric::Relmse];
    metrics.extend(o.exp.exp.metrics.report.iter().copied());
    let mut table = Vec::new();
    for (label, name) in &o.strategies {
        let rows: Vec<&Row> = o
            .rows
            .iter()
            .filter(|r| r.is_sweep() && &r.strategy == label && r.spp == spp)
            .collect();
        if rows.is_empty() {
            continue;
        }
        let means = metrics
            .iter()
            .map(|&m| rows.iter().map(|r| raw_metric(r, m)).sum::<f64>() / rows.len() as f64)
            .collect();
        table.push((name.clone(), means));
    }
    (metrics, table)
}

/// Convergence rates: each curve's slope with its bootstrap interval over seeds, and the
/// local slopes between consecutive spp, with why the errors are taken across seeds.
pub(super) fn rate_table(md: &mut String, o: &Outcome, series: &[Series]) {
    let seeds = o.exp.exp.seeds;
    let _ = writeln!(
        md,
        "## Convergence rates\n\nEach error is the mean over {seeds} seeds of one seed's error against the \
         reference: every seed is an independent randomisation of the sampler, so this holds for \
         correlated samples (stratified, Sobol') as well as independent ones. The error a run's own \
         per-pixel variance predicts assumes independent samples and is wrong for the others: \
         'measured / predicted' below is that diagnostic (about 1 for independent samples, under 1 \
         where a sampler's samples are negatively correlated). Intervals: 95 % percentile bootstrap \
         over seeds ({} draws; a seed is resampled with all its spp), which needs at least 2 seeds \
         and is only as good as the seeds are many (32 or more for a rate).\n\n\
         | strategy | slope | 95 % interval | local slopes (spp: slope) |\n|---|---|---|---|",
        crate::stats::slope::BOOTSTRAP_DRAWS
    );
    for s in series {
        let local: Vec<String> = s
            .local_slopes()
            .iter()
            .map(|(a, b, k)| format!("{a}→{b}: {k:.2}"))
            .collect();
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} |",
            s.name,
            s.slope.map_or("-".into(), |k| format!("{k:.2}")),
            s.slope_ci
                .map_or("-".into(), |(lo, hi)| format!("[{lo:.2}, {hi:.2}]")),
            if local.is_empty() {
                "-".into()
            } else {
                local.join(", ")
            }
        );
    }
    md.push('\n');
}

/// Reads each curve: does it fall as 1/N, and do run and reference agree pixel by pixel? The
/// verdicts are rules of thumb, stated as such in the report.
pub(super) fn diagnostics(md: &mut String, o: &Outcome, series: &[Series]) {
    let m = o.exp.exp.metrics.primary;
    let mse_series = crate::experiment::analysis::series(&o.rows, &o.strategies, ErrorMetric::Mse);
    let _ = writeln!(md, "## Reading the curves\n\nFor an unbiased estimator with finite variance, N x error is constant, the measured error matches the one the run's own variance images predict (`*_predicted` in the CSV), and the per-pixel z^2 = (x - r)^2 / (var_x + var_r) averages about 1. Rules of thumb used below: mean z^2 and measured / predicted both above 1.5 at the highest spp suggest a **bias** (z^2 alone also rises for rare-event estimators, whose pixels without a hit report zero variance); a slope within 0.15 of -1 is 1/N convergence; a shallow relMSE slope with a 1/N MSE slope means a few pixels dominate relMSE (typically pixels barely covered by an emitter, whose rare samples on the emitter are huge relative to the pixel value); a shallow slope in both means a heavy-tailed estimator whose rare large samples (fireflies) are not yet drawn at low spp, so its error and its variance estimates are both too low there.\n\n| strategy | slope | slope (MSE) | N x error, lowest spp | N x error, highest spp | measured / predicted | mean z^2 | reading |\n|---|---|---|---|---|---|---|---|");
    for (s, sm) in series.iter().zip(&mse_series) {
        let (Some(first), Some(last)) = (s.points.first(), s.points.last()) else {
            continue;
        };
        let rows: Vec<&Row> = o
            .rows
            .iter()
            .filter(|r| r.is_sweep() && r.strategy == s.label && r.spp == last.spp)
            .collect();
        let n = rows.len().max(1) as f64;
        let pred = rows.iter().map(|r| predicted_of(r, m)).sum::<f64>() / n;
        let ratio = if pred > 0.0 {
            last.error / pred
        } else {
            f64::NAN
        };
        let z2 = rows.iter().map(|r| r.mean_z2).sum::<f64>() / n;
        let near = |k: Option<f64>| k.is_some_and(|k| (k + 1.0).abs() <= 0.15);
        let reading = match s.slope {
            // z^2 alone also rises for rare-event estimators (a pixel with no hit yet reports
            // zero variance), so a bias needs the error above its prediction as well.
            _ if z2 > 1.5 && ratio > 1.5 && last.spp >= 16 => {
                "**bias?** error above its variance, pixels beyond their noise".to_string()
            }
            None => "too few points".into(),
            k if near(k) => "converges as 1/N".into(),
            _ if near(sm.slope) => "1/N in MSE; relMSE dominated by a few pixels".into(),
            Some(k) if k > -0.85 => "heavy-tailed: not yet in the 1/N regime".into(),
            Some(_) => "steeper than 1/N (noisy curve)".into(),
        };
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {:.2} | {:.3e} | {reading} |",
            s.name,
            s.slope.map_or("-".into(), |k| format!("{k:.2}")),
            sm.slope.map_or("-".into(), |k| format!("{k:.2}")),
            e(first.error * first.spp as f64),
            e(last.error * last.spp as f64),
            ratio,
            z2
        );
    }
    md.push('\n');
}

pub(super) fn equal_time_table(md: &mut String, o: &Outcome, costs: Option<&Costs>) {
    let rows: Vec<(usize, &Row)> = o
        .rows
        .iter()
        .enumerate()
        .filter(|(_, r)| r.kind == EQUAL_TIME)
        .collect();
    if rows.is_empty() {
        return;
    }
    let m = o.exp.exp.metrics.primary;
    let what = metric_name(m, o.exp.exp.metrics.relmse_epsilon);
    let _ = writeln!(md, "## Equal time\n\nspp chosen from each strategy's measured sample rate; each run's measured seconds, its rays per camera sample and its modelled seconds (Counted cost).\n\n| budget (s) | strategy | seed | spp | seconds | rays per sample | modelled seconds | {what} |\n|---|---|---|---|---|---|---|---|");
    for (i, r) in rows {
        let rays = r.counts().map_or("-".into(), |c| {
            format!("{:.3}", per_camera_sample(&c, c.rays()))
        });
        let modelled = costs
            .and_then(|c| c.modelled[i])
            .map_or("-".into(), |s| format!("{s:.2}"));
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {:.2} | {rays} | {modelled} | {} |",
            r.budget_s,
            r.name,
            r.seed,
            r.spp,
            r.seconds,
            e(error_of(r, m))
        );
    }
    md.push('\n');
}

pub(super) fn variance_table(md: &mut String, o: &Outcome) {
    let spp = o.exp.variance_spp();
    let _ = writeln!(md, "## Variance of the image mean at {spp} spp\n\nFrom the per-pixel variance images (pixels are independent, so Var(image mean) = sum of pixel variances / pixels^2), averaged over seeds; x spp gives the per-sample value, x seconds the cost-weighted value (lower is better).\n\n| strategy | Var R | Var G | Var B | Var G x spp | Var G x seconds |\n|---|---|---|---|---|---|");
    for (label, name) in &o.strategies {
        let rs: Vec<&Row> = o
            .rows
            .iter()
            .filter(|r| r.is_sweep() && &r.strategy == label && r.spp == spp)
            .collect();
        if rs.is_empty() || spp < 2 {
            continue;
        }
        let n = rs.len() as f64;
        let v = [0, 1, 2].map(|c| rs.iter().map(|r| r.mean_var()[c]).sum::<f64>() / n);
        let secs = rs.iter().map(|r| r.seconds).sum::<f64>() / n;
        let _ = writeln!(
            md,
            "| {name} | {} | {} | {} | {} | {} |",
            e(v[0]),
            e(v[1]),
            e(v[2]),
            e(v[1] * spp as f64),
            e(v[1] * secs)
        );
    }
    md.push('\n');
}
