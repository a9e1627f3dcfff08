//! `directlab slurm submit`: an experiment's plan as Slurm jobs. A job array for the
//! reference chunks, a job that merges the reference, an array for the sweep, one for the
//! equal-time runs and a final merge, each depending on the one before (`afterok`, with
//! `--kill-on-invalid-dep=yes` so a failed shard cancels what follows instead of leaving it
//! pending forever). Submitted again, it sends only the shards that still own missing units.
//! Slurm's own scheduler does the scheduling; directlab only writes and submits the scripts.

use crate::experiment::args::{options, SelectArgs};
use crate::experiment::events::{emit, say};
use crate::experiment::shard::units::Stage;
use crate::experiment::shard::{self, Planned, Status};
use clap::{Args, Subcommand};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

#[derive(Args, Debug)]
pub struct SlurmArgs {
    #[command(subcommand)]
    pub command: SlurmCommand,
}

#[derive(Subcommand, Debug)]
pub enum SlurmCommand {
    /// Write the sbatch scripts of an experiment's missing work and submit them.
    Submit(SubmitArgs),
}

#[derive(Args, Debug)]
pub struct SubmitArgs {
    /// Experiment files (TOML).
    #[arg(required = true)]
    pub experiments: Vec<PathBuf>,
    /// Shards per stage, the size of each job array (default: the plan's count if it has
    /// one above 1, else 8). Keep it when resubmitting, so shard numbers keep their units.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub shards: Option<u32>,
    /// Slurm partition (default: the cluster's).
    #[arg(long)]
    pub partition: Option<String>,
    /// At most K tasks of an array running at once (`--array=...%K`).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub throttle: Option<u32>,
    /// Time limit per task, in Slurm's format (e.g. 30:00, 2:00:00).
    #[arg(long)]
    pub time: Option<String>,
    /// CPUs per task; the renderer uses that many threads (SLURM_CPUS_PER_TASK).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    pub cpus: u32,
    /// Print the scripts and the sbatch commands instead of submitting.
    #[arg(long)]
    pub dry_run: bool,
    #[command(flatten)]
    pub sweep: SelectArgs,
}

pub fn run(a: &SlurmArgs) -> Result<(), String> {
    match &a.command {
        SlurmCommand::Submit(s) => {
            for f in &s.experiments {
                submit(f, s)?;
            }
            Ok(())
        }
    }
}

/// One job to submit.
struct Step {
    /// File stem of the script and of its logs.
    label: &'static str,
    /// Array task indices (shards), or None for a single job.
    array: Option<BTreeSet<u32>>,
    /// The directlab arguments after the binary.
    args: Vec<String>,
}

/// Single-quotes `s` for the shell.
fn quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', r"'\''"))
}

fn absolute(p: &Path) -> Result<PathBuf, String> {
    let cwd = std::env::current_dir().map_err(|e| format!("no working directory: {e}"))?;
    Ok(std::fs::canonicalize(p).unwrap_or_else(|_| cwd.join(p)))
}

/// Array indices as Slurm spells them: `0-3,5,7`.
fn array_spec(set: &BTreeSet<u32>) -> String {
    let v: Vec<u32> = set.iter().copied().collect();
    let mut parts = Vec::new();
    let mut i = 0;
    while i < v.len() {
        let mut j = i;
        while j + 1 < v.len() && v[j + 1] == v[j] + 1 {
            j += 1;
        }
        parts.push(if j > i + 1 {
            format!("{}-{}", v[i], v[j])
        } else if j == i + 1 {
            format!("{},{}", v[i], v[j])
        } else {
            v[i].to_string()
        });
        i = j + 1;
    }
    parts.join(",")
}

/// What to submit, in dependency order.
fn steps(p: &Planned, st: &Status, n: u32, common: &[String]) -> Vec<Step> {
    let mut steps = Vec::new();
    let run = |stage: Stage| -> Vec<String> {
        let mut v = vec!["run".to_string()];
        v.extend(common.iter().cloned());
        v.extend([
            "--shard".into(),
            format!("${{SLURM_ARRAY_TASK_ID}}/{n}"),
            "--stage".into(),
            stage.name().into(),
        ]);
        v
    };
    let merge = |only_reference: bool| -> Vec<String> {
        let mut v = vec!["merge".to_string()];
        v.extend(common.iter().cloned());
        if only_reference {
            v.extend(["--stage".into(), "reference".into()]);
        }
        v
    };
    let todo = |stage: Stage| -> BTreeSet<u32> {
        st.stages
            .iter()
            .find(|(s, _)| *s == stage)
            .map(|(_, sp)| shard::shards_of(p, n, sp.todo()))
            .unwrap_or_default()
    };
    let has = |stage: Stage| p.plan.of_stage(stage).next().is_some();
    if has(Stage::Reference) && !st.reference_merged {
        let shards = todo(Stage::Reference);
        if !shards.is_empty() {
            steps.push(Step {
                label: "reference",
                array: Some(shards),
                args: run(Stage::Reference),
            });
        }
        steps.push(Step {
            label: "merge-reference",
            array: None,
            args: merge(true),
        });
    }
    for (stage, label) in [(Stage::Sweep, "sweep"), (Stage::Timed, "timed")] {
        let shards = todo(stage);
        if !shards.is_empty() {
            steps.push(Step {
                label,
                array: Some(shards),
                args: run(stage),
            });
        }
    }
    if !steps.is_empty() || !st.merged {
        steps.push(Step {
            label: "merge",
            array: None,
            args: merge(false),
        });
    }
    steps
}

/// Settings every script shares.
struct Site<'a> {
    a: &'a SubmitArgs,
    job_name: String,
    logs: PathBuf,
    cwd: PathBuf,
    exe: PathBuf,
}

fn script(site: &Site, step: &Step) -> String {
    let a = site.a;
    let mut s = String::from("#!/bin/bash\n");
    let mut sb = |line: String| s.push_str(&format!("#SBATCH {line}\n"));
    sb(format!("--job-name={}-{}", site.job_name, step.label));
    let log = match &step.array {
        Some(set) => {
            let throttle = a.throttle.map(|k| format!("%{k}")).unwrap_or_default();
            sb(format!("--array={}{throttle}", array_spec(set)));
            site.logs.join(format!("{}-%A_%a.log", step.label))
        }
        None => site.logs.join(format!("{}-%j.log", step.label)),
    };
    sb(format!("--output={}", log.display()));
    sb(format!("--cpus-per-task={}", a.cpus));
    if let Some(t) = &a.time {
        sb(format!("--time={t}"));
    }
    if let Some(p) = &a.partition {
        sb(format!("--partition={p}"));
    }
    s.push_str(
        "# Written by `directlab slurm submit`; resubmit with it (it sends only missing work).\n",
    );
    s.push_str("set -eu\n");
    s.push_str(&format!("cd {}\n", quote(&site.cwd.display().to_string())));
    let args: Vec<String> = step
        .args
        .iter()
        .map(|x| {
            if x.contains("${SLURM_ARRAY_TASK_ID}") {
                format!("\"{x}\"")
            } else {
                quote(x)
            }
        })
        .collect();
    s.push_str(&format!(
        "exec {} {}\n",
        quote(&site.exe.display().to_string()),
        args.join(" ")
    ));
    s
}

/// Job ids of this experiment's jobs still queued or running.
fn active_jobs(job_name: &str) -> Result<Vec<String>, String> {
    let out = Command::new("squeue")
        .args(["-h", "-o", "%i %j"])
        .output()
        .map_err(|e| format!("cannot run squeue ({e}); is this a Slurm login node?"))?;
    if !out.status.success() {
        return Err(format!(
            "squeue failed: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        ));
    }
    let prefix = format!("{job_name}-");
    Ok(String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| l.split_once(' '))
        .filter(|(_, n)| n.starts_with(&prefix))
        .map(|(id, _)| id.to_string())
        .collect())
}

fn sbatch(script: &Path, after: Option<&str>) -> Result<String, String> {
    let mut c = Command::new("sbatch");
    c.arg("--parsable");
    if let Some(id) = after {
        c.arg(format!("--dependency=afterok:{id}"))
            .arg("--kill-on-invalid-dep=yes");
    }
    let out = c
        .arg(script)
        .output()
        .map_err(|e| format!("cannot run sbatch ({e}); is this a Slurm login node?"))?;
    if !out.status.success() {
        return Err(format!(
            "sbatch {} failed: {}",
            script.display(),
            String::from_utf8_lossy(&out.stderr).trim()
        ));
    }
    let text = String::from_utf8_lossy(&out.stdout);
    // `--parsable` prints "id" or "id;cluster".
    Ok(text.trim().split(';').next().unwrap_or("").to_string())
}

fn submit(file: &Path, a: &SubmitArgs) -> Result<(), String> {
    let opts = options(&a.sweep.sweep());
    let probe = shard::open(file, a.sweep.quick, &opts, false, None)?;
    let n = a.shards.unwrap_or(if probe.plan.shards > 1 {
        probe.plan.shards
    } else {
        8
    });
    let p = shard::open(file, a.sweep.quick, &opts, !a.dry_run, Some(n))?;
    let name = p.name().to_string();
    let dir = absolute(p.dir())?;
    let mut h = crate::experiment::cache::Fnv::new();
    h.field(dir.as_os_str().as_encoded_bytes());
    let safe: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    let site = Site {
        a,
        job_name: format!("dl-{safe}-{}", &h.hex()[..6]),
        logs: dir.join("slurm").join("logs"),
        cwd: std::env::current_dir().map_err(|e| format!("no working directory: {e}"))?,
        exe: std::env::current_exe()
            .and_then(std::fs::canonicalize)
            .map_err(|e| format!("cannot find the directlab binary: {e}"))?,
    };
    let mut common = vec![
        absolute(file)?.display().to_string(),
        "--out".into(),
        absolute(&a.sweep.out)?.display().to_string(),
    ];
    if a.sweep.quick {
        common.push("--quick".into());
    }
    if !a.dry_run {
        let active = active_jobs(&site.job_name)?;
        if !active.is_empty() {
            return Err(format!(
                "{name}: jobs {} of this experiment are still queued or running; wait for them \
                 (squeue) or cancel them (scancel) before submitting again",
                active.join(", ")
            ));
        }
    }
    let st = shard::status_of(&p);
    let steps = steps(&p, &st, n, &common);
    if steps.is_empty() {
        say(&format!(
            "{name}: nothing to submit: every unit is done and the results are merged"
        ));
        emit(
            "slurm_nothing_to_submit",
            serde_json::json!({ "experiment": name }),
        );
        return Ok(());
    }
    let scripts = dir.join("slurm");
    let mut prev: Option<String> = None;
    for step in &steps {
        let text = script(&site, step);
        let path = scripts.join(format!("{}.sbatch", step.label));
        let what = match &step.array {
            Some(s) => format!("{} shard(s) {} of {n}", s.len(), array_spec(s)),
            None => "one job".into(),
        };
        if a.dry_run {
            let dep = match &prev {
                Some(d) => format!(" --dependency=afterok:<{d}> --kill-on-invalid-dep=yes"),
                None => String::new(),
            };
            say(&format!(
                "# {name}: {} ({what}): sbatch --parsable{dep} {}",
                step.label,
                path.display()
            ));
            say(&text);
            emit(
                "slurm_script",
                serde_json::json!({
                    "experiment": name, "step": step.label, "script": path,
                    "array": step.array, "text": text,
                }),
            );
            prev = Some(step.label.to_string());
            continue;
        }
        std::fs::create_dir_all(&site.logs).map_err(|e| format!("{}: {e}", site.logs.display()))?;
        crate::output::write_atomic(&path, |tmp| {
            std::fs::write(tmp, &text).map_err(|e| format!("{}: {e}", path.display()))
        })?;
        let id = sbatch(&path, prev.as_deref())?;
        say(&format!(
            "{name}: submitted {} ({what}) as job {id}",
            step.label
        ));
        emit(
            "slurm_submitted",
            serde_json::json!({
                "experiment": name, "step": step.label, "job": id, "array": step.array,
            }),
        );
        prev = Some(id);
    }
    if !a.dry_run {
        say(&format!(
            "{name}: logs in {}; `directlab status {} --out {}{}` shows progress",
            site.logs.display(),
            file.display(),
            a.sweep.out.display(),
            if a.sweep.quick { " --quick" } else { "" }
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn array_indices_are_compressed_into_ranges() {
        let s = |v: &[u32]| array_spec(&v.iter().copied().collect());
        assert_eq!(s(&[0, 1, 2, 3]), "0-3");
        assert_eq!(s(&[0, 1, 3, 5, 6, 7, 9]), "0,1,3,5-7,9");
        assert_eq!(s(&[4]), "4");
    }

    #[test]
    fn quoting_survives_spaces_and_quotes() {
        assert_eq!(quote("a b"), "'a b'");
        assert_eq!(quote("it's"), r"'it'\''s'");
    }
}
