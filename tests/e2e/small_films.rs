//! Films too small for a rule: a 1x1 film still flags a biased strategy and says which
//! metrics do not apply; a 1x1 film at one sample per run keeps one sampler and says why.

use crate::common;
use crate::experiment_cli::FURNACE;
use common::{directlab, run, scratch};
use std::path::{Path, PathBuf};

/// The furnace on a 1x1 film, and `experiment` (TOML) beside it; returns the experiment file.
fn one_pixel(out: &Path, experiment: &str) -> PathBuf {
    let one = FURNACE
        .replace(r#"name="width" value="6""#, r#"name="width" value="1""#)
        .replace(r#"name="height" value="4""#, r#"name="height" value="1""#);
    std::fs::write(out.join("furnace.xml"), one).unwrap();
    let exp = out.join("furnace.toml");
    std::fs::write(&exp, experiment).unwrap();
    exp
}

/// A 1x1 film at one sample per run: every sampler draws one uniform point, so stratified and
/// sobol are left out as the same estimator as independent (stderr and a `left_out` event
/// each), and trimmed relMSE, which would trim nothing from three terms, is an empty value
/// with its reason.
#[test]
fn a_one_sample_film_keeps_one_sampler_and_says_why() {
    let out = scratch("one-sample");
    let exp = one_pixel(
        &out,
        r#"
scene = "furnace.xml"
spp = [1]
seeds = 3
samplers = ["independent", "stratified", "sobol"]
[reference]
value = 1.5
[metrics]
report = ["trimmed-relmse"]
[[strategy]]
name = "light"
strategy = "light"
"#,
    );
    let o = run(directlab()
        .args(["run", exp.to_str().unwrap(), "--json", "--out"])
        .arg(&out));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    for s in ["stratified", "sobol"] {
        let line = format!("leaving out 'light, {s}'");
        assert!(err.contains(&line), "{err}");
    }
    assert!(err.contains("uniform under every sampler"), "{err}");
    let events: Vec<serde_json::Value> = String::from_utf8_lossy(&o.stdout)
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
        .collect();
    let left: Vec<&str> = events
        .iter()
        .filter(|v| v["event"] == "left_out")
        .map(|v| v["strategy"].as_str().unwrap())
        .collect();
    assert_eq!(left, ["light, stratified", "light, sobol"]);
    let rows: Vec<&serde_json::Value> = events.iter().filter(|v| v["event"] == "result").collect();
    assert_eq!(rows.len(), 3, "one column, three seeds");
    assert!(rows.iter().all(|v| v["row"]["not_applicable"]
        .as_str()
        .unwrap()
        .starts_with("trimmed-relmse: the film has under 334 pixels")));
    let metrics = std::fs::read_to_string(out.join("furnace/metrics.csv")).unwrap();
    let trimmed: Vec<&str> = metrics
        .lines()
        .filter(|l| l.contains(",trimmed-relmse,"))
        .collect();
    assert_eq!(trimmed.len(), 3, "{metrics}");
    assert!(
        trimmed
            .iter()
            .all(|l| l.contains(",,\"the film has under 334 pixels")),
        "{metrics}"
    );
    let index = std::fs::read_to_string(out.join("furnace/index.md")).unwrap();
    assert!(index.contains("uniform under every sampler"), "{index}");
    std::fs::remove_dir_all(&out).unwrap();
}

/// A 1x1 film: a strategy 10 % off (against a reference of 1.65 where the furnace is 1.5) is
/// flagged DIFFERENT, not excused as an unsampled tail (0.1 % of one pixel is all of it), and
/// 1-SSIM, whose window does not fit, is an empty value with its reason in metrics.csv and
/// in the --json rows, never NaN.
#[test]
fn a_one_pixel_film_still_flags_a_bias_and_says_what_does_not_apply() {
    let out = scratch("one-pixel");
    let exp = one_pixel(
        &out,
        r#"
scene = "furnace.xml"
spp = [64, 16384]
seeds = 2
[reference]
value = 1.65
[metrics]
report = ["ssim"]
[[strategy]]
name = "light"
strategy = "light"
"#,
    );
    let o = run(directlab()
        .args(["run", exp.to_str().unwrap(), "--json", "--out"])
        .arg(&out));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    let check = err
        .lines()
        .find(|l| l.contains("same expectation, light"))
        .unwrap_or_else(|| panic!("{err}"));
    assert!(check.contains("DIFFERENT"), "{check}");
    let index = std::fs::read_to_string(out.join("furnace/index.md")).unwrap();
    assert!(index.contains("the tail rule does not apply"), "{index}");
    let metrics = std::fs::read_to_string(out.join("furnace/metrics.csv")).unwrap();
    let ssim: Vec<&str> = metrics.lines().filter(|l| l.contains(",1-ssim,")).collect();
    assert_eq!(ssim.len(), 4, "{metrics}");
    assert!(
        ssim.iter()
            .all(|l| l.ends_with(",,the film is smaller than SSIM's 11x11 window")),
        "{metrics}"
    );
    assert!(!metrics.contains("NaN"), "{metrics}");
    let results = String::from_utf8_lossy(&o.stdout);
    let rows: Vec<serde_json::Value> = results
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
        .filter(|v| v["event"] == "result")
        .collect();
    assert_eq!(rows.len(), 4);
    assert!(rows.iter().all(|v| v["row"]["not_applicable"]
        .as_str()
        .unwrap()
        .starts_with("ssim: the film is smaller")));
    std::fs::remove_dir_all(&out).unwrap();
}
