//! End to end through `directlab run --quick`, as a user runs it: results, plots and report
//! appear, and a second run resumes instead of rendering again.

use crate::common;

use common::{directlab, repo, run, scratch};
use std::path::Path;
use std::process::Output;

/// A closed cube whose inside emits radiance 1 and reflects half: 1.5 in every pixel.
pub(crate) const FURNACE: &str = r#"<scene version="3.0.0">
    <sensor type="perspective">
        <float name="fov" value="60"/>
        <film type="hdrfilm">
            <integer name="width" value="6"/>
            <integer name="height" value="4"/>
        </film>
    </sensor>
    <shape type="cube">
        <boolean name="flip_normals" value="true"/>
        <transform name="to_world"><scale value="2"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf>
        <emitter type="area"><rgb name="radiance" value="1"/></emitter>
    </shape>
</scene>"#;

/// `directlab run EXP --out OUT`, which must succeed.
fn run_ok(exp: &Path, out: &Path) {
    let o = run(directlab().args(["run", exp.to_str().unwrap(), "--out", out.to_str().unwrap()]));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

pub(crate) fn run_quick(exp: &str, out: &Path) -> Output {
    run(directlab()
        .args([
            "run",
            repo(exp).to_str().unwrap(),
            "--quick",
            "--threads",
            "2",
        ])
        .arg("--out")
        .arg(out))
}

#[test]
fn quick_experiment_writes_results_plots_report_and_resumes() {
    let out = scratch("fig2");
    let first = run_quick("experiments/fig2.toml", &out);
    assert!(first.status.success());
    let dir = out.join("fig2-quick");
    let csv = std::fs::read_to_string(dir.join("results.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    // [quick]: 2 strategies x spp [1, 4, 16] x 2 seeds, plus one equal-time run per strategy.
    assert_eq!(rows.len(), 2 * 3 * 2 + 2, "{csv}");
    let header = csv.lines().next().unwrap();
    for col in [
        "strategy",
        "spp",
        "seed",
        "mse",
        "relmse",
        "relmse_eps",
        "seconds",
        "samples_per_s",
        "mean_r",
    ] {
        assert!(
            header.split(',').any(|c| c == col),
            "no column {col}: {header}"
        );
    }
    assert!(
        rows.iter().all(|r| r.contains(",0.01,")),
        "epsilon stated per row"
    );
    for f in [
        "convergence.png",
        "convergence.svg",
        "error_vs_time.png",
        "error_vs_time.svg",
        "error_vs_cost.png",
        "error_vs_cost.svg",
        "efficiency.png",
        "efficiency.svg",
        "equal_spp.png",
        "equal_time_0.02s.png",
        "variance.png",
        "index.md",
    ] {
        assert!(dir.join(f).exists(), "missing {f}");
    }
    // The metrics beside MSE and relMSE: a column each, a plot each, and metrics.csv with
    // one row per run and metric naming its epsilon and tone mapping.
    for col in [
        "trimmed_relmse",
        "mape",
        "smape",
        "mape_eps",
        "ssim_error",
        "flip",
        "exposure",
    ] {
        assert!(header.split(',').any(|c| c == col), "no column {col}");
    }
    for m in ["trimmed-relmse", "mape", "smape", "ssim", "flip"] {
        assert!(dir.join(format!("convergence-{m}.png")).exists(), "{m}");
    }
    let long = std::fs::read_to_string(dir.join("metrics.csv")).unwrap();
    assert!(long.starts_with(
        "case,strategy,name,kind,budget_s,spp,seed,metric,epsilon,tone_mapping,value,note"
    ));
    assert_eq!(long.lines().count() - 1, rows.len() * 7, "{long}");
    for (metric, eps, tm) in [
        ("mse", "", "linear"),
        ("relmse", "0.01", "linear"),
        ("trimmed-relmse", "0.01", "linear"),
        ("mape", "0.01", "linear"),
        ("smape", "0.01", "linear"),
        ("1-ssim", "", "exposure 1; clamp to [0 1]; sRGB"),
        ("flip", "", "exposure 1; clamp to [0 1]; sRGB"),
    ] {
        let line = long
            .lines()
            .find(|l| l.contains(&format!(",{metric},{eps},{tm},")))
            .unwrap_or_else(|| panic!("no {metric} row with eps '{eps}' and '{tm}'"));
        // The value, then an empty note (every metric applies to this film).
        assert!(line.ends_with(','), "{line}");
        let v: f64 = line.rsplit(',').nth(1).unwrap().parse().unwrap();
        assert!(v.is_finite() && v >= 0.0, "{line}");
        if metric == "1-ssim" || metric == "flip" || metric == "smape" {
            assert!(v <= 1.0, "{line}");
        }
    }
    let index = std::fs::read_to_string(dir.join("index.md")).unwrap();
    assert!(index.contains("## Left out") && index.contains("noise floor"));
    assert!(index.contains("convergence.png"));
    // Every run counted and modelled: the section, a row per strategy, the code path stated.
    assert!(index.contains("## Counted cost") && index.contains("error_vs_cost.png"));
    assert!(index.contains("Code path: every strategy and sampler ran in the same lane kernel"));
    let counted = &index[index.find("## Counted cost").unwrap()..];
    let table_rows = counted
        .lines()
        .skip_while(|l| !l.starts_with("|---"))
        .skip(1)
        .take_while(|l| l.starts_with('|'))
        .count();
    assert_eq!(table_rows, 2, "{counted}");
    for col in ["camera_rays", "shadow_rays", "bsdf_evals", "choice_evals"] {
        assert!(header.split(',').any(|c| c == col), "no column {col}");
    }
    let root = std::fs::read_to_string(out.join("index.md")).unwrap();
    assert!(root.contains("fig2-quick/index.md"), "{root}");
    let stdout = String::from_utf8_lossy(&first.stdout);
    assert!(
        stdout.contains("95% CI"),
        "mean difference printed: {stdout}"
    );
    assert!(stdout.contains("(14 rendered now)"), "{stdout}");

    // Resume: nothing is rendered again and the rows are kept as they were.
    let second = run_quick("experiments/fig2.toml", &out);
    assert!(second.status.success());
    let stdout = String::from_utf8_lossy(&second.stdout);
    assert!(stdout.contains("(0 rendered now)"), "{stdout}");
    let stderr = String::from_utf8_lossy(&second.stderr);
    assert!(stderr.contains("cached"), "reference reused: {stderr}");
    assert_eq!(
        std::fs::read_to_string(dir.join("results.csv")).unwrap(),
        csv
    );

    // An interrupted sweep: drop the last sweep rows; only they are rendered again.
    let kept: Vec<&str> = csv.lines().take(1 + 10).collect();
    std::fs::write(dir.join("results.csv"), kept.join("\n") + "\n").unwrap();
    let third = run_quick("experiments/fig2.toml", &out);
    assert!(third.status.success());
    let stdout = String::from_utf8_lossy(&third.stdout);
    assert!(stdout.contains("(4 rendered now)"), "{stdout}");
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn scene_with_one_emitter_leaves_out_power_choice_with_its_reason() {
    let out = scratch("leftout");
    let exp = out.join("one-light.toml");
    let scene = repo("scenes/cbox/cbox.xml");
    std::fs::write(
        &exp,
        format!(
            r#"
scene = "{}"
defines = {{ res = "8" }}
spp = [1, 2]
seeds = 1
[reference]
spp = 16
[[strategy]]
name = "uniform"
strategy = "light"
[[strategy]]
name = "power"
strategy = "light"
emitter_selection = "power"
[[strategy]]
name = "tree"
strategy = "light"
emitter_selection = "bvh"
[[strategy]]
name = "oracle"
strategy = "light"
emitter_selection = "exhaustive"
"#,
            scene.display().to_string().replace('\\', "/")
        ),
    )
    .unwrap();
    run_ok(&exp, &out);
    // Again with --json: each strategy left out is an event with its reason.
    let o = run(directlab()
        .args(["run", exp.to_str().unwrap(), "--json", "--out"])
        .arg(&out));
    assert!(o.status.success());
    let left: Vec<serde_json::Value> = String::from_utf8_lossy(&o.stdout)
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
        .filter(|v| v["event"] == "left_out")
        .collect();
    let names: Vec<&str> = left
        .iter()
        .map(|v| v["strategy"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["power", "tree", "oracle"], "{left:?}");
    assert!(left
        .iter()
        .all(|v| v["reason"].as_str().unwrap().contains("pmf 1")));
    let index = std::fs::read_to_string(out.join("one-light/index.md")).unwrap();
    assert!(
        index.contains("**power** (`light-e1-pow-area`): identical to 'uniform'"),
        "{index}"
    );
    assert!(index.contains("one emitter"));
    let csv = std::fs::read_to_string(out.join("one-light/results.csv")).unwrap();
    assert_eq!(
        csv.lines().count(),
        1 + 2,
        "only the kept strategy runs: {csv}"
    );
    std::fs::remove_dir_all(&out).unwrap();
}

/// A closed-form reference in an image sweep: the inside of an emitting diffuse cube (L = 1,
/// albedo 0.5) is exactly 1.5 in every pixel, so `[reference] value = 1.5` replaces a render:
/// no noise floor, and the measured mean agrees with it (|z| <= 4.9: alpha = 1e-6 per test,
/// 2 strategies x 2 spp x 3 channels = 12 tests, family-wise < 1.2e-5; BSDF sampling is
/// exact here, with zero variance).
#[test]
fn image_sweep_with_a_constant_reference() {
    let out = scratch("constant");
    std::fs::write(out.join("furnace.xml"), FURNACE).unwrap();
    let exp = out.join("furnace.toml");
    std::fs::write(
        &exp,
        r#"
scene = "furnace.xml"
spp = [4, 16]
seeds = 1
[reference]
value = 1.5
[[strategy]]
name = "light"
strategy = "light"
[[strategy]]
name = "bsdf"
strategy = "bsdf"
"#,
    )
    .unwrap();
    run_ok(&exp, &out);
    let index = std::fs::read_to_string(out.join("furnace/index.md")).unwrap();
    assert!(
        index.contains("the constant 1.5e0 in every pixel"),
        "{index}"
    );
    let rows: Vec<directlab::experiment::results::Row> =
        csv::Reader::from_path(out.join("furnace/results.csv"))
            .unwrap()
            .deserialize()
            .collect::<Result<_, _>>()
            .unwrap();
    assert_eq!(rows.len(), 4);
    for r in &rows {
        assert_eq!(r.mse_corrected, r.mse, "no noise floor");
        for (m, v) in r.mean().iter().zip(r.mean_var()) {
            assert!(
                (m - 1.5).abs() <= 4.9 * v.sqrt(),
                "{}: {m} +- {}",
                r.strategy,
                v.sqrt()
            );
        }
    }
    std::fs::remove_dir_all(&out).unwrap();
}

/// `samplers = [...]` crosses every strategy with every sampler: one row per (strategy,
/// sampler, spp, seed), labelled apart, each unbiased on a furnace whose radiance is 1.5
/// everywhere, the report's legend naming both; a second run renders nothing; a misspelt
/// sampler is refused with the file and the names it takes.
#[test]
fn samplers_axis_crosses_strategies() {
    let out = scratch("samplers");
    std::fs::write(out.join("furnace.xml"), FURNACE).unwrap();
    let text = |samplers: &str| {
        format!(
            r#"
scene = "furnace.xml"
spp = [4, 16]
seeds = 2
samplers = {samplers}
[reference]
value = 1.5
[[strategy]]
name = "light"
strategy = "light"
[[strategy]]
name = "bsdf"
strategy = "bsdf"
"#
        )
    };
    let exp = out.join("furnace.toml");
    std::fs::write(
        &exp,
        text(r#"["independent", "stratified", "sobol", "sobol:padded", "sobol-xor", "zsobol"]"#),
    )
    .unwrap();
    run_ok(&exp, &out);
    let rows: Vec<directlab::experiment::results::Row> =
        csv::Reader::from_path(out.join("furnace/results.csv"))
            .unwrap()
            .deserialize()
            .collect::<Result<_, _>>()
            .unwrap();
    assert_eq!(rows.len(), 2 * 6 * 2 * 2);
    let labels: std::collections::BTreeSet<_> = rows.iter().map(|r| r.strategy.clone()).collect();
    assert_eq!(labels.len(), 12, "{labels:?}");
    assert!(
        labels.iter().any(|l| l.ends_with("~sobol-padded")),
        "{labels:?}"
    );
    for r in &rows {
        for (m, v) in r.mean().iter().zip(r.mean_var()) {
            assert!(
                (m - 1.5).abs() <= 4.9 * v.sqrt().max(1e-6),
                "{}: {m} +- {}",
                r.strategy,
                v.sqrt()
            );
        }
    }
    let index = std::fs::read_to_string(out.join("furnace/index.md")).unwrap();
    assert!(index.contains("light, sobol:padded"), "{index}");
    // The rates table: a bootstrap interval over the 2 seeds and the local slope 4 -> 16.
    let rates = &index[index.find("## Convergence rates").expect("rates table")..];
    let row = rates
        .lines()
        .find(|l| l.starts_with("| light, sobol |"))
        .expect("a row per column");
    assert!(
        row.contains("4→16: ") && row.matches('[').count() == 1,
        "{row}"
    );
    let again =
        run(directlab().args(["run", exp.to_str().unwrap(), "--out", out.to_str().unwrap()]));
    assert!(again.status.success());
    let after = std::fs::read_to_string(out.join("furnace/results.csv")).unwrap();
    assert_eq!(
        after.lines().count(),
        1 + rows.len(),
        "resumed without new rows"
    );

    std::fs::write(&exp, text(r#"["independent", "sobl"]"#)).unwrap();
    let bad = run(directlab().args(["run", exp.to_str().unwrap(), "--out", out.to_str().unwrap()]));
    let err = String::from_utf8_lossy(&bad.stderr);
    assert_eq!(bad.status.code(), Some(1), "{err}");
    assert!(
        err.contains("furnace.toml") && err.contains("unknown sampler 'sobl'"),
        "{err}"
    );
    // zsobol numbers the whole film's samples in one sequence: a run past it is refused
    // before anything renders, naming the file, the film and the limit.
    // (A 2048x2048 film, so the limit lies below the bound on any run's spp.)
    let big = FURNACE
        .replace(r#"name="width" value="6""#, r#"name="width" value="2048""#)
        .replace(
            r#"name="height" value="4""#,
            r#"name="height" value="2048""#,
        );
    std::fs::write(out.join("furnace-big.xml"), big).unwrap();
    let huge = text(r#"["zsobol"]"#)
        .replace("spp = [4, 16]", "spp = [4, 4096]")
        .replace("furnace.xml", "furnace-big.xml");
    std::fs::write(&exp, huge).unwrap();
    let bad = run(directlab().args(["run", exp.to_str().unwrap(), "--out", out.to_str().unwrap()]));
    let err = String::from_utf8_lossy(&bad.stderr);
    assert_eq!(bad.status.code(), Some(1), "{err}");
    assert!(
        err.contains("furnace.toml")
            && err.contains("2048x2048 film")
            && err.contains("at most 1024 samples per pixel"),
        "{err}"
    );
    std::fs::remove_dir_all(&out).unwrap();
}

/// `--json`: stdout is one JSON object per line, events in order, one result per row;
/// results.jsonl holds the rows; progress without a terminal is plain lines counted in
/// samples.
#[test]
fn json_events_and_results_jsonl() {
    let out = scratch("json");
    let o = run(directlab()
        .args(["run", repo("experiments/fig2.toml").to_str().unwrap()])
        .args(["--quick", "--json", "--out"])
        .arg(&out));
    assert!(o.status.success());
    let stdout = String::from_utf8_lossy(&o.stdout);
    let events: Vec<serde_json::Value> = stdout
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("not JSON: {l}: {e}")))
        .collect();
    let kinds: Vec<&str> = events
        .iter()
        .map(|e| e["event"].as_str().unwrap())
        .collect();
    let results = kinds.iter().filter(|k| **k == "result").count();
    assert_eq!(results, 2 * 3 * 2 + 2, "{kinds:?}");
    let order: Vec<&str> = kinds.iter().copied().filter(|k| *k != "result").collect();
    assert_eq!(
        order,
        [
            "experiment_started",
            "reference",
            "sweep_started",
            "report_written",
            "finished"
        ]
    );
    let row = &events.iter().find(|e| e["event"] == "result").unwrap()["row"];
    assert_eq!(row["relmse_eps"], 0.01);
    assert!(row["flip"].as_f64().is_some(), "{row}");
    // A 1 spp row has no z^2 (NaN): null in JSON.
    assert!(events
        .iter()
        .any(|e| e["event"] == "result" && e["row"]["spp"] == 1 && e["row"]["mean_z2"].is_null()));
    let report = events
        .iter()
        .find(|e| e["event"] == "report_written")
        .unwrap();
    let jsonl = std::fs::read_to_string(report["results_jsonl"].as_str().unwrap()).unwrap();
    assert_eq!(jsonl.lines().count(), results);
    for l in jsonl.lines() {
        let r: serde_json::Value = serde_json::from_str(l).unwrap();
        assert!(r["strategy"].is_string());
    }
    // The human lines went to stderr, with a final progress line in samples.
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains("rendered now"), "{stderr}");
    assert!(stderr.contains("14/14 runs, 100 % of samples"), "{stderr}");
}
