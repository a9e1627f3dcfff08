//! Per-pixel error metrics of rendering papers, each a mean over pixels and channels of one
//! term per (pixel, channel), with the epsilon that keeps dark pixels from dominating.

use crate::film::Image;

fn terms(img: &Image, reference: &Image, f: impl Fn(f64, f64) -> f64) -> Vec<f64> {
    assert_eq!((img.width, img.height), (reference.width, reference.height));
    img.data
        .iter()
        .zip(&reference.data)
        .flat_map(|(x, r)| (0..3).map(move |c| (x[c], r[c])))
        .map(|(x, r)| f(x, r))
        .collect()
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// The share of relMSE's terms a trimmed relMSE drops: the largest 0.1 %.
pub const TRIM: f64 = 0.001;

/// Why trimming does not apply to a `w` x `h` film: with fewer than 1 / [`TRIM`] terms (three
/// per pixel) the largest 0.1 % is no term at all, and trimmed relMSE would be relMSE.
pub fn trim_not_applicable(w: usize, h: usize) -> Option<&'static str> {
    ((w * h * 3) as f64 * TRIM < 1.0).then_some(
        "the film has under 334 pixels: 0.1 % of its terms is none, so nothing would be \
         trimmed (it would equal relMSE)",
    )
}

/// relMSE without its largest `trim` share of terms (x - r)^2 / (r^2 + eps), the count dropped
/// rounded down: robust to a few fireflies; reported beside relMSE, never instead of it.
pub fn trimmed_rel_mse(img: &Image, reference: &Image, eps: f64, trim: f64) -> f64 {
    let mut t = terms(img, reference, |x, r| (x - r) * (x - r) / (r * r + eps));
    let keep = t.len() - (t.len() as f64 * trim).floor() as usize;
    if keep < t.len() {
        t.select_nth_unstable_by(keep, |a, b| a.total_cmp(b));
    }
    mean(&t[..keep])
}

/// Mean absolute percentage error: mean of |x - r| / (|r| + eps).
pub fn mape(img: &Image, reference: &Image, eps: f64) -> f64 {
    mean(&terms(img, reference, |x, r| {
        (x - r).abs() / (r.abs() + eps)
    }))
}

/// Symmetric MAPE: mean of |x - r| / (|x| + |r| + eps), in [0, 1] (without the factor 2
/// some tools put in front).
pub fn smape(img: &Image, reference: &Image, eps: f64) -> f64 {
    mean(&terms(img, reference, |x, r| {
        (x - r).abs() / (x.abs() + r.abs() + eps)
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn img(v: &[f64]) -> Image {
        let mut i = Image::new(v.len() as u32, 1);
        for (k, &x) in v.iter().enumerate() {
            i.set(k as u32, 0, [x, x, x]);
        }
        i
    }

    #[test]
    fn hand_computed_values() {
        let r = img(&[1.0, 0.0, 2.0, 0.5]);
        let x = img(&[1.5, 0.1, 2.0, 0.0]);
        let eps = 0.01;
        // |x - r| = 0.5, 0.1, 0, 0.5
        let mape_want = (0.5 / 1.01 + 0.1 / 0.01 + 0.0 + 0.5 / 0.51) / 4.0;
        assert!((mape(&x, &r, eps) - mape_want).abs() < 1e-12);
        let smape_want = (0.5 / 2.51 + 0.1 / 0.11 + 0.0 + 0.5 / 0.51) / 4.0;
        assert!((smape(&x, &r, eps) - smape_want).abs() < 1e-12);
        assert!(smape(&x, &r, 0.0) <= 1.0);
        let rel = [0.25 / 1.01, 0.01 / 0.01, 0.0, 0.25 / 0.26];
        let full = rel.iter().sum::<f64>() / 4.0;
        assert!((crate::metrics::rel_mse(&x, &r, eps) - full).abs() < 1e-12);
        // 12 terms, trimming a quarter drops 3: the three channels of the 1.0 term.
        let want = (rel[0] + rel[2] + rel[3]) / 3.0;
        assert!((trimmed_rel_mse(&x, &r, eps, 0.25) - want).abs() < 1e-12);
        // 0.1 % of 12 terms rounds down to none.
        assert!((trimmed_rel_mse(&x, &r, eps, TRIM) - full).abs() < 1e-12);
    }

    #[test]
    fn trimming_removes_a_firefly_only() {
        // 2000 pixels (6000 terms): 0.1 % is 6 terms, the firefly pixel's three channels and
        // the three next largest.
        let n = 2000;
        let r = img(&vec![1.0; n]);
        let mut v: Vec<f64> = (0..n)
            .map(|i| 1.0 + 0.01 * ((i % 7) as f64 - 3.0))
            .collect();
        v[17] = 1e4;
        let x = img(&v);
        let full = crate::metrics::rel_mse(&x, &r, 0.01);
        let trimmed = trimmed_rel_mse(&x, &r, 0.01, TRIM);
        assert!(full > 1e4, "{full}");
        let mut ts: Vec<f64> = v.iter().map(|x| (x - 1.0).powi(2) / 1.01).collect();
        ts.sort_by(|a, b| a.total_cmp(b));
        // Dropping 6 terms = 2 pixels of 3 channels.
        let want = ts[..n - 2].iter().sum::<f64>() * 3.0 / (3 * n - 6) as f64;
        assert!((trimmed - want).abs() < 1e-15, "{trimmed} vs {want}");
    }
}

/// Hand-computed cases of the registered metrics of this file, run through their registry
/// lines' `compute` (`experiment::metric` names each).
#[cfg(test)]
pub(crate) mod hand {
    use crate::metrics::{close, constant, grey, run, Compute};

    pub(crate) fn trimmed_relmse(compute: Compute) {
        // 2000 pixels of 1.0 against 1.0 except one firefly of 11: 6000 terms, 0.1 % is 6,
        // the firefly's three channels and three zeros: nothing is left.
        let r = constant(2000, 1, 1.0);
        let mut x = r.clone();
        x.data[7] = [11.0; 3];
        close(run(compute, &x, &r, 0.01, 0.5), 0.0, "firefly trimmed");
        // An error everywhere is kept: (0.1^2 / 1.01) per term, whichever 6 are dropped.
        let y = constant(2000, 1, 1.1);
        close(
            run(compute, &y, &r, 0.01, 0.5),
            0.01 / 1.01,
            "uniform error",
        );
    }

    pub(crate) fn mape(compute: Compute) {
        let (r, x) = (grey(&[1.0, 0.0, 2.0, 0.5]), grey(&[1.5, 0.1, 2.0, 0.0]));
        let want = (0.5 / 1.01 + 0.1 / 0.01 + 0.0 + 0.5 / 0.51) / 4.0;
        close(run(compute, &x, &r, 0.5, 0.01), want, "mape");
    }

    pub(crate) fn smape(compute: Compute) {
        let (r, x) = (grey(&[1.0, 0.0, 2.0, 0.5]), grey(&[1.5, 0.1, 2.0, 0.0]));
        let want = (0.5 / 2.51 + 0.1 / 0.11 + 0.0 + 0.5 / 0.51) / 4.0;
        close(run(compute, &x, &r, 0.5, 0.01), want, "smape");
    }
}
