//! An experiment run in shards: a fixed plan of units ([`units`], `plan.json`), each shard's
//! units run into their own files ([`run`], [`unitfile`]), merged exactly in plan order
//! ([`merge`]): the merged reference is bitwise the same for any shard count and equals the
//! one-machine run's. [`status`] says what is done and what is missing; [`cli`] holds the
//! commands.

pub mod merge;
pub mod run;
pub mod status;
pub mod unitfile;
pub mod units;

use super::runner::{setup, Setup};
use super::{load, RunOptions};
pub use status::{shards_of, status_of, Status};
use std::path::{Path, PathBuf};
use std::str::FromStr;
use unitfile::{Owner, UnitResult};
use units::{Plan, Stage};

/// `I/N`: shard I of N, numbered from 0.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShardRef {
    pub index: u32,
    pub count: u32,
}

impl FromStr for ShardRef {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let (i, n) = s
            .split_once('/')
            .ok_or_else(|| format!("'{s}': expected I/N (shard I of N, 0 <= I < N), e.g. 2/8"))?;
        let num = |t: &str, what: &str| {
            t.trim().parse::<u32>().map_err(|_| {
                format!("'{s}': the {what} '{t}' is not a whole number (expected I/N, e.g. 2/8)")
            })
        };
        let (index, count) = (num(i, "shard index")?, num(n, "shard count")?);
        if count == 0 {
            return Err(format!("'{s}': the shard count must be at least 1"));
        }
        if index >= count {
            return Err(format!(
                "shard {index}/{count} is out of range: the {count} shard(s) are numbered 0 to {}",
                count - 1
            ));
        }
        Ok(ShardRef { index, count })
    }
}

/// An experiment with its plan.
pub struct Planned {
    s: Setup,
    pub plan: Plan,
}

impl Planned {
    pub fn name(&self) -> &str {
        &self.s.exp.name
    }

    pub fn dir(&self) -> &Path {
        &self.s.dir
    }

    fn owner(&self, i: usize) -> Owner<'_> {
        Owner {
            plan: &self.plan.id,
            index: i,
            name: &self.plan.units[i].name,
        }
    }

    fn unit_path(&self, i: usize) -> PathBuf {
        self.plan.unit_path(self.dir(), i)
    }

    /// Whether unit `i` is finished: Ok(false) when absent, Err(reason) when its file is
    /// not this unit's or is damaged.
    fn done(&self, i: usize) -> Result<bool, String> {
        unitfile::is_done(&self.unit_path(i), self.owner(i))
            .map_err(|why| format!("{}: unit file {why}", self.unit_path(i).display()))
    }

    fn read(&self, i: usize) -> Result<UnitResult, String> {
        unitfile::read(&self.unit_path(i), self.owner(i))
    }

    fn merged_marker(&self) -> PathBuf {
        self.plan.units_dir(self.dir()).join("merged")
    }
}

/// The experiment's setup and the plan it has now (with one shard).
fn current(file: &Path, quick: bool, opts: &RunOptions) -> Result<(Setup, Plan), String> {
    let exp = load(file, quick)?;
    if exp.exp.probe.is_some() {
        return Err(format!(
            "{}: probe-mode experiments ([probe]) are not split into units; run them on one \
             machine with `directlab run`",
            file.display()
        ));
    }
    let s = setup(exp, opts)?;
    let plan = Plan::of(&s, 1)?;
    Ok((s, plan))
}

/// Loads the experiment and its plan. The stored plan must be this experiment's (else an
/// error says what changed); without one, the plan is made and, if `write`, stored.
/// `shards` replaces the stored shard count.
pub fn open(
    file: &Path,
    quick: bool,
    opts: &RunOptions,
    write: bool,
    shards: Option<u32>,
) -> Result<Planned, String> {
    let (s, current) = current(file, quick, opts)?;
    let path = Plan::path(&s.dir);
    let mut plan = match Plan::load(&path)? {
        Some(stored) => {
            stored.check_matches(&current, &path)?;
            stored
        }
        None => current,
    };
    let changed = shards.is_some_and(|n| n != plan.shards);
    if let Some(n) = shards {
        plan.shards = n.max(1);
    }
    if write && (changed || !path.exists()) {
        plan.save(&path)?;
    }
    Ok(Planned { s, plan })
}

/// `directlab plan`: writes the plan, replacing one of an older version of the experiment
/// (or an unreadable one) and removing that plan's unit files; prints its units per stage.
pub fn make_plan(file: &Path, quick: bool, opts: &RunOptions, shards: u32) -> Result<(), String> {
    let (s, mut plan) = current(file, quick, opts)?;
    plan.shards = shards.max(1);
    let path = Plan::path(&s.dir);
    match Plan::load(&path) {
        Ok(Some(old)) if old.id != plan.id => {
            let _ = std::fs::remove_dir_all(old.units_dir(&s.dir));
            eprintln!(
                "{}: replaced the plan of an older version (its units are removed)",
                s.exp.name
            );
        }
        Err(e) => eprintln!("{e}: replacing it"),
        _ => {}
    }
    plan.save(&path)?;
    let p = Planned { s, plan };
    let count = |st| p.plan.of_stage(st).count();
    println!(
        "{}: plan {} -> {}: {} reference chunks, {} sweep runs, {} equal-time runs, {} shard(s)",
        p.s.exp.name,
        p.plan.id,
        Plan::path(p.dir()).display(),
        count(Stage::Reference),
        count(Stage::Sweep),
        count(Stage::Timed),
        p.plan.shards
    );
    Ok(())
}

/// Worker threads: `--threads`, else Slurm's `SLURM_CPUS_PER_TASK` (jobs are not CPU-limited
/// without cgroups, so using every core of a shared node would oversubscribe it).
pub fn threads(opts: &RunOptions) -> Option<usize> {
    opts.threads.or_else(|| {
        std::env::var("SLURM_CPUS_PER_TASK")
            .ok()
            .and_then(|v| v.trim().parse::<usize>().ok())
            .filter(|&n| n > 0)
    })
}
