//! `directlab run --shard I/N`: one shard's units, each into its own file; finished ones
//! are skipped, a failing one does not stop the others.

use super::merge::{merge_reference, stage_rows};
use super::unitfile::{self, UnitResult};
use super::units::{Stage, Unit};
use super::{open, threads, Planned, ShardRef};
use crate::experiment::budget::{equal_time_spp, Retime};
use crate::experiment::chunks::{render_chunk, Accum};
use crate::experiment::plan::Job;
use crate::experiment::results::{Row, EQUAL_TIME, SWEEP};
use crate::experiment::runner::{render_job, Ctx, RefSource};
use crate::experiment::RunOptions;
use std::path::Path;
use std::time::Instant;

fn job_of(p: &Planned, u: &Unit, spp: u32) -> Result<Job, String> {
    let (name, method) =
        p.s.kept
            .iter()
            .find(|(_, m)| m.label() == u.strategy)
            .ok_or_else(|| {
                format!(
                    "the plan names '{}', which this experiment does not run",
                    u.strategy
                )
            })?;
    let (kind, budget) = match u.stage {
        Stage::Timed => (EQUAL_TIME, u.budget),
        _ => (SWEEP, 0.0),
    };
    Ok(Job {
        name: name.clone(),
        method: *method,
        kind,
        budget,
        spp,
        seed: u.seed,
        // Unit files carry the image; `merge` writes it where the figures look.
        image: None,
    })
}

/// `directlab run --shard I/N [--stage S]`: runs the shard's units of each stage in order,
/// skipping finished ones; a failing unit does not stop the others, but fails the shard.
pub fn run_shard(
    file: &Path,
    quick: bool,
    opts: &RunOptions,
    shard: ShardRef,
    only: Option<Stage>,
) -> Result<(), String> {
    let p = open(file, quick, opts, true, None)?;
    let threads = threads(opts);
    let name = p.s.exp.name.clone();
    let assignment = p.plan.assignment(shard.count);
    let start = Instant::now();
    let (mut ran, mut skipped, mut failed) = (0, 0, Vec::new());
    for stage in Stage::ALL {
        if only.is_some_and(|o| o != stage) {
            continue;
        }
        let mine: Vec<usize> = p
            .plan
            .of_stage(stage)
            .filter(|&i| assignment[i] == shard.index)
            .collect();
        let mut todo = Vec::new();
        for &i in &mine {
            match p.done(i) {
                Ok(true) => skipped += 1,
                Ok(false) => todo.push(i),
                Err(e) => {
                    eprintln!("{name}: {e}; running the unit again");
                    todo.push(i);
                }
            }
        }
        if todo.is_empty() {
            continue;
        }
        if stage == Stage::Reference && p.s.ready_reference().is_some() {
            skipped += todo.len();
            continue;
        }
        let mut run_unit: Box<dyn FnMut(usize) -> Result<UnitResult, String>> = match stage {
            Stage::Reference => {
                let RefSource::Rendered { strategy, seed, .. } = p.s.source else {
                    unreachable!("reference units exist for rendered references only");
                };
                let scene = &p.s.scene;
                let plan = &p.plan;
                Box::new(move |i| {
                    let u = &plan.units[i];
                    let acc = render_chunk(
                        scene,
                        strategy,
                        seed,
                        (u.first_sample, u.spp),
                        threads,
                        false,
                    );
                    Ok(UnitResult {
                        row: None,
                        accum: Some(acc),
                    })
                })
            }
            Stage::Sweep | Stage::Timed => {
                let reference = merge_reference(&p)?;
                let rows: Vec<Row> = if stage == Stage::Timed {
                    stage_rows(&p, Stage::Sweep)?
                        .into_iter()
                        .filter_map(|(_, r)| r.row)
                        .collect()
                } else {
                    Vec::new()
                };
                let p = &p;
                Box::new(move |i| {
                    let u = &p.plan.units[i];
                    let spp = match stage {
                        Stage::Timed => equal_time_spp(&rows, &u.strategy, u.budget)?,
                        _ => u.spp,
                    };
                    let ctx = Ctx {
                        scene: &p.s.scene,
                        reference: &reference,
                        eps: p.s.eps,
                        extra: &p.s.extra,
                        context: p.s.context.clone(),
                        threads,
                    };
                    let job = job_of(p, u, spp)?;
                    // An equal-time unit that misses its budget is rendered once more (each
                    // unit alone: no correction carries over from other seeds).
                    let (row, out) = match stage {
                        Stage::Timed => Retime::default().run_with(
                            &job,
                            |j| render_job(&ctx, j),
                            |(row, _)| row,
                        )?,
                        _ => render_job(&ctx, &job)?,
                    };
                    Ok(UnitResult {
                        row: Some(row),
                        accum: u.image.then(|| Accum::of(&out)),
                    })
                })
            }
        };
        for i in todo {
            let t = Instant::now();
            let r = run_unit(i).and_then(|r| unitfile::write(&p.unit_path(i), p.owner(i), &r));
            match r {
                Ok(()) => {
                    ran += 1;
                    crate::experiment::events::emit(
                        "unit_done",
                        serde_json::json!({
                            "experiment": name,
                            "shard": format!("{}/{}", shard.index, shard.count),
                            "unit": i,
                            "name": p.plan.units[i].name,
                            "seconds": t.elapsed().as_secs_f64(),
                        }),
                    );
                    eprintln!(
                        "{name}: shard {}/{}: {} done in {:.2} s",
                        shard.index,
                        shard.count,
                        p.plan.units[i].name,
                        t.elapsed().as_secs_f64()
                    );
                }
                Err(e) => {
                    eprintln!("{name}: {}: {e}", p.plan.units[i].name);
                    failed.push(p.plan.units[i].name.clone());
                }
            }
        }
    }
    eprintln!(
        "{name}: shard {}/{}: {ran} units run, {skipped} already done, {} failed, in {:.1} s",
        shard.index,
        shard.count,
        failed.len(),
        start.elapsed().as_secs_f64()
    );
    if failed.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "shard {}/{}: {} unit(s) failed: {}",
            shard.index,
            shard.count,
            failed.len(),
            failed.join(", ")
        ))
    }
}
