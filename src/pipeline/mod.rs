//! What a command runs: an experiment (or a merge of its shards), then the report of what it
//! produced. The experiment runner (`experiment/`) produces results and never calls the
//! report writer (`report/`), which only reads results; this module is the one place that
//! runs the one after the other.

pub mod shard;

use crate::experiment::costs::Costs;
use crate::experiment::events;
use crate::experiment::probe::{self, ProbeOutcome};
use crate::experiment::{figures, load, metric, run_experiment, Outcome, RunOptions};
use crate::report::html::Viewer;
use std::path::Path;

/// Runs one experiment file and writes its figures and report; prints the mean check (image
/// sweeps) or the table's summary (probe mode).
pub fn run_and_report(file: &Path, quick: bool, opts: &RunOptions) -> Result<(), String> {
    let exp = load(file, quick)?;
    // Held until the report is written: one run at a time per experiment folder.
    let _lock = crate::experiment::lock::acquire(&opts.out.join(&exp.name))
        .map_err(|e| format!("{}: {e}", file.display()))?;
    if exp.exp.probe.is_some() {
        return report_probe(&probe::run_probe(exp, opts)?, opts.viewer);
    }
    report_outcome(&run_experiment(exp, opts)?, opts.viewer)
}

/// Writes the figures and report of a finished sweep and prints its summary.
pub fn report_outcome(o: &Outcome, viewer: Viewer) -> Result<(), String> {
    // The report's files replace the old ones as one set: an error part-way leaves the old
    // report whole.
    crate::output::as_one_set(|| {
        metric::write_long(&o.dir.join("metrics.csv"), &o.rows)?;
        events::write_jsonl(&o.dir.join("results.jsonl"), &o.rows)?;
        // One fit of the cost model for the chart and the report.
        let costs = Costs::of(o);
        let (series, mut figs) = figures::charts(o, costs.as_ref())?;
        figs.extend(figures::images(o)?);
        crate::report::write_experiment(o, &series, &figs, costs.as_ref(), viewer)
    })?;
    for l in crate::report::mean_check_lines(o) {
        events::say(&format!("{}: {l}", o.exp.name));
    }
    let index = o.dir.join("index.md");
    events::say(&format!(
        "{}: {} runs ({} rendered now) in {:.1} s -> {}",
        o.exp.name,
        o.rows.len(),
        o.rendered,
        o.seconds,
        index.display()
    ));
    events::emit(
        "report_written",
        serde_json::json!({
            "experiment": o.exp.name,
            "index": index,
            "results_csv": o.dir.join("results.csv"),
            "results_jsonl": o.dir.join("results.jsonl"),
            "metrics_csv": o.dir.join("metrics.csv"),
            "runs": o.rows.len(),
            "rendered": o.rendered,
            "seconds": o.seconds,
        }),
    );
    Ok(())
}

/// Writes the figure and report of a finished probe experiment and prints its summary.
pub fn report_probe(o: &ProbeOutcome, viewer: Viewer) -> Result<(), String> {
    crate::output::as_one_set(|| {
        let figure = probe::figure::write(o)?;
        crate::report::probe::write(o, figure.as_deref(), viewer)?;
        events::write_jsonl(&o.dir.join("results.jsonl"), &o.rows)
    })?;
    events::emit(
        "report_written",
        serde_json::json!({
            "experiment": o.exp.name,
            "index": o.dir.join("index.md"),
            "results_csv": o.dir.join("results.csv"),
            "results_jsonl": o.dir.join("results.jsonl"),
            "runs": o.rows.len(),
            "seconds": o.seconds,
        }),
    );
    let table = crate::report::probe::table(o);
    let count = |v: &str| table.iter().filter(|r| r.verdict == v).count();
    let failed_checks = o.checks.iter().filter(|c| !c.ok).count();
    events::say(&format!(
        "{}: {} streams ({} drawn now), {} non-finite samples; {} ok, {} tail unsampled, {} biased; {} of {} input checks failed; {:.1} s -> {}",
        o.exp.name,
        o.streams,
        o.drawn,
        table.iter().map(|r| r.non_finite).sum::<u64>(),
        count(crate::report::probe::OK),
        count(crate::report::probe::TAIL),
        count(crate::report::probe::BIASED),
        failed_checks,
        o.checks.len(),
        o.seconds,
        o.dir.join("index.md").display()
    ));
    Ok(())
}
