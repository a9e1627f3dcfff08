//! Every registered metric, computed through its registry line (so the line's function,
//! epsilon and tone mapping are checked too), against its hand-computed case, which lives
//! beside the metric (`src/metrics/`) and which the line must name.

use super::*;

#[test]
fn every_registered_metric_passes_its_hand_computed_case() {
    let registered: Vec<&str> = EXTRA_METRICS.iter().map(|d| d.slug).collect();
    let cased: Vec<&str> = HAND.iter().map(|c| c.0).collect();
    assert_eq!(registered, cased);
    for (d, (slug, case)) in EXTRA_METRICS.iter().zip(HAND) {
        eprintln!("hand-computed case of {slug}");
        case(d.compute);
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
