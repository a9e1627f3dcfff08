//! The check that strategies and reference share one expectation: image means with 95 %
//! intervals from the variance images, z-tests Sidak-corrected over all comparisons.

use crate::experiment::analysis::{mean_difference, pooled_means, MeanDiff, PooledMean};
use crate::experiment::Outcome;
use crate::stats::sidak;
use std::fmt::Write;

/// Family-wise level of the mean check.
pub const MEAN_ALPHA: f64 = 0.01;

const CHANNELS: [&str; 3] = ["R", "G", "B"];

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

pub(super) fn means(md: &mut String, o: &Outcome) {
    let (pm, _, _) = mean_check(o);
    if pm.len() < 2 {
        return;
    }
    let _ = writeln!(md, "## Same expectation?\n\nEvery correct strategy converges to the same image, so the image means must agree within noise (a difference is a bias, not an improvement). Each strategy's image mean at its highest spp, pooled over seeds, with a 95 % interval from its variance images (the variance of the mean is dominated by pixels on emitter edges, which the box filter makes noisy). Differences treat the two images as independent: true against the reference (its own seed), conservative between strategies, which share seeds and so sub-pixel positions (positively correlated edge pixels):\n\n| image | spp x seeds | mean R | mean G | mean B |\n|---|---|---|---|---|");
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
