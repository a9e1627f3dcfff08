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
use super::{chunks, load, RunOptions};
use crate::limits;
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
            t.trim().parse::<u64>().map_err(|_| {
                format!("'{s}': the {what} '{t}' is not a whole number (expected I/N, e.g. 2/8)")
            })
        };
        let (index, count) = (num(i, "shard index")?, num(n, "shard count")?);
        let count = shard_count(count).map_err(|e| format!("'{s}': {e}"))?;
        if index >= count as u64 {
            return Err(format!(
                "shard {index}/{count} is out of range: the {count} shard(s) are numbered 0 to {}",
                count - 1
            ));
        }
        Ok(ShardRef {
            index: index as u32,
            count,
        })
    }
}

/// A shard count, checked: at least 1 and within [`limits::SHARDS`] (beyond it the plan's
/// assignment alone would take gigabytes).
pub fn shard_count(n: u64) -> Result<u32, String> {
    if n == 0 {
        return Err("the shard count must be at least 1".into());
    }
    Ok(limits::count(n, "the shard count", limits::SHARDS)? as u32)
}

/// `--shards N` on the command line.
pub fn parse_shards(s: &str) -> Result<u32, String> {
    limits::parser("the shard count", 1, limits::SHARDS)(s).map(|n| n as u32)
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
    /// not this unit's, is damaged or does not hold what the plan says.
    fn done(&self, i: usize) -> Result<bool, String> {
        self.load(i).map(|r| r.is_some())
    }

    /// Unit `i`'s result, checked against the plan (the film's size, the sample count, the
    /// row's column, seed and reference): None when its file is absent, Err naming the file
    /// when it is not this unit's, is damaged or holds something else.
    fn load(&self, i: usize) -> Result<Option<UnitResult>, String> {
        let path = self.unit_path(i);
        if std::fs::symlink_metadata(&path).is_err_and(|e| e.kind() == std::io::ErrorKind::NotFound)
        {
            return Ok(None);
        }
        let r = unitfile::read(&path, self.owner(i))?;
        self.check_unit(i, &r)
            .map_err(|why| format!("{}: unit file {why}", path.display()))?;
        Ok(Some(r))
    }

    /// What unit `i`'s file must hold, given the plan and the scene.
    fn check_unit(&self, i: usize, r: &UnitResult) -> Result<(), String> {
        let u = &self.plan.units[i];
        let (w, h) = (self.s.scene.camera.width, self.s.scene.camera.height);
        let film = |a: &chunks::Accum, n: u64| {
            if (a.width, a.height) != (w, h) || a.n != n {
                return Err(format!(
                    "holds {} samples of a {}x{} film; the plan says {n} of {w}x{h}",
                    a.n, a.width, a.height
                ));
            }
            Ok(())
        };
        if u.stage == Stage::Reference {
            let a = r.accum.as_ref().ok_or("holds no statistics")?;
            return film(a, u.spp as u64);
        }
        let row = r.row.as_ref().ok_or("holds no result row")?;
        if row.context != self.plan.context {
            return Err("was measured against another reference or epsilon".into());
        }
        let spp_ok = u.stage == Stage::Timed || row.spp == u.spp;
        if row.strategy != u.strategy
            || row.seed != u.seed
            || !spp_ok
            || (row.width, row.height) != (w, h)
        {
            return Err(format!(
                "holds a row of '{}' at {} spp, seed {}, {}x{}; the plan says '{}' at {} spp, \
                 seed {}, {w}x{h}",
                row.strategy, row.spp, row.seed, row.width, row.height, u.strategy, u.spp, u.seed
            ));
        }
        match (&r.accum, u.image) {
            (Some(a), _) => film(a, row.spp as u64),
            (None, true) => Err("holds no image, which the figures need".into()),
            (None, false) => Ok(()),
        }
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
    super::events::say(&format!(
        "{}: plan {} -> {}: {} reference chunks, {} sweep runs, {} equal-time runs, {} shard(s)",
        p.s.exp.name,
        p.plan.id,
        Plan::path(p.dir()).display(),
        count(Stage::Reference),
        count(Stage::Sweep),
        count(Stage::Timed),
        p.plan.shards
    ));
    super::events::emit(
        "plan",
        serde_json::json!({
            "experiment": p.s.exp.name,
            "plan": p.plan.id,
            "path": Plan::path(p.dir()),
            "units": p.plan.units.len(),
            "reference_chunks": count(Stage::Reference),
            "sweep_runs": count(Stage::Sweep),
            "equal_time_runs": count(Stage::Timed),
            "shards": p.plan.shards,
        }),
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
