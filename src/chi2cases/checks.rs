//! Checks beside chi-square: the pdf's total mass against the sampler's success rate, and a
//! BSDF sample's weight against eval / pdf.

use super::Check;
use crate::stats::Chi2Result;
use statrs::distribution::{ContinuousCDF, Normal};

/// Absolute error tolerated in the numerically integrated total of a pdf. The engine's own
/// tests measure errors below 1e-4 (cone rims, light silhouettes); this leaves a margin of
/// ten while still seeing a 0.1 % normalisation error.
pub const INTEGRATION_TOL: f64 = 1e-3;

/// Relative tolerance of the per-sample identities (f32 arithmetic on both sides).
pub const WEIGHT_TOL: f64 = 1e-3;

/// Two-sided critical |z| at level `alpha`.
pub fn z_critical(alpha: f64) -> f64 {
    Normal::new(0.0, 1.0)
        .expect("standard normal")
        .inverse_cdf(1.0 - 0.5 * alpha)
}

/// The pdf integrates to the probability that the sampler returns a sample. The success
/// fraction s of N draws is binomial around that integral I: it passes when
/// |s - I| <= z * sqrt(I (1 - I) / N) + INTEGRATION_TOL, z two-sided at `alpha`.
pub fn integral(r: &Chi2Result, alpha: f64) -> Check {
    let n = r.samples as f64;
    let success = 1.0 - r.lost as f64 / n;
    let i = r.pdf_integral;
    let sd = (i.clamp(0.0, 1.0) * (1.0 - i.clamp(0.0, 1.0)) / n).sqrt();
    let bound = z_critical(alpha) * sd + INTEGRATION_TOL;
    let diff = success - i;
    Check {
        name: "integral",
        passed: diff.abs() <= bound,
        detail: format!(
            "pdf integrates to {i:.6}, sampler succeeded in {success:.6} of draws \
             (difference {diff:+.2e}, allowed {bound:.2e})"
        ),
    }
}

/// Accumulates per-sample identities of a BSDF sampler: the pdf it returns equals pdf() of
/// the direction, and its weight equals eval / pdf.
#[derive(Clone, Debug, Default)]
pub struct WeightCheck {
    pub checked: u64,
    pub failures: u64,
    pub worst: f64,
    pub first: Option<String>,
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(1e-6)
}

impl WeightCheck {
    /// `weight` and `eval` are the channel maxima; `pdf_sampled` what sample() returned,
    /// `pdf_eval` what pdf() says of the same direction.
    pub fn record(&mut self, weight: f64, eval: f64, pdf_sampled: f64, pdf_eval: f64) {
        self.checked += 1;
        let e_pdf = rel(pdf_sampled, pdf_eval);
        let e_w = rel(weight, eval / pdf_sampled);
        let e = e_pdf.max(e_w);
        self.worst = self.worst.max(e);
        if !(e <= WEIGHT_TOL) {
            self.failures += 1;
            self.first.get_or_insert_with(|| {
                format!(
                    "weight {weight:.6e} vs eval/pdf {:.6e}, sampled pdf {pdf_sampled:.6e} vs \
                     pdf() {pdf_eval:.6e}",
                    eval / pdf_sampled
                )
            });
        }
    }

    pub fn check(&self) -> Check {
        let detail = match &self.first {
            None => format!(
                "{} samples: weight == eval/pdf and pdf() == sampled pdf (worst relative \
                 error {:.1e}, tolerance {WEIGHT_TOL:.0e})",
                self.checked, self.worst
            ),
            Some(f) => format!(
                "{} of {} samples disagree (first: {f})",
                self.failures, self.checked
            ),
        };
        Check {
            name: "weight",
            passed: self.failures == 0 && self.checked > 0,
            detail,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weight_check_flags_mismatch() {
        let mut w = WeightCheck::default();
        w.record(0.5, 1.0, 2.0, 2.0);
        assert!(w.check().passed);
        w.record(0.5, 1.0, 2.0, 1.0);
        let c = w.check();
        assert!(!c.passed && c.detail.contains("1 of 2"), "{}", c.detail);
        assert!(!WeightCheck::default().check().passed, "nothing checked");
    }

    #[test]
    fn z_critical_textbook() {
        assert!((z_critical(0.05) - 1.959964).abs() < 1e-5);
    }
}
