//! Statistics for proving estimators and samplers right: running moments, t-tests against
//! closed forms, chi-square tests of samplers against their pdfs, and heat maps of the latter.

pub mod chi2;
pub mod domain;
pub mod heatmap;
pub mod integrate;
pub mod integrate_batched;
pub mod nnls;
pub mod ratio;
pub mod slope;
pub mod spectrum;
pub mod ttest;
pub mod welch_map;
pub mod welford;

pub use chi2::{chi2_test, Chi2Config, Chi2Result, Grid, Verdict};
pub use domain::{Disk, Domain, Sphere, Triangle, UnitSquare};
pub use integrate::Integration;
pub use ttest::{one_sample, one_sample_welford, sidak, welch, Group, TTest};
pub use welford::Welford;

/// A `top_share` above this marks an error held by outliers: a mean that is too low then
/// most likely missed a rare large value rather than being biased.
pub const TAIL_SHARE: f64 = 0.5;

/// The fewest terms (pixels, samples) the tail rule reads: below it the largest 0.1 % is one
/// term that is more than 0.1 % of them (on a 1x1 film, all of it), so the rule would fire
/// on any error, a bias included.
pub const MIN_TAIL_TERMS: usize = 1000;

/// Share of the sum of non-negative terms (squared errors) carried by its largest 0.1 %:
/// near 1 when a handful of outliers (fireflies, a tiny bright light) hold the error, which
/// is when a sample variance underestimates the true one. NaN if all terms are 0, or if there
/// are fewer than [`MIN_TAIL_TERMS`] (the rule does not apply).
pub fn top_share(mut e: Vec<f64>) -> f64 {
    let total: f64 = e.iter().sum();
    if !(total > 0.0) || e.len() < MIN_TAIL_TERMS {
        return f64::NAN;
    }
    let k = e.len().div_ceil(1000).max(1);
    let i = e.len() - k;
    e.select_nth_unstable_by(i, f64::total_cmp);
    e[i..].iter().sum::<f64>() / total
}

/// Kolmogorov-Smirnov distance of sorted values in [0, 1] from Uniform(0, 1) (the check that
/// p-values of correct samplers are uniform).
pub fn ks_uniform(sorted: &[f64]) -> f64 {
    let n = sorted.len() as f64;
    sorted
        .iter()
        .enumerate()
        .map(|(i, &p)| (p - i as f64 / n).abs().max(((i + 1) as f64 / n - p).abs()))
        .fold(0.0, f64::max)
}

/// P(D >= d) for the KS distance of `n` uniform values: the Kolmogorov distribution at
/// (sqrt(n) + 0.12 + 0.11 / sqrt(n)) d (Stephens' correction, within 1 % of the exact value
/// for n >= 5 in the tail that matters).
pub fn ks_p_value(d: f64, n: usize) -> f64 {
    let sn = (n as f64).sqrt();
    let lambda = (sn + 0.12 + 0.11 / sn) * d;
    if lambda < 0.2 {
        return 1.0;
    }
    let mut sum = 0.0;
    for k in 1..=100 {
        let term = (-2.0 * (k * k) as f64 * lambda * lambda).exp();
        sum += if k % 2 == 1 { term } else { -term };
        if term < 1e-16 {
            break;
        }
    }
    (2.0 * sum).clamp(0.0, 1.0)
}

#[cfg(test)]
mod ks_tests {
    use super::*;

    /// Against the exact critical values of the one-sample KS test (Massey 1951 tables).
    #[test]
    fn ks_p_value_matches_tabulated_critical_values() {
        for (n, d, alpha) in [(20, 0.294, 0.05), (20, 0.352, 0.01), (10, 0.409, 0.05)] {
            let p = ks_p_value(d, n);
            assert!(
                (p / alpha - 1.0).abs() < 0.06,
                "n {n} d {d}: p {p} vs {alpha}"
            );
        }
        assert_eq!(ks_p_value(0.0, 20), 1.0);
        assert!(ks_p_value(0.9, 20) < 1e-12);
    }
}
