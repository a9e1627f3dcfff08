//! Markdown reports: `reports/<experiment>/index.md` (settings, reference and its noise,
//! what was left out and why, tables, figures) and `reports/index.md` linking them all.

mod means;
mod tables;

pub use means::{mean_check, mean_check_lines, Comparison, MEAN_ALPHA};

use crate::experiment::analysis::{metric_name, Series};
use crate::experiment::figures::Figure;
use crate::experiment::Outcome;
use crate::film::write_atomic;
use std::fmt::Write;
use std::path::Path;

pub(crate) fn e(v: f64) -> String {
    format!("{v:.3e}")
}

fn settings(md: &mut String, o: &Outcome) {
    let x = &o.exp.exp;
    let defines: Vec<String> = o
        .exp
        .defines
        .iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect();
    let _ = writeln!(md, "## Settings\n");
    let _ = writeln!(
        md,
        "- Scene: `{}`{} ({}x{} pixels)",
        o.exp.scene.display(),
        if defines.is_empty() {
            String::new()
        } else {
            format!(" with `-D {}`", defines.join(" -D "))
        },
        o.width,
        o.height
    );
    let _ = writeln!(
        md,
        "- Experiment file: `{}`{}",
        o.exp.file.display(),
        if o.exp.quick { " (`--quick`)" } else { "" }
    );
    let _ = writeln!(md, "- Sweep: spp {:?}, seeds 0..{}", x.spp, x.seeds);
    let _ = writeln!(
        md,
        "- Error: {}; relMSE = mean((x - r)^2 / (r^2 + eps)) with eps = {}; both are corrected \
         for the reference's own noise (below).",
        metric_name(x.metrics.primary, x.metrics.relmse_epsilon),
        x.metrics.relmse_epsilon
    );
    let ri = &o.reference.info;
    let _ = writeln!(
        md,
        "- Reference: `{}` at {} spp, seed {}, {:.1} s to render ({}), {} non-finite samples; \
         cache key `{}`.",
        ri.strategy,
        ri.spp,
        ri.seed,
        ri.seconds,
        if o.reference.cached {
            "from the cache"
        } else {
            "rendered in this run"
        },
        ri.non_finite_samples,
        ri.key
    );
    let near = o.rows.iter().filter(|r| r.near_floor).count();
    let _ = writeln!(
        md,
        "- Reference noise floor: mean per-pixel variance {} (MSE), {} (relMSE). A run's \
         measured MSE estimates its true MSE plus this floor (the two renders are independent), \
         so the floor is subtracted. {}",
        e(ri.mse_floor),
        e(ri.relmse_floor),
        if near == 0 {
            "No run came within 2x of the floor.".to_string()
        } else {
            format!("**Warning:** {near} of {} runs measured an error within 2x of the floor; their corrected errors are unreliable and are left out of the slope fits.", o.rows.len())
        }
    );
    let _ = writeln!(
        md,
        "- This invocation rendered {} runs ({} came from `results.csv`) in {:.1} s.\n",
        o.rendered,
        o.rows.len() - o.rendered.min(o.rows.len()),
        o.seconds
    );
}

fn left_out(md: &mut String, o: &Outcome) {
    let _ = writeln!(md, "## Left out\n");
    if o.omitted.is_empty() {
        let _ = writeln!(
            md,
            "Nothing: every listed strategy is a different estimator on this scene.\n"
        );
        return;
    }
    for om in &o.omitted {
        let _ = writeln!(md, "- **{}** (`{}`): {}", om.name, om.label, om.reason);
    }
    md.push('\n');
}

/// Writes `<dir>/index.md`.
pub fn write_experiment(o: &Outcome, series: &[Series], figures: &[Figure]) -> Result<(), String> {
    let mut md = String::new();
    let title = o
        .exp
        .exp
        .title
        .clone()
        .unwrap_or_else(|| o.exp.name.clone());
    let _ = writeln!(md, "# {title}\n");
    if !o.exp.exp.description.is_empty() {
        let _ = writeln!(md, "{}\n", o.exp.exp.description.trim());
    }
    settings(&mut md, o);
    left_out(&mut md, o);
    tables::error_table(&mut md, o, series);
    tables::diagnostics(&mut md, o, series);
    tables::equal_time_table(&mut md, o);
    means::means(&mut md, o);
    tables::variance_table(&mut md, o);
    let _ = writeln!(md, "## Figures\n");
    for f in figures {
        let _ = writeln!(md, "![{}]({})\n\n{}\n", f.file, f.file, f.caption);
    }
    let _ = writeln!(
        md,
        "Raw numbers: [results.csv](results.csv), one row per render."
    );
    let path = o.dir.join("index.md");
    write_atomic(&path, |tmp| {
        std::fs::write(tmp, &md).map_err(|e| format!("{}: {e}", path.display()))
    })
}

/// Writes `<root>/index.md` linking every experiment folder that has a report.
pub fn write_root_index(root: &Path) -> Result<(), String> {
    let mut entries: Vec<(String, String)> = Vec::new();
    if let Ok(rd) = std::fs::read_dir(root) {
        for d in rd.flatten() {
            let idx = d.path().join("index.md");
            let Ok(text) = std::fs::read_to_string(&idx) else {
                continue;
            };
            let name = d.file_name().to_string_lossy().to_string();
            let title = text
                .lines()
                .next()
                .and_then(|l| l.strip_prefix("# "))
                .unwrap_or(&name)
                .to_string();
            entries.push((name, title));
        }
    }
    entries.sort();
    let mut md =
        String::from("# Experiments\n\nWritten by `directlab run` / `directlab reproduce`.\n\n");
    for (name, title) in &entries {
        let _ = writeln!(md, "- [{title}]({name}/index.md)");
    }
    let path = root.join("index.md");
    write_atomic(&path, |tmp| {
        std::fs::write(tmp, &md).map_err(|e| format!("{}: {e}", path.display()))
    })
}
