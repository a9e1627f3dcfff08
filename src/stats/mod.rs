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
pub mod ttest;
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

/// Kolmogorov-Smirnov distance of sorted values in [0, 1] from Uniform(0, 1) (the tests'
/// check that p-values of correct samplers are uniform).
#[cfg(test)]
pub(crate) fn ks_uniform(sorted: &[f64]) -> f64 {
    let n = sorted.len() as f64;
    sorted
        .iter()
        .enumerate()
        .map(|(i, &p)| (p - i as f64 / n).abs().max(((i + 1) as f64 / n - p).abs()))
        .fold(0.0, f64::max)
}
