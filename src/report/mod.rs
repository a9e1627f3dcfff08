//! Reports: `reports/<experiment>/index.md` (and the same as `index.html`) (settings, reference and its noise,
//! what was left out and why, tables, figures) and `reports/index.md` linking them all.

mod cost;
pub mod html;
mod means;
pub mod probe;
mod probe_table;
pub(crate) mod ratios;
pub(crate) mod tables;

pub use means::{mean_check, mean_check_lines, Comparison, MEAN_ALPHA};

use crate::experiment::analysis::{metric_name, Series};
use crate::experiment::costs::Costs;
use crate::experiment::figures::Figure;
use crate::experiment::runner::Outcome;
use crate::output::write_atomic;
use std::fmt::Write;
use std::path::Path;

pub(crate) fn e(v: f64) -> String {
    format!("{v:.3e}")
}

/// How every image run of an experiment was rendered, stated in its report: one code path for
/// all, so that time compares estimators (`render` has no other path).
pub const LANES_NOTE: &str = "Code path: every strategy and sampler ran in the same lane kernel, \
     eight camera samples at a time in vector lanes (a hit on an all-delta BSDF, or on another \
     material than its batch's, is shaded lane by lane inside it); times compare estimators, \
     and Counted cost compares their work without a clock.";

fn settings(md: &mut String, o: &Outcome) {
    let x = &o.exp.exp;
    let defines: Vec<String> = o
        .exp
        .defines()
        .iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect();
    let _ = writeln!(md, "## Settings\n");
    let _ = writeln!(
        md,
        "- Scene: `{}`{} ({}x{} pixels)",
        o.exp.scene().display(),
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
    let _ = writeln!(md, "- {LANES_NOTE}");
    let _ = writeln!(
        md,
        "- Error: {}; relMSE = mean((x - r)^2 / (r^2 + eps)) with eps = {}; both are corrected \
         for the reference's own noise (below).",
        metric_name(x.metrics.primary, x.metrics.relmse_epsilon),
        x.metrics.relmse_epsilon
    );
    let ri = &o.reference.info;
    if let Some(v) = o.exp.cases[0].value {
        let _ = writeln!(
            md,
            "- Reference: the constant {v:e} in every pixel and channel (a closed form, without \
             noise: the noise floor below is 0); key `{}`.",
            ri.key
        );
    } else {
        let _ = writeln!(
            md,
            "- Reference: `{}` at {} spp, seed {}, {:.1} s to render ({}), {} non-finite samples; \
         cache key `{}`, renderer source hash `{}`.",
            ri.strategy,
            ri.spp,
            ri.seed,
            ri.seconds,
            match &o.reference.why_rendered {
                None => "from the cache".to_string(),
                Some(why) => format!("rendered in this run: {why}"),
            },
            ri.non_finite_samples,
            ri.key,
            ri.renderer
        );
    }
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

/// What a report says when its scene's integrator was read as its direct part.
pub fn direct_part_note(integrator: &str) -> String {
    format!(
        "**Direct illumination only.** The scene names the global-illumination integrator \
         `{integrator}`; with `integrator = \"direct\"` directlab renders its direct part (one \
         bounce from the camera's hit), so these images are not what `{integrator}` renders \
         where light bounces more than once."
    )
}

/// Writes `<dir>/index.md` and `<dir>/index.html`.
pub fn write_experiment(
    o: &Outcome,
    series: &[Series],
    figures: &[Figure],
    costs: Option<&Costs>,
    viewer: html::Viewer,
) -> Result<(), String> {
    let mut md = String::new();
    let title = o.title();
    let _ = writeln!(md, "# {title}\n");
    if !o.exp.exp.description.is_empty() {
        let _ = writeln!(md, "{}\n", o.exp.exp.description.trim());
    }
    if let Some(t) = &o.direct_part_of {
        let _ = writeln!(md, "{}\n", direct_part_note(t));
    }
    settings(&mut md, o);
    left_out(&mut md, o);
    tables::error_table(&mut md, o, series);
    tables::rate_table(&mut md, o, series);
    tables::metrics_table(&mut md, o);
    tables::diagnostics(&mut md, o, series);
    tables::equal_time_table(&mut md, o, costs);
    ratios::gains(&mut md, o);
    means::means(&mut md, o);
    tables::variance_table(&mut md, o);
    if let Some(c) = costs {
        cost::cost_section(&mut md, &o.rows, &o.strategies, c, o.exp.equal_spp());
    }
    let _ = writeln!(md, "## Figures\n");
    for f in figures {
        let _ = writeln!(md, "![{}]({})\n\n{}\n", f.file, f.file, f.caption);
    }
    let _ = writeln!(
        md,
        "Raw numbers: [results.csv](results.csv), one row per render."
    );
    let top = match viewer {
        html::Viewer::Full => Some(html::sweep::section(o)?),
        html::Viewer::None => None,
    };
    write_report(&o.dir, &md, top.as_ref(), viewer)
}

/// Writes a report as `<dir>/index.md` and `<dir>/index.html` (with `top` above the report).
pub fn write_report(
    dir: &Path,
    md: &str,
    top: Option<&html::Section>,
    viewer: html::Viewer,
) -> Result<(), String> {
    let path = dir.join("index.md");
    write_atomic(&path, |tmp| {
        std::fs::write(tmp, md).map_err(|e| format!("{}: {e}", path.display()))
    })?;
    html::write(dir, md, top, viewer.figures())
}

/// Writes `<root>/index.md` linking every report under `root`: each folder's `index.md`
/// (experiments, and other commands' reports) and loose Markdown files.
pub fn write_root_index(root: &Path) -> Result<(), String> {
    let mut entries: Vec<(String, String)> = Vec::new();
    if let Ok(rd) = std::fs::read_dir(root) {
        for d in rd.flatten() {
            let name = d.file_name().to_string_lossy().to_string();
            let link = if d.path().is_dir() {
                format!("{name}/index.md")
            } else if name.ends_with(".md") && name != "index.md" {
                name.clone()
            } else {
                continue;
            };
            let Ok(text) = std::fs::read_to_string(root.join(&link)) else {
                continue;
            };
            let title = text
                .lines()
                .next()
                .and_then(|l| l.strip_prefix("# "))
                .unwrap_or(&name)
                .to_string();
            entries.push((link, title));
        }
    }
    entries.sort();
    let mut md = String::from("# Reports\n\nWritten by `directlab run` / `directlab reproduce`; links every report found here.\n\n");
    for (link, title) in &entries {
        let _ = writeln!(md, "- [{title}]({link})");
    }
    let path = root.join("index.md");
    write_atomic(&path, |tmp| {
        std::fs::write(tmp, &md).map_err(|e| format!("{}: {e}", path.display()))
    })?;
    html::write_root(root, &entries)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn root_index_links_report_folders_and_loose_markdown() {
        let dir = std::env::temp_dir().join(format!("directlab-root-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("fig1")).unwrap();
        std::fs::create_dir_all(dir.join("empty")).unwrap();
        std::fs::write(dir.join("fig1/index.md"), "# Figure 1\n").unwrap();
        std::fs::write(dir.join("gallery.md"), "# Bug gallery\n").unwrap();
        write_root_index(&dir).unwrap();
        let md = std::fs::read_to_string(dir.join("index.md")).unwrap();
        assert!(md.contains("- [Figure 1](fig1/index.md)"), "{md}");
        assert!(md.contains("- [Bug gallery](gallery.md)"), "{md}");
        // The HTML index links the interactive page where there is one, else the Markdown.
        std::fs::write(dir.join("fig1/index.html"), "<html></html>").unwrap();
        write_root_index(&dir).unwrap();
        let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
        assert!(
            html.contains("<a href=\"fig1/index.html\">Figure 1</a>"),
            "{html}"
        );
        assert!(
            html.contains("<a href=\"gallery.md\">Bug gallery</a>"),
            "{html}"
        );
        assert!(!md.contains("empty"), "{md}");
        write_root_index(&dir).unwrap();
        let again = std::fs::read_to_string(dir.join("index.md")).unwrap();
        assert_eq!(md, again, "the index does not list itself");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
