//! False colour for scalar maps (errors, variances, efficiencies) on a log scale.

/// Viridis at nine stops (perceptually uniform, readable in greyscale and for colour-blind
/// readers), linearly interpolated.
const VIRIDIS: [[f64; 3]; 9] = [
    [68.0, 1.0, 84.0],
    [71.0, 44.0, 122.0],
    [59.0, 81.0, 139.0],
    [44.0, 113.0, 142.0],
    [33.0, 144.0, 141.0],
    [39.0, 173.0, 129.0],
    [92.0, 200.0, 99.0],
    [170.0, 220.0, 50.0],
    [253.0, 231.0, 37.0],
];

/// Colour of t in [0, 1] (clamped).
pub fn viridis(t: f64) -> [u8; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let x = t * (VIRIDIS.len() - 1) as f64;
    let i = (x as usize).min(VIRIDIS.len() - 2);
    let f = x - i as f64;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    [0, 1, 2].map(|c| (a[c] + (b[c] - a[c]) * f).round() as u8)
}

/// Widest range a colour scale spans, in powers of ten.
pub const DECADES: i32 = 5;

/// A log10 colour scale shared by several maps so they can be compared.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LogScale {
    pub lo: f64,
    pub hi: f64,
}

impl LogScale {
    /// From the 1st and 99th percentiles of the positive values, so a few outliers do not
    /// wash out the map; at most `DECADES` decades (pixels that are exact up to rounding would
    /// otherwise stretch the scale to 1e-50), at least one.
    pub fn from_values(values: impl Iterator<Item = f64>) -> LogScale {
        let mut v: Vec<f64> = values.filter(|x| x.is_finite() && *x > 0.0).collect();
        if v.is_empty() {
            return LogScale { lo: 1e-3, hi: 1.0 };
        }
        v.sort_by(f64::total_cmp);
        let at = |q: f64| v[((v.len() - 1) as f64 * q) as usize];
        let (mut lo, mut hi) = (at(0.01), at(0.99));
        lo = lo.max(hi * 10f64.powi(-DECADES));
        if hi < 10.0 * lo {
            let mid = (lo * hi).sqrt();
            lo = mid / 10f64.sqrt();
            hi = mid * 10f64.sqrt();
        }
        LogScale { lo, hi }
    }

    /// Position of v on the scale; zero and negatives map to the bottom.
    pub fn t(&self, v: f64) -> f64 {
        if !(v > 0.0) {
            return 0.0;
        }
        (v.log10() - self.lo.log10()) / (self.hi.log10() - self.lo.log10())
    }

    pub fn colour(&self, v: f64) -> [u8; 3] {
        viridis(self.t(v))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viridis_ends_and_clamps() {
        assert_eq!(viridis(0.0), [68, 1, 84]);
        assert_eq!(viridis(1.0), [253, 231, 37]);
        assert_eq!(viridis(-3.0), viridis(0.0));
        assert_eq!(viridis(f64::NAN), viridis(0.0));
    }

    #[test]
    fn log_scale_is_robust_to_outliers() {
        let mut v: Vec<f64> = (1..=1000).map(|i| i as f64 * 1e-3).collect();
        v.push(1e9);
        v.push(0.0);
        let s = LogScale::from_values(v.into_iter());
        assert!(s.hi < 2.0 && s.lo > 1e-3 * 0.9, "{s:?}");
        assert_eq!(s.t(s.lo), 0.0);
        assert!((s.t(s.hi) - 1.0).abs() < 1e-12);
        assert_eq!(s.t(0.0), 0.0);
        // Rounding-level values (many exact pixels) must not stretch the scale.
        let mut v: Vec<f64> = (0..500).map(|_| 1e-50).collect();
        v.extend((1..=500).map(|i| i as f64));
        let s = LogScale::from_values(v.into_iter());
        assert!((s.lo - s.hi * 1e-5).abs() < 1e-12 * s.hi, "{s:?}");
    }
}
