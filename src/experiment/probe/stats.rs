//! Statistics of one stream of a pixel's samples against its closed-form reference: bias
//! (z), error of batch means, the largest sample and the fireflies' share.

/// What the individual samples of one stream say beyond the error of its batch means.
#[derive(Clone, Debug, Default)]
pub struct Stream {
    pub n: u64,
    pub non_finite: u64,
    pub mean: f64,
    /// Sample variance (of one sample, not of the mean).
    pub variance: f64,
    /// (mean - reference) / standard error (see `z_score`).
    pub z: f64,
    pub max_sample: f64,
    /// Share of the total squared error (x - reference)^2 carried by the largest 0.1 %.
    pub top_share: f64,
}

/// Confidence level of the bound on outcomes a stream never drew (see `z_score`); also the
/// default family-wise level of the probe tables' z-tests, as in the render tests.
pub const ALPHA: f64 = 1e-3;

/// Two-sided critical |z| at level `alpha`, Šidák-corrected for `m` tests.
pub fn z_critical(alpha: f64, m: usize) -> f64 {
    use statrs::distribution::{ContinuousCDF, Normal};
    let a = 1.0 - (1.0 - alpha).powf(1.0 / m.max(1) as f64);
    Normal::new(0.0, 1.0)
        .expect("standard normal")
        .inverse_cdf(1.0 - a / 2.0)
}

/// relMSE normalisation: r^2 + epsilon, or 1 (the absolute MSE) when that is 0.
pub fn norm(reference: f64, eps: f64) -> f64 {
    let n = reference * reference + eps;
    if n > 0.0 {
        n
    } else {
        1.0
    }
}

/// Relative accuracy an f32 estimator can be held to: its per-sample arithmetic is rounded at
/// ~6e-8 a step, and a systematic error of a few such steps survives any sample count. Added
/// to the standard error so that near-constant estimators are not failed for f32 rounding.
pub const F32_FLOOR: f64 = 1e-6;

/// Confidence bound on an outcome never seen in n draws: p < -ln(alpha) / n at level alpha
/// (the rule of three at alpha = 0.05), here at the report's alpha = 1e-3.
fn unseen_probability(n: u64) -> f64 {
    -(ALPHA.ln()) / n as f64
}

/// z of the mean against the reference, with the f32 floor in the standard error.
///
/// Zero sample variance (all n samples equal) says nothing about outcomes rarer than ~1/n.
/// For a non-negative estimator, a missed rare outcome below the constant value v shifts the
/// mean by at most p v, so a constant v above the reference is consistent when
/// v - reference <= v p_unseen(n); a constant below the reference is not (the missing
/// outcomes would have to be larger, by an unknown amount) and gets an infinite z.
pub fn z_score(mean: f64, variance: f64, n: u64, reference: f64) -> f64 {
    let floor = F32_FLOOR * reference.abs();
    if variance == 0.0 {
        let d = mean - reference;
        return if d.abs() <= floor || (d > 0.0 && d <= mean * unseen_probability(n)) {
            0.0
        } else {
            d.signum() * f64::INFINITY
        };
    }
    (mean - reference) / (variance / n as f64 + floor * floor).sqrt()
}

/// MSE of the means of batches of `spp` consecutive samples against `reference` (batches
/// are independent: every sample has its own random stream). The tail short of a whole
/// batch is left out.
pub fn batch_mse(x: &[f64], spp: usize, reference: f64) -> f64 {
    let batches = x.len() / spp;
    let s: f64 = x
        .chunks_exact(spp)
        .map(|b| (b.iter().sum::<f64>() / spp as f64 - reference).powi(2))
        .sum();
    s / batches as f64
}

/// Share of sum (x - r)^2 carried by the largest ceil(0.1 %) of the terms; NaN if all are 0.
pub fn top_share(x: &[f64], reference: f64) -> f64 {
    crate::stats::top_share(x.iter().map(|v| (v - reference).powi(2)).collect())
}

pub fn stream(x: &[f64], non_finite: u64, reference: f64) -> Stream {
    let n = x.len();
    let mean = x.iter().sum::<f64>() / n as f64;
    let variance = if n > 1 {
        x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64
    } else {
        0.0
    };
    Stream {
        n: n as u64,
        non_finite,
        mean,
        variance,
        z: z_score(mean, variance, n as u64, reference),
        max_sample: x.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        top_share: top_share(x, reference),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    #[test]
    fn stream_of_uniform_samples() {
        let mut rng = Rng::new(3, 1);
        let x: Vec<f64> = (0..1 << 16).map(|_| rng.next_f64()).collect();
        let m = stream(&x, 0, 0.5);
        // |z| < 4 fails with probability 6e-5 for an unbiased mean.
        assert!(m.z.abs() < 4.0, "{m:?}");
        assert!((m.variance - 1.0 / 12.0).abs() < 2e-3);
        // Batch MSE at 1024 spp: (1/12) / 1024, from 64 batches (relative sd 0.18).
        assert!((batch_mse(&x, 1024, 0.5) / (1.0 / 12.0 / 1024.0) - 1.0).abs() < 0.6);
        assert!((batch_mse(&x, 1, 0.5) - 1.0 / 12.0).abs() < 2e-3);
        // The top 0.1 % of squared errors of U(0,1) around 0.5 carry about 0.3 % of the sum.
        assert!(
            m.top_share > 0.002 && m.top_share < 0.005,
            "{}",
            m.top_share
        );
    }

    #[test]
    fn firefly_share_and_zero_variance() {
        let mut x = vec![1.0; 10_000];
        x[17] = 1e6;
        assert!(top_share(&x, 1.0) > 0.999);
        assert_eq!(z_score(2.0, 0.0, 10, 2.0), 0.0);
        assert!(z_score(2.0 * (1.0 + 1e-7), 1e-30, 10, 2.0).abs() < 1.0);
        assert_eq!(z_score(2.0 * (1.0 - 5e-7), 0.0, 10, 2.0), 0.0);
        assert!(z_score(2.1, 0.0, 10_000, 2.0).is_infinite());
        // Constant above the reference: a rare zero (p < 6.9 / n) may not have been drawn.
        assert_eq!(z_score(2.001, 0.0, 1000, 2.0), 0.0);
        assert!(z_score(2.1, 0.0, 1000, 2.0).is_infinite());
        assert!(z_score(1.999, 0.0, 1000, 2.0) == f64::NEG_INFINITY);
        assert!(top_share(&[0.0; 10], 0.0).is_nan());
    }
}
