//! Running mean and variance in one pass (Welford 1962), mergeable (Chan et al. 1979).
//!
//! Naive `sum(x^2) - n mean^2` cancels catastrophically when the mean is large relative to
//! the spread, which is exactly the case for pixel estimates; this update does not.

/// Streaming mean/variance accumulator in f64.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Welford {
    n: u64,
    mean: f64,
    /// Sum of squared deviations from the current mean.
    m2: f64,
}

impl Welford {
    pub fn new() -> Self {
        Self::default()
    }

    #[inline]
    pub fn push(&mut self, x: f64) {
        self.n += 1;
        let delta = x - self.mean;
        self.mean += delta / self.n as f64;
        self.m2 += delta * (x - self.mean);
    }

    /// Combines two accumulators as if all samples had been pushed into one, so per-thread
    /// or per-tile statistics can be reduced in any order.
    pub fn merge(&mut self, other: &Welford) {
        if other.n == 0 {
            return;
        }
        if self.n == 0 {
            *self = *other;
            return;
        }
        let n = self.n + other.n;
        let delta = other.mean - self.mean;
        let (na, nb, nf) = (self.n as f64, other.n as f64, n as f64);
        self.mean += delta * nb / nf;
        self.m2 += other.m2 + delta * delta * na * nb / nf;
        self.n = n;
    }

    pub fn count(&self) -> u64 {
        self.n
    }

    pub fn mean(&self) -> f64 {
        self.mean
    }

    /// Unbiased sample variance; 0 with fewer than two samples.
    pub fn variance(&self) -> f64 {
        if self.n < 2 {
            0.0
        } else {
            self.m2 / (self.n - 1) as f64
        }
    }

    /// Standard error of the mean, sqrt(s^2 / n).
    pub fn std_error(&self) -> f64 {
        if self.n == 0 {
            0.0
        } else {
            (self.variance() / self.n as f64).sqrt()
        }
    }
}

impl Extend<f64> for Welford {
    fn extend<I: IntoIterator<Item = f64>>(&mut self, iter: I) {
        for x in iter {
            self.push(x);
        }
    }
}

impl FromIterator<f64> for Welford {
    fn from_iter<I: IntoIterator<Item = f64>>(iter: I) -> Self {
        let mut w = Welford::new();
        w.extend(iter);
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    fn two_pass(xs: &[f64]) -> (f64, f64) {
        let n = xs.len() as f64;
        let mean = xs.iter().sum::<f64>() / n;
        let var = xs.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0);
        (mean, var)
    }

    fn data(n: usize, offset: f64) -> Vec<f64> {
        let mut rng = Rng::new(3, 9);
        (0..n).map(|_| offset + rng.next_f64() * 3.0).collect()
    }

    #[test]
    fn matches_two_pass() {
        // A large offset is where the naive sum-of-squares formula loses all its digits.
        for offset in [0.0, 1e6] {
            let xs = data(10_000, offset);
            let w: Welford = xs.iter().copied().collect();
            let (mean, var) = two_pass(&xs);
            assert_eq!(w.count(), 10_000);
            assert!((w.mean() - mean).abs() <= 1e-12 * mean.abs().max(1.0));
            assert!(
                (w.variance() - var).abs() <= 1e-9 * var,
                "{} {}",
                w.variance(),
                var
            );
            assert!((w.std_error() - (var / 10_000.0).sqrt()).abs() < 1e-9);
        }
    }

    #[test]
    fn merge_equals_sequential() {
        let xs = data(1_001, 5.0);
        let whole: Welford = xs.iter().copied().collect();
        for split in [0, 1, 500, 1_000, 1_001] {
            let mut a: Welford = xs[..split].iter().copied().collect();
            let b: Welford = xs[split..].iter().copied().collect();
            a.merge(&b);
            assert_eq!(a.count(), whole.count());
            assert!((a.mean() - whole.mean()).abs() < 1e-12);
            assert!((a.variance() - whole.variance()).abs() < 1e-11);
        }
    }

    #[test]
    fn degenerate_counts() {
        let mut w = Welford::new();
        assert_eq!((w.mean(), w.variance(), w.std_error()), (0.0, 0.0, 0.0));
        w.push(4.0);
        assert_eq!((w.mean(), w.variance()), (4.0, 0.0));
    }

    /// Two samples are enough for a variance: (1, 3) has mean 2 and variance 2.
    #[test]
    fn two_samples_have_a_variance() {
        let mut w = Welford::default();
        w.push(1.0);
        assert_eq!(w.variance(), 0.0);
        w.push(3.0);
        assert_eq!((w.mean(), w.variance()), (2.0, 2.0));
    }
}
