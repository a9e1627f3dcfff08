//! Student t-tests: a render region against a closed-form reference, or two renders against
//! each other (Welch, because two estimators rarely share a variance).

use super::welford::Welford;
use statrs::distribution::{ContinuousCDF, StudentsT};

/// Outcome of a two-sided t-test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TTest {
    pub t: f64,
    pub dof: f64,
    /// Two-sided: probability of |T| >= |t| under the null hypothesis.
    pub p_value: f64,
}

impl TTest {
    pub fn passes(&self, alpha: f64) -> bool {
        self.p_value >= alpha
    }
}

/// Per-test level that keeps the family-wise false-alarm rate at `alpha` over `m` independent
/// tests (Sidak), as Nori and Mitsuba do for their batches of cases.
pub fn sidak(alpha: f64, m: usize) -> f64 {
    assert!(m >= 1, "sidak correction needs at least one test");
    1.0 - (1.0 - alpha).powf(1.0 / m as f64)
}

/// Two-sided tail probability of Student's t with `dof` degrees of freedom.
pub fn two_sided_p(t: f64, dof: f64) -> f64 {
    if t.is_nan() || dof.is_nan() || dof <= 0.0 {
        return f64::NAN;
    }
    if t.is_infinite() {
        return 0.0;
    }
    let dist = StudentsT::new(0.0, 1.0, dof).expect("valid Student t parameters");
    // sf of |t| keeps its relative precision far in the tail, where 1 - cdf would round to 0.
    (2.0 * dist.sf(t.abs())).min(1.0)
}

/// Handles zero variance: a constant estimate either equals the reference or is certainly off.
fn from_parts(diff: f64, se: f64, dof: f64) -> TTest {
    if se == 0.0 {
        let (t, p_value) = if diff == 0.0 {
            (0.0, 1.0)
        } else {
            (diff.signum() * f64::INFINITY, 0.0)
        };
        return TTest { t, dof, p_value };
    }
    let t = diff / se;
    TTest {
        t,
        dof,
        p_value: two_sided_p(t, dof),
    }
}

/// One-sample test of H0: E[X] = reference, from sample mean, unbiased variance and count.
pub fn one_sample(mean: f64, variance: f64, n: u64, reference: f64) -> TTest {
    assert!(n >= 2, "a t-test needs at least two samples");
    from_parts(
        mean - reference,
        (variance / n as f64).sqrt(),
        (n - 1) as f64,
    )
}

/// [`one_sample`] on an accumulator.
pub fn one_sample_welford(w: &Welford, reference: f64) -> TTest {
    one_sample(w.mean(), w.variance(), w.count(), reference)
}

/// Summary of one group for [`welch`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Group {
    pub mean: f64,
    pub variance: f64,
    pub n: u64,
}

impl From<&Welford> for Group {
    fn from(w: &Welford) -> Self {
        Group {
            mean: w.mean(),
            variance: w.variance(),
            n: w.count(),
        }
    }
}

/// Welch's two-sample test of H0: E[A] = E[B] with unequal variances; dof from
/// Welch-Satterthwaite.
pub fn welch(a: Group, b: Group) -> TTest {
    assert!(
        a.n >= 2 && b.n >= 2,
        "Welch test needs two samples per group"
    );
    let va = a.variance / a.n as f64;
    let vb = b.variance / b.n as f64;
    let se2 = va + vb;
    let denom = va * va / (a.n - 1) as f64 + vb * vb / (b.n - 1) as f64;
    // Both variances zero: dof is undefined but unused by the zero-se branch.
    let dof = if denom > 0.0 {
        se2 * se2 / denom
    } else {
        (a.n + b.n - 2) as f64
    };
    from_parts(a.mean - b.mean, se2.sqrt(), dof)
}

#[cfg(test)]
mod tests {
    /// Size and power of the one-sample test on normal data (Box-Muller from the project's
    /// generator), 200 trials of n = 2000 at alpha = 0.01. No bias: at most 6 rejections
    /// (binomial(200, 0.01) exceeds 6 with probability 0.0045). A bias of 0.1 sd (t about
    /// 4.5, power 0.98): at least 185 rejections (binomial(200, 0.98) falls below 185 with
    /// probability below 1e-4).
    #[test]
    fn one_sample_has_its_size_and_power() {
        let mut rng = crate::rng::Rng::new(5, 1);
        let mut normal = || {
            let (u1, u2) = (1.0 - rng.next_f64(), rng.next_f64());
            (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
        };
        let mut rejections = [0; 2];
        for (k, bias) in [0.0, 0.1].into_iter().enumerate() {
            for _ in 0..200 {
                let x: Vec<f64> = (0..2000).map(|_| bias + normal()).collect();
                let n = x.len() as f64;
                let m = x.iter().sum::<f64>() / n;
                let v = x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0);
                if !super::one_sample(m, v, 2000, 0.0).passes(0.01) {
                    rejections[k] += 1;
                }
            }
        }
        assert!(rejections[0] <= 6, "size: {} of 200", rejections[0]);
        assert!(rejections[1] >= 185, "power: {} of 200", rejections[1]);
    }

    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn textbook_critical_values() {
        // Two-sided 5 % critical values from standard t tables.
        for (t, dof) in [(12.706, 1.0), (4.303, 2.0), (2.228, 10.0), (2.042, 30.0)] {
            let p = two_sided_p(t, dof);
            assert!(close(p, 0.05, 2e-4), "t={t} dof={dof} p={p}");
        }
        // Two-sided 1 % critical value, dof 5.
        assert!(close(two_sided_p(-4.032, 5.0), 0.01, 1e-4));
        assert_eq!(two_sided_p(0.0, 7.0), 1.0);
    }

    #[test]
    fn closed_form_cdfs() {
        // dof 1 is Cauchy: p = 1 - 2 atan(|t|)/pi. dof 2: p = 1 - |t|/sqrt(2 + t^2).
        for t in [0.3, 1.0, 3.0, 40.0] {
            let cauchy = 1.0 - 2.0 * f64::atan(t) / std::f64::consts::PI;
            assert!(close(two_sided_p(t, 1.0), cauchy, 1e-10));
            let two = 1.0 - t / (2.0 + t * t).sqrt();
            assert!(close(two_sided_p(t, 2.0), two, 1e-10));
        }
    }

    #[test]
    fn one_sample_worked_example() {
        // Data {1, 2, 3} against 0: mean 2, s^2 = 1, t = 2 sqrt(3), dof 2,
        // p = 1 - t / sqrt(2 + t^2) = 0.0741799...
        let w: Welford = [1.0, 2.0, 3.0].into_iter().collect();
        let r = one_sample_welford(&w, 0.0);
        assert!(close(r.t, 2.0 * 3f64.sqrt(), 1e-12));
        assert_eq!(r.dof, 2.0);
        assert!(close(
            r.p_value,
            1.0 - r.t / (2.0 + r.t * r.t).sqrt(),
            1e-12
        ));
        assert!(close(r.p_value, 0.0741799, 1e-6));
    }

    #[test]
    fn zero_variance() {
        assert_eq!(one_sample(1.0, 0.0, 10, 1.0).p_value, 1.0);
        assert_eq!(one_sample(1.0, 0.0, 10, 1.5).p_value, 0.0);
    }

    #[test]
    fn welch_worked_example() {
        // Group A: mean 20, s^2 = 4, n = 10; group B: mean 22, s^2 = 16, n = 20.
        // se^2 = 0.4 + 0.8 = 1.2, t = -2/sqrt(1.2) = -1.8257,
        // dof = 1.44 / (0.16/9 + 0.64/19) = 27.946...
        let a = Group {
            mean: 20.0,
            variance: 4.0,
            n: 10,
        };
        let b = Group {
            mean: 22.0,
            variance: 16.0,
            n: 20,
        };
        let r = welch(a, b);
        assert!(close(r.t, -2.0 / 1.2f64.sqrt(), 1e-12));
        let dof = 1.44 / (0.16 / 9.0 + 0.64 / 19.0);
        assert!(close(r.dof, dof, 1e-9));
        assert!(close(r.p_value, two_sided_p(r.t, dof), 1e-12));
        // Equal variances and sizes: Welch dof reduces to the pooled 2(n - 1).
        let c = Group {
            mean: 1.0,
            variance: 3.0,
            n: 50,
        };
        assert!(close(welch(c, c).dof, 98.0, 1e-9));
        assert_eq!(welch(c, c).p_value, 1.0);
    }

    #[test]
    fn sidak_values() {
        assert!(close(sidak(0.01, 1), 0.01, 1e-15));
        // 1 - 0.99^(1/5) = 0.00200804834...
        assert!(close(sidak(0.01, 5), 0.002_008_048_34, 1e-11));
        assert!(sidak(0.01, 1000) > 0.01 / 1000.0);
    }

    /// Degenerate inputs: NaN or non-positive dof give a NaN p-value; a constant estimate is
    /// certainly off by the sign of its difference; Welch with both variances zero reports
    /// the pooled dof n_a + n_b - 2.
    #[test]
    fn degenerate_inputs() {
        assert!(two_sided_p(f64::NAN, 5.0).is_nan());
        assert!(two_sided_p(1.0, f64::NAN).is_nan());
        assert!(two_sided_p(1.0, 0.0).is_nan());
        assert!(two_sided_p(1.0, -2.0).is_nan());
        assert_eq!(two_sided_p(f64::INFINITY, 3.0), 0.0);
        let below = one_sample(1.0, 0.0, 10, 2.0);
        assert_eq!((below.t, below.p_value), (f64::NEG_INFINITY, 0.0));
        let above = one_sample(3.0, 0.0, 10, 2.0);
        assert_eq!((above.t, above.p_value), (f64::INFINITY, 0.0));
        let g = |mean: f64, n: u64| Group {
            mean,
            variance: 0.0,
            n,
        };
        let w = welch(g(1.0, 5), g(1.0, 7));
        assert_eq!((w.t, w.dof, w.p_value), (0.0, 10.0, 1.0));
    }
}
