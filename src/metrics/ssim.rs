//! SSIM (Wang, Bovik, Sheikh and Simoncelli 2004) as rendering papers report it: on
//! tone-mapped sRGB values in [0, 1], with an 11x11 Gaussian window of sigma 1.5, K1 = 0.01,
//! K2 = 0.03 and L = 1, averaged over the pixels whose window lies inside the image and over
//! the three channels (the convention of Wang's code and of scikit-image with
//! `gaussian_weights=True, use_sample_covariance=False`).

const RADIUS: usize = 5;
const SIGMA: f64 = 1.5;
const C1: f64 = 0.01 * 0.01;
const C2: f64 = 0.03 * 0.03;

fn window() -> [f64; 2 * RADIUS + 1] {
    let mut w = [0.0; 2 * RADIUS + 1];
    for (i, v) in w.iter_mut().enumerate() {
        let d = i as f64 - RADIUS as f64;
        *v = (-d * d / (2.0 * SIGMA * SIGMA)).exp();
    }
    let s: f64 = w.iter().sum();
    w.map(|v| v / s)
}

/// The window-weighted mean of `f` around every pixel whose window fits: a (w - 10) x
/// (h - 10) image, rows then columns.
fn filter(f: &[f64], w: usize, h: usize, win: &[f64]) -> Vec<f64> {
    let ow = w - 2 * RADIUS;
    let oh = h - 2 * RADIUS;
    let mut rows = vec![0.0; ow * h];
    for y in 0..h {
        for x in 0..ow {
            rows[y * ow + x] = win
                .iter()
                .enumerate()
                .map(|(k, c)| c * f[y * w + x + k])
                .sum();
        }
    }
    let mut out = vec![0.0; ow * oh];
    for y in 0..oh {
        for x in 0..ow {
            out[y * ow + x] = win
                .iter()
                .enumerate()
                .map(|(k, c)| c * rows[(y + k) * ow + x])
                .sum();
        }
    }
    out
}

/// Mean SSIM of one channel `a` against `b` (values in [0, 1], row-major `w` x `h`).
fn channel(a: &[f64], b: &[f64], w: usize, h: usize) -> f64 {
    let win = window();
    let prod = |f: &dyn Fn(f64, f64) -> f64| -> Vec<f64> {
        a.iter().zip(b).map(|(&x, &y)| f(x, y)).collect()
    };
    let mx = filter(a, w, h, &win);
    let my = filter(b, w, h, &win);
    let mxx = filter(&prod(&|x, _| x * x), w, h, &win);
    let myy = filter(&prod(&|_, y| y * y), w, h, &win);
    let mxy = filter(&prod(&|x, y| x * y), w, h, &win);
    let mut sum = 0.0;
    for i in 0..mx.len() {
        let (ux, uy) = (mx[i], my[i]);
        let vx = mxx[i] - ux * ux;
        let vy = myy[i] - uy * uy;
        let cxy = mxy[i] - ux * uy;
        sum +=
            (2.0 * ux * uy + C1) * (2.0 * cxy + C2) / ((ux * ux + uy * uy + C1) * (vx + vy + C2));
    }
    sum / mx.len() as f64
}

/// Why SSIM does not apply to a `w` x `h` image, if it does not.
pub fn not_applicable(w: usize, h: usize) -> Option<&'static str> {
    (w <= 2 * RADIUS || h <= 2 * RADIUS).then_some("the film is smaller than SSIM's 11x11 window")
}

/// Mean SSIM of two RGB images of tone-mapped values in [0, 1]; None if the image is smaller
/// than the 11x11 window.
pub fn ssim(a: &[[f64; 3]], b: &[[f64; 3]], w: usize, h: usize) -> Option<f64> {
    assert_eq!(a.len(), w * h);
    assert_eq!(b.len(), w * h);
    if not_applicable(w, h).is_some() {
        return None;
    }
    let plane = |img: &[[f64; 3]], c: usize| -> Vec<f64> { img.iter().map(|p| p[c]).collect() };
    let s: f64 = (0..3)
        .map(|c| channel(&plane(a, c), &plane(b, c), w, h))
        .sum();
    Some(s / 3.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn noise(n: usize, seed: u64) -> Vec<[f64; 3]> {
        let mut r = crate::rng::Rng::new(seed, 1);
        (0..n)
            .map(|_| [r.next_f64(), r.next_f64(), r.next_f64()])
            .collect()
    }

    #[test]
    fn identical_images_score_one_and_the_window_is_gaussian() {
        let a = noise(20 * 16, 1);
        assert!((ssim(&a, &a, 20, 16).unwrap() - 1.0).abs() < 1e-12);
        assert!(ssim(&a[..100], &a[..100], 10, 10).is_none());
        let w = window();
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        assert!((w[5] / w[6] - (1.0 / 4.5f64).exp()).abs() < 1e-12);
    }

    /// Constant images: the SSIM is the luminance term alone,
    /// (2 a b + C1) / (a^2 + b^2 + C1), by hand.
    #[test]
    fn constant_images_give_the_luminance_term() {
        let a = vec![[0.5; 3]; 144];
        let b = vec![[0.25; 3]; 144];
        let want = (2.0 * 0.5 * 0.25 + C1) / (0.25 + 0.0625 + C1);
        assert!((ssim(&a, &b, 12, 12).unwrap() - want).abs() < 1e-12);
    }

    /// Independent noise images share nothing but their means: SSIM near 0.
    #[test]
    fn unrelated_noise_scores_near_zero() {
        let (a, b) = (noise(64 * 64, 2), noise(64 * 64, 3));
        let s = ssim(&a, &b, 64, 64).unwrap();
        assert!(s.abs() < 0.05, "{s}");
    }
}

/// The hand-computed case of the registered 1-SSIM, run through its registry line.
#[cfg(test)]
pub(crate) mod hand {
    use crate::film::linear_to_srgb;
    use crate::metrics::{close, constant, run, Compute};

    pub(crate) fn ssim_error(compute: Compute) {
        // Constant images: SSIM is the luminance term (2 a b + C1) / (a^2 + b^2 + C1) of the
        // tone-mapped values, C1 = (0.01)^2; 1-SSIM is reported.
        let (a, b) = (linear_to_srgb(0.5), linear_to_srgb(0.25));
        let c1 = 1e-4;
        let want = 1.0 - (2.0 * a * b + c1) / (a * a + b * b + c1);
        let (x, r) = (constant(12, 12, 0.5), constant(12, 12, 0.25));
        close(run(compute, &x, &r, 0.01, 0.01), want, "1-ssim");
        // A film smaller than the 11x11 window: the metric does not apply.
        let (x, r) = (constant(4, 4, 0.5), constant(4, 4, 0.25));
        assert_eq!(run(compute, &x, &r, 0.01, 0.01), None);
    }
}
