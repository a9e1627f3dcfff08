//! `directlab slurm submit` on a real Slurm: a one-node cluster started by
//! `scripts/slurm-local start` (CI runs it before the tests and exports SLURM_CONF). Without
//! one the test says why and is skipped, unless DIRECTLAB_REQUIRE_SLURM=1 (set by `.ci/run`
//! once the cluster is up), where a missing cluster fails it.
//!
//! One experiment runs on one machine and through Slurm with 3 shards: the reference is the
//! same bytes and the sweep rows are equal. A shard made to fail (a directory where one of its
//! unit files goes) leaves the merge cancelled and `status` naming the unit and its shard;
//! submitting again sends that shard only and completes the run without redoing a unit.

use crate::common;
use common::{
    directlab, plan_of, reference_bytes, run, scratch, sweep_rows, tiny_experiment, unit_files,
};
use std::process::Command;
use std::time::{Duration, Instant};

/// Whether a cluster answers; None (after saying why) when the test is to be skipped.
fn cluster() -> Option<()> {
    let required = std::env::var("DIRECTLAB_REQUIRE_SLURM").is_ok_and(|v| v == "1");
    let why = match std::env::var("SLURM_CONF") {
        Err(_) => "SLURM_CONF is not set".to_string(),
        Ok(conf) => match Command::new("sinfo").args(["-h", "-o", "%T"]).output() {
            Ok(o) if o.status.success() => return Some(()),
            Ok(o) => format!(
                "sinfo failed with {conf}: {}",
                String::from_utf8_lossy(&o.stderr).trim()
            ),
            Err(e) => format!("sinfo cannot run: {e}"),
        },
    };
    assert!(!required, "DIRECTLAB_REQUIRE_SLURM=1 but no cluster: {why}");
    eprintln!(
        "SKIPPED slurm_e2e: {why}; start a one-node cluster with `scripts/slurm-local start` \
         and export the SLURM_CONF it prints"
    );
    None
}

/// Waits until no job whose name starts with `dl-tiny-` is queued or running.
fn wait_for_jobs() {
    let start = Instant::now();
    loop {
        let o = Command::new("squeue")
            .args(["-h", "-o", "%j"])
            .output()
            .expect("squeue");
        let text = String::from_utf8_lossy(&o.stdout);
        if !text.lines().any(|l| l.starts_with("dl-tiny-")) {
            return;
        }
        assert!(
            start.elapsed() < Duration::from_secs(90),
            "jobs still queued after 90 s:\n{text}"
        );
        std::thread::sleep(Duration::from_millis(250));
    }
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn slurm_submit_matches_one_machine_and_resubmits_only_what_failed() {
    if cluster().is_none() {
        return;
    }
    let d = scratch("slurm");
    let exp = tiny_experiment(&d, 2);
    let o = run(directlab()
        .arg("run")
        .arg(&exp)
        .arg("--out")
        .arg(d.join("one")));
    assert!(o.status.success());
    let one = d.join("one/tiny");

    let out = d.join("sl");
    let submit = || {
        run(directlab()
            .args(["slurm", "submit"])
            .arg(&exp)
            .arg("--out")
            .arg(&out)
            .args(["--shards", "3", "--cpus", "1"]))
    };
    assert!(run(directlab()
        .arg("plan")
        .arg(&exp)
        .arg("--out")
        .arg(&out)
        .args(["--shards", "3"]))
    .status
    .success());
    // Make one sweep unit impossible to write: its shard fails.
    let exp_dir = out.join("tiny");
    let (units, plan) = plan_of(&exp_dir);
    let list = plan["units"].as_array().unwrap();
    let victim = list.iter().position(|u| u["stage"] == "sweep").unwrap() + 4;
    let victim_name = list[victim]["name"].as_str().unwrap().to_string();
    std::fs::create_dir_all(units.join(format!("{victim:05}.unit"))).unwrap();

    let o = submit();
    assert!(o.status.success(), "{}", text(&o.stderr));
    let s = text(&o.stdout);
    for step in [
        "reference (3 shard(s)",
        "merge-reference",
        "sweep (3 shard(s)",
        "timed",
        "merge (one job)",
    ] {
        assert!(s.contains(step), "{step}: {s}");
    }
    // The first submission's jobs are still queued: a second one is refused.
    let o = submit();
    assert!(!o.status.success());
    assert!(
        text(&o.stderr).contains("still queued or running"),
        "{}",
        text(&o.stderr)
    );
    wait_for_jobs();

    // The failed shard cancelled the merge (with --kill-on-invalid-dep it does not wait).
    assert!(
        !exp_dir.join("results.csv").exists(),
        "merged despite a failed shard"
    );
    let logs = exp_dir.join("slurm/logs");
    let names: Vec<String> = std::fs::read_dir(&logs)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(
        !names
            .iter()
            .any(|n| n.starts_with("merge-") && !n.starts_with("merge-reference")),
        "the final merge ran: {names:?}"
    );
    assert_eq!(
        names.iter().filter(|n| n.starts_with("sweep-")).count(),
        3,
        "{names:?}"
    );
    let o = run(directlab().arg("status").arg(&exp).arg("--out").arg(&out));
    let s = text(&o.stdout);
    assert!(
        s.contains("bad:") && s.contains(&format!("{victim:05}.unit")) && s.contains("not merged"),
        "{s}"
    );
    assert!(s.contains("shards to rerun"), "{s}");
    let failed_log = names
        .iter()
        .map(|n| std::fs::read_to_string(logs.join(n)).unwrap())
        .find(|t| t.contains("1 unit(s) failed"))
        .expect("a shard's log names the failure");
    assert!(failed_log.contains(&victim_name), "{failed_log}");

    // Repaired, submitted again: only the failed shard's sweep, then timed and the merge.
    std::fs::remove_dir(units.join(format!("{victim:05}.unit"))).unwrap();
    let before = unit_files(&units);
    let o = submit();
    assert!(o.status.success(), "{}", text(&o.stderr));
    let s = text(&o.stdout);
    assert!(s.contains("sweep (1 shard(s)"), "{s}");
    assert!(!s.contains("reference"), "{s}");
    wait_for_jobs();
    let after = unit_files(&units);
    for f in &before {
        assert!(after.contains(f), "{} was redone", f.0.display());
    }
    assert!(
        reference_bytes(&exp_dir) == reference_bytes(&one),
        "Slurm's reference (EXR or f64 statistics) differs from the one-machine run's"
    );
    assert_eq!(
        sweep_rows(&exp_dir.join("results.csv")),
        sweep_rows(&one.join("results.csv"))
    );
    assert!(exp_dir.join("index.md").exists());
    let o = submit();
    assert!(
        text(&o.stdout).contains("nothing to submit"),
        "{}",
        text(&o.stdout)
    );
}
