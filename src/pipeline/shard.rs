//! The command line of sharded runs: `plan`, `run --shard`, `merge` and `status`.

use crate::experiment::args::{options, ReportArgs, SelectArgs, SweepArgs};
use crate::experiment::shard::units::Stage;
use crate::experiment::shard::{self as shard, merge, run, status, ShardRef};
use clap::Args;
use std::path::PathBuf;

/// `run`'s sharding options.
#[derive(Args, Debug, Clone)]
pub struct ShardArgs {
    /// Run only shard I of N (numbered from 0) of each experiment's plan of units, each unit
    /// to its own file under <out>/<name>/units/; finished units are skipped. `directlab
    /// merge` combines them.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<ShardRef>,
    /// With --shard: only the units of this stage (reference chunks, sweep runs, equal-time
    /// runs). Without it, stages run in order and one whose inputs are missing stops the run.
    #[arg(long, value_enum, requires = "shard")]
    pub stage: Option<Stage>,
}

#[derive(Args, Debug)]
pub struct PlanArgs {
    /// Experiment files (TOML).
    #[arg(required = true)]
    pub experiments: Vec<PathBuf>,
    /// Shard count `status` assumes (a shard's units follow from this count alone).
    #[arg(long, default_value_t = 1, value_parser = shard::parse_shards)]
    pub shards: u32,
    #[command(flatten)]
    pub select: SelectArgs,
}

#[derive(Args, Debug)]
pub struct MergeArgs {
    /// Experiment files (TOML).
    #[arg(required = true)]
    pub experiments: Vec<PathBuf>,
    /// Merge only the reference's chunks (what the sweep's shards need first).
    #[arg(long, value_enum)]
    pub stage: Option<Stage>,
    #[command(flatten)]
    pub report: ReportArgs,
}

#[derive(Args, Debug)]
pub struct StatusArgs {
    /// Experiment files (TOML).
    #[arg(required = true)]
    pub experiments: Vec<PathBuf>,
    /// Name the shards of this count that own missing units (default: the plan's).
    #[arg(long, value_parser = shard::parse_shards)]
    pub shards: Option<u32>,
    #[command(flatten)]
    pub select: SelectArgs,
}

/// Runs `f` on every file; one failing does not stop the others.
fn each(
    files: &[PathBuf],
    mut f: impl FnMut(&PathBuf) -> Result<(), String>,
) -> Result<(), String> {
    let mut failed = Vec::new();
    for file in files {
        if let Err(e) = f(file) {
            eprintln!("error: {e}");
            failed.push(file.display().to_string());
        }
    }
    if failed.is_empty() {
        Ok(())
    } else {
        Err(format!("failed: {}", failed.join(", ")))
    }
}

pub fn cmd_plan(a: &PlanArgs) -> Result<(), String> {
    let sweep = a.select.sweep();
    let opts = options(&sweep);
    each(&a.experiments, |f| {
        shard::make_plan(f, sweep.quick, &opts, a.shards)
    })
}

pub fn cmd_run_shard(
    files: &[PathBuf],
    a: &SweepArgs,
    shard: ShardRef,
    stage: Option<Stage>,
) -> Result<(), String> {
    let opts = options(a);
    each(files, |f| run::run_shard(f, a.quick, &opts, shard, stage))
}

pub fn cmd_merge(a: &MergeArgs) -> Result<(), String> {
    let sweep = a.report.sweep();
    let opts = options(&sweep);
    each(&a.experiments, |f| {
        // Every unit is read and checked before anything is written; the images, results.csv
        // and the report then replace the old ones as one set.
        let name = crate::experiment::load(f, sweep.quick)?.name;
        let _lock = crate::experiment::lock::acquire(&sweep.out.join(name))?;
        let merged = crate::output::as_one_set(|| {
            let m = merge::merge(f, sweep.quick, &opts, a.stage)?;
            if let Some(m) = &m {
                super::report_outcome(&m.outcome, opts.viewer)?;
            }
            Ok(m)
        })?;
        if let Some(m) = merged {
            m.mark()?;
        }
        Ok(())
    })?;
    if a.stage.is_none() {
        crate::report::write_root_index(&sweep.out)?;
    }
    Ok(())
}

pub fn cmd_status(a: &StatusArgs) -> Result<(), String> {
    let sweep = a.select.sweep();
    let opts = options(&sweep);
    each(&a.experiments, |f| {
        let p = shard::open(f, sweep.quick, &opts, false, None)?;
        status::print_status(&p, a.shards);
        Ok(())
    })
}
