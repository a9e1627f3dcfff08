//! Optimal MIS weights for two techniques per pixel (Kondapaneni, Vevoda, Grittmann, Skrivan,
//! Slusallek and Krivanek 2019), in the cross-fitted form that is exactly unbiased
//! (`shared/REFERENCE.md` section 15).
//!
//! Per pixel, every sample of either technique (light or BSDF; those that found nothing too,
//! with f = 0) adds to `Sums`: with p = (p_L, p_B) its direction's densities under both
//! techniques and P = n_L p_L + n_B p_B, A += p p^T / P^2, b += f p / P^2, S_f += f / P and
//! S_p += p / P. For weights alpha chosen independently of the samples in S_f and S_p,
//! F(alpha) = sum_i alpha_i + (S_f - alpha . S_p) / N is unbiased (E[S_p / N] = (1, 1)), and
//! alpha* = A^-1 b minimises its variance. Taking alpha from the same samples (`in_sample`,
//! what the public codes do) makes the residual vanish and biases F by O(1/N); cross-fitting
//! (`cross_fitted`) solves each fold's alpha from the other folds' sums only. alpha = 0 gives
//! exactly the balance heuristic (S_f / N), the fallback where a fold's complement is singular
//! or the pixel has too few iterations: a rule of the other folds' samples or of N alone, so
//! the estimate stays unbiased. Pixel values can be negative and are never clamped.

/// Below this many iterations per pixel the cross-fitted estimator is the balance heuristic
/// (too few samples for a 2 x 2 system per fold complement).
pub const MIN_ITERATIONS: u64 = 8;

/// A fold's (or a pixel's) sums, per colour channel where f enters.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sums {
    /// A = sum p p^T / P^2, as (A_LL, A_LB, A_BB).
    pub a: [f64; 3],
    /// b = sum f p / P^2: per technique, per channel.
    pub b: [[f64; 3]; 2],
    /// S_f = sum f / P, per channel.
    pub sf: [f64; 3],
    /// S_p = sum p / P, per technique.
    pub sp: [f64; 2],
    /// Iterations (each n_L light and n_B BSDF samples).
    pub n: u64,
}

impl Sums {
    /// One sample of either technique: its value `f` (0 when it found no light), the
    /// densities `p` = (p_L, p_B) of its direction under both techniques, and the techniques'
    /// sample counts per iteration. A direction neither technique can draw (P = 0) cannot
    /// have been drawn and adds nothing.
    #[inline]
    pub fn add(&mut self, f: [f64; 3], p: [f64; 2], counts: [f64; 2]) {
        let big_p = counts[0] * p[0] + counts[1] * p[1];
        if !(big_p > 0.0 && big_p.is_finite()) {
            return;
        }
        let inv = 1.0 / big_p;
        let inv2 = inv * inv;
        self.a[0] += p[0] * p[0] * inv2;
        self.a[1] += p[0] * p[1] * inv2;
        self.a[2] += p[1] * p[1] * inv2;
        for (c, &fc) in f.iter().enumerate() {
            self.b[0][c] += fc * p[0] * inv2;
            self.b[1][c] += fc * p[1] * inv2;
            self.sf[c] += fc * inv;
        }
        self.sp[0] += p[0] * inv;
        self.sp[1] += p[1] * inv;
    }

    /// Closes one iteration (n_L light and n_B BSDF samples added).
    #[inline]
    pub fn end_iteration(&mut self) {
        self.n += 1;
    }

    /// The sums of `self` and `o` together.
    pub fn plus(&self, o: &Sums) -> Sums {
        self.combine(o, 1.0)
    }

    /// `self` + `sign` x `o`, field by field (the counts as integers).
    fn combine(&self, o: &Sums, sign: f64) -> Sums {
        let mut s = *self;
        for i in 0..3 {
            s.a[i] += sign * o.a[i];
            s.sf[i] += sign * o.sf[i];
            for t in 0..2 {
                s.b[t][i] += sign * o.b[t][i];
            }
        }
        s.sp[0] += sign * o.sp[0];
        s.sp[1] += sign * o.sp[1];
        s.n = if sign > 0.0 { s.n + o.n } else { s.n - o.n };
        s
    }

    /// alpha = A^-1 b per channel, as [alpha_L, alpha_B]; None where A is singular (to a
    /// relative 1e-9 of its diagonal's product, or empty).
    pub fn alpha(&self) -> Option<[[f64; 2]; 3]> {
        let [a00, a01, a11] = self.a;
        let det = a00 * a11 - a01 * a01;
        if !(a00 > 0.0 && a11 > 0.0 && det > 1e-9 * a00 * a11) {
            return None;
        }
        Some(std::array::from_fn(|c| {
            let (b0, b1) = (self.b[0][c], self.b[1][c]);
            [(a11 * b0 - a01 * b1) / det, (a00 * b1 - a01 * b0) / det]
        }))
    }

    /// The balance heuristic's estimate, S_f / N (0 without iterations).
    pub fn balance(&self) -> [f64; 3] {
        let n = self.n.max(1) as f64;
        self.sf.map(|s| s / n)
    }

    /// F(alpha) over these sums' own samples: sum alpha + (S_f - alpha . S_p) / N.
    fn estimate(&self, alpha: &[[f64; 2]; 3]) -> [f64; 3] {
        let n = self.n.max(1) as f64;
        std::array::from_fn(|c| {
            let [al, ab] = alpha[c];
            al + ab + (self.sf[c] - al * self.sp[0] - ab * self.sp[1]) / n
        })
    }

    /// The in-sample optimal estimate, alpha solved from these very samples: biased by
    /// O(1/N), for showing that bias (never what a strategy runs); balance where singular.
    pub fn in_sample(&self) -> [f64; 3] {
        match self.alpha() {
            Some(alpha) => self.estimate(&alpha),
            None => self.balance(),
        }
    }
}

/// The cross-fitted optimal-MIS estimate of a pixel from its folds: each fold's weights
/// solved from the other folds' sums (0, the balance heuristic, where that complement is
/// singular), each fold's estimate weighted by its share of the iterations. Below
/// [`MIN_ITERATIONS`] in all, or with fewer than two folds, the balance heuristic.
pub fn cross_fitted(folds: &[Sums]) -> [f64; 3] {
    let total = folds.iter().fold(Sums::default(), |s, f| s.plus(f));
    if folds.len() < 2 || total.n < MIN_ITERATIONS {
        return total.balance();
    }
    let n = total.n as f64;
    let mut out = [0.0; 3];
    for k in folds {
        if k.n == 0 {
            continue;
        }
        let rest = complement(&total, k);
        let alpha = rest.alpha().unwrap_or([[0.0; 2]; 3]);
        let part = k.estimate(&alpha);
        for c in 0..3 {
            out[c] += part[c] * (k.n as f64 / n);
        }
    }
    out
}

/// `total` without fold `k`'s sums (one subtraction per fold rather than K - 1 additions).
fn complement(total: &Sums, k: &Sums) -> Sums {
    total.combine(k, -1.0)
}

#[cfg(test)]
#[path = "optimal_tests.rs"]
mod tests;
