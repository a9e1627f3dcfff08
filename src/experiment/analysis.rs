//! From result rows to what the plots and tables show: error per (strategy, spp) over seeds,
//! the convergence slope, and the check that strategies agree on the image mean.

use super::results::Row;
use super::schema::ErrorMetric;
use crate::stats::slope::{bootstrap_slope, local_slopes, SeedErrors, BOOTSTRAP_DRAWS};
use statrs::distribution::{ContinuousCDF, Normal};

/// The chosen error of a row: MSE and relMSE corrected for the reference's noise, the
/// others raw (NaN where the row lacks them).
pub fn error_of(r: &Row, m: ErrorMetric) -> f64 {
    match m {
        ErrorMetric::Mse => r.mse_corrected,
        ErrorMetric::Relmse => r.relmse_corrected,
        m => (m.def().expect("registered").value)(r).unwrap_or(f64::NAN),
    }
}

/// The error a row's own variance image predicts for an unbiased estimator (MSE and relMSE;
/// NaN for the others).
pub fn predicted_of(r: &Row, m: ErrorMetric) -> f64 {
    match m {
        ErrorMetric::Mse => r.mse_predicted,
        ErrorMetric::Relmse => r.relmse_predicted,
        _ => f64::NAN,
    }
}

/// Short name for captions; figure titles state epsilon.
pub fn metric_short(m: ErrorMetric) -> &'static str {
    m.short()
}

/// The metric with what defines it: epsilon, trimming, tone mapping (`exposure`).
pub fn metric_name(m: ErrorMetric, eps: f64) -> String {
    metric_label(m, eps, eps, 1.0)
}

/// [`metric_name`] with MAPE's epsilon and the tone mapping's exposure.
pub fn metric_label(m: ErrorMetric, eps: f64, mape_eps: f64, exposure: f64) -> String {
    m.label(eps, mape_eps, exposure)
}

/// One point of a convergence curve: the seeds' errors at one spp.
#[derive(Clone, Debug)]
pub struct Point {
    pub spp: u32,
    /// Arithmetic mean of the seeds' errors (the MSE estimate; a geometric mean would be
    /// biased low).
    pub error: f64,
    pub min: f64,
    pub max: f64,
    pub seconds: f64,
    pub seeds: usize,
    pub near_floor: bool,
}

impl Point {
    /// Efficiency 1 / (error * time): higher is better, flat in spp for a 1/N estimator.
    pub fn efficiency(&self) -> f64 {
        1.0 / (self.error * self.seconds)
    }
}

#[derive(Clone, Debug)]
pub struct Series {
    pub label: String,
    pub name: String,
    pub points: Vec<Point>,
    /// Least-squares slope of log(error) over log(spp), from points clear of the noise floor.
    pub slope: Option<f64>,
    /// Its 95 % bootstrap interval over seeds (`stats::slope::bootstrap_slope`), from the
    /// seeds present at every fitted spp; None with fewer than two.
    pub slope_ci: Option<(f64, f64)>,
}

impl Series {
    /// Slopes between consecutive spp of the curve.
    pub fn local_slopes(&self) -> Vec<(u32, u32, f64)> {
        let pts: Vec<(u32, f64)> = self.points.iter().map(|p| (p.spp, p.error)).collect();
        local_slopes(&pts)
    }
}

/// Each fitted spp's errors per seed, over the seeds present at all of them.
fn seed_errors(rows: &[Row], label: &str, spps: &[u32], m: ErrorMetric) -> Vec<SeedErrors> {
    let at = |spp: u32, seed: u64| {
        rows.iter()
            .find(|r| r.is_sweep() && r.strategy == label && r.spp == spp && r.seed == seed)
    };
    let mut seeds: Vec<u64> = rows
        .iter()
        .filter(|r| r.is_sweep() && r.strategy == label)
        .map(|r| r.seed)
        .collect();
    seeds.sort();
    seeds.dedup();
    seeds.retain(|&s| spps.iter().all(|&spp| at(spp, s).is_some()));
    spps.iter()
        .map(|&spp| SeedErrors {
            spp,
            errors: seeds
                .iter()
                .filter_map(|&s| at(spp, s).map(|r| error_of(r, m)))
                .collect(),
        })
        .collect()
}

/// Sweep rows grouped per strategy (in `order`, a list of labels) and spp.
pub fn series(rows: &[Row], order: &[(String, String)], m: ErrorMetric) -> Vec<Series> {
    order
        .iter()
        .map(|(label, name)| {
            let mut spps: Vec<u32> = rows
                .iter()
                .filter(|r| r.is_sweep() && &r.strategy == label)
                .map(|r| r.spp)
                .collect();
            spps.sort();
            spps.dedup();
            let points: Vec<Point> = spps
                .iter()
                .map(|&spp| {
                    let rs: Vec<&Row> = rows
                        .iter()
                        .filter(|r| r.is_sweep() && &r.strategy == label && r.spp == spp)
                        .collect();
                    let n = rs.len() as f64;
                    let errs: Vec<f64> = rs.iter().map(|r| error_of(r, m)).collect();
                    Point {
                        spp,
                        error: errs.iter().sum::<f64>() / n,
                        min: errs.iter().cloned().fold(f64::INFINITY, f64::min),
                        max: errs.iter().cloned().fold(f64::NEG_INFINITY, f64::max),
                        seconds: rs.iter().map(|r| r.seconds).sum::<f64>() / n,
                        seeds: rs.len(),
                        near_floor: rs.iter().any(|r| r.near_floor),
                    }
                })
                .collect();
            let fitted: Vec<&Point> = points
                .iter()
                .filter(|p| !p.near_floor && p.error > 0.0)
                .collect();
            let fit: Vec<(f64, f64)> = fitted
                .iter()
                .map(|p| ((p.spp as f64).ln(), p.error.ln()))
                .collect();
            let fit_spps: Vec<u32> = fitted.iter().map(|p| p.spp).collect();
            Series {
                label: label.clone(),
                name: name.clone(),
                slope: fit_slope(&fit),
                slope_ci: bootstrap_slope(&seed_errors(rows, label, &fit_spps, m), BOOTSTRAP_DRAWS),
                points,
            }
        })
        .collect()
}

pub use crate::stats::slope::fit_slope;

/// A strategy's image mean per channel, pooled over seeds at one spp, with its variance.
#[derive(Clone, Debug)]
pub struct PooledMean {
    pub label: String,
    pub name: String,
    pub spp: u32,
    pub seeds: usize,
    pub mean: [f64; 3],
    pub var: [f64; 3],
    /// The largest `Row::top_share` among the pooled rows, where recorded.
    pub top_share: Option<f64>,
}

/// Pools each strategy's rows at its highest spp with at least two samples per pixel (the
/// variance image needs two).
pub fn pooled_means(rows: &[Row], order: &[(String, String)]) -> Vec<PooledMean> {
    order
        .iter()
        .filter_map(|(label, name)| {
            let spp = rows
                .iter()
                .filter(|r| r.is_sweep() && &r.strategy == label && r.spp >= 2)
                .map(|r| r.spp)
                .max()?;
            let rs: Vec<&Row> = rows
                .iter()
                .filter(|r| r.is_sweep() && &r.strategy == label && r.spp == spp)
                .collect();
            let n = rs.len() as f64;
            let mut mean = [0.0; 3];
            let mut var = [0.0; 3];
            for r in &rs {
                for c in 0..3 {
                    mean[c] += r.mean()[c] / n;
                    var[c] += r.mean_var()[c] / (n * n);
                }
            }
            Some(PooledMean {
                label: label.clone(),
                name: name.clone(),
                spp,
                seeds: rs.len(),
                mean,
                var,
                top_share: rs.iter().filter_map(|r| r.top_share).reduce(f64::max),
            })
        })
        .collect()
}

/// Difference of two pooled image means in one channel, with a 95 % interval and whether it
/// passes a two-sided z-test at `alpha_per_test`.
#[derive(Clone, Debug)]
pub struct MeanDiff {
    pub channel: usize,
    pub diff: f64,
    pub half_width_95: f64,
    pub z: f64,
    pub consistent: bool,
}

pub fn mean_difference(a: &PooledMean, b: &PooledMean, alpha_per_test: f64) -> Vec<MeanDiff> {
    let normal = Normal::new(0.0, 1.0).expect("standard normal");
    let crit = normal.inverse_cdf(1.0 - alpha_per_test / 2.0);
    (0..3)
        .map(|c| {
            let diff = a.mean[c] - b.mean[c];
            let sd = (a.var[c] + b.var[c]).sqrt();
            let z = if sd > 0.0 {
                diff / sd
            } else if diff == 0.0 {
                0.0
            } else {
                f64::INFINITY
            };
            MeanDiff {
                channel: c,
                diff,
                half_width_95: 1.959_964 * sd,
                z,
                consistent: z.abs() < crit,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::results::test_row;

    #[test]
    fn series_average_seeds_and_skip_floor_points_in_the_fit() {
        let mut rows = Vec::new();
        for spp in [1, 2, 4, 8] {
            for seed in 0..2 {
                let mut r = test_row("light", spp, seed);
                // seeds 0 and 1 give 0.5x and 1.5x of 1/spp: mean 1/spp.
                r.relmse_corrected = (0.5 + seed as f64) / spp as f64;
                rows.push(r);
            }
        }
        // A point at the floor would flatten the slope if it were fitted.
        let mut floor = test_row("light", 16, 0);
        floor.relmse_corrected = 1.0;
        floor.near_floor = true;
        rows.push(floor);
        let order = vec![("light".to_string(), "Light".to_string())];
        let s = &series(&rows, &order, ErrorMetric::Relmse)[0];
        assert_eq!(s.points.len(), 5);
        assert!((s.points[1].error - 0.5).abs() < 1e-12);
        assert_eq!((s.points[1].min, s.points[1].max), (0.25, 0.75));
        assert!((s.slope.unwrap() + 1.0).abs() < 1e-12, "{:?}", s.slope);
    }

    #[test]
    fn mean_difference_flags_a_bias_larger_than_the_noise() {
        let pm = |m: f64| PooledMean {
            label: String::new(),
            name: String::new(),
            spp: 4,
            seeds: 1,
            mean: [m; 3],
            var: [1e-6; 3],
            top_share: None,
        };
        let same = mean_difference(&pm(1.0), &pm(1.001), 0.01);
        assert!(same.iter().all(|d| d.consistent));
        assert!((same[0].half_width_95 - 1.959_964 * (2e-6f64).sqrt()).abs() < 1e-12);
        let biased = mean_difference(&pm(1.0), &pm(1.02), 0.01);
        assert!(biased.iter().all(|d| !d.consistent));
    }

    #[test]
    fn pooled_mean_uses_the_highest_spp_and_averages_seeds() {
        let mut rows = vec![
            test_row("a", 1, 0),
            test_row("a", 8, 0),
            test_row("a", 8, 1),
        ];
        rows[2].mean_r = 0.3;
        let p = &pooled_means(&rows, &[("a".into(), "A".into())])[0];
        assert_eq!((p.spp, p.seeds), (8, 2));
        assert!((p.mean[0] - 0.2).abs() < 1e-12);
        assert!((p.var[0] - 2e-6 / 4.0).abs() < 1e-18);
    }
}
