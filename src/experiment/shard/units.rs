//! The plan of an experiment run in shards: a fixed list of work units, stored as
//! `<out>/<name>/plan.json`. Reference chunks (the same sample ranges of the same per-pixel
//! streams a one-machine reference renders, [`super::chunks::chunk_ranges`]), sweep cells
//! (strategy x sampler x spp x seed, in the one-machine sweep's order) and equal-time runs.
//! The plan depends on the experiment file, the scene (through the reference key) and the
//! renderer, never on the machine; which shard runs a unit depends on the shard count only.

use crate::experiment::cache::Fnv;
use crate::experiment::chunks::chunk_ranges;
use crate::experiment::results::Results;
use crate::experiment::runner::{RefSource, Setup};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Stages run in order: the sweep is measured against the merged reference, and equal-time
/// runs take their spp from the sweep's measured rates.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum Stage {
    Reference,
    Sweep,
    Timed,
}

impl Stage {
    pub const ALL: [Stage; 3] = [Stage::Reference, Stage::Sweep, Stage::Timed];

    pub fn name(self) -> &'static str {
        match self {
            Stage::Reference => "reference",
            Stage::Sweep => "sweep",
            Stage::Timed => "timed",
        }
    }
}

/// One unit of work.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Unit {
    pub stage: Stage,
    /// Unique within the plan, for messages.
    pub name: String,
    /// Reference chunks: the first sample of the chunk's range.
    #[serde(default)]
    pub first_sample: u64,
    /// Reference chunks and sweep cells: samples per pixel.
    #[serde(default)]
    pub spp: u32,
    #[serde(default)]
    pub seed: u64,
    /// Sweep cells and equal-time runs: the column's label (`Method::label`).
    #[serde(default)]
    pub strategy: String,
    /// Equal-time runs: seconds.
    #[serde(default)]
    pub budget: f64,
    /// The figures need this run's image: its unit file keeps the per-pixel statistics.
    #[serde(default)]
    pub image: bool,
}

impl Unit {
    /// What the unit costs relative to others of its stage (for balancing shards).
    fn cost(&self) -> f64 {
        match self.stage {
            Stage::Reference | Stage::Sweep => self.spp as f64,
            Stage::Timed => self.budget,
        }
    }
}

/// Bumped when the plan or unit file layout changes.
pub const FORMAT: u32 = 1;

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Plan {
    pub format: u32,
    /// The directlab version that made it.
    pub directlab: String,
    /// The experiment file as given, and a hash of its bytes (with `--quick`).
    pub experiment: String,
    pub experiment_hash: String,
    pub quick: bool,
    /// The reference's cache key: scene, meshes, defines, reference settings, renderer.
    pub reference_key: String,
    /// Rows' context (reference key and relMSE epsilon).
    pub context: String,
    /// Shard count `plan --shards` or `slurm submit --shards` chose (status uses it).
    pub shards: u32,
    pub units: Vec<Unit>,
    /// Hash of everything above but `shards`: names the plan in every unit file.
    pub id: String,
    /// Hash of the id and `shards`: the shard count may change (`plan --shards`), but not by
    /// an edit of the file.
    #[serde(default)]
    pub shards_id: String,
}

/// Hash of an experiment file's bytes and the quick flag.
pub fn experiment_hash(file: &Path, quick: bool) -> Result<String, String> {
    let bytes = std::fs::read(file).map_err(|e| format!("{}: cannot read: {e}", file.display()))?;
    let mut h = Fnv::new();
    h.field(&bytes).field(&[quick as u8]);
    Ok(h.hex())
}

impl Plan {
    /// The plan of `s`'s experiment.
    pub(crate) fn of(s: &Setup, shards: u32) -> Result<Plan, String> {
        let mut units = Vec::new();
        if let RefSource::Rendered { spp, seed, .. } = s.source {
            for (first, n) in chunk_ranges(spp) {
                units.push(Unit {
                    stage: Stage::Reference,
                    name: format!("reference samples {first}..{}", first + n as u64),
                    first_sample: first,
                    spp: n,
                    seed,
                    strategy: String::new(),
                    budget: 0.0,
                    image: false,
                });
            }
        }
        let none = Results {
            rows: Vec::new(),
            dropped: 0,
        };
        for j in s.sweep_jobs(&none) {
            units.push(Unit {
                stage: Stage::Sweep,
                name: format!("sweep {} {} spp seed {}", j.method.label(), j.spp, j.seed),
                first_sample: 0,
                spp: j.spp,
                seed: j.seed,
                strategy: j.method.label(),
                budget: 0.0,
                image: j.image.is_some(),
            });
        }
        if let Some(et) = &s.exp.exp.equal_time {
            for &budget in &et.seconds {
                for seed in 0..et.seeds as u64 {
                    for (_, m) in &s.kept {
                        units.push(Unit {
                            stage: Stage::Timed,
                            name: format!("equal time {} {budget} s seed {seed}", m.label()),
                            first_sample: 0,
                            spp: 0,
                            seed,
                            strategy: m.label(),
                            budget,
                            image: true,
                        });
                    }
                }
            }
        }
        let mut plan = Plan {
            format: FORMAT,
            directlab: env!("CARGO_PKG_VERSION").to_string(),
            experiment: s.exp.file.display().to_string(),
            experiment_hash: experiment_hash(&s.exp.file, s.exp.quick)?,
            quick: s.exp.quick,
            reference_key: s.key.clone(),
            context: s.context.clone(),
            shards: shards.max(1),
            units,
            id: String::new(),
            shards_id: String::new(),
        };
        plan.id = plan.hash();
        Ok(plan)
    }

    fn hash(&self) -> String {
        let units = serde_json::to_string(&self.units).expect("plain data");
        let mut h = Fnv::new();
        h.field(&self.format.to_le_bytes())
            .field(self.directlab.as_bytes())
            .field(self.experiment_hash.as_bytes())
            .field(self.reference_key.as_bytes())
            .field(self.context.as_bytes())
            .field(units.as_bytes());
        h.hex()
    }

    fn shards_hash(&self) -> String {
        let mut h = Fnv::new();
        h.field(self.id.as_bytes())
            .field(&self.shards.to_le_bytes());
        h.hex()
    }

    pub fn path(dir: &Path) -> PathBuf {
        dir.join("plan.json")
    }

    /// Where this plan's unit files live (one folder per plan, so a new plan never mixes
    /// with an old one's units).
    pub fn units_dir(&self, dir: &Path) -> PathBuf {
        dir.join("units").join(&self.id)
    }

    pub fn unit_path(&self, dir: &Path, index: usize) -> PathBuf {
        self.units_dir(dir).join(format!("{index:05}.unit"))
    }

    pub fn save(&self, path: &Path) -> Result<(), String> {
        let mut sealed = self.clone();
        sealed.shards_id = self.shards_hash();
        let json = serde_json::to_string_pretty(&sealed).map_err(|e| e.to_string())?;
        crate::output::write_atomic(path, |tmp| {
            std::fs::write(tmp, json + "\n").map_err(|e| format!("{}: {e}", path.display()))
        })
    }

    /// The plan stored at `path`, None if there is none.
    pub fn load(path: &Path) -> Result<Option<Plan>, String> {
        let text = match std::fs::read_to_string(path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(format!("{}: cannot read plan: {e}", path.display())),
        };
        let plan: Plan = serde_json::from_str(&text).map_err(|e| {
            format!(
                "{}: not a directlab plan ({e}); run `directlab plan` again",
                path.display()
            )
        })?;
        if plan.id != plan.hash() {
            return Err(format!(
                "{}: the plan was edited after it was made (its id {} does not match its \
                 contents); run `directlab plan` again",
                path.display(),
                plan.id
            ));
        }
        crate::experiment::shard::shard_count(plan.shards as u64)
            .map_err(|e| format!("{}: \"shards\": {e}", path.display()))?;
        if plan.shards_id != plan.shards_hash() {
            return Err(format!(
                "{}: its \"shards\" ({}) was edited after the plan was made; change the count \
                 with `directlab plan --shards N` (or run `directlab plan` again)",
                path.display(),
                plan.shards
            ));
        }
        Ok(Some(plan))
    }

    /// Refuses a stored plan (`self`, read from `path`) that is not `current`'s: made from
    /// another version of the experiment file, scene or renderer.
    pub fn check_matches(&self, current: &Plan, path: &Path) -> Result<(), String> {
        let again = format!(
            "run `directlab plan {}` again (units of the old plan are not reused)",
            current.experiment
        );
        let why = if self.format != current.format || self.directlab != current.directlab {
            format!(
                "was made by directlab {} (plan format {}), this is {} (format {})",
                self.directlab, self.format, current.directlab, current.format
            )
        } else if self.experiment_hash != current.experiment_hash
            && self.experiment != current.experiment
        {
            format!(
                "was made from the experiment file {}, not from {} (both write to this \
                 folder; give one of them another --out)",
                self.experiment, current.experiment
            )
        } else if self.experiment_hash != current.experiment_hash {
            format!(
                "was made from another version of {} (the file changed since)",
                current.experiment
            )
        } else if self.reference_key != current.reference_key {
            "was made for another scene, mesh, define, reference setting or build of the \
             renderer (the reference key changed)"
                .to_string()
        } else if self.id != current.id {
            "lists other units than this experiment has now".to_string()
        } else {
            return Ok(());
        };
        Err(format!("{}: the plan {why}; {again}", path.display()))
    }

    /// Which shard of `n` runs each unit: within each stage, longest first to the least
    /// loaded shard (ties to the lowest index), so shards finish together.
    pub fn assignment(&self, n: u32) -> Vec<u32> {
        let n = n.max(1) as usize;
        let mut shard = vec![0u32; self.units.len()];
        for stage in Stage::ALL {
            let mut idx: Vec<usize> = (0..self.units.len())
                .filter(|&i| self.units[i].stage == stage)
                .collect();
            idx.sort_by(|&a, &b| self.units[b].cost().total_cmp(&self.units[a].cost()));
            let mut load = vec![0.0f64; n];
            for i in idx {
                let (k, _) = load
                    .iter()
                    .enumerate()
                    .min_by(|a, b| a.1.total_cmp(b.1))
                    .expect("n >= 1");
                shard[i] = k as u32;
                load[k] += self.units[i].cost().max(1e-9);
            }
        }
        shard
    }

    /// Indices of the units of `stage`.
    pub fn of_stage(&self, stage: Stage) -> impl Iterator<Item = usize> + '_ {
        (0..self.units.len()).filter(move |&i| self.units[i].stage == stage)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit(stage: Stage, spp: u32) -> Unit {
        Unit {
            stage,
            name: format!("{stage:?} {spp}"),
            first_sample: 0,
            spp,
            seed: 0,
            strategy: String::new(),
            budget: 0.0,
            image: false,
        }
    }

    fn plan(units: Vec<Unit>) -> Plan {
        let mut p = Plan {
            format: FORMAT,
            directlab: "0".into(),
            experiment: "e.toml".into(),
            experiment_hash: "h".into(),
            quick: false,
            reference_key: "k".into(),
            context: "c".into(),
            shards: 1,
            units,
            id: String::new(),
            shards_id: String::new(),
        };
        p.id = p.hash();
        p
    }

    #[test]
    fn assignment_balances_each_stage_and_covers_every_unit() {
        let mut units: Vec<Unit> = [1024, 1024, 1024, 100]
            .map(|s| unit(Stage::Reference, s))
            .to_vec();
        units.extend([1, 2, 4, 8, 16, 32, 64].map(|s| unit(Stage::Sweep, s)));
        let p = plan(units);
        let a = p.assignment(3);
        assert_eq!(
            &a[..4],
            [0, 1, 2, 0],
            "chunks spread, the short one to the least loaded"
        );
        // Sweep: 64 alone (no split can do better), 32 on the next, the rest on the third.
        let mut load = [0u32; 3];
        for i in 4..11 {
            load[a[i] as usize] += p.units[i].spp;
        }
        assert_eq!(load, [64, 32, 31]);
        assert!(p.assignment(1).iter().all(|&s| s == 0));
        // More shards than units: every unit still has exactly one shard below n.
        assert!(p.assignment(20).iter().all(|&s| s < 20));
        assert_eq!(p.assignment(7), p.assignment(7), "deterministic");
    }

    #[test]
    fn an_edited_shard_count_is_refused_and_a_bounded_one_kept() {
        let dir = std::env::temp_dir().join(format!("directlab-plan-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("plan.json");
        let mut p = plan(vec![unit(Stage::Sweep, 4)]);
        p.shards = 4;
        p.save(&path).unwrap();
        assert_eq!(Plan::load(&path).unwrap().unwrap().shards, 4);
        let text = std::fs::read_to_string(&path).unwrap();
        for (shards, want) in [("5", "was edited"), ("4294967295", "at most 100000")] {
            let edited = text.replace("\"shards\": 4", &format!("\"shards\": {shards}"));
            std::fs::write(&path, edited).unwrap();
            let e = Plan::load(&path).unwrap_err();
            assert!(e.contains("plan.json") && e.contains(want), "{e}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_changed_plan_is_named_by_what_changed() {
        let p = plan(vec![unit(Stage::Sweep, 4)]);
        let path = Path::new("out/e/plan.json");
        assert!(p.check_matches(&p, path).is_ok());
        let mut other = p.clone();
        other.experiment_hash = "h2".into();
        let e = other.check_matches(&p, path).unwrap_err();
        assert!(
            e.contains("out/e/plan.json") && e.contains("another version of e.toml"),
            "{e}"
        );
        let mut other = p.clone();
        other.experiment_hash = "h3".into();
        other.experiment = "elsewhere/sh.toml".into();
        let e = other.check_matches(&p, path).unwrap_err();
        assert!(
            e.contains("experiment file elsewhere/sh.toml, not from e.toml"),
            "{e}"
        );
        let mut other = p.clone();
        other.reference_key = "k2".into();
        let e = other.check_matches(&p, path).unwrap_err();
        assert!(e.contains("reference key"), "{e}");
        let mut other = p.clone();
        other.directlab = "9".into();
        assert!(other
            .check_matches(&p, path)
            .unwrap_err()
            .contains("directlab 9"));
        let mut other = plan(vec![unit(Stage::Sweep, 8)]);
        other.experiment_hash = p.experiment_hash.clone();
        assert!(other
            .check_matches(&p, path)
            .unwrap_err()
            .contains("other units"));
    }
}
