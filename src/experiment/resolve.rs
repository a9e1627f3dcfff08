//! Reading an experiment file: TOML into the schema, `--quick` applied, then validated.

use super::schema::{Experiment, Resolved};
use super::validate::{cases, validate, validate_cases};
use std::path::Path;

pub fn parse(text: &str, file: &Path) -> Result<Experiment, String> {
    toml::from_str(text).map_err(|e| format!("{}: {e}", file.display()))
}

/// Reads, applies `--quick` and validates an experiment file.
pub fn load(file: &Path, quick: bool) -> Result<Resolved, String> {
    let text = std::fs::read_to_string(file)
        .map_err(|e| format!("{}: cannot read experiment: {e}", file.display()))?;
    resolve(parse(&text, file)?, file, quick)
}

pub fn resolve(mut exp: Experiment, file: &Path, quick: bool) -> Result<Resolved, String> {
    let stem = file
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "experiment".into());
    let mut name = exp.name.clone().unwrap_or(stem);
    if quick {
        let q = exp.quick.clone().unwrap_or_default();
        exp.defines.extend(q.defines);
        if let Some(s) = q.spp {
            exp.spp = s;
        }
        if let Some(s) = q.seeds {
            exp.seeds = s;
        }
        if let Some(s) = q.reference_spp {
            exp.reference.spp = Some(s);
        }
        if let (Some(t), Some(et)) = (q.equal_time_seconds, exp.equal_time.as_mut()) {
            et.seconds = t;
        }
        if q.equal_spp.is_some() {
            exp.figures.equal_spp = q.equal_spp;
        }
        // The full run's variance spp is rarely in the quick sweep: use the quick maximum.
        exp.figures.variance_spp = None;
        if let Some(p) = q.progression {
            exp.figures.progression = p;
        }
        if let (Some(n), Some(p)) = (q.probe_samples, exp.probe.as_mut()) {
            p.samples = n;
        }
        if let (Some(n), Some(a)) = (q.accumulation_spp, exp.accumulation.as_mut()) {
            a.spp = n;
        }
        // Quick results live apart, so they never mix with (or resume into) the full run.
        name.push_str("-quick");
    }
    validate(&exp, file)?;
    let cases = cases(&exp, file)?;
    validate_cases(&exp, &cases, file)?;
    Ok(Resolved {
        name,
        file: file.to_path_buf(),
        quick,
        exp,
        cases,
    })
}
