//! Issue 6 end to end: every extreme case renders finite samples whose mean matches its
//! closed form, degenerate input gives its documented error or warning, and the report
//! command writes its files.
//!
//! Significance: two-sided z-tests at family-wise alpha = 1e-3, Šidák-corrected over the
//! rows of each test, as the render tests. A strategy a case declares blind to part of its
//! integrand (e.g. BSDF sampling of a 1e-8 sr light) is checked for finiteness only.

use directlab::extreme::cases::all_cases;
use directlab::extreme::measure::{z_critical, ALPHA};
use directlab::extreme::{accumulate, build, invalid, report_strategies, run_cases, Row};
use std::path::{Path, PathBuf};

fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/extreme")
}

fn check(rows: &[Row], what: &str) {
    let tested: Vec<&Row> = rows.iter().filter(|r| r.blind.is_none()).collect();
    let zc = z_critical(ALPHA, tested.len());
    let mut failures = Vec::new();
    for r in rows {
        assert_eq!(
            r.m.non_finite,
            0,
            "{} {}: non-finite samples",
            r.case,
            r.strategy.label()
        );
    }
    for r in tested {
        if r.m.z.abs() >= zc || r.m.z.is_nan() {
            failures.push(format!(
                "{} {}: mean {:e} vs {:e} ({}), z = {:.2}",
                r.case,
                r.strategy.label(),
                r.m.mean,
                r.reference,
                r.reference_from,
                r.m.z
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "{what}: |z| >= {zc:.2} in {} rows:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// 2^15 samples per (case, strategy): 28 cases x 7 strategies in a few seconds.
#[test]
fn every_case_is_finite_and_matches_its_reference() {
    let cases = all_cases(&scenes());
    let scenes = build(&cases).expect("every case builds with its expected warnings");
    let rows = run_cases(&cases, &scenes, &report_strategies(), 1 << 15, 21);
    check(&rows, "extreme cases");
}

/// The guards that drop a light sample (zero distance, cos_light <= 0, infinite or zero pdf)
/// act where the integrand's measure vanishes, so they must not move the mean: the cases where
/// they fire most (a light seen edge-on, receivers next to a light's edge, a grazing camera),
/// with more samples (2^18) for the strategies that rely on them.
#[test]
fn sample_guards_leave_the_mean_unbiased() {
    let cases: Vec<_> = all_cases(&scenes())
        .into_iter()
        .filter(|c| {
            [
                "light-edge-on",
                "light-at-89.9deg",
                "camera-at-89.9deg",
                "huge-dim",
            ]
            .contains(&c.name.as_str())
        })
        .collect();
    assert_eq!(cases.len(), 4);
    let scenes = build(&cases).unwrap();
    let s = report_strategies();
    let rows = run_cases(&cases, &scenes, &[s[0], s[1], s[4]], 1 << 18, 5);
    check(&rows, "guards");
}

#[test]
fn degenerate_and_invalid_input_give_the_documented_outcome() {
    for o in invalid::check_all(&scenes()) {
        assert!(
            o.ok,
            "{}: expected {} containing '{}', got: {}",
            o.input, o.expect, o.must_contain, o.message
        );
    }
}

/// 2 x 2 pixels at 2e5 spp through `render`: the f64 mean is the exact mean of the samples.
#[test]
fn high_sample_counts_keep_the_mean_exact() {
    let c = accumulate::case();
    let scene = directlab::scene::Scene::build(c.desc.clone()).unwrap();
    for s in [report_strategies()[0], report_strategies()[4]] {
        let a = accumulate::measure(&c, &scene, s, 200_000, 3);
        assert_eq!(a.non_finite, 0);
        assert!(
            a.f64_rel_error < 1e-12,
            "{}: {}",
            a.strategy,
            a.f64_rel_error
        );
        assert!(
            a.z.abs() < z_critical(ALPHA, 2),
            "{}: z = {}",
            a.strategy,
            a.z
        );
    }
}

#[test]
fn extreme_command_writes_report_csv_and_figure() {
    let out = std::env::temp_dir().join(format!("directlab-extreme-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_directlab"))
        .args(["extreme", "--quick", "--threads", "2"])
        .arg("--out")
        .arg(&out)
        .arg("--scenes")
        .arg(scenes())
        .status()
        .expect("run directlab");
    assert!(status.success());
    let index = std::fs::read_to_string(out.join("index.md")).unwrap();
    assert!(
        index.contains("| tiny-bright | light-e1-uni-area | 0 |"),
        "{index}"
    );
    assert!(index.contains("## Invalid and degenerate input"));
    let csv = std::fs::read_to_string(out.join("extreme.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 28 * report_strategies().len());
    let png = std::fs::read(out.join("convergence.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
}
