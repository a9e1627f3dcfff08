//! Every registered metric, computed through its registry line (so the line's function,
//! epsilon and tone mapping are checked too), against values worked out by hand. A metric
//! registered without a case here fails `every_registered_metric_has_a_hand_computed_case`.

use super::*;
use crate::film::linear_to_srgb;

/// A one-row image of grey pixels.
fn grey(v: &[f64]) -> Image {
    let mut i = Image::new(v.len() as u32, 1);
    for (k, &x) in v.iter().enumerate() {
        i.set(k as u32, 0, [x; 3]);
    }
    i
}

/// A constant `w` x `h` image.
fn constant(w: u32, h: u32, v: f64) -> Image {
    let mut i = Image::new(w, h);
    i.data.fill([v; 3]);
    i
}

fn run(m: ErrorMetric, img: &Image, reference: &Image, eps: f64, mape_eps: f64) -> Option<f64> {
    (m.def().unwrap().compute)(&Inputs {
        img,
        reference,
        relmse_eps: eps,
        mape_eps,
        exposure: 1.0,
    })
}

fn close(got: Option<f64>, want: f64, what: &str) {
    let g = got.unwrap_or_else(|| panic!("{what}: no value"));
    assert!(
        (g - want).abs() <= 1e-12 * want.abs().max(1.0),
        "{what}: {g} vs {want}"
    );
}

/// Hand-computed cases, one per registered metric.
const HAND: &[(&str, fn())] = &[
    ("trimmed-relmse", || {
        // 2000 pixels of 1.0 against 1.0 except one firefly of 11: 6000 terms, 0.1 % is 6,
        // the firefly's three channels and three zeros: nothing is left.
        let r = constant(2000, 1, 1.0);
        let mut x = r.clone();
        x.data[7] = [11.0; 3];
        close(
            run(ErrorMetric::TrimmedRelmse, &x, &r, 0.01, 0.5),
            0.0,
            "firefly trimmed",
        );
        // An error everywhere is kept: (0.1^2 / 1.01) per term, whichever 6 are dropped.
        let y = constant(2000, 1, 1.1);
        close(
            run(ErrorMetric::TrimmedRelmse, &y, &r, 0.01, 0.5),
            0.01 / 1.01,
            "uniform error",
        );
    }),
    ("mape", || {
        let (r, x) = (grey(&[1.0, 0.0, 2.0, 0.5]), grey(&[1.5, 0.1, 2.0, 0.0]));
        let want = (0.5 / 1.01 + 0.1 / 0.01 + 0.0 + 0.5 / 0.51) / 4.0;
        close(run(ErrorMetric::Mape, &x, &r, 0.5, 0.01), want, "mape");
    }),
    ("smape", || {
        let (r, x) = (grey(&[1.0, 0.0, 2.0, 0.5]), grey(&[1.5, 0.1, 2.0, 0.0]));
        let want = (0.5 / 2.51 + 0.1 / 0.11 + 0.0 + 0.5 / 0.51) / 4.0;
        close(run(ErrorMetric::Smape, &x, &r, 0.5, 0.01), want, "smape");
    }),
    ("ssim", || {
        // Constant images: SSIM is the luminance term (2 a b + C1) / (a^2 + b^2 + C1) of the
        // tone-mapped values, C1 = (0.01)^2; 1-SSIM is reported.
        let (a, b) = (linear_to_srgb(0.5), linear_to_srgb(0.25));
        let c1 = 1e-4;
        let want = 1.0 - (2.0 * a * b + c1) / (a * a + b * b + c1);
        close(
            run(
                ErrorMetric::Ssim,
                &constant(12, 12, 0.5),
                &constant(12, 12, 0.25),
                0.01,
                0.01,
            ),
            want,
            "ssim",
        );
        // A film smaller than the 11x11 window: the metric does not apply.
        assert_eq!(
            run(
                ErrorMetric::Ssim,
                &constant(4, 4, 0.5),
                &constant(4, 4, 0.25),
                0.01,
                0.01
            ),
            None
        );
    }),
    ("flip", || {
        // Identical images: no difference. (Its value on a real pair equals NVIDIA's own
        // implementation: `metrics::reference_tests`.)
        let a = constant(16, 16, 0.3);
        close(
            run(ErrorMetric::Flip, &a, &a, 0.01, 0.01),
            0.0,
            "flip of identical images",
        );
        let b = constant(16, 16, 0.6);
        let d = run(ErrorMetric::Flip, &a, &b, 0.01, 0.01).unwrap();
        assert!(d > 0.0 && d <= 1.0, "flip {d}");
    }),
];

#[test]
fn every_registered_metric_has_a_hand_computed_case() {
    let registered: Vec<&str> = EXTRA_METRICS.iter().map(|d| d.slug).collect();
    let cased: Vec<&str> = HAND.iter().map(|c| c.0).collect();
    assert_eq!(
        registered, cased,
        "one hand-computed case per registered metric, in order"
    );
    for (slug, case) in HAND {
        eprintln!("hand-computed case of {slug}");
        case();
    }
}

#[test]
fn names_parse_back_and_labels_state_what_defines_the_metric() {
    for name in ErrorMetric::names() {
        let m: ErrorMetric = name.parse().unwrap();
        assert_eq!(m.slug(), name);
    }
    let e = "psnr".parse::<ErrorMetric>().unwrap_err();
    assert!(
        e.contains("unknown metric 'psnr': expected one of mse, relmse, trimmed-relmse"),
        "{e}"
    );
    assert_eq!(
        ErrorMetric::Relmse.label(0.01, 0.1, 2.0),
        "relMSE (eps 0.01)"
    );
    assert_eq!(
        ErrorMetric::TrimmedRelmse.label(0.01, 0.1, 2.0),
        "trimmed relMSE (eps 0.01, largest 0.1 % dropped)"
    );
    assert_eq!(
        ErrorMetric::Smape.label(0.01, 0.1, 2.0),
        "SMAPE (eps 0.1, no factor 2)"
    );
    assert_eq!(
        ErrorMetric::Flip.label(0.01, 0.1, 2.0),
        "FLIP (sRGB at exposure 2, clamped, 67 ppd)"
    );
    // Each line stores and reads its own column.
    for d in EXTRA_METRICS {
        let mut r = crate::experiment::results::test_row("s", 1, 0);
        (d.set)(&mut r, Some(0.25));
        assert_eq!((d.value)(&r), Some(0.25), "{}", d.slug);
        for o in EXTRA_METRICS.iter().filter(|o| o.slug != d.slug) {
            assert_eq!((o.value)(&r), None, "{} wrote {}'s column", d.slug, o.slug);
        }
    }
}
