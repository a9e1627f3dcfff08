//! The pages of a `check-sampler` run, as `directlab chi2` writes them: `results.csv` (one
//! row per check), and `index.md` / `index.html` with the verdicts and the heat maps of the
//! failures (or of the first check when all passed).

use super::Report;
use crate::chi2cases::command::{write_csv, Timed};
use crate::chi2cases::CaseConfig;
use std::fmt::Write;
use std::path::Path;

/// Writes the pages of `report` into `out`; `what` says what was checked, `cfg` the size.
pub fn write(out: &Path, report: &Report, what: &str, cfg: &CaseConfig) -> Result<(), String> {
    let rows: Vec<Timed> = report
        .outcomes
        .iter()
        .map(|(o, _, seconds)| Timed {
            outcome: o.clone(),
            seconds: *seconds,
        })
        .collect();
    write_csv(&out.join("results.csv"), &rows, cfg)?;
    let verdict = |ok: bool| if ok { "pass" } else { "**FAIL**" };
    let mut md = format!("# check-sampler: {what}\n\n");
    let _ = writeln!(
        md,
        "{} samples per check on {} cells along v, seed {}; alpha {:.3e} per check (Sidak \
         over the run). Raw numbers: [results.csv](results.csv).\n",
        cfg.samples, cfg.resolution, cfg.seed, cfg.alpha
    );
    md.push_str("| check | verdict | chi2 | dof | p | pdf integral | other checks |\n");
    md.push_str("| --- | --- | --- | --- | --- | --- | --- |\n");
    for (o, _, _) in &report.outcomes {
        let c = &o.chi2;
        let others: Vec<String> = o
            .checks
            .iter()
            .map(|k| format!("{} {}", k.name, verdict(k.passed)))
            .collect();
        let _ = writeln!(
            md,
            "| {} | {} | {:.2} | {} | {:.4e} | {:.6} | {} |",
            o.name,
            verdict(o.passed()),
            c.statistic,
            c.dof,
            c.p_value,
            c.pdf_integral,
            others.join(", ")
        );
    }
    for (name, c) in &report.calibration {
        let _ = writeln!(
            md,
            "\n{name}: {} {} ({})",
            c.name,
            verdict(c.passed),
            c.detail
        );
    }
    let failed: Vec<_> = report.outcomes.iter().filter(|o| !o.0.passed()).collect();
    let shown = match failed.is_empty() {
        true => report.outcomes.iter().take(1).collect(),
        false => failed,
    };
    md.push_str("\n## Heat maps\n\nObserved, expected and their residuals per cell.\n");
    for (o, map, _) in shown {
        let file = map
            .file_name()
            .map(|f| f.to_string_lossy())
            .unwrap_or_default();
        let _ = writeln!(
            md,
            "\n### {}\n\n{}\n\n![{}]({file})",
            o.name,
            o.summary(),
            o.name
        );
    }
    crate::report::write_report(out, &md, None, Default::default())
}
