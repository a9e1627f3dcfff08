//! The experiment runner: sweeps of (strategy, spp, seed) against a cached reference, with
//! resumable results, left-out analysis, figures and a report per experiment.

pub mod analysis;
pub mod args;
pub mod cache;
pub mod cases;
pub mod chunks;
pub mod events;
pub mod figures;
pub mod leftout;
mod measure;
pub mod method;
pub mod plan;
pub mod probe;
pub mod resolve;
pub mod results;
pub mod runner;
pub mod schema;
pub mod shard;
mod validate;

pub use resolve::load;
pub use runner::{run_experiment, Outcome, RunOptions};
pub use schema::Resolved;
use std::path::{Path, PathBuf};

/// Runs one experiment file and writes its figures and report; prints the mean check (image
/// sweeps) or the table's summary (probe mode).
pub fn run_and_report(file: &Path, quick: bool, opts: &RunOptions) -> Result<(), String> {
    let exp = load(file, quick)?;
    if exp.exp.probe.is_some() {
        return probe::run_and_report(exp, opts);
    }
    report_outcome(&run_experiment(exp, opts)?, opts.viewer)
}

/// Writes the figures and report of a finished sweep and prints its summary.
pub fn report_outcome(o: &Outcome, viewer: crate::report::html::Viewer) -> Result<(), String> {
    results::write_long(&o.dir.join("metrics.csv"), &o.rows)?;
    events::write_jsonl(&o.dir.join("results.jsonl"), &o.rows)?;
    let (series, mut figs) = figures::charts(o)?;
    figs.extend(figures::images(o)?);
    crate::report::write_experiment(o, &series, &figs, viewer)?;
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

/// The `experiments/` folder: in the working directory, else in the source tree this binary
/// was built from (so `cargo run -- reproduce` works from anywhere in a clone).
pub fn experiments_dir() -> Result<PathBuf, String> {
    let local = PathBuf::from("experiments");
    if local.is_dir() {
        return Ok(local);
    }
    let built = Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments");
    if built.is_dir() {
        return Ok(built);
    }
    Err("no experiments/ folder in the working directory; run from the repository root".into())
}

/// Every `*.toml` in the experiments folder, sorted.
pub fn all_experiments() -> Result<Vec<PathBuf>, String> {
    let dir = experiments_dir()?;
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    v.sort();
    Ok(v)
}
