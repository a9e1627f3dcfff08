//! Issue 6 end to end: `experiments/extreme.toml` loads its cases from `scenes/extreme/`, every
//! case renders finite samples whose mean matches its closed form, degenerate input gives its
//! documented error or warning, and the run resumes like any experiment.
//!
//! Significance: two-sided z-tests at family-wise alpha = 1e-3, Šidák-corrected over the
//! (case, strategy) pairs of each test, as the render tests. A strategy a case declares blind
//! to part of its integrand (e.g. BSDF sampling of a 1e-8 sr light) is checked for finiteness
//! only.

use common::{directlab, repo, run, scratch};
use directlab::experiment::cases::Case;
use directlab::experiment::probe::accumulate::{self, Accumulation};
use directlab::experiment::probe::closed_form;
use directlab::experiment::probe::measure_stream;
use directlab::experiment::probe::stats::{z_critical, ALPHA};
use directlab::experiment::results::Row;
use directlab::experiment::{load, Resolved};
use directlab::integrator::Strategy;
use directlab::scene::{load_scene, Scene};
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Output;

use crate::common;

fn experiment(quick: bool) -> Resolved {
    load(&repo("experiments/extreme.toml"), quick).expect("extreme.toml loads")
}

fn scene(c: &Case) -> Scene {
    let desc = load_scene(&c.scene, &c.defines).unwrap_or_else(|e| panic!("{}: {e}", c.name));
    Scene::build(desc).unwrap_or_else(|e| panic!("{}: {e}", c.name))
}

/// The strategy the experiment calls `name`, on this scene.
fn strategy(exp: &Resolved, scene: &Scene, name: &str) -> Strategy {
    let spec = exp.exp.strategies.iter().find(|s| s.name == name).unwrap();
    spec.on(Strategy::from_desc(&scene.desc.integrator))
        .unwrap()
}

/// `directlab ARGS --out OUT`.
fn directlab_out(args: &[&str], out: &Path) -> Output {
    run(directlab().args(args).arg("--out").arg(out))
}

fn read_rows(csv: &Path) -> Vec<Row> {
    csv::Reader::from_path(csv)
        .unwrap()
        .deserialize()
        .collect::<Result<_, _>>()
        .unwrap()
}

#[test]
fn every_scene_file_loads_and_matches_its_stated_closed_form() {
    let exp = experiment(false);
    assert_eq!(exp.cases.len(), 28);
    for c in &exp.cases {
        assert!(c.scene.starts_with(repo("experiments/../scenes/extreme")));
        let s = scene(c);
        let form = c
            .closed_form
            .unwrap_or_else(|| panic!("{}: no closed form", c.name));
        let v = closed_form::evaluate(&s, form).unwrap();
        let stated = c.value.unwrap();
        assert!(
            (v - stated).abs() <= 1e-9 * v.abs().max(stated.abs()),
            "{}: stated {stated:e}, closed form {v:e}",
            c.name
        );
    }
}

#[test]
fn a_stale_reference_value_stops_the_run_naming_file_case_and_key() {
    let dir = scratch("stale");
    let text = std::fs::read_to_string(repo("experiments/extreme.toml")).unwrap();
    let scenes = repo("scenes").display().to_string().replace('\\', "/");
    let stale = text
        .replace("\"../scenes/", &format!("\"{scenes}/"))
        .replacen("value = 1.641545252881648e-1", "value = 1.6415e-1", 1);
    assert_ne!(stale, text.replace("\"../scenes/", &format!("\"{scenes}/")));
    let file = dir.join("stale.toml");
    std::fs::write(&file, stale).unwrap();
    let o = directlab_out(&["run", file.to_str().unwrap(), "--quick"], &dir);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("stale.toml: case 'tiny-and-huge': reference.value = 1.6415e-1"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Per (case, strategy) of the quick run (2^15 samples, seed 0, one stream each): zero
/// non-finite samples everywhere, and |z| below the Šidák critical value at alpha = 1e-3 for
/// every strategy the case does not declare blind.
fn check_quick_results(exp: &Resolved, rows: &[Row]) {
    let p = exp.exp.probe.as_ref().unwrap();
    assert_eq!(
        (p.samples, exp.exp.seeds),
        (1 << 15, 1),
        "the stated sample count"
    );
    let mut z: BTreeMap<(String, String), f64> = BTreeMap::new();
    for r in rows {
        assert_eq!(
            r.non_finite, 0,
            "{} {}: non-finite samples",
            r.case, r.strategy
        );
        z.insert((r.case.clone(), r.name.clone()), r.z.unwrap());
    }
    let mut tested = Vec::new();
    for c in &exp.cases {
        let s = scene(c);
        let names: Vec<&String> = z.keys().filter(|k| k.0 == c.name).map(|k| &k.1).collect();
        assert!(names.len() >= 3, "{}: rows for {names:?}", c.name);
        for n in names {
            if c.blind_for(&strategy(exp, &s, n)).is_none() {
                tested.push((c.name.clone(), n.clone(), z[&(c.name.clone(), n.clone())]));
            }
        }
    }
    let zc = z_critical(ALPHA, tested.len());
    let failed: Vec<String> = tested
        .iter()
        .filter(|t| t.2.is_nan() || t.2.abs() >= zc)
        .map(|t| format!("{} / {}: z = {:.2}", t.0, t.1, t.2))
        .collect();
    assert!(
        failed.is_empty(),
        "|z| >= {zc:.2} in {} of {} tested pairs:\n{}",
        failed.len(),
        tested.len(),
        failed.join("\n")
    );
}

/// Degenerate input: every `[[invalid]]` file and every case `warning` gives its documented
/// outcome (the report's table says `yes` for each, `NO` for none).
fn check_input_table(exp: &Resolved, index: &str) {
    let section = index
        .split("## Invalid and degenerate input")
        .nth(1)
        .expect("input checks section");
    let rows: Vec<&str> = section
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| input"))
        .collect();
    let warned = exp.cases.iter().filter(|c| c.warning.is_some()).count();
    assert_eq!(rows.len(), exp.exp.invalid.len() + warned, "{section}");
    assert_eq!((exp.exp.invalid.len(), warned), (5, 3));
    for r in rows {
        assert!(r.ends_with("| yes |"), "{r}");
    }
    for v in &exp.exp.invalid {
        let name = v.scene.file_name().unwrap().to_string_lossy().to_string();
        assert!(section.contains(&name), "{name}");
    }
}

#[test]
fn quick_suite_through_the_cli_is_finite_unbiased_and_resumes() {
    let out = scratch("quick");
    let exp = experiment(true);
    // The alias first, then the runner's own command: both run experiments/extreme.toml.
    let first = directlab_out(&["extreme", "--quick", "--threads", "2"], &out);
    assert!(first.status.success());
    let dir = out.join("extreme-quick");
    let csv = dir.join("results.csv");
    let rows = read_rows(&csv);
    check_quick_results(&exp, &rows);
    let index = std::fs::read_to_string(dir.join("index.md")).unwrap();
    check_input_table(&exp, &index);
    assert!(
        index.contains("| tiny-bright | light-e1-uni-area | 0 |"),
        "{index}"
    );
    assert!(index.contains("![relMSE against spp](convergence.png)"));
    // Time and error at equal work per strategy, beside the error alone.
    let header = index
        .lines()
        .find(|l| l.starts_with("| case | strategy | non-finite"))
        .unwrap();
    assert!(
        header.contains("| ns / sample | relMSE x time |"),
        "{header}"
    );
    let row = index
        .lines()
        .find(|l| l.starts_with("| tiny-bright | light-e1-uni-area | 0 |"))
        .unwrap();
    let ns: f64 = row.split('|').nth(7).unwrap().trim().parse().unwrap();
    assert!(ns > 0.0 && ns < 1e6, "{row}");
    assert!(index.contains("0 biased"), "{index}");
    let png = std::fs::read(dir.join("convergence.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    let acc: Vec<Accumulation> = csv::Reader::from_path(dir.join("accumulation.csv"))
        .unwrap()
        .deserialize()
        .collect::<Result<_, _>>()
        .unwrap();
    assert_eq!(acc.len(), 2);
    for a in &acc {
        assert_eq!((a.non_finite, a.spp, a.pixels), (0, 20_000, 4));
        assert!(a.f64_rel_error < 1e-12, "{a:?}");
    }

    let run = || directlab_out(&["run", "experiments/extreme.toml", "--quick"], &out);
    let text = std::fs::read_to_string(&csv).unwrap();
    let second = run();
    assert!(second.status.success());
    let stdout = String::from_utf8_lossy(&second.stdout);
    assert!(stdout.contains("(0 drawn now)"), "{stdout}");
    assert_eq!(
        std::fs::read_to_string(&csv).unwrap(),
        text,
        "rows kept as they were"
    );

    // An interrupted run: one case's rows are missing; only its streams are drawn again.
    let kept: Vec<&str> = text.lines().filter(|l| !l.contains(",huge-dim,")).collect();
    let streams = rows
        .iter()
        .filter(|r| r.case == "huge-dim" && r.spp == 1)
        .count();
    std::fs::write(&csv, kept.join("\n") + "\n").unwrap();
    let third = run();
    assert!(third.status.success());
    let stdout = String::from_utf8_lossy(&third.stdout);
    assert!(
        stdout.contains(&format!("({streams} drawn now)")),
        "{stdout}"
    );
    std::fs::remove_dir_all(&out).unwrap();
}

/// The guards that drop a light sample (zero distance, cos_light <= 0, infinite or zero pdf)
/// act where the integrand's measure vanishes, so they must not move the mean: the cases where
/// they fire most (a light seen edge-on, a light at 89.9 degrees, a grazing camera, a light
/// reaching the horizon), with 2^18 samples of the strategies that rely on them.
#[test]
fn sample_guards_leave_the_mean_unbiased() {
    let exp = experiment(false);
    let names = [
        "light-edge-on",
        "light-at-89.9deg",
        "camera-at-89.9deg",
        "huge-dim",
    ];
    let strategies = ["light, area", "light, solid angle", "MIS balance"];
    let zc = z_critical(ALPHA, names.len() * strategies.len());
    for c in exp
        .cases
        .iter()
        .filter(|c| names.contains(&c.name.as_str()))
    {
        let s = scene(c);
        for n in strategies {
            let m = measure_stream(
                &s,
                strategy(&exp, &s, n),
                [0, 0],
                1 << 18,
                5,
                c.value.unwrap(),
            );
            assert_eq!(m.non_finite, 0);
            assert!(
                m.z.abs() < zc,
                "{} / {n}: mean {:e} vs {:e}, z = {:.2}",
                c.name,
                m.mean,
                c.value.unwrap(),
                m.z
            );
        }
    }
}

/// 2 x 2 pixels at 2e5 spp through `render`: the f64 mean is the exact mean of the samples.
#[test]
fn high_sample_counts_keep_the_mean_exact() {
    let exp = experiment(false);
    let c = exp.cases.iter().find(|c| c.name == "tiny-bright").unwrap();
    let mut defines = c.defines.clone();
    defines.push(("res".into(), "2".into()));
    let s = Scene::build(load_scene(&c.scene, &defines).unwrap()).unwrap();
    let zc = z_critical(ALPHA, 2);
    for n in ["light, area", "MIS balance"] {
        let a = accumulate::measure(
            &s,
            strategy(&exp, &s, n),
            200_000,
            3,
            c.value.unwrap(),
            Some(2),
        );
        assert_eq!((a.non_finite, a.pixels), (0, 4));
        assert!(
            a.f64_rel_error < 1e-12,
            "{}: {}",
            a.strategy,
            a.f64_rel_error
        );
        assert!(a.z.abs() < zc, "{}: z = {}", a.strategy, a.z);
    }
}
