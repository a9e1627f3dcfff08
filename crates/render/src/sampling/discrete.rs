//! Discrete distributions: an alias table for O(1) sampling with a pmf lookup, the structure
//! behind triangle-by-area and emitter-by-power choice.

/// `(x as usize).min(n - 1)` for n >= 1, NaN giving 0 as `as` does, in a few instructions
/// where `as usize` takes a dozen (it saturates in software on x86-64): a table lookup per
/// light sample.
#[inline(always)]
pub fn bin_index(x: f32, n: usize) -> usize {
    // max turns NaN into 0, and every float from 2^62 up saturates to n - 1 anyway.
    let c = x.max(0.0).min((1u64 << 62) as f32);
    // SAFETY: c is in [0, 2^62], so it truncates to an i64 exactly.
    let i = unsafe { c.to_int_unchecked::<i64>() } as usize;
    i.min(n - 1)
}

/// Walker/Vose alias table. Zero-weight entries are never chosen and have pmf 0.
#[derive(Clone, Debug)]
pub struct AliasTable {
    /// Per bin: probability of keeping the bin (vs. jumping to its alias), and the alias.
    bins: Vec<(f32, u32)>,
    pmf: Vec<f32>,
    total: f64,
}

impl AliasTable {
    /// Returns None when no weight is positive and finite.
    pub fn new(weights: &[f64]) -> Option<Self> {
        let n = weights.len();
        let total: f64 = weights.iter().filter(|w| w.is_finite() && **w > 0.0).sum();
        if n == 0 || total <= 0.0 || !total.is_finite() {
            return None;
        }
        let clean = |w: f64| if w.is_finite() && w > 0.0 { w } else { 0.0 };
        let pmf: Vec<f32> = weights.iter().map(|&w| (clean(w) / total) as f32).collect();
        let mut scaled: Vec<f64> = weights
            .iter()
            .map(|&w| clean(w) / total * n as f64)
            .collect();
        let mut bins = vec![(1.0f32, 0u32); n];
        let (mut small, mut large): (Vec<usize>, Vec<usize>) =
            (0..n).partition(|&i| scaled[i] < 1.0);
        while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
            small.pop();
            bins[s] = (scaled[s] as f32, l as u32);
            scaled[l] -= 1.0 - scaled[s];
            if scaled[l] < 1.0 {
                large.pop();
                small.push(l);
            }
        }
        // Leftovers are 1 up to rounding and keep themselves, except zero-weight bins (left
        // over only through rounding), which must never be returned.
        let fallback = pmf.iter().position(|&p| p > 0.0).unwrap_or(0) as u32;
        for i in small.into_iter().chain(large) {
            bins[i] = if pmf[i] > 0.0 {
                (1.0, i as u32)
            } else {
                (0.0, fallback)
            };
        }
        Some(AliasTable { bins, pmf, total })
    }

    /// The number of bins.
    pub fn len(&self) -> usize {
        self.bins.len()
    }

    /// Whether there are no bins.
    pub fn is_empty(&self) -> bool {
        self.bins.is_empty()
    }

    /// Sum of the (valid) weights the table was built from.
    pub fn total(&self) -> f64 {
        self.total
    }

    /// Bin i: the probability of keeping it (against the fractional part of `u * len`) and
    /// its alias.
    pub fn bin(&self, i: usize) -> (f32, u32) {
        self.bins[i]
    }

    /// The probability of bin i.
    #[inline]
    pub fn pmf(&self, i: usize) -> f32 {
        self.pmf[i]
    }

    /// Picks an index with one uniform number. The fractional part chooses between a bin and
    /// its alias, so a zero-pmf bin (whose keep-probability is 0) is never returned.
    #[inline]
    pub fn sample(&self, u: f32) -> usize {
        let n = self.bins.len();
        let x = u * n as f32;
        let i = bin_index(x, n);
        let frac = x - i as f32;
        let (keep, alias) = self.bins[i];
        if frac < keep {
            i
        } else {
            alias as usize
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `bin_index` is `as usize` then `min(n - 1)`, on the edges too: negatives, NaN,
    /// infinities, x at and past n, and n that f32 cannot hold exactly.
    #[test]
    fn bin_index_is_saturating_cast_then_min() {
        let ns = [1usize, 2, 3, 7, 1000, (1 << 24) + 1, (1 << 25) + 3];
        for n in ns {
            let nf = n as f32;
            let xs = [
                0.0,
                -0.0,
                -1.0,
                0.5,
                1.0,
                nf * 0.999,
                nf - 1.0,
                nf,
                nf * 1.5,
                f32::MAX,
                f32::INFINITY,
                f32::NEG_INFINITY,
                f32::NAN,
                f32::from_bits(1),
            ];
            for x in xs {
                assert_eq!(bin_index(x, n), (x as usize).min(n - 1), "x = {x}, n = {n}");
            }
        }
    }
    /// `len`, `is_empty` and `bin` describe the table `sample` walks (the lane kernel
    /// reads the bins directly): u in bin i picks i below the keep probability, else the
    /// alias; bins of zero pmf are never kept.
    #[test]
    fn bins_describe_what_sample_picks() {
        let pmf = [0.5f64, 0.0, 2.0, 1.0, 0.25, 3.0, 0.0];
        let t = AliasTable::new(&pmf).unwrap();
        assert_eq!(t.len(), pmf.len());
        assert!(!t.is_empty());
        let n = t.len() as f32;
        let mut kept_somewhere = 0;
        for i in 0..t.len() {
            let (keep, alias) = t.bin(i);
            assert!((0.0..=1.0).contains(&keep) && (alias as usize) < t.len());
            assert!(pmf[i] > 0.0 || keep == 0.0, "bin {i}");
            assert!(pmf[alias as usize] > 0.0 || keep == 1.0, "bin {i}");
            for f in [0.001f32, 0.25, 0.5, 0.75, 0.999] {
                let u = (i as f32 + f) / n;
                let want = if f < keep { i } else { alias as usize };
                assert_eq!(t.sample(u), want, "bin {i}, fraction {f}");
            }
            kept_somewhere += (keep > 0.0 && keep < 1.0) as usize;
        }
        assert!(kept_somewhere > 0, "the test needs bins that split");
    }

    use crate::rng::Rng;

    #[test]
    fn frequencies_match_pmf() {
        let w = [1.0, 0.0, 3.0, 0.5, 10.0, 2.5];
        let t = AliasTable::new(&w).unwrap();
        let total: f64 = w.iter().sum();
        let n = 1_000_000;
        let mut counts = [0u64; 6];
        let mut rng = Rng::new(11, 0);
        for _ in 0..n {
            counts[t.sample(rng.next_f32())] += 1;
        }
        for i in 0..6 {
            let p = w[i] / total;
            assert!((t.pmf(i) as f64 - p).abs() < 1e-6);
            // Binomial sd sqrt(n p (1-p)); 5 sd per bin (6 bins, false alarm ~3.4e-6).
            let sd = (n as f64 * p * (1.0 - p)).sqrt();
            assert!(
                (counts[i] as f64 - n as f64 * p).abs() <= 5.0 * sd + 1e-9,
                "bin {i}: {} vs {}",
                counts[i],
                n as f64 * p
            );
        }
        assert_eq!(counts[1], 0, "a zero-weight bin was chosen");
    }

    #[test]
    fn rejects_all_zero_or_nan() {
        assert!(AliasTable::new(&[]).is_none());
        assert!(AliasTable::new(&[0.0, 0.0]).is_none());
        assert!(AliasTable::new(&[f64::NAN]).is_none());
        let t = AliasTable::new(&[f64::NAN, 2.0]).unwrap();
        assert_eq!(t.pmf(0), 0.0);
        assert_eq!(t.sample(0.0), 1);
    }
}
