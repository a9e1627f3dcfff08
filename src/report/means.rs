//! The check that strategies and reference share one expectation: image means with 95 %
//! intervals from the variance images, z-tests Sidak-corrected over all comparisons.

use crate::experiment::analysis::{mean_difference, pooled_means, MeanDiff, PooledMean};
use crate::experiment::runner::Outcome;
use crate::stats::{sidak, TAIL_SHARE};
use std::fmt::Write;

/// Family-wise level of the mean check.
pub const MEAN_ALPHA: f64 = 0.01;

const CHANNELS: [&str; 3] = ["R", "G", "B"];

/// One comparison of image means: `a - b` per channel.
pub struct Comparison {
    pub a: String,
    pub b: String,
    pub diffs: Vec<MeanDiff>,
    /// `a`'s and `b`'s `top_share`, where above `TAIL_SHARE` (see `MeanVerdict::Tail`).
    pub tail_share: [Option<f64>; 2],
}

/// What one channel's test says.
#[derive(Debug, PartialEq)]
pub enum MeanVerdict {
    Consistent,
    /// Failed, but the lower image holds this share of its squared error in 0.1 % of its
    /// pixels: a rare large value (a tiny bright light seen directly, or through a
    /// near-specular reflection) went unsampled there, its variance image underestimates the
    /// true variance and the z-test's normal approximation does not hold. Not evidence of bias
    /// at this spp. (A tail only makes a mean too low, never too high.)
    Tail(f64),
    Different,
}

impl Comparison {
    /// The image that is lower in this channel, and its tail share.
    fn low(&self, d: &MeanDiff) -> (&str, Option<f64>) {
        if d.diff < 0.0 {
            (&self.a, self.tail_share[0])
        } else {
            (&self.b, self.tail_share[1])
        }
    }

    pub fn verdict(&self, d: &MeanDiff) -> MeanVerdict {
        match self.low(d).1 {
            _ if d.consistent => MeanVerdict::Consistent,
            Some(share) => MeanVerdict::Tail(share),
            None => MeanVerdict::Different,
        }
    }
}

fn compare(a: &PooledMean, b: &PooledMean, alpha: f64) -> Comparison {
    let tail = |p: &PooledMean| p.top_share.filter(|&s| s > TAIL_SHARE);
    Comparison {
        a: a.name.clone(),
        b: b.name.clone(),
        diffs: mean_difference(a, b, alpha),
        tail_share: [tail(a), tail(b)],
    }
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
        top_share: None,
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
    let comparisons = pairs.iter().map(|(a, b)| compare(a, b, alpha)).collect();
    let mut all = pm;
    all.push(reference);
    (all, comparisons, alpha)
}

/// One line per strategy for the terminal: its image mean against the first strategy's and
/// the reference's, each at its worst channel (a bias first, else the largest |z|), with the
/// verdict. Every channel's numbers are in the report's "Same expectation?" table.
pub fn mean_check_lines(o: &Outcome) -> Vec<String> {
    let (_, comparisons, alpha) = mean_check(o);
    let mut order: Vec<&str> = Vec::new();
    for c in &comparisons {
        if !order.contains(&c.a.as_str()) {
            order.push(&c.a);
        }
    }
    order
        .iter()
        .map(|name| {
            let parts: Vec<String> = comparisons
                .iter()
                .filter(|c| c.a == *name)
                .map(|cmp| {
                    let d = &cmp.diffs;
                    let grey = d
                        .iter()
                        .all(|x| x.diff == d[0].diff && x.half_width_95 == d[0].half_width_95);
                    let worst = d
                        .iter()
                        .max_by(|x, y| {
                            let rank = |v: &MeanDiff| {
                                (matches!(cmp.verdict(v), MeanVerdict::Different), v.z.abs())
                            };
                            let (rx, ry) = (rank(x), rank(y));
                            rx.0.cmp(&ry.0).then(rx.1.total_cmp(&ry.1))
                        })
                        .expect("three channels");
                    let ch = if grey { "RGB" } else { CHANNELS[worst.channel] };
                    let verdict = match cmp.verdict(worst) {
                        MeanVerdict::Consistent => "consistent".to_string(),
                        MeanVerdict::Tail(share) => format!(
                            "low, but {:.0} % of the squared error sits in 0.1 % of the pixels: \
                             an unsampled tail, not evidence of bias (render more to decide)",
                            100.0 * share
                        ),
                        MeanVerdict::Different => format!(
                            "DIFFERENT at family-wise alpha {MEAN_ALPHA} (per test {alpha:.1e}): \
                             one of them is biased"
                        ),
                    };
                    format!(
                        "vs {}: {:+.3e} +- {:.1e} [{ch}], z = {:+.2}, {verdict}",
                        cmp.b, worst.diff, worst.half_width_95, worst.z
                    )
                })
                .collect();
            format!(
                "same expectation, {name} (95% CI, worst channel): {}",
                parts.join("; ")
            )
        })
        .collect()
}

/// Lines stating each difference with its 95 % interval, per channel, for the report.
/// Channels with identical numbers (grey scenes) are stated once.
fn mean_check_detail_lines(o: &Outcome) -> Vec<String> {
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
                match cmp.verdict(x) {
                    MeanVerdict::Consistent => "consistent (same expectation)".to_string(),
                    MeanVerdict::Tail(share) => format!(
                        "too low at family-wise alpha {MEAN_ALPHA}, but {:.0} % of {}'s squared error sits in 0.1 % of its pixels: a rare bright value went unsampled and its variance is underestimated, so this is not evidence of bias at this spp (render more to decide)",
                        100.0 * share,
                        cmp.low(x).0
                    ),
                    MeanVerdict::Different => format!("DIFFERENT at family-wise alpha {MEAN_ALPHA} (per test {alpha:.1e}): one of them is biased"),
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
    let _ = writeln!(md, "## Same expectation?\n\nEvery correct strategy converges to the same image, so the image means must agree within noise (a difference is a bias, not an improvement). Each strategy's image mean at its highest spp, pooled over seeds, with a 95 % interval from its variance images (the variance of the mean is dominated by pixels on emitter edges, which the box filter makes noisy). Differences treat the two images as independent: true against the reference (its own seed), conservative between strategies, which share seeds and so sub-pixel positions (positively correlated edge pixels). A test fails as a bias unless the lower image holds more than half of its squared error against the reference in 0.1 % of its pixels: then a rare bright value (a tiny light seen directly) went unsampled, the variance images underestimate the true variance, and the failure is reported as a tail to settle with more samples, not as a bias:\n\n| image | spp x seeds | mean R | mean G | mean B |\n|---|---|---|---|---|");
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
    let (w, h) = (o.reference.mean.width, o.reference.mean.height);
    let pixels = w as usize * h as usize;
    if pixels < crate::stats::MIN_TAIL_TERMS {
        let _ = writeln!(
            md,
            "On this {w}x{h} film ({pixels} pixels, fewer than {}) the tail rule does not \
             apply: its 0.1 % of the pixels would be all the error, so a failed test is \
             reported as a bias.\n",
            crate::stats::MIN_TAIL_TERMS
        );
    }
    for l in mean_check_detail_lines(o) {
        let _ = writeln!(md, "- {l}");
    }
    md.push('\n');
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pm(name: &str, m: f64, top_share: Option<f64>) -> PooledMean {
        PooledMean {
            label: name.into(),
            name: name.into(),
            spp: 16,
            seeds: 2,
            mean: [m; 3],
            var: [1e-6; 3],
            top_share,
        }
    }

    fn verdicts(a: &PooledMean, b: &PooledMean) -> Vec<MeanVerdict> {
        let c = compare(a, b, 0.01);
        c.diffs.iter().map(|d| c.verdict(d)).collect()
    }

    #[test]
    fn a_low_mean_with_its_error_in_a_few_pixels_is_a_tail() {
        let reference = pm("reference", 1.0, None);
        // 20 standard errors low: a failed test either way.
        let tail = pm("MIS", 0.98, Some(0.92));
        assert!(verdicts(&tail, &reference)
            .iter()
            .all(|v| matches!(v, MeanVerdict::Tail(s) if *s == 0.92)));
        assert!(verdicts(&reference, &tail)
            .iter()
            .all(|v| matches!(v, MeanVerdict::Tail(s) if *s == 0.92)));
        // Spread error, or no share recorded: a bias.
        for share in [Some(0.3), None] {
            let spread = pm("MIS", 0.98, share);
            assert!(verdicts(&spread, &reference)
                .iter()
                .all(|v| *v == MeanVerdict::Different));
        }
        // A tail can only make a mean too low: a high one is a bias whatever its share.
        let high = pm("MIS", 1.02, Some(0.92));
        assert!(verdicts(&high, &reference)
            .iter()
            .all(|v| *v == MeanVerdict::Different));
        assert!(verdicts(&pm("MIS", 1.0005, Some(0.92)), &reference)
            .iter()
            .all(|v| *v == MeanVerdict::Consistent));
    }
}
