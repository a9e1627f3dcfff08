//! What a sharded run has done and still lacks: per stage, finished, missing and damaged
//! units, and the shards that own them (`directlab status`, and what `slurm submit` resends).

use super::units::Stage;
use super::Planned;
use std::collections::BTreeSet;

/// What one stage still lacks.
#[derive(Debug, Default)]
pub struct StageProgress {
    pub total: usize,
    pub done: usize,
    /// Unit indices without a file.
    pub missing: Vec<usize>,
    /// Unit indices whose file is damaged or foreign, with the reason.
    pub bad: Vec<(usize, String)>,
}

impl StageProgress {
    pub fn complete(&self) -> bool {
        self.done == self.total
    }

    /// Units to run again: missing and bad.
    pub fn todo(&self) -> impl Iterator<Item = usize> + '_ {
        self.missing
            .iter()
            .copied()
            .chain(self.bad.iter().map(|b| b.0))
    }
}

fn progress(p: &Planned, stage: Stage) -> StageProgress {
    let mut sp = StageProgress::default();
    for i in p.plan.of_stage(stage) {
        sp.total += 1;
        match p.done(i) {
            Ok(true) => sp.done += 1,
            Ok(false) => sp.missing.push(i),
            Err(e) => sp.bad.push((i, e)),
        }
    }
    sp
}

/// The shards of `n` that own a unit of `todo`.
pub fn shards_of(p: &Planned, n: u32, todo: impl Iterator<Item = usize>) -> BTreeSet<u32> {
    let a = p.plan.assignment(n);
    todo.map(|i| a[i]).collect()
}

/// What is left of an experiment, as `status` and `slurm submit` need it.
pub struct Status {
    pub reference_merged: bool,
    pub stages: Vec<(Stage, StageProgress)>,
    pub merged: bool,
}

pub fn status_of(p: &Planned) -> Status {
    let reference_merged = p.s.ready_reference().is_some();
    let stages = Stage::ALL
        .into_iter()
        .filter(|&st| p.plan.of_stage(st).next().is_some())
        .map(|st| (st, progress(p, st)))
        .collect();
    Status {
        reference_merged,
        stages,
        merged: p.merged_marker().exists(),
    }
}

impl Status {
    /// Whether `stage` needs no more work (the reference: merged, or every chunk done).
    pub fn stage_done(&self, stage: Stage) -> bool {
        (stage == Stage::Reference && self.reference_merged)
            || self
                .stages
                .iter()
                .find(|(st, _)| *st == stage)
                .is_none_or(|(_, sp)| sp.complete())
    }
}

/// `directlab status`: prints per stage what is done, what is missing or damaged (with the
/// shards of `shards` that own it) and whether the results are merged; with `--json`, one
/// `status` event instead (the text goes to stderr).
pub fn print_status(p: &Planned, shards: Option<u32>) -> Status {
    let n = shards.unwrap_or(p.plan.shards);
    let st = status_of(p);
    let name = &p.s.exp.name;
    let a = p.plan.assignment(n);
    let mut lines = vec![format!(
        "{name}: plan {} ({} units), {n} shard(s); units in {}",
        p.plan.id,
        p.plan.units.len(),
        p.plan.units_dir(p.dir()).display()
    )];
    let mut stages = Vec::new();
    for (stage, sp) in &st.stages {
        let merged = *stage == Stage::Reference && st.reference_merged;
        let rerun: Vec<u32> = if merged {
            Vec::new()
        } else {
            shards_of(p, n, sp.todo()).into_iter().collect()
        };
        let mut line = format!("  {:<9} {:>5}/{} done", stage.name(), sp.done, sp.total);
        if merged {
            line.push_str(", reference merged");
        } else if !sp.complete() {
            let list: Vec<String> = rerun.iter().map(|s| s.to_string()).collect();
            line.push_str(&format!(
                ", {} missing, {} bad; shards to rerun: {}",
                sp.missing.len(),
                sp.bad.len(),
                list.join(",")
            ));
        }
        lines.push(line);
        if !merged {
            for &i in sp.missing.iter().take(10) {
                lines.push(format!(
                    "    missing: {} (shard {}/{n})",
                    p.plan.units[i].name, a[i]
                ));
            }
            if sp.missing.len() > 10 {
                lines.push(format!(
                    "    ... and {} more missing",
                    sp.missing.len() - 10
                ));
            }
            for (i, why) in &sp.bad {
                lines.push(format!("    bad: {why} (shard {}/{n})", a[*i]));
            }
        }
        let unit = |i: usize| serde_json::json!({ "unit": p.plan.units[i].name, "shard": a[i] });
        stages.push(serde_json::json!({
            "stage": stage.name(),
            "done": sp.done,
            "total": sp.total,
            "reference_merged": merged,
            "missing": if merged { vec![] } else { sp.missing.iter().map(|&i| unit(i)).collect::<Vec<_>>() },
            "bad": if merged { vec![] } else {
                sp.bad.iter().map(|(i, why)| {
                    let mut u = unit(*i);
                    u["why"] = why.clone().into();
                    u
                }).collect::<Vec<_>>()
            },
            "shards_to_rerun": rerun,
        }));
    }
    lines.push(format!(
        "  results   {}",
        if st.merged {
            "merged"
        } else {
            "not merged (`directlab merge`)"
        }
    ));
    for l in &lines {
        crate::experiment::events::say(l);
    }
    crate::experiment::events::emit(
        "status",
        serde_json::json!({
            "experiment": name,
            "plan": p.plan.id,
            "shards": n,
            "stages": stages,
            "merged": st.merged,
        }),
    );
    st
}

pub(crate) fn incomplete(p: &Planned, stage: Stage, sp: &StageProgress) -> String {
    let n = p.plan.shards;
    let shards: Vec<String> = shards_of(p, n, sp.todo())
        .iter()
        .map(|s| s.to_string())
        .collect();
    let mut names: Vec<String> = sp
        .todo()
        .take(3)
        .map(|i| p.plan.units[i].name.clone())
        .collect();
    if sp.total - sp.done > 3 {
        names.push("...".into());
    }
    let a = p.plan.assignment(n);
    let bad = sp
        .bad
        .first()
        .map(|(i, why)| format!("; {why} (shard {}/{n})", a[*i]))
        .unwrap_or_default();
    format!(
        "{}: the {} stage is not complete: {} of {} units missing or bad ({}){bad}; \
         run shards {} of {n} (`directlab status` lists them)",
        p.s.exp.name,
        stage.name(),
        sp.total - sp.done,
        sp.total,
        names.join(", "),
        shards.join(",")
    )
}
