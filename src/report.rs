//! Markdown reports: `reports/<experiment>/index.md` (settings, reference and its noise,
//! what was left out and why, tables, figures) and `reports/index.md` linking them all.

use crate::experiment::analysis::{
    error_of, mean_difference, metric_name, pooled_means, predicted_of, MeanDiff, PooledMean,
    Series,
};
use crate::experiment::figures::Figure;
use crate::experiment::results::{Row, EQUAL_TIME};
use crate::experiment::schema::ErrorMetric;
use crate::experiment::Outcome;
use crate::film::write_atomic;
use crate::stats::sidak;
use std::fmt::Write;
use std::path::Path;

/// Family-wise level of the mean check.
pub const MEAN_ALPHA: f64 = 0.01;

const CHANNELS: [&str; 3] = ["R", "G", "B"];

fn e(v: f64) -> String {
    format!("{v:.3e}")
}

/// One comparison of image means: `a - b` per channel.
pub struct Comparison {
    pub a: String,
    pub b: String,
    pub diffs: Vec<MeanDiff>,
}

/// The reference as a pooled mean, its variance from its own variance image.
fn reference_mean(o: &Outcome) -> PooledMean {
    let r = &o.reference;
    let n = r.mean.data.len() as f64;
    let mut var = [0.0; 3];
    for v in &r.variance.data {
        for c in 0..3 {
            var[c] += v[c] / (n * n);
        }
    }
    PooledMean {
        label: "reference".into(),
        name: "reference".into(),
        spp: r.info.spp,
        seeds: 1,
        mean: r.mean.mean_rgb(),
        var,
    }
}

/// Every strategy's image mean against the first strategy's and against the reference's, per
/// channel, Sidak-corrected over all tests at family-wise level `MEAN_ALPHA`.
pub fn mean_check(o: &Outcome) -> (Vec<PooledMean>, Vec<Comparison>, f64) {
    let pm = pooled_means(&o.rows, &o.strategies);
    let reference = reference_mean(o);
    let mut pairs: Vec<(&PooledMean, &PooledMean)> =
        pm.iter().skip(1).map(|b| (b, &pm[0])).collect();
    pairs.extend(pm.iter().map(|a| (a, &reference)));
    let tests = 3 * pairs.len();
    let alpha = if tests > 0 {
        sidak(MEAN_ALPHA, tests)
    } else {
        MEAN_ALPHA
    };
    let comparisons = pairs
        .iter()
        .map(|(a, b)| Comparison {
            a: a.name.clone(),
            b: b.name.clone(),
            diffs: mean_difference(a, b, alpha),
        })
        .collect();
    let mut all = pm;
    all.push(reference);
    (all, comparisons, alpha)
}

/// Lines stating each difference with its 95 % interval, for the terminal and the report.
/// Channels with identical numbers (grey scenes) are stated once.
pub fn mean_check_lines(o: &Outcome) -> Vec<String> {
    let (_, comparisons, alpha) = mean_check(o);
    let mut out = Vec::new();
    for cmp in &comparisons {
        let d = &cmp.diffs;
        let grey = d
            .iter()
            .all(|x| x.diff == d[0].diff && x.half_width_95 == d[0].half_width_95);
        for x in if grey { &d[..1] } else { &d[..] } {
            let ch = if grey { "RGB" } else { CHANNELS[x.channel] };
            out.push(format!(
                "mean({}) - mean({}) [{ch}] = {:+.4e} +- {:.2e} (95% CI), z = {:+.2}: {}",
                cmp.a,
                cmp.b,
                x.diff,
                x.half_width_95,
                x.z,
                if x.consistent {
                    "consistent (same expectation)".to_string()
                } else {
                    format!("DIFFERENT at family-wise alpha {MEAN_ALPHA} (per test {alpha:.1e}): one of them is biased")
                }
            ));
        }
    }
    out
}

fn settings(md: &mut String, o: &Outcome) {
    let x = &o.exp.exp;
    let defines: Vec<String> = o
        .exp
        .defines
        .iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect();
    let _ = writeln!(md, "## Settings\n");
    let _ = writeln!(
        md,
        "- Scene: `{}`{} ({}x{} pixels)",
        o.exp.scene.display(),
        if defines.is_empty() {
            String::new()
        } else {
            format!(" with `-D {}`", defines.join(" -D "))
        },
        o.width,
        o.height
    );
    let _ = writeln!(
        md,
        "- Experiment file: `{}`{}",
        o.exp.file.display(),
        if o.exp.quick { " (`--quick`)" } else { "" }
    );
    let _ = writeln!(md, "- Sweep: spp {:?}, seeds 0..{}", x.spp, x.seeds);
    let _ = writeln!(
        md,
        "- Error: {}; relMSE = mean((x - r)^2 / (r^2 + eps)) with eps = {}; both are corrected \
         for the reference's own noise (below).",
        metric_name(x.metrics.primary, x.metrics.relmse_epsilon),
        x.metrics.relmse_epsilon
    );
    let ri = &o.reference.info;
    let _ = writeln!(
        md,
        "- Reference: `{}` at {} spp, seed {}, {:.1} s to render ({}), {} non-finite samples; \
         cache key `{}`.",
        ri.strategy,
        ri.spp,
        ri.seed,
        ri.seconds,
        if o.reference.cached {
            "from the cache"
        } else {
            "rendered in this run"
        },
        ri.non_finite_samples,
        ri.key
    );
    let near = o.rows.iter().filter(|r| r.near_floor).count();
    let _ = writeln!(
        md,
        "- Reference noise floor: mean per-pixel variance {} (MSE), {} (relMSE). A run's \
         measured MSE estimates its true MSE plus this floor (the two renders are independent), \
         so the floor is subtracted. {}",
        e(ri.mse_floor),
        e(ri.relmse_floor),
        if near == 0 {
            "No run came within 2x of the floor.".to_string()
        } else {
            format!("**Warning:** {near} of {} runs measured an error within 2x of the floor; their corrected errors are unreliable and are left out of the slope fits.", o.rows.len())
        }
    );
    let _ = writeln!(
        md,
        "- This invocation rendered {} runs ({} came from `results.csv`) in {:.1} s.\n",
        o.rendered,
        o.rows.len() - o.rendered.min(o.rows.len()),
        o.seconds
    );
}

fn left_out(md: &mut String, o: &Outcome) {
    let _ = writeln!(md, "## Left out\n");
    if o.omitted.is_empty() {
        let _ = writeln!(
            md,
            "Nothing: every listed strategy is a different estimator on this scene.\n"
        );
        return;
    }
    for om in &o.omitted {
        let _ = writeln!(md, "- **{}** (`{}`): {}", om.name, om.label, om.reason);
    }
    md.push('\n');
}

fn error_table(md: &mut String, o: &Outcome, series: &[Series]) {
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

/// Reads each curve: does it fall as 1/N, and do run and reference agree pixel by pixel? The
/// verdicts are rules of thumb, stated as such in the report.
fn diagnostics(md: &mut String, o: &Outcome, series: &[Series]) {
    let m = o.exp.exp.metrics.primary;
    let mse_series = crate::experiment::analysis::series(&o.rows, &o.strategies, ErrorMetric::Mse);
    let _ = writeln!(md, "## Reading the curves\n\nFor an unbiased estimator with finite variance, N x error is constant, the measured error matches the one the run's own variance images predict (`*_predicted` in the CSV), and the per-pixel z^2 = (x - r)^2 / (var_x + var_r) averages about 1. Rules of thumb used below: mean z^2 and measured / predicted both above 1.5 at the highest spp suggest a **bias** (z^2 alone also rises for rare-event estimators, whose pixels without a hit report zero variance); a slope within 0.15 of -1 is 1/N convergence; a shallow relMSE slope with a 1/N MSE slope means a few high-weight pixels (dark pixels next to emitter edges) dominate relMSE; a shallow slope in both means a heavy-tailed estimator whose rare large samples (fireflies) are not yet drawn at low spp, so its error and its variance estimates are both too low there.\n\n| strategy | slope | slope (MSE) | N x error, lowest spp | N x error, highest spp | measured / predicted | mean z^2 | reading |\n|---|---|---|---|---|---|---|---|");
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
            "| {} | {} | {} | {} | {} | {:.2} | {:.3} | {reading} |",
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

fn equal_time_table(md: &mut String, o: &Outcome) {
    let rows: Vec<&Row> = o.rows.iter().filter(|r| r.kind == EQUAL_TIME).collect();
    if rows.is_empty() {
        return;
    }
    let m = o.exp.exp.metrics.primary;
    let what = metric_name(m, o.exp.exp.metrics.relmse_epsilon);
    let _ = writeln!(md, "## Equal time\n\nspp chosen from each strategy's measured sample rate.\n\n| budget (s) | strategy | seed | spp | seconds | {what} |\n|---|---|---|---|---|---|");
    for r in rows {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {:.2} | {} |",
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

fn variance_table(md: &mut String, o: &Outcome) {
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

fn means(md: &mut String, o: &Outcome) {
    let (pm, _, _) = mean_check(o);
    if pm.len() < 2 {
        return;
    }
    let _ = writeln!(md, "## Same expectation?\n\nEvery correct strategy converges to the same image, so the image means must agree within noise (a difference is a bias, not an improvement). Each strategy's image mean at its highest spp, pooled over seeds, with a 95 % interval from its variance images (the variance of the mean is dominated by pixels on emitter edges, which the box filter makes noisy):\n\n| image | spp x seeds | mean R | mean G | mean B |\n|---|---|---|---|---|");
    for p in &pm {
        let cell = |c: usize| format!("{:.5e} +- {:.1e}", p.mean[c], 1.959_964 * p.var[c].sqrt());
        let _ = writeln!(
            md,
            "| {} | {} x {} | {} | {} | {} |",
            p.name,
            p.spp,
            p.seeds,
            cell(0),
            cell(1),
            cell(2)
        );
    }
    md.push('\n');
    for l in mean_check_lines(o) {
        let _ = writeln!(md, "- {l}");
    }
    md.push('\n');
}

/// Writes `<dir>/index.md`.
pub fn write_experiment(o: &Outcome, series: &[Series], figures: &[Figure]) -> Result<(), String> {
    let mut md = String::new();
    let title = o
        .exp
        .exp
        .title
        .clone()
        .unwrap_or_else(|| o.exp.name.clone());
    let _ = writeln!(md, "# {title}\n");
    if !o.exp.exp.description.is_empty() {
        let _ = writeln!(md, "{}\n", o.exp.exp.description.trim());
    }
    settings(&mut md, o);
    left_out(&mut md, o);
    error_table(&mut md, o, series);
    diagnostics(&mut md, o, series);
    equal_time_table(&mut md, o);
    means(&mut md, o);
    variance_table(&mut md, o);
    let _ = writeln!(md, "## Figures\n");
    for f in figures {
        let _ = writeln!(md, "![{}]({})\n\n{}\n", f.file, f.file, f.caption);
    }
    let _ = writeln!(
        md,
        "Raw numbers: [results.csv](results.csv), one row per render."
    );
    let path = o.dir.join("index.md");
    write_atomic(&path, |tmp| {
        std::fs::write(tmp, &md).map_err(|e| format!("{}: {e}", path.display()))
    })
}

/// Writes `<root>/index.md` linking every experiment folder that has a report.
pub fn write_root_index(root: &Path) -> Result<(), String> {
    let mut entries: Vec<(String, String)> = Vec::new();
    if let Ok(rd) = std::fs::read_dir(root) {
        for d in rd.flatten() {
            let idx = d.path().join("index.md");
            let Ok(text) = std::fs::read_to_string(&idx) else {
                continue;
            };
            let name = d.file_name().to_string_lossy().to_string();
            let title = text
                .lines()
                .next()
                .and_then(|l| l.strip_prefix("# "))
                .unwrap_or(&name)
                .to_string();
            entries.push((name, title));
        }
    }
    entries.sort();
    let mut md =
        String::from("# Experiments\n\nWritten by `directlab run` / `directlab reproduce`.\n\n");
    for (name, title) in &entries {
        let _ = writeln!(md, "- [{title}]({name}/index.md)");
    }
    let path = root.join("index.md");
    write_atomic(&path, |tmp| {
        std::fs::write(tmp, &md).map_err(|e| format!("{}: {e}", path.display()))
    })
}
