//! End to end through `directlab integrands` at a reduced size: the report has a slope row
//! per (integrand, sampler) with a published rate where the paper has one, the CSV a row
//! per (integrand, sampler, N), a chart per integrand; bad arguments are refused.

use crate::common;

use common::{directlab, run, scratch};

#[test]
fn integrands_report_rates_against_the_published_ones() {
    let out = scratch("integrands");
    let o = run(directlab().args([
        "integrands",
        "--seeds",
        "24",
        "--max-n",
        "256",
        "--samplers",
        "independent,sobol,sobol-xor",
        "--out",
        out.to_str().unwrap(),
    ]));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let dir = out.join("integrands");
    let md = std::fs::read_to_string(dir.join("index.md")).unwrap();
    let rows: Vec<&str> = md
        .lines()
        .filter(|l| {
            l.starts_with("| ") && !l.starts_with("| integrand |") && l.matches('|').count() == 8
        })
        .collect();
    assert_eq!(rows.len(), 5 * 3, "{md}");
    for integrand in ["quarter disk", "triangle", "step", "Gaussian", "bilinear"] {
        let row = |s: &str| {
            rows.iter()
                .find(|r| r.starts_with(&format!("| {integrand} | {s} |")))
                .unwrap_or_else(|| panic!("no row for {integrand}, {s}: {md}"))
                .to_string()
        };
        assert!(
            row("independent").contains("| -0.50 |"),
            "{}",
            row("independent")
        );
        assert!(row("sobol-xor").contains("no published rate"));
        let slug = integrand.to_lowercase().replace(' ', "-");
        for ext in ["png", "svg"] {
            assert!(
                dir.join(format!("rmse-{slug}.{ext}")).is_file(),
                "{slug}.{ext}"
            );
        }
    }
    // The pixel check: every case, strategy and sampler (all of them, with sobol:padded),
    // and a chart per case.
    for case in ["unoccluded", "penumbra"] {
        for strategy in ["light", "BSDF", "MIS power"] {
            for sampler in ["independent", "zsobol", "sobol:padded"] {
                let head = format!("| {case} | {strategy} | {sampler} | -");
                assert!(md.contains(&head), "no row {head}: {md}");
            }
        }
        assert!(dir.join(format!("pixel-{case}.png")).is_file());
    }
    let csv = std::fs::read_to_string(dir.join("results.csv")).unwrap();
    // Counts 16, 23, 32, 45, 64, 91, 128, 181, 256.
    assert_eq!(csv.lines().count(), 1 + 5 * 3 * 9, "{csv}");

    for (args, want) in [
        (vec!["--seeds", "1"], "--seeds 1"),
        (vec!["--max-n", "20"], "--max-n 20"),
        (vec!["--samplers", "sobl"], "sobl"),
    ] {
        let o = run(directlab()
            .arg("integrands")
            .args(&args)
            .args(["--out", out.to_str().unwrap()]));
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains(want), "{args:?}: {err}");
    }
    std::fs::remove_dir_all(&out).unwrap();
}
