//! `directlab check-sampler` end to end with Python samplers (numpy, through
//! helpers/python/directlab_sampler.py), all at alpha 0.01:
//! - the cosine-hemisphere example passes at 200,000 samples and its three wrong variants
//!   are rejected;
//! - directlab's own warps in numpy get the built-in cases' p-values (100,000 samples) and
//!   p-values uniform over 20 seeds (20,000 samples, resolution 21; the full size is the same
//!   command at 1e6);
//! - the diffuse BSDF example passes, and its wrong weight, eval and support are each caught
//!   by the check that should catch them;
//! - programs that crash, hang, answer the wrong count or a NaN end in an error naming the
//!   phase and batch, through the pipe and through files;
//! - a correct rectangle light passes where Mitsuba's fixed 4x4 trapezoid (`--ires 4`)
//!   rejects it (1e6 samples); a Mitsuba-style ChiSquareTest runs unchanged but for its
//!   import; the README's walkthrough runs as written.
//!
//! Without numpy the tests say so and are skipped, unless DIRECTLAB_REQUIRE_NUMPY=1 (set by
//! `.ci/run` once numpy imports).

use crate::common;
use common::{directlab, repo, run, run_text, scratch};
use std::process::Command;

fn numpy() -> bool {
    let ok = Command::new("python3")
        .args(["-c", "import numpy"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !ok {
        let required = std::env::var("DIRECTLAB_REQUIRE_NUMPY").is_ok_and(|v| v == "1");
        assert!(
            !required,
            "DIRECTLAB_REQUIRE_NUMPY=1 but python3 cannot import numpy"
        );
        eprintln!("SKIPPED check-sampler: python3 cannot import numpy (pip install numpy)");
    }
    ok
}

fn check(extra: &[&str], program: &[&str]) -> (bool, String) {
    let mut args = vec!["--domain", "sphere", "--samples", "200000"];
    args.extend(extra);
    check_with(&args, program)
}

pub(crate) fn check_with(args: &[&str], program: &[&str]) -> (bool, String) {
    static RUN: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let k = RUN.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
    let out = scratch(&format!("check-sampler-{k}"));
    run_text(
        directlab()
            .arg("check-sampler")
            .args(args)
            .arg("--out")
            .arg(&out)
            .arg("--")
            .args(program),
    )
}

#[test]
fn the_python_example_passes_and_its_wrong_variants_are_rejected() {
    if !numpy() {
        return;
    }
    let example = repo("examples/samplers/cosine_hemisphere.py");
    let ex = example.to_str().unwrap();
    let (ok, text) = check(&[], &["python3", ex]);
    assert!(ok && text.contains("check-sampler/sphere: pass"), "{text}");
    assert!(text.contains("claimed pdf: pass"), "{text}");
    for (wrong, why) in [
        ("cosine", "the histogram's shape failed"),
        ("horizon", "integral: FAIL"),
        ("outside", "its pdf says are impossible"),
    ] {
        let (ok, text) = check(&[], &["python3", ex, "--wrong", wrong]);
        assert!(!ok && text.contains("FAIL"), "{wrong}: {text}");
        assert!(text.contains(why), "{wrong}: {text}");
    }
}

#[test]
fn misbehaving_programs_end_in_errors_naming_the_phase() {
    if !numpy() {
        return;
    }
    let (ok, text) = check(&[], &["python3", "-c", "import sys; sys.exit(3)"]);
    assert!(!ok && text.contains("sample phase, batch 0"), "{text}");
    assert!(text.contains("exited"), "{text}");
    let (ok, text) = check(
        &["--timeout", "1"],
        &["python3", "-c", "import time; time.sleep(30)"],
    );
    assert!(!ok && text.contains("no reply within 1 s"), "{text}");
    // One row instead of 65,536, then a NaN pdf.
    let one_row = "import sys, json; sys.stdin.buffer.readline(); \
        sys.stdout.buffer.write(b'{\"count\": 1, \"cols\": 5}\\n' + bytes(40)); sys.stdout.flush()";
    let (ok, text) = check(&[], &["python3", "-c", one_row]);
    assert!(
        !ok && text.contains("expected a reply of 65536 rows x 5 or 6 or 8 columns"),
        "{text}"
    );
    let nan = "import sys, os, numpy as np; sys.path.insert(0, os.path.join(sys.argv[1], \
        'helpers', 'python')); from directlab_sampler import serve; \
        serve(lambda u: np.array([0*u[0], 0*u[0], 1+0*u[0]]), lambda d: np.full(d.shape[1], np.nan))";
    let root = repo("");
    let (ok, text) = check(&[], &["python3", "-c", nan, root.to_str().unwrap()]);
    assert!(!ok && text.contains("non-finite value NaN"), "{text}");
    assert!(text.contains("sample phase, batch 0"), "{text}");
}

/// The number after `key` in `text` (up to the next comma, semicolon or space).
pub(crate) fn number_after(text: &str, key: &str) -> f64 {
    let at = text
        .find(key)
        .unwrap_or_else(|| panic!("no '{key}' in {text}"))
        + key.len();
    let tail = &text[at..];
    let end = tail.find([',', ';', ' ', ')']).unwrap_or(tail.len());
    tail[..end]
        .parse()
        .unwrap_or_else(|e| panic!("'{}': {e}", &tail[..end]))
}

/// (case, the example's warp argument)
pub(crate) const WARPS: [(&str, &str); 5] = [
    ("warp/uniform-disk", "uniform-disk"),
    ("warp/cosine-hemisphere", "cosine-hemisphere"),
    ("warp/spherical-triangle", "spherical-triangle"),
    ("warp/beckmann-a0.5-dcos", "beckmann"),
    ("warp/beckmann-a0.01-dcos", "beckmann"),
];

/// The p-value of a built-in case at seed 0 (`directlab chi2`), run once per case and size
/// whichever test asks first.
pub(crate) fn builtin_p_value(case: &str, samples: u64) -> f64 {
    use std::collections::HashMap;
    use std::sync::{Mutex, OnceLock};
    static DONE: OnceLock<Mutex<HashMap<(String, u64), f64>>> = OnceLock::new();
    let mut done = DONE.get_or_init(Default::default).lock().unwrap();
    if let Some(p) = done.get(&(case.to_string(), samples)) {
        return *p;
    }
    let out = scratch(&format!("check-sampler-builtin-{}", case.replace('/', "-")));
    let o = run(directlab()
        .args(["chi2", case, "--samples", &samples.to_string(), "--out"])
        .arg(&out));
    assert!(o.status.success(), "{case}: {o:?}");
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let row = csv
        .lines()
        .find(|l| l.starts_with(&format!("{case},")))
        .unwrap();
    let p = row.split(',').nth(7).unwrap().parse().unwrap();
    done.insert((case.to_string(), samples), p);
    p
}

/// Each of directlab's warps served by `program` followed by the warp's name gets the
/// built-in case's p-value at 100,000 samples; returns each case's report.
pub(crate) fn warps_get_the_built_in_p_values(program: &[&str]) -> Vec<String> {
    let mut reports = Vec::new();
    for (case, warp) in WARPS {
        let prog: Vec<&str> = program.iter().copied().chain([warp]).collect();
        let (ok, text) = check_with(&["--case", case, "--samples", "100000"], &prog);
        assert!(ok, "{case}: {text}");
        let (p, builtin) = (number_after(&text, "p = "), builtin_p_value(case, 100_000));
        // The same points in the same cells: only the cell integration (batched through
        // the program's pdf, or recursive on directlab's) may move the statistic a little.
        assert!(
            (p - builtin).abs() < 0.01,
            "{case}: p {p} from the program, {builtin} built in"
        );
        reports.push(text);
    }
    reports
}

/// The same warps' p-values over 20 seeds pass the KS test of uniformity (20,000 samples,
/// resolution 21).
pub(crate) fn warps_have_uniform_p_values_over_20_seeds(program: &[&str]) {
    for (case, warp) in WARPS {
        let prog: Vec<&str> = program.iter().copied().chain([warp]).collect();
        let args = [
            "--case",
            case,
            "--samples",
            "20000",
            "--resolution",
            "21",
            "--seeds",
            "20",
        ];
        let (ok, text) = check_with(&args, &prog);
        assert!(
            ok && text.contains("uniform p-values: pass (20 seeds"),
            "{case}: {text}"
        );
    }
}

#[test]
fn directlab_warps_in_python_get_the_built_in_p_values() {
    if numpy() {
        let example = repo("examples/samplers/directlab_warps.py");
        warps_get_the_built_in_p_values(&["python3", example.to_str().unwrap()]);
    }
}

#[test]
fn directlab_warps_in_python_have_uniform_p_values_over_20_seeds() {
    if numpy() {
        let example = repo("examples/samplers/directlab_warps.py");
        warps_have_uniform_p_values_over_20_seeds(&["python3", example.to_str().unwrap()]);
    }
}

#[test]
fn bsdf_example_passes_and_each_wrong_variant_fails_its_check() {
    if !numpy() {
        return;
    }
    let example = repo("examples/samplers/diffuse_bsdf.py");
    let ex = example.to_str().unwrap();
    let args = ["--domain", "bsdf", "--samples", "100000"];
    let (ok, text) = check_with(&args, &["python3", ex]);
    assert!(ok, "{text}");
    for wi in ["normal", "oblique", "grazing", "below"] {
        assert!(text.contains(&format!("bsdf/wi={wi}: pass")), "{text}");
    }
    assert!(
        text.contains("furnace: pass (mean weight 0.80000"),
        "{text}"
    );
    for (wrong, failing) in [
        ("weight", "weight: FAIL"),
        ("eval", "energy: FAIL"),
        ("support", "furnace: FAIL"),
    ] {
        let (ok, text) = check_with(&args, &["python3", ex, "--wrong", wrong]);
        assert!(!ok && text.contains(failing), "{wrong}: {text}");
        // The support error is seen by the furnace alone: weights and shape are right.
        if wrong == "support" {
            assert!(!text.contains("weight: FAIL") && !text.contains("energy: FAIL"));
            assert!(!text.contains("shape failed"), "{text}");
        }
    }
}

#[test]
fn bad_cases_and_parameters_are_named() {
    let py = ["python3", "-c", "pass"];
    for (args, words) in [
        (
            vec!["--case", "warp/nope"],
            "--case warp/nope: no such case",
        ),
        (
            vec!["--case", "bsdf/diffuse-normal"],
            "has no protocol form; these do: warp/uniform-disk",
        ),
        (
            vec!["--domain", "cap"],
            "--domain cap needs --param cos_theta_max=VALUE",
        ),
        (
            vec!["--domain", "bsdf", "--param", "wi=[1,2]"],
            "--param wi=[1,2]: expected [x, y, z] or a list of them",
        ),
        (
            vec!["--domain", "disk", "--param", "x"],
            "--param 'x': expected KEY=VALUE",
        ),
    ] {
        let (ok, text) = check_with(&args, &py);
        assert!(!ok && text.contains(words), "{args:?}: {text}");
    }
}

#[test]
fn the_files_transport_gives_the_pipes_result_and_names_bad_replies() {
    if !numpy() {
        return;
    }
    let example = repo("examples/samplers/directlab_warps.py");
    let prog = ["python3", example.to_str().unwrap(), "cosine-hemisphere"];
    let args = ["--case", "warp/cosine-hemisphere", "--samples", "50000"];
    let (ok_pipe, pipe) = check_with(&args, &prog);
    let mut files_args = args.to_vec();
    files_args.extend(["--transport", "files"]);
    let (ok_files, files) = check_with(&files_args, &prog);
    assert!(ok_pipe && ok_files, "{pipe}\n{files}");
    assert_eq!(
        number_after(&pipe, "chi2 = "),
        number_after(&files, "chi2 = "),
        "{pipe}\n{files}"
    );
    // A program that fails, one that writes nothing, one that writes float32.
    let f32_reply = "import sys, json, numpy as np; h = json.load(open(sys.argv[-1])); \
        np.save(h['output'], np.zeros((h['count'], 5), dtype='<f4'))";
    for (program, words) in [
        ("import sys; sys.exit(4)", "exited: exit status: 4"),
        ("pass", "finished without writing"),
        (f32_reply, "expected little-endian float64 ('<f8')"),
        (
            "import time; time.sleep(30)",
            "did not finish within 1 s (killed)",
        ),
    ] {
        let mut args = files_args.clone();
        args.extend(["--timeout", "1"]);
        let (ok, text) = check_with(&args, &["python3", "-c", program]);
        assert!(!ok && text.contains(words), "{program}: {text}");
        assert!(text.contains("sample phase, batch 0"), "{text}");
    }
}

/// The issue's point against a fixed per-cell rule: at 1e6 samples a correct rectangle-light
/// sampler passes with adaptive integration and is rejected (p ~ 0) when every cell is
/// integrated by a fixed 4 x 4 trapezoid, as Mitsuba's ChiSquareTest does.
#[test]
fn a_rectangle_light_passes_where_a_fixed_trapezoid_rejects_it() {
    if !numpy() {
        return;
    }
    let example = repo("examples/samplers/rectangle_light.py");
    let prog = ["python3", example.to_str().unwrap()];
    let (ok, text) = check_with(&["--domain", "sphere"], &prog);
    assert!(ok, "{text}");
    let (ok, text) = check_with(&["--domain", "sphere", "--ires", "4"], &prog);
    assert!(
        !ok && text.contains("the histogram's shape failed"),
        "{text}"
    );
    assert!(number_after(&text, "p = ") < 1e-10, "{text}");
}

/// The README's walkthrough as written: its Python file, then each of its `directlab
/// check-sampler` lines (at full size, output redirected to scratch) passes.
#[test]
fn the_readme_walkthrough_works_as_written() {
    if !numpy() {
        return;
    }
    let readme = std::fs::read_to_string(repo("README.md")).unwrap();
    let section = &readme[readme.find("## Checking your own sampler").unwrap()..];
    let block = |fence: &str| {
        let at = section.find(fence).unwrap() + fence.len();
        section[at..at + section[at..].find("```").unwrap()].to_string()
    };
    let dir = scratch("readme-walkthrough");
    std::fs::write(dir.join("my_sampler.py"), block("```python\n")).unwrap();
    let lines: Vec<String> = block("```sh\n")
        .lines()
        .filter(|l| l.starts_with("directlab check-sampler"))
        .map(|l| l.split('#').next().unwrap().to_string())
        .collect();
    assert_eq!(lines.len(), 2, "{lines:?}");
    for line in lines {
        let words: Vec<&str> = line.split_whitespace().skip(1).collect();
        let split = words.iter().position(|w| *w == "--").unwrap();
        let o = run(directlab()
            .args(&words[..split])
            .arg("--out")
            .arg(dir.join("out"))
            .args(&words[split..])
            .current_dir(&dir)
            .env("PYTHONPATH", repo("helpers/python")));
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(
            o.status.success() && text.contains(": pass ("),
            "{line}: {text}"
        );
    }
}

/// A test written for Mitsuba's chi2 module with only its import changed: the Python
/// helper's ChiSquareTest runs directlab (`--transport stdio`) and answers it; a halved pdf
/// makes run() return False.
#[test]
fn a_mitsuba_style_test_ports_by_changing_its_import() {
    if !numpy() {
        return;
    }
    let example = repo("examples/samplers/mitsuba_style.py");
    let out = scratch("mitsuba-style");
    let go = |extra: &[&str]| {
        run_text(
            Command::new("python3")
                .arg(&example)
                .args(extra)
                .arg(&out)
                .env("DIRECTLAB", env!("CARGO_BIN_EXE_directlab")),
        )
    };
    let (ok, text) = go(&[]);
    assert!(
        ok && text.contains("cosine hemisphere: pass | disk: pass"),
        "{text}"
    );
    assert!(out.join("sphere/heatmap.png").exists() && out.join("disk/heatmap.png").exists());
    let (ok, text) = go(&["--wrong"]);
    assert!(
        !ok && text.contains("cosine hemisphere: FAIL | disk: pass"),
        "{text}"
    );
    assert!(text.contains("integral: FAIL"), "{text}");
}

/// A run leaves the pages `directlab chi2` leaves: results.csv with a row per check, and
/// index.html with the verdicts and the failure's heat map.
#[test]
fn a_run_writes_results_csv_and_a_page_with_the_failures() {
    if !numpy() {
        return;
    }
    let example = repo("examples/samplers/diffuse_bsdf.py");
    let out = scratch("check-sampler-pages");
    let o = run(directlab()
        .args([
            "check-sampler",
            "--domain",
            "bsdf",
            "--samples",
            "20000",
            "--out",
        ])
        .arg(&out)
        .args([
            "--",
            "python3",
            example.to_str().unwrap(),
            "--wrong",
            "support",
        ]));
    assert!(!o.status.success());
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    assert_eq!(csv.lines().count(), 5, "{csv}");
    assert!(csv.contains("check-sampler/bsdf/wi=normal,") && csv.contains("furnace=fail"));
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(html.contains("check-sampler/bsdf/wi=grazing") && html.contains("FAIL"));
    assert!(html.contains("<img"), "the failures' heat maps are shown");
    let md = std::fs::read_to_string(out.join("index.md")).unwrap();
    assert!(md.contains("](heatmap-0.png)") && md.contains("furnace: mean weight"));
}
