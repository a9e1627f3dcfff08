//! Sharded runs without Slurm: `plan`, `run --shard I/N`, `merge` and `status` through the
//! CLI. Any shard count gives the one-machine run's reference byte for byte and its sweep
//! rows (timing columns aside); finished units are skipped; missing, truncated and foreign
//! unit files, stale plans and shards out of range are named, and nothing is merged then.

use crate::common;
use common::{
    directlab, plan_of, reference_bytes, repo, run, scratch, sweep_rows, tiny_experiment,
    unit_files,
};
use std::path::Path;

fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn stdout(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn ok(cmd: &mut std::process::Command) -> std::process::Output {
    let o = run(cmd);
    assert!(o.status.success(), "{:?}: {}", cmd, stderr(&o));
    o
}

fn shard(exp: &Path, out: &Path, i: u32, n: u32, stage: Option<&str>) -> std::process::Output {
    let mut c = directlab();
    c.arg("run")
        .arg(exp)
        .arg("--out")
        .arg(out)
        .args(["--shard", &format!("{i}/{n}")]);
    if let Some(s) = stage {
        c.args(["--stage", s]);
    }
    run(&mut c)
}

fn merge(exp: &Path, out: &Path) -> std::process::Output {
    run(directlab().arg("merge").arg(exp).arg("--out").arg(out))
}

#[test]
fn any_shard_count_merges_to_the_one_machine_run() {
    let d = scratch("shards-equal");
    let exp = tiny_experiment(&d, 2);
    ok(directlab()
        .arg("run")
        .arg(&exp)
        .arg("--out")
        .arg(d.join("one")));
    let one = d.join("one/tiny");
    let ref_bytes = reference_bytes(&one);
    let rows = sweep_rows(&one.join("results.csv"));
    assert_eq!(rows.len(), 2 * 3 * 2);
    for n in [1u32, 3, 7] {
        let out = d.join(format!("n{n}"));
        ok(directlab()
            .arg("plan")
            .arg(&exp)
            .arg("--out")
            .arg(&out)
            .args(["--shards", &n.to_string()]));
        if n == 1 {
            // Without --stage, one shard runs every stage in order.
            let o = shard(&exp, &out, 0, 1, None);
            assert!(o.status.success(), "{}", stderr(&o));
        } else {
            for stage in ["reference", "sweep", "timed"] {
                // Shards in reverse order: arrival order must not matter.
                for i in (0..n).rev() {
                    let o = shard(&exp, &out, i, n, Some(stage));
                    assert!(
                        o.status.success(),
                        "{n} shards, {stage} {i}: {}",
                        stderr(&o)
                    );
                }
            }
        }
        let o = merge(&exp, &out);
        assert!(o.status.success(), "{}", stderr(&o));
        let exp_dir = out.join("tiny");
        let (exr, stats) = reference_bytes(&exp_dir);
        assert!(exr == ref_bytes.0, "{n} shards: the reference EXR differs");
        assert!(
            stats == ref_bytes.1,
            "{n} shards: the reference's f64 statistics differ from the one-machine run's"
        );
        assert_eq!(sweep_rows(&exp_dir.join("results.csv")), rows, "{n} shards");
        let text = std::fs::read_to_string(exp_dir.join("results.csv")).unwrap();
        assert_eq!(text.lines().filter(|l| l.contains(",time,")).count(), 2);
        // The figures' sweep images too (equal-time ones depend on the measured rate).
        let images = one.join("cache/images");
        for e in std::fs::read_dir(&images).unwrap() {
            let name = e.unwrap().file_name();
            if name.to_string_lossy().contains("-spp") {
                let mine = exp_dir.join("cache/images").join(&name);
                assert_eq!(
                    std::fs::read(&mine).unwrap(),
                    std::fs::read(images.join(&name)).unwrap(),
                    "{n} shards: {}",
                    name.to_string_lossy()
                );
            }
        }
        assert!(exp_dir.join("index.md").exists() && exp_dir.join("convergence.png").exists());
    }
}

#[test]
fn finished_units_are_skipped_and_missing_ones_named() {
    let d = scratch("shards-resume");
    let exp = tiny_experiment(&d, 1);
    let out = d.join("out");
    ok(directlab()
        .arg("plan")
        .arg(&exp)
        .arg("--out")
        .arg(&out)
        .args(["--shards", "2"]));
    // Shard 0 alone cannot measure its sweep: the reference lacks shard 1's chunks.
    let o = shard(&exp, &out, 0, 2, None);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(
        e.contains("the reference stage is not complete") && e.contains("run shards 1 of 2"),
        "{e}"
    );
    let o = ok(directlab().arg("status").arg(&exp).arg("--out").arg(&out));
    let s = stdout(&o);
    assert!(
        s.contains("missing: reference samples") && s.contains("(shard 1/2)"),
        "{s}"
    );
    assert!(s.contains("not merged"), "{s}");

    assert!(shard(&exp, &out, 1, 2, Some("reference")).status.success());
    for i in [0, 1] {
        assert!(shard(&exp, &out, i, 2, Some("sweep")).status.success());
    }
    // Merging before the equal-time runs: refused, nothing written.
    let o = merge(&exp, &out);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("the timed stage is not complete"),
        "{}",
        stderr(&o)
    );
    assert!(!out.join("tiny/results.csv").exists());

    let (units, _) = plan_of(&out.join("tiny"));
    let before = unit_files(&units);
    let o = shard(&exp, &out, 0, 2, Some("sweep"));
    assert!(stderr(&o).contains("0 units run"), "{}", stderr(&o));
    assert_eq!(unit_files(&units), before, "a finished unit was rewritten");
    for i in [0, 1] {
        assert!(shard(&exp, &out, i, 2, Some("timed")).status.success());
    }
    assert!(merge(&exp, &out).status.success());
    let s = stdout(&ok(directlab()
        .arg("status")
        .arg(&exp)
        .arg("--out")
        .arg(&out)));
    assert!(s.contains("results   merged"), "{s}");
}

#[test]
fn bad_plans_shards_and_unit_files_are_refused() {
    let d = scratch("shards-bad");
    let exp = tiny_experiment(&d, 1);
    let out = d.join("out");
    for (spec, want) in [
        ("3/3", "out of range"),
        ("1/0", "at least 1"),
        ("x/2", "not a whole number"),
        ("2", "expected I/N"),
    ] {
        let o = run(directlab()
            .arg("run")
            .arg(&exp)
            .arg("--out")
            .arg(&out)
            .args(["--shard", spec]));
        assert!(!o.status.success(), "{spec}");
        assert!(stderr(&o).contains(want), "{spec}: {}", stderr(&o));
    }
    assert!(!out.exists(), "a refused shard wrote something");

    // A plan made from another version of the experiment file.
    ok(directlab().arg("plan").arg(&exp).arg("--out").arg(&out));
    let text = std::fs::read_to_string(&exp).unwrap();
    std::fs::write(&exp, text.replace("seeds = 1", "seeds = 2")).unwrap();
    let o = shard(&exp, &out, 0, 1, None);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(
        e.contains("plan.json") && e.contains("another version of") && e.contains("directlab plan"),
        "{e}"
    );
    // Planning again replaces the plan and removes the old plan's units.
    let (old_units, _) = plan_of(&out.join("tiny"));
    std::fs::create_dir_all(&old_units).unwrap();
    let o = ok(directlab().arg("plan").arg(&exp).arg("--out").arg(&out));
    assert!(stderr(&o).contains("replaced the plan"), "{}", stderr(&o));
    assert!(!old_units.exists());
    assert_ne!(plan_of(&out.join("tiny")).0, old_units);
    std::fs::write(&exp, &text).unwrap();
    ok(directlab().arg("plan").arg(&exp).arg("--out").arg(&out));

    // A complete set of units, then damaged ones: the merge names them and writes nothing.
    assert!(shard(&exp, &out, 0, 1, None).status.success());
    let (units, plan) = plan_of(&out.join("tiny"));
    let first_sweep = plan["units"]
        .as_array()
        .unwrap()
        .iter()
        .position(|u| u["stage"] == "sweep")
        .unwrap();
    let a = units.join(format!("{:05}.unit", first_sweep));
    let b = units.join(format!("{:05}.unit", first_sweep + 1));
    let good = std::fs::read(&a).unwrap();
    std::fs::write(&a, &good[..good.len() - 100]).unwrap();
    let o = merge(&exp, &out);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(
        e.contains(&a.display().to_string()) && e.contains("truncated"),
        "{e}"
    );
    assert!(!out.join("tiny/results.csv").exists());
    let s = stdout(&ok(directlab()
        .arg("status")
        .arg(&exp)
        .arg("--out")
        .arg(&out)));
    assert!(s.contains("bad:") && s.contains("truncated"), "{s}");

    // Another unit's file under this unit's name.
    std::fs::copy(&b, &a).unwrap();
    let e = stderr(&merge(&exp, &out));
    assert!(
        e.contains(&format!("holds unit {}", first_sweep + 1)),
        "{e}"
    );

    // A unit file of another plan (another experiment's, same unit number).
    let other = d.join("other");
    std::fs::create_dir_all(&other).unwrap();
    let exp2 = tiny_experiment(&other, 2);
    let out2 = other.join("out");
    assert!(shard(&exp2, &out2, 0, 1, Some("reference"))
        .status
        .success());
    let (units2, _) = plan_of(&out2.join("tiny"));
    std::fs::copy(units2.join("00000.unit"), units.join("00000.unit")).unwrap();
    std::fs::write(&a, &good).unwrap();
    // The reference merged already, so its chunks are not read again: remove it to make the
    // merge read the foreign chunk.
    std::fs::remove_dir_all(out.join("tiny/cache")).unwrap();
    let o = merge(&exp, &out);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(
        e.contains("00000.unit") && e.contains("belongs to plan"),
        "{e}"
    );
    assert!(!out.join("tiny/results.csv").exists());

    // A shard redoes the damaged unit; then the merge succeeds.
    assert!(shard(&exp, &out, 0, 1, None).status.success());
    assert!(merge(&exp, &out).status.success());

    // Probe-mode experiments are not split.
    let o = run(directlab()
        .arg("run")
        .arg(repo("experiments/extreme.toml"))
        .arg("--quick")
        .arg("--out")
        .arg(d.join("x"))
        .args(["--shard", "0/2"]));
    assert!(!o.status.success());
    assert!(stderr(&o).contains("probe-mode"), "{}", stderr(&o));
}

/// `slurm submit --dry-run` needs no Slurm: it prints the scripts of what is missing.
#[test]
fn slurm_dry_run_prints_only_the_missing_work() {
    let d = scratch("shards-dry");
    let exp = tiny_experiment(&d, 1);
    let out = d.join("out");
    let dry = || {
        stdout(&ok(directlab()
            .args(["slurm", "submit"])
            .arg(&exp)
            .arg("--out")
            .arg(&out)
            .args([
                "--shards",
                "3",
                "--throttle",
                "2",
                "--time",
                "10:00",
                "--dry-run",
            ])))
    };
    let s = dry();
    for want in [
        "#SBATCH --array=0-2%2",
        "#SBATCH --time=10:00",
        "#SBATCH --cpus-per-task=1",
        "\"${SLURM_ARRAY_TASK_ID}/3\" '--stage' 'reference'",
        "'merge'",
        "--dependency=afterok:<merge-reference> --kill-on-invalid-dep=yes",
        "reference-%A_%a.log",
    ] {
        assert!(s.contains(want), "missing {want:?} in\n{s}");
    }
    assert!(!out.join("tiny/slurm").exists(), "a dry run wrote scripts");
    for stage in ["reference", "sweep"] {
        for i in 0..3 {
            assert!(shard(&exp, &out, i, 3, Some(stage)).status.success());
        }
    }
    let s = dry();
    assert!(
        !s.contains("'--stage' 'reference'") && !s.contains("'--stage' 'sweep'"),
        "{s}"
    );
    assert!(
        s.contains("'--stage' 'timed'") && s.contains("# tiny: merge (one job)"),
        "{s}"
    );
}
