//! Error metrics between images, and a test that two renders have the same expectation.

pub mod flip;
pub mod pointwise;
pub mod ssim;

use crate::film::Image;
use statrs::distribution::{ContinuousCDF, Normal};

/// What a registered metric is computed from (`experiment::metric`).
pub struct Inputs<'a> {
    pub img: &'a Image,
    pub reference: &'a Image,
    pub relmse_eps: f64,
    pub mape_eps: f64,
    /// The tone mapping's exposure (the figures').
    pub exposure: f64,
}

/// A registered metric's computation, as its registry line gives it.
pub type Compute = fn(&Inputs) -> Option<f64>;

/// A one-row image of grey pixels (the metrics' hand-computed cases).
#[cfg(test)]
pub(crate) fn grey(v: &[f64]) -> Image {
    let mut i = Image::new(v.len() as u32, 1);
    for (k, &x) in v.iter().enumerate() {
        i.set(k as u32, 0, [x; 3]);
    }
    i
}

/// A constant `w` x `h` image (the metrics' hand-computed cases).
#[cfg(test)]
pub(crate) fn constant(w: u32, h: u32, v: f64) -> Image {
    let mut i = Image::new(w, h);
    i.data.fill([v; 3]);
    i
}

/// `compute` of `img` against `reference` (exposure 1), for the hand-computed cases.
#[cfg(test)]
pub(crate) fn run(
    compute: Compute,
    img: &Image,
    reference: &Image,
    eps: f64,
    mape_eps: f64,
) -> Option<f64> {
    compute(&Inputs {
        img,
        reference,
        relmse_eps: eps,
        mape_eps,
        exposure: 1.0,
    })
}

/// Asserts `got` is `want` to 1e-12 relative.
#[cfg(test)]
pub(crate) fn close(got: Option<f64>, want: f64, what: &str) {
    let g = got.unwrap_or_else(|| panic!("{what}: no value"));
    assert!(
        (g - want).abs() <= 1e-12 * want.abs().max(1.0),
        "{what}: {g} vs {want}"
    );
}

/// Mean squared error over all pixels and channels.
pub fn mse(img: &Image, reference: &Image) -> f64 {
    assert_eq!((img.width, img.height), (reference.width, reference.height));
    let s: f64 = img
        .data
        .iter()
        .zip(&reference.data)
        .map(|(a, r)| (0..3).map(|c| (a[c] - r[c]).powi(2)).sum::<f64>())
        .sum();
    s / (3.0 * img.data.len() as f64)
}

/// Relative MSE: mean of (x - r)^2 / (r^2 + eps) over pixels and channels. `eps` keeps dark
/// pixels from dominating; always report it with the number (0.01 is common).
pub fn rel_mse(img: &Image, reference: &Image, eps: f64) -> f64 {
    assert_eq!((img.width, img.height), (reference.width, reference.height));
    let s: f64 = img
        .data
        .iter()
        .zip(&reference.data)
        .map(|(a, r)| {
            (0..3)
                .map(|c| (a[c] - r[c]).powi(2) / (r[c] * r[c] + eps))
                .sum::<f64>()
        })
        .sum();
    s / (3.0 * img.data.len() as f64)
}

/// Outcome of comparing two independent renders region by region.
#[derive(Clone, Debug)]
pub struct RegionComparison {
    /// Number of (region, channel) tests.
    pub tests: usize,
    /// The largest |z| and where: (region x, region y, channel).
    pub max_abs_z: f64,
    pub worst: (u32, u32, usize),
    /// Two-sided critical |z| at the requested level, Sidak-corrected over `tests`.
    pub critical_z: f64,
}

impl RegionComparison {
    pub fn passed(&self) -> bool {
        self.max_abs_z < self.critical_z
    }
}

/// z-tests of the region means of two independent renders, each given as its per-pixel mean
/// and variance-of-the-mean images. Region means of many pixels are close to normal, so
/// z = (mean_a - mean_b) / sqrt(var_a + var_b) per region and channel. Regions where both
/// variances are zero must agree to 1e-6 relative. `alpha` is Sidak-corrected.
pub fn compare_regions(
    a: (&Image, &Image),
    b: (&Image, &Image),
    region: u32,
    alpha: f64,
) -> RegionComparison {
    let (w, h) = (a.0.width, a.0.height);
    assert_eq!((w, h), (b.0.width, b.0.height));
    let (rx, ry) = (w.div_ceil(region), h.div_ceil(region));
    let tests = (rx * ry * 3) as usize;
    let mut out = RegionComparison {
        tests,
        max_abs_z: 0.0,
        worst: (0, 0, 0),
        critical_z: 0.0,
    };
    for gy in 0..ry {
        for gx in 0..rx {
            let mut s = [[0.0f64; 3]; 4];
            let mut n = 0.0;
            for y in gy * region..((gy + 1) * region).min(h) {
                for x in gx * region..((gx + 1) * region).min(w) {
                    n += 1.0;
                    for (k, img) in [a.0, a.1, b.0, b.1].iter().enumerate() {
                        let p = img.get(x, y);
                        for c in 0..3 {
                            s[k][c] += p[c];
                        }
                    }
                }
            }
            let [mean_a, var_a, mean_b, var_b] = s;
            for c in 0..3 {
                let diff = (mean_a[c] - mean_b[c]) / n;
                let var = (var_a[c] + var_b[c]) / (n * n);
                let z = if var > 0.0 {
                    diff.abs() / var.sqrt()
                } else if diff.abs() <= 1e-6 * (mean_a[c] / n).abs().max(1e-12) {
                    0.0
                } else {
                    f64::INFINITY
                };
                if z > out.max_abs_z {
                    out.max_abs_z = z;
                    out.worst = (gx, gy, c);
                }
            }
        }
    }
    let a_sidak = 1.0 - (1.0 - alpha).powf(1.0 / tests as f64);
    out.critical_z = Normal::new(0.0, 1.0)
        .expect("standard normal")
        .inverse_cdf(1.0 - a_sidak / 2.0);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn constant(v: f64) -> Image {
        let mut i = Image::new(4, 4);
        i.data.iter_mut().for_each(|p| *p = [v; 3]);
        i
    }

    #[test]
    fn mse_and_rel_mse() {
        let (a, r) = (constant(1.5), constant(1.0));
        assert!((mse(&a, &r) - 0.25).abs() < 1e-12);
        assert!((rel_mse(&a, &r, 0.0) - 0.25).abs() < 1e-12);
        assert!((rel_mse(&a, &r, 1.0) - 0.125).abs() < 1e-12);
    }

    /// Hand-computed on a 2x1 image whose channels all differ, so that a channel or pixel mix-up,
    /// a wrong divisor or the wrong image's value in relMSE's denominator changes the number.
    #[test]
    fn mse_and_rel_mse_by_hand_per_channel() {
        let img = Image {
            width: 2,
            height: 1,
            data: vec![[1.0, 2.0, 3.0], [0.0, 0.5, 4.0]],
        };
        let r = Image {
            width: 2,
            height: 1,
            data: vec![[1.0, 1.0, 1.0], [2.0, 0.5, 2.0]],
        };
        // Squared errors 0, 1, 4 | 4, 0, 4 over 6 values.
        assert!((mse(&img, &r) - 13.0 / 6.0).abs() < 1e-12);
        // Divided by r^2 + 0.5: 1.5, 1.5, 1.5 | 4.5, 0.75, 4.5.
        let want = (1.0 / 1.5 + 4.0 / 1.5 + 4.0 / 4.5 + 4.0 / 4.5) / 6.0;
        assert!((rel_mse(&img, &r, 0.5) - want).abs() < 1e-12);
        // The reference, not the image, is in the denominator.
        assert!((rel_mse(&r, &img, 0.5) - want).abs() > 0.1);
    }

    #[test]
    fn region_comparison_detects_a_shift_larger_than_the_noise() {
        let var = constant(1e-4);
        let same = compare_regions((&constant(1.0), &var), (&constant(1.001), &var), 2, 0.01);
        assert!(same.passed(), "{same:?}");
        let shifted = compare_regions((&constant(1.0), &var), (&constant(1.1), &var), 2, 0.01);
        assert!(!shifted.passed(), "{shifted:?}");
        let zero = constant(0.0);
        assert!(
            compare_regions((&constant(1.0), &zero), (&constant(1.0), &zero), 2, 0.01).passed()
        );
        assert!(
            !compare_regions((&constant(1.0), &zero), (&constant(1.01), &zero), 2, 0.01).passed()
        );
    }

    /// z by hand on a 5x3 image in regions of 2: 3 x 2 regions (the last column and row of
    /// regions clipped to one pixel), 18 tests. Variance of the mean 0.01 per pixel.
    #[test]
    fn region_comparison_by_hand() {
        let filled = |v: f64| {
            let mut i = Image::new(5, 3);
            i.data.iter_mut().for_each(|p| *p = [v; 3]);
            i
        };
        let (a, var) = (filled(1.0), filled(0.01));
        // Ties name the first region and channel.
        let r = compare_regions((&a, &var), (&a, &var), 2, 0.01);
        assert_eq!((r.max_abs_z, r.worst), (0.0, (0, 0, 0)));
        // A 2x2 region: mean difference 0.2 / 4, variance (4 * 0.01 * 2) / 16.
        let mut b = filled(1.0);
        b.data[0][2] = 1.2;
        let r = compare_regions((&a, &var), (&b, &var), 2, 0.01);
        assert_eq!((r.tests, r.worst), (18, (0, 0, 2)));
        assert!((r.max_abs_z - 0.05 / 0.005f64.sqrt()).abs() < 1e-9, "{r:?}");
        // Sidak: 1 - 0.99^(1/18) = 5.582e-4, two-sided: z = 3.45115.
        assert!((r.critical_z - 3.451153).abs() < 1e-5, "{r:?}");
        assert!(r.passed());
        // The clipped corner region, pixel (4, 2) alone: 0.5 / sqrt(0.02) = 3.5355.
        b.data[2 * 5 + 4][1] = 1.5;
        let r = compare_regions((&a, &var), (&b, &var), 2, 0.01);
        assert_eq!(r.worst, (2, 1, 1));
        assert!((r.max_abs_z - 0.5 / 0.02f64.sqrt()).abs() < 1e-9, "{r:?}");
        assert!(!r.passed());
        // At the critical value itself the test rejects (p = alpha).
        let edge = RegionComparison {
            max_abs_z: 2.0,
            critical_z: 2.0,
            ..r
        };
        assert!(!edge.passed());
        // Without noise, region means must agree to 1e-6 relative: in a region of 4 pixels
        // of 1000, a pixel off by 2e-3 moves the mean 5e-7 relative, one off by 8e-3, 2e-6.
        let zero = filled(0.0);
        let (a, mut b) = (filled(1000.0), filled(1000.0));
        b.data[1][0] += 2e-3;
        let r = compare_regions((&a, &zero), (&b, &zero), 2, 0.01);
        assert!(r.passed() && r.max_abs_z == 0.0, "{r:?}");
        b.data[1][0] += 6e-3;
        let r = compare_regions((&a, &zero), (&b, &zero), 2, 0.01);
        assert!(!r.passed() && r.worst == (0, 0, 0), "{r:?}");
    }
}

#[cfg(test)]
mod reference_tests {
    /// SSIM and FLIP of a 4 spp Cornell box against its 4096 spp reference (8-bit sRGB PNGs
    /// in tests/data/metrics) equal the values of scikit-image 0.26.0 and of NVIDIA's
    /// flip-evaluator 1.7 (`experiments/metrics_reference.py` prints them).
    #[test]
    fn ssim_and_flip_match_reference_implementations() {
        let load = |name: &str| {
            let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("tests/data/metrics")
                .join(name);
            image::open(&p).unwrap().into_rgb8()
        };
        let (r, t) = (load("reference.png"), load("test.png"));
        let (w, h) = r.dimensions();
        let unit = |i: &image::RgbImage| -> Vec<[f64; 3]> {
            i.pixels().map(|p| p.0.map(|c| c as f64 / 255.0)).collect()
        };
        let s = super::ssim::ssim(&unit(&t), &unit(&r), w as usize, h as usize).unwrap();
        assert!((s - 0.8861945720).abs() < 1e-9, "SSIM {s}");
        let f = super::flip::flip_srgb8(t.as_raw(), r.as_raw(), w, h);
        assert!((f - 0.0478728116).abs() < 1e-6, "FLIP {f}");
        // A different image must not pass: the reference against itself scores 0.
        assert_eq!(super::flip::flip_srgb8(r.as_raw(), r.as_raw(), w, h), 0.0);
    }
}
