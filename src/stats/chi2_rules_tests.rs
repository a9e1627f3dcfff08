//! The chi-square test's bookkeeping rules checked on hand-made inputs: Nori's pooling with
//! hand-computed statistics, what counts as an expected count of zero, and the tolerance
//! for stray and lost samples at its exact limit.

use super::*;

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-12 * b.abs().max(1.0)
}

#[test]
fn pooling_matches_hand_computed_statistics() {
    // Expected 2 and 3 pool to exactly 5 (obs 3 + 4): a pool that has reached the minimum
    // takes no more, so 7 and 8 stay on their own.
    let mut a = vec![(9.0, 7.0), (3.0, 2.0), (6.0, 8.0), (4.0, 3.0)];
    let p = pearson(&mut a, 5.0).unwrap();
    let want = 4.0 / 5.0 + 4.0 / 7.0 + 4.0 / 8.0;
    assert!(close(p.statistic, want) && p.dof == 2, "{p:?} vs {want}");
    // Expected counts of exactly the minimum are not pooled.
    let mut b = vec![(4.0, 5.0), (7.0, 5.0), (9.0, 7.0)];
    let p = pearson(&mut b, 5.0).unwrap();
    let want = 1.0 / 5.0 + 4.0 / 5.0 + 4.0 / 7.0;
    assert!(close(p.statistic, want) && p.dof == 2, "{p:?} vs {want}");
    // A pool still below the minimum takes the next category: 1 + 2 < 5, + 4 = 7.
    let mut c = vec![(2.0, 1.0), (1.0, 2.0), (6.0, 4.0), (10.0, 9.0)];
    let p = pearson(&mut c, 5.0).unwrap();
    let want = 4.0 / 7.0 + 1.0 / 9.0;
    assert!(close(p.statistic, want) && p.dof == 1, "{p:?} vs {want}");
}

fn result(observed: &[f64], expected: &[f64], lost: u64, pdf_integral: f64) -> Chi2Result {
    let n = observed.len();
    Chi2Result {
        domain: "test",
        axes: ["u", "v"],
        statistic: 0.0,
        dof: 0,
        p_value: 1.0,
        threshold: 0.01,
        verdict: Verdict::Pass,
        reason: String::new(),
        observed: Grid {
            cols: n,
            rows: 1,
            data: observed.to_vec(),
        },
        expected: Grid {
            cols: n,
            rows: 1,
            data: expected.to_vec(),
        },
        samples: 100_000,
        lost,
        outside: 0,
        pdf_integral,
    }
}

/// N = 1e5, tolerance 1e-4: up to 10 strays or losses are forgiven, 11 are not; expected
/// counts at or below 1e-12 N = 1e-7 are zero, just above it they are categories.
#[test]
fn zero_expectations_and_the_stray_tolerance_at_their_limits() {
    let cfg = Chi2Config {
        samples: 100_000,
        zero_tolerance: 1e-4,
        ..Chi2Config::default()
    };
    let cats = |o: &[f64], e: &[f64], lost: u64, integral: f64| {
        categories(&result(o, e, lost, integral), &cfg)
    };
    let e = [50_000.0, 50_000.0, 1e-7, 2e-7];
    let ok = cats(&[49_990.0, 50_000.0, 10.0, 0.0], &e, 0, 1.0).unwrap();
    assert_eq!(
        ok.len(),
        3,
        "{ok:?}: the cell at 1e-7 is zero, the one at 2e-7 is not"
    );
    let err = cats(&[49_989.0, 50_000.0, 11.0, 0.0], &e, 0, 1.0).unwrap_err();
    assert!(err.contains("11 samples in cell (col 2, row 0)"), "{err}");
    // Empty cells where the pdf is zero are fine at any tolerance, 0 included.
    let strict = Chi2Config {
        zero_tolerance: 0.0,
        ..cfg
    };
    let r = result(
        &[50_000.0, 50_000.0, 0.0],
        &[50_000.0, 50_000.0, 0.0],
        0,
        1.0,
    );
    assert_eq!(categories(&r, &strict).unwrap().len(), 2);

    // Losses when the pdf leaves no room for them: 5 and 10 forgiven, 11 not.
    let e = [50_000.0, 50_000.0];
    for lost in [5, 10] {
        let c = cats(&[49_995.0, 50_000.0], &e, lost, 1.0).unwrap();
        assert_eq!(c.len(), 2, "{lost} lost: {c:?}");
    }
    let err = cats(&[49_989.0, 50_000.0], &e, 11, 1.0).unwrap_err();
    assert!(err.contains("failed (returned None) 11 times"), "{err}");
    // When the pdf integrates below 1, losses are a category of their own.
    let c = cats(&[49_000.0, 49_000.0], &[49_500.0, 49_500.0], 2000, 0.99).unwrap();
    assert_eq!(c.len(), 3);
    assert!(close(c[2].0, 2000.0) && close(c[2].1, 1000.0), "{c:?}");
}
