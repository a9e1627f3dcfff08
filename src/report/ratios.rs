//! "A is N times B", with its interval: every strategy against the experiment's first, at the
//! comparison spp (error and efficiency) and at each equal-time budget (error), each ratio
//! with its 95 % bootstrap-t interval over seeds (`stats::ratio`), paired when both ran the
//! same seeds, and marked where the interval holds 1 and so does not rank the two.

use crate::experiment::analysis::{error_of, metric_name};
use crate::experiment::results::{Row, EQUAL_TIME};
use crate::experiment::runner::Outcome;
use crate::experiment::schema::ErrorMetric;
use crate::stats::ratio::{ratio_of_means, Ratio, DRAWS};
use std::fmt::Write;

/// Which runs of a strategy a ratio compares.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Runs {
    /// Sweep runs at this spp.
    Spp(u32),
    /// Equal-time runs of this budget (seconds).
    Budget(f64),
}

/// What is compared per seed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Quantity {
    /// The error: the ratio is the other's error over this one's (above 1: this is better).
    Error,
    /// 1 / (error x seconds): the ratio is this one's over the other's.
    Efficiency,
}

/// Per seed, the quantity of `label`'s runs (sorted by seed), or None where an error is not
/// positive (at the reference's noise floor) or a time is missing.
fn per_seed(
    rows: &[Row],
    label: &str,
    runs: Runs,
    q: Quantity,
    m: ErrorMetric,
) -> Option<Vec<(u64, f64)>> {
    let mut v: Vec<(u64, f64)> = rows
        .iter()
        .filter(|r| r.strategy == label)
        .filter(|r| match runs {
            Runs::Spp(n) => r.is_sweep() && r.spp == n,
            Runs::Budget(b) => r.kind == EQUAL_TIME && r.budget_s == b,
        })
        .map(|r| {
            let e = error_of(r, m);
            let x = match q {
                Quantity::Error => e,
                Quantity::Efficiency => 1.0 / (e * r.seconds),
            };
            (r.seed, x)
        })
        .collect();
    v.sort_by_key(|p| p.0);
    v.iter().all(|p| p.1.is_finite() && p.1 > 0.0).then_some(v)
}

/// `label`'s gain over `base`: the base's mean error over its own (or its mean efficiency
/// over the base's), with the interval; paired when both ran the same seeds.
pub(crate) fn gain(
    rows: &[Row],
    base: &str,
    label: &str,
    runs: Runs,
    q: Quantity,
    m: ErrorMetric,
) -> Option<Ratio> {
    let b = per_seed(rows, base, runs, q, m)?;
    let s = per_seed(rows, label, runs, q, m)?;
    let paired = b.len() == s.len() && b.iter().zip(&s).all(|(x, y)| x.0 == y.0);
    let (bv, sv): (Vec<f64>, Vec<f64>) = (
        b.iter().map(|p| p.1).collect(),
        s.iter().map(|p| p.1).collect(),
    );
    match q {
        Quantity::Error => ratio_of_means(&bv, &sv, paired, DRAWS),
        Quantity::Efficiency => ratio_of_means(&sv, &bv, paired, DRAWS),
    }
}

/// A table cell: the ratio and its interval, "(not ranked)" where the interval holds 1.
pub(crate) fn cell(r: Option<Ratio>) -> String {
    match r {
        None => "—".into(),
        Some(r) if r.ranks() => r.show(),
        Some(r) => format!("{} (not ranked)", r.show()),
    }
}

/// The "Gains" section: every strategy after the first against the first.
pub(super) fn gains(md: &mut String, o: &Outcome) {
    if o.strategies.len() < 2 {
        return;
    }
    let m = o.exp.exp.metrics.primary;
    let what = metric_name(m, o.exp.exp.metrics.relmse_epsilon);
    let spp = o.exp.equal_spp();
    let mut budgets: Vec<f64> = o
        .rows
        .iter()
        .filter(|r| r.kind == EQUAL_TIME)
        .map(|r| r.budget_s)
        .collect();
    budgets.sort_by(f64::total_cmp);
    budgets.dedup();
    let (base, base_name) = &o.strategies[0];
    let seeds = o
        .rows
        .iter()
        .filter(|r| &r.strategy == base && r.is_sweep() && r.spp == spp)
        .count();
    let _ = writeln!(
        md,
        "## Gains over {base_name}, with 95 % intervals\n\nEach strategy against {base_name} ({what}): \
         at {spp} spp the error ratio ({base_name}'s error over the strategy's) and the \
         efficiency ratio (per seed 1 / (error x seconds), the strategy's over {base_name}'s); the \
         time to reach a given error is the inverse of the efficiency ratio for estimators whose \
         error falls as 1 / time. At each budget the equal-time error ratio. Above 1 favours the \
         strategy. Intervals are bootstrap-t over seeds ({seeds} at {spp} spp), paired where both \
         ran the same seeds; \"not ranked\" where the interval holds 1, so the runs do not say \
         which is better; — where a ratio cannot be formed (an error at the reference's noise \
         floor, or fewer than two seeds).\n"
    );
    let mut head =
        format!("| strategy | error ratio at {spp} spp | efficiency ratio | time to an error |");
    let mut rule = String::from("|---|---|---|---|");
    for b in &budgets {
        let _ = write!(head, " error ratio at {b} s |");
        rule.push_str("---|");
    }
    let _ = writeln!(md, "{head}\n{rule}");
    for (label, name) in &o.strategies[1..] {
        let eff = gain(
            &o.rows,
            base,
            label,
            Runs::Spp(spp),
            Quantity::Efficiency,
            m,
        );
        let mut line = format!(
            "| {name} | {} | {} | {} |",
            cell(gain(
                &o.rows,
                base,
                label,
                Runs::Spp(spp),
                Quantity::Error,
                m
            )),
            cell(eff),
            cell(eff.map(|r| r.inverse())),
        );
        for &b in &budgets {
            let _ = write!(
                line,
                " {} |",
                cell(gain(
                    &o.rows,
                    base,
                    label,
                    Runs::Budget(b),
                    Quantity::Error,
                    m
                ))
            );
        }
        let _ = writeln!(md, "{line}");
    }
    md.push('\n');
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::results::test_row;

    fn row(label: &str, spp: u32, seed: u64, mse: f64, seconds: f64) -> Row {
        let mut r = test_row(label, spp, seed);
        r.mse_corrected = mse;
        r.seconds = seconds;
        r
    }

    /// Hand-computed: B has a quarter of A's error on every seed and takes twice as long:
    /// error ratio 4, efficiency ratio 4 / 2 = 2, time to an error 1/2; all exact (no spread),
    /// paired. Unpaired seeds, a zero error and a missing strategy are refused or named.
    #[test]
    fn gains_by_hand() {
        let mut rows = Vec::new();
        for seed in 0..3 {
            let e = 1.0 + seed as f64;
            rows.push(row("A", 16, seed, 4.0 * e, 1.0));
            rows.push(row("B", 16, seed, e, 2.0));
        }
        let m = ErrorMetric::Mse;
        let g = gain(&rows, "A", "B", Runs::Spp(16), Quantity::Error, m).unwrap();
        assert_eq!((g.value, g.lo, g.hi, g.paired), (4.0, 4.0, 4.0, true));
        let eff = gain(&rows, "A", "B", Runs::Spp(16), Quantity::Efficiency, m).unwrap();
        assert_eq!((eff.value, eff.lo, eff.hi), (2.0, 2.0, 2.0));
        assert_eq!(eff.inverse().value, 0.5);
        assert_eq!(cell(Some(g)), "4.00x [4.00, 4.00]");
        // The other direction, unranked when the errors overlap.
        let mut noisy = Vec::new();
        for (seed, (a, b)) in [(1.0, 1.2), (2.0, 1.5), (1.5, 1.8), (1.1, 0.9)]
            .into_iter()
            .enumerate()
        {
            noisy.push(row("A", 16, seed as u64, a, 1.0));
            noisy.push(row("B", 16, seed as u64, b, 1.0));
        }
        let r = gain(&noisy, "A", "B", Runs::Spp(16), Quantity::Error, m).unwrap();
        assert!((r.value - 5.6 / 5.4).abs() < 1e-12 && !r.ranks());
        assert!(cell(Some(r)).ends_with("(not ranked)"));
        // Seeds differ: resampled independently.
        let mut shifted = rows.clone();
        shifted
            .iter_mut()
            .filter(|r| r.strategy == "B")
            .for_each(|r| r.seed += 10);
        assert!(
            !gain(&shifted, "A", "B", Runs::Spp(16), Quantity::Error, m)
                .unwrap()
                .paired
        );
        // An error at the noise floor (corrected to 0), or no runs: no ratio.
        rows[1].mse_corrected = 0.0;
        assert!(gain(&rows, "A", "B", Runs::Spp(16), Quantity::Error, m).is_none());
        assert!(gain(&rows, "A", "C", Runs::Spp(16), Quantity::Error, m).is_none());
        assert_eq!(cell(None), "—");
    }
}
