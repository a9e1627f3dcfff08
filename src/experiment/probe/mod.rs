//! Probe mode (`[probe]` in an experiment file): for every case, strategy and seed, draw one
//! stream of a pixel's individual samples exactly as `render` draws them, and measure it
//! against the case's closed form: non-finite samples, bias (z), the error of batch means at
//! every sweep spp (one `results.csv` row each, so convergence plots and slopes are the
//! runner's), the largest sample and the share of squared error in the top 0.1 %.
//! `experiments/extreme.toml` (the stability suite of issue 6) is the probe experiment.

pub mod accumulate;
pub mod closed_form;
mod figure;
pub mod invalid;
mod rows;
pub mod run;
pub mod samples;
pub mod stats;

pub use run::{measure_stream, run_probe, CaseRun, ProbeOutcome};

use super::RunOptions;

/// Runs a probe experiment and writes its figure and report.
pub fn run_and_report(exp: super::Resolved, opts: &RunOptions) -> Result<(), String> {
    let o = run_probe(exp, opts)?;
    let figure = figure::write(&o)?;
    crate::report::probe::write(&o, figure.as_deref(), opts.viewer)?;
    super::events::write_jsonl(&o.dir.join("results.jsonl"), &o.rows)?;
    super::events::emit(
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
    let table = crate::report::probe::table(&o);
    let count = |v: &str| table.iter().filter(|r| r.verdict == v).count();
    let failed_checks = o.checks.iter().filter(|c| !c.ok).count();
    super::events::say(&format!(
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

#[cfg(test)]
#[path = "sampler_bias_tests.rs"]
mod sampler_bias_tests;
