//! Gauss-Legendre quadrature on [-1, 1]: the n nodes (roots of the Legendre polynomial P_n)
//! and weights 2 / ((1 - x^2) P_n'(x)^2), by Newton's iteration from the classical
//! cosine guesses. Exact for polynomials of degree 2n - 1; used for the tables BSDFs
//! precompute, as Mitsuba's `quad::gauss_legendre`.

/// (node, weight) pairs, nodes in decreasing order.
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    assert!(n > 0, "Gauss-Legendre needs at least one node");
    // P_n(x) and P_n'(x) by the three-term recurrence.
    let legendre = |x: f64| {
        let (mut p0, mut p1) = (1.0, x);
        for k in 2..=n {
            let k = k as f64;
            (p0, p1) = (p1, ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k);
        }
        (p1, n as f64 * (x * p1 - p0) / (x * x - 1.0))
    };
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            for _ in 0..100 {
                let (p, dp) = legendre(x);
                let step = p / dp;
                x -= step;
                if step.abs() < 1e-16 {
                    break;
                }
            }
            let (_, dp) = legendre(x);
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every n up to 64 has n distinct nodes in (-1, 1), in decreasing order, symmetric about
    /// 0, with positive weights summing to 2: Newton from each cosine guess found its own root.
    #[test]
    fn nodes_are_distinct_decreasing_and_symmetric() {
        for n in 1..=64usize {
            let q = gauss_legendre(n);
            for w in q.windows(2) {
                assert!(w[0].0 > w[1].0 + 1e-6, "n = {n}: {:?}", w);
            }
            for i in 0..n {
                assert!(q[i].0.abs() < 1.0 && q[i].1 > 0.0, "n = {n}");
                assert!((q[i].0 + q[n - 1 - i].0).abs() < 1e-14, "n = {n}, node {i}");
            }
            let sum: f64 = q.iter().map(|p| p.1).sum();
            assert!((sum - 2.0).abs() < 1e-13, "n = {n}: {sum}");
        }
    }

    /// Monomials up to degree 2n - 1 integrate exactly (to 1e-13); degree 2n does not (checked
    /// where its error is visible, n <= 5).
    #[test]
    fn exact_to_degree_two_n_minus_one() {
        for n in [1usize, 2, 5, 32, 128] {
            let q = gauss_legendre(n);
            assert_eq!(q.len(), n);
            for deg in 0..2 * n as i32 {
                let got: f64 = q.iter().map(|&(x, w)| w * x.powi(deg)).sum();
                let want = if deg % 2 == 1 {
                    0.0
                } else {
                    2.0 / (deg + 1) as f64
                };
                assert!(
                    (got - want).abs() < 1e-13,
                    "n {n} degree {deg}: {got} vs {want}"
                );
            }
            if n <= 5 {
                let deg = 2 * n as i32;
                let got: f64 = q.iter().map(|&(x, w)| w * x.powi(deg)).sum();
                assert!((got - 2.0 / (deg + 1) as f64).abs() > 1e-6, "n {n}");
            }
        }
        assert_eq!(gauss_legendre(1), vec![(0.0, 2.0)]);
    }
}
