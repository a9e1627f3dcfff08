//! FLIP (Andersson et al. 2020), NVIDIA's perceptual difference of two LDR images, through
//! the nv-flip crate (bindings to NVIDIA's C++ code). FLIP takes 8-bit sRGB: the HDR renders
//! are tone-mapped first as every figure is (exposure, clamp to [0, 1], the sRGB curve, 8
//! bits; [`crate::film::to_srgb8`]), and the metric is the mean of FLIP's error map at 67
//! pixels per degree (its default viewing condition).

use crate::film::{to_srgb8, Image};

/// Mean FLIP error of `img` against `reference`, both shown at `exposure`.
pub fn flip(img: &Image, reference: &Image, exposure: f64) -> f64 {
    let (w, h) = (img.width, img.height);
    assert_eq!((w, h), (reference.width, reference.height));
    flip_srgb8(
        &to_srgb8(img, exposure),
        &to_srgb8(reference, exposure),
        w,
        h,
    )
}

/// Mean FLIP error of two 8-bit sRGB images (row-major RGB triples).
pub fn flip_srgb8(test: &[u8], reference: &[u8], width: u32, height: u32) -> f64 {
    let map = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(width, height, reference),
        nv_flip::FlipImageRgb8::with_data(width, height, test),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    );
    let v = map.to_vec();
    v.iter().map(|&e| e as f64).sum::<f64>() / v.len().max(1) as f64
}

/// The case of the registered FLIP, run through its registry line. (Its value on a real pair
/// equals NVIDIA's own implementation: `metrics::reference_tests`.)
#[cfg(test)]
pub(crate) mod hand {
    use crate::metrics::{close, constant, run, Compute};

    pub(crate) fn flip(compute: Compute) {
        let a = constant(16, 16, 0.3);
        close(
            run(compute, &a, &a, 0.01, 0.01),
            0.0,
            "flip of identical images",
        );
        let b = constant(16, 16, 0.6);
        let d = run(compute, &a, &b, 0.01, 0.01).unwrap();
        assert!(d > 0.0 && d <= 1.0, "flip {d}");
    }
}
