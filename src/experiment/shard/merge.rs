//! Merging a plan's units in plan order: the reference's chunks by Chan's formula in f64
//! (also what the sweep's shards need first), then every run's row and kept image into
//! results.csv, figures and report, exactly as a one-machine run writes them.

use super::status::{incomplete, StageProgress};
use super::unitfile::UnitResult;
use super::units::Stage;
use super::{open, Planned};
use crate::experiment::cache::{self, Identity, Reference};
use crate::experiment::chunks::Accum;
use crate::experiment::plan::{image_path, spp_tag, time_tag, variance_path};
use crate::experiment::results::Results;
use crate::experiment::runner::{print_reference, RefSource};
use crate::experiment::RunOptions;
use crate::film;
use std::path::Path;
use std::time::Instant;

/// Merges the reference chunks in plan order (Chan's formula in f64) into the cache; errors
/// name the missing or damaged units and the shards to rerun.
pub(crate) fn merge_reference(p: &Planned) -> Result<Reference, String> {
    if let Some(r) = p.s.ready_reference() {
        return Ok(r);
    }
    let RefSource::Rendered {
        strategy,
        spp,
        seed,
    } = p.s.source
    else {
        unreachable!("a constant reference is always there");
    };
    let mut acc: Option<Accum> = None;
    for (_, r) in stage_rows(p, Stage::Reference)? {
        let chunk = r.accum.expect("checked by Planned::load");
        match &mut acc {
            Some(a) => a.merge(&chunk),
            None => acc = Some(chunk),
        }
    }
    let acc = acc.expect("a rendered reference has at least one chunk");
    let r = cache::store(
        &p.dir().join("cache"),
        &Identity {
            key: &p.s.key,
            strategy: &strategy,
            spp,
            seed,
            relmse_epsilon: p.s.eps,
        },
        &acc,
    )?;
    eprintln!(
        "{}: merged the reference from {} chunks",
        p.s.exp.name,
        p.plan.of_stage(Stage::Reference).count()
    );
    Ok(r)
}

/// The units of `stage`, in plan order, each read and checked once; an error names the
/// missing or damaged ones and the shards to rerun.
pub(crate) fn stage_rows(p: &Planned, stage: Stage) -> Result<Vec<(usize, UnitResult)>, String> {
    let mut sp = StageProgress::default();
    let mut units = Vec::new();
    for i in p.plan.of_stage(stage) {
        sp.total += 1;
        match p.load(i) {
            Ok(Some(r)) => {
                sp.done += 1;
                units.push((i, r));
            }
            Ok(None) => sp.missing.push(i),
            Err(e) => sp.bad.push((i, e)),
        }
    }
    if !sp.complete() {
        return Err(incomplete(p, stage, &sp));
    }
    Ok(units)
}

/// `directlab merge`: the reference from its chunks, then (unless `only` is the reference)
/// results.csv, the kept images, figures and report from every unit, exactly as a
/// one-machine run writes them. Nothing is written unless every unit is there and sound.
pub fn merge(
    file: &Path,
    quick: bool,
    opts: &RunOptions,
    only: Option<Stage>,
) -> Result<Option<Merged>, String> {
    let start = Instant::now();
    let p = open(file, quick, opts, true, None)?;
    if only.is_some_and(|s| s != Stage::Reference) {
        return Err("merge --stage takes `reference` only (the sweep merges as a whole)".into());
    }
    let reference = merge_reference(&p)?;
    print_reference(&p.s.exp.name, &reference);
    if only == Some(Stage::Reference) {
        return Ok(None);
    }
    let mut units = stage_rows(&p, Stage::Sweep)?;
    if p.plan.of_stage(Stage::Timed).next().is_some() {
        units.extend(stage_rows(&p, Stage::Timed)?);
    }
    let dir = p.dir().to_path_buf();
    let mut rows = Vec::with_capacity(units.len());
    for (i, r) in units {
        let u = &p.plan.units[i];
        let row = r.row.expect("checked by stage_rows");
        if u.image {
            let acc = r.accum.expect("checked by Planned::load");
            let tag = match u.stage {
                Stage::Timed => time_tag(u.budget),
                _ => spp_tag(u.spp),
            };
            let path = image_path(&dir, &u.strategy, &tag, u.seed);
            let (mean, var) = acc.images();
            film::write_exr(&path, &mean)?;
            film::write_exr(&variance_path(&path), &var)?;
        }
        rows.push(row);
    }
    let csv = dir.join("results.csv");
    let results = Results { rows, dropped: 0 };
    results.save(&csv)?;
    let marker = p.merged_marker();
    let outcome = crate::experiment::Outcome::of(p.s, reference, results.rows, start);
    Ok(Some(Merged { outcome, marker }))
}

/// A merged sweep: its outcome, to be reported, and the marker that says it is merged.
pub struct Merged {
    pub outcome: crate::experiment::Outcome,
    marker: std::path::PathBuf,
}

impl Merged {
    /// Marks the experiment merged: written once its report is, so that an interrupted
    /// merge is merged again.
    pub fn mark(&self) -> Result<(), String> {
        std::fs::write(&self.marker, "merged\n")
            .map_err(|e| format!("{}: {e}", self.marker.display()))
    }
}
