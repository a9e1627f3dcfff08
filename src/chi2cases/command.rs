//! `directlab chi2`: runs the selected cases, prints a table, writes `results.csv` and one
//! heat map (observed | expected | residual) per case, and fails if any case fails.
//!
//! Significance: alpha = 0.01 for the whole run, Sidak-corrected over the cases run, so a
//! correct renderer fails a full run with probability 1 %.

use super::{select, CaseConfig, Outcome};
use crate::output::write_atomic;
use crate::stats::{heatmap, sidak};
use clap::Args;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Family-wise significance level of one run.
pub const ALPHA: f64 = 0.01;

#[derive(Args, Debug, Clone)]
pub struct Chi2Args {
    /// Run only cases whose name contains this (e.g. `emitter/`, `grazing`).
    pub filter: Option<String>,
    /// Samples per case.
    #[arg(long, default_value_t = 1_000_000, value_parser = crate::limits::parser("--samples", 1, crate::limits::TEST_SAMPLES))]
    pub samples: u64,
    /// Cells along a domain's v axis (the sphere gets 2R-1 rows of cos(theta), R of phi):
    /// 3 to 2048 (2048 is 8.4 million cells a case, about 200 MB of tables per case run).
    #[arg(long, default_value_t = 51, value_parser = parse_resolution)]
    pub resolution: usize,
    /// Seed of every case's random numbers (a run is reproducible from it).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Output directory for results.csv and the heat maps.
    #[arg(long, default_value = "reports/chi2")]
    pub out: PathBuf,
    /// List the cases (name and description) and exit.
    #[arg(long)]
    pub list: bool,
    /// Test a scene's own BSDFs and light sampling instead of the built-in cases (results
    /// under `<out>/scenes/<scene name>/`).
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// The scene's emitter choice (default: uniform, the study's).
    #[arg(long, default_value = "uniform", value_parser = crate::choices::EmitterSelectionParser)]
    pub emitter_selection: crate::emitter::EmitterSelection,
    /// The scene's light sampling.
    #[arg(long, value_parser = crate::choices::named::<crate::emitter::LightSampling>(), default_value = "area")]
    pub light_sampling: crate::emitter::LightSampling,
    /// Set a scene parameter declared with <default>: -D name=value (repeatable).
    #[arg(short = 'D', value_parser = crate::scene::loader::parse_define)]
    pub define: Vec<(String, String)>,
    /// `none`: the HTML report links the failures' heat maps instead of carrying them.
    #[arg(long, value_enum, default_value_t)]
    pub viewer: crate::report::html::Viewer,
}

/// The largest `--resolution`: its tables stay within a few hundred MB per case in flight.
pub const MAX_RESOLUTION: usize = 2048;

fn parse_resolution(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(r) if (3..=MAX_RESOLUTION).contains(&r) => Ok(r),
        _ => Err(format!(
            "expected a resolution from 3 to {MAX_RESOLUTION} cells, found '{s}'"
        )),
    }
}

/// One finished case and how long it took.
pub struct Timed {
    pub outcome: Outcome,
    pub seconds: f64,
}

fn verdict(o: &Outcome) -> &'static str {
    if o.passed() {
        "pass"
    } else {
        "FAIL"
    }
}

/// The heat map's path: the case name's groups become directories.
pub fn png_path(out: &Path, name: &str) -> PathBuf {
    out.join(format!("{name}.png"))
}

fn write_png(out: &Path, o: &Outcome) -> Result<(), String> {
    let path = png_path(out, &o.name);
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    let (c, r) = (o.chi2.observed.cols, o.chi2.observed.rows);
    let cell_px = (360 / c.max(r).max(1)).clamp(2, 24) as u32;
    heatmap::write(&path, &o.chi2, cell_px)
}

/// `results.csv`, one row per case.
pub fn write_csv(path: &Path, rows: &[Timed], cfg: &CaseConfig) -> Result<(), String> {
    write_atomic(path, |tmp| {
        let mut w = csv::Writer::from_path(tmp).map_err(|e| e.to_string())?;
        let err = |e: csv::Error| e.to_string();
        w.write_record([
            "case",
            "domain",
            "samples",
            "resolution",
            "seed",
            "statistic",
            "dof",
            "p_value",
            "threshold",
            "verdict",
            "lost",
            "pdf_integral",
            "checks",
            "reason",
            "seconds",
        ])
        .map_err(err)?;
        for t in rows {
            let o = &t.outcome;
            let c = &o.chi2;
            let checks: Vec<String> = o
                .checks
                .iter()
                .map(|k| format!("{}={}", k.name, if k.passed { "pass" } else { "fail" }))
                .collect();
            w.write_record([
                o.name.clone(),
                c.domain.to_string(),
                c.samples.to_string(),
                cfg.resolution.to_string(),
                cfg.seed.to_string(),
                format!("{:.6}", c.statistic),
                c.dof.to_string(),
                format!("{:.6e}", c.p_value),
                format!("{:.6e}", c.threshold),
                verdict(o).to_string(),
                c.lost.to_string(),
                format!("{:.8}", c.pdf_integral),
                checks.join(";"),
                o.summary(),
                format!("{:.3}", t.seconds),
            ])
            .map_err(err)?;
        }
        w.flush().map_err(|e| e.to_string())
    })
}

/// `index.md`: the settings, the failures with their heat maps, and every case's result
/// (each linking its heat map; embedding all of them would make a page of several MB).
pub fn markdown(rows: &[Timed], cfg: &CaseConfig, family_alpha: f64) -> String {
    use std::fmt::Write;
    let failed: Vec<&Timed> = rows.iter().filter(|t| !t.outcome.passed()).collect();
    let mut md = String::from("# Chi-square tests of the sampling routines\n\n");
    let _ = writeln!(
        md,
        "{} cases, {} samples each on {} cells along v, seed {}. Significance: alpha = \
         {family_alpha} for the whole run, Sidak-corrected to {:.3e} per case (a continuous \
         case shares it, Sidak again, between its chi-square test and the check of the pdf's \
         integral: hence the threshold column), so a correct implementation fails a run with \
         probability {family_alpha}. Each heat map shows the observed histogram, the pdf's \
         expected counts and their residual.\n",
        rows.len(),
        cfg.samples,
        cfg.resolution,
        cfg.seed,
        cfg.alpha
    );
    if failed.is_empty() {
        let _ = writeln!(md, "**All {} cases passed.**\n", rows.len());
    } else {
        let _ = writeln!(
            md,
            "**{} of {} cases failed.**\n\n## Failures\n",
            failed.len(),
            rows.len()
        );
        for t in &failed {
            let o = &t.outcome;
            let _ = writeln!(
                md,
                "### {}\n\n{}\n\n![{} heat map]({}.png)\n",
                o.name,
                o.summary().replace('|', "/"),
                o.name,
                o.name
            );
        }
    }
    let _ = writeln!(
        md,
        "## Cases\n\n| case | domain | statistic | dof | p-value | threshold | verdict | seconds |\n\
         |---|---|---:|---:|---:|---:|---|---:|"
    );
    for t in rows {
        let (o, c) = (&t.outcome, &t.outcome.chi2);
        let _ = writeln!(
            md,
            "| [{}]({}.png) | {} | {:.2} | {} | {:.3e} | {:.3e} | {} | {:.2} |",
            o.name,
            o.name,
            c.domain,
            c.statistic,
            c.dof,
            c.p_value,
            c.threshold,
            verdict(o),
            t.seconds
        );
    }
    md.push_str("\nRaw numbers: [results.csv](results.csv).\n");
    md
}

/// The printed table.
pub fn table(rows: &[Timed]) -> String {
    let width = rows
        .iter()
        .map(|t| t.outcome.name.len())
        .max()
        .unwrap_or(4)
        .max(4);
    let mut s = format!(
        "{:<width$}  {:>12}  {:>6}  {:>10}  {:>10}  {:>7}\n",
        "case", "statistic", "dof", "p-value", "threshold", "verdict"
    );
    for t in rows {
        let o = &t.outcome;
        let c = &o.chi2;
        // No statistic: an immediate verdict (impossible samples, or nothing to compare).
        let stat = if c.statistic.is_nan() {
            "-".to_string()
        } else {
            format!("{:.2}", c.statistic)
        };
        s += &format!(
            "{:<width$}  {:>12}  {:>6}  {:>10.3e}  {:>10.3e}  {:>7}\n",
            o.name,
            stat,
            c.dof,
            c.p_value,
            c.threshold,
            verdict(o)
        );
    }
    s
}

/// Runs the command; Ok(true) when every case passed.
pub fn run(a: &Chi2Args) -> Result<bool, String> {
    let (cases, out) = match &a.scene {
        None => (select(a.filter.as_deref().unwrap_or("")), a.out.clone()),
        Some(path) => {
            use crate::scene::loader::IntegratorMode;
            // The integrator does not matter to the samplers tested: a path tracer's scene
            // is read as its direct part.
            let scene = crate::scene::open_with(path, &a.define, Some(IntegratorMode::Direct))?;
            let (all, left) = super::scene::cases(
                std::sync::Arc::new(scene),
                a.emitter_selection,
                a.light_sampling,
            );
            for l in &left {
                eprintln!("left out: {l}");
            }
            let filter = a.filter.as_deref().unwrap_or("");
            let cases: Vec<_> = all
                .into_iter()
                .filter(|c| c.name.contains(filter))
                .collect();
            let stem = path
                .file_stem()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned();
            (cases, a.out.join("scenes").join(stem))
        }
    };
    if a.list {
        for c in &cases {
            println!("{:<40} {}", c.name, c.about);
        }
        return Ok(true);
    }
    if cases.is_empty() {
        return Err(format!(
            "no case matches '{}' (see --list)",
            a.filter.as_deref().unwrap_or("")
        ));
    }
    if a.samples < 100 {
        return Err("--samples must be at least 100".into());
    }
    let cfg = CaseConfig {
        samples: a.samples,
        resolution: a.resolution.max(3),
        seed: a.seed,
        alpha: sidak(ALPHA, cases.len()),
        ..CaseConfig::default()
    };
    run_cases(&cases, &cfg, ALPHA, &out, a.viewer)
}

/// Runs `cases` (in parallel) with `cfg`, whose `alpha` is the per-case level that makes
/// `family_alpha` over the run; prints the table and failures, writes `results.csv` and the
/// heat maps under `out`. Ok(true) when every case passed.
pub fn run_cases(
    cases: &[super::Case],
    cfg: &CaseConfig,
    family_alpha: f64,
    out: &Path,
    viewer: crate::report::html::Viewer,
) -> Result<bool, String> {
    eprintln!(
        "{} cases, {} samples each, resolution {}, seed {}; alpha {family_alpha} \
         Sidak-corrected to {:.3e} per case",
        cases.len(),
        cfg.samples,
        cfg.resolution,
        cfg.seed,
        cfg.alpha
    );
    let start = Instant::now();
    let rows: Vec<Timed> = cases
        .par_iter()
        .map(|case| {
            let t = Instant::now();
            let outcome = case.run(cfg);
            let seconds = t.elapsed().as_secs_f64();
            eprintln!(
                "  {:<44} {} ({seconds:.1} s)",
                outcome.name,
                verdict(&outcome)
            );
            Timed { outcome, seconds }
        })
        .collect();
    print!("{}", table(&rows));
    for t in &rows {
        write_png(out, &t.outcome)?;
    }
    let csv = out.join("results.csv");
    write_csv(&csv, &rows, cfg)?;
    let md = markdown(&rows, cfg, family_alpha);
    crate::report::write_report(out, &md, None, viewer)?;
    // In a reports root (such as `reports/`), its index now lists this page.
    if let Some(root) = out.parent().filter(|p| p.join("index.md").exists()) {
        crate::report::write_root_index(root)?;
    }
    let failed: Vec<&Timed> = rows.iter().filter(|t| !t.outcome.passed()).collect();
    for t in &failed {
        println!("FAIL {}: {}", t.outcome.name, t.outcome.summary());
    }
    eprintln!(
        "{} of {} cases passed in {:.1} s; wrote {} and heat maps under {}",
        rows.len() - failed.len(),
        rows.len(),
        start.elapsed().as_secs_f64(),
        csv.display(),
        out.display()
    );
    Ok(failed.is_empty())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_csv_and_heat_maps_and_reports_failures() {
        let dir = std::env::temp_dir().join(format!("directlab-chi2cmd-{}", std::process::id()));
        let args = Chi2Args {
            filter: Some("warp/uniform-disk".into()),
            samples: 20_000,
            resolution: 11,
            seed: 3,
            out: dir.clone(),
            list: false,
            scene: None,
            emitter_selection: crate::emitter::EmitterSelection::Uniform,
            light_sampling: crate::emitter::LightSampling::Area,
            define: vec![],
            viewer: Default::default(),
        };
        // 20k samples on 11 x 11 cells at alpha 0.01: a correct warp passes.
        assert_eq!(run(&args), Ok(true));
        let csv = std::fs::read_to_string(dir.join("results.csv")).unwrap();
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 2, "{csv}");
        assert!(lines[0].starts_with("case,domain,samples,resolution,seed,statistic,dof,p_value"));
        assert!(lines[1].starts_with("warp/uniform-disk,unit disk,20000,11,3,"));
        assert!(png_path(&dir, "warp/uniform-disk").exists());
        let md = std::fs::read_to_string(dir.join("index.md")).unwrap();
        assert!(md.contains("**All 1 cases passed.**"), "{md}");
        assert!(
            md.contains("| [warp/uniform-disk](warp/uniform-disk.png) | unit disk |"),
            "{md}"
        );
        assert!(dir.join("index.html").exists());
        let none = Chi2Args {
            filter: Some("no-such-case".into()),
            ..args
        };
        assert!(run(&none).is_err());
        std::fs::remove_dir_all(&dir).unwrap();

        // A failing outcome is marked in the table.
        let mut o = select("warp/uniform-disk")[0].run(&CaseConfig {
            samples: 1000,
            resolution: 5,
            ..CaseConfig::default()
        });
        o.chi2.verdict = crate::stats::Verdict::Fail;
        let timed = [Timed {
            outcome: o,
            seconds: 0.0,
        }];
        let t = table(&timed);
        assert!(t.lines().nth(1).unwrap().ends_with("FAIL"), "{t}");
        // The report shows a failure's heat map and says how many failed.
        let md = markdown(&timed, &CaseConfig::default(), ALPHA);
        assert!(md.contains("**1 of 1 cases failed.**"), "{md}");
        assert!(
            md.contains("## Failures\n\n### warp/uniform-disk\n"),
            "{md}"
        );
        assert!(
            md.contains("![warp/uniform-disk heat map](warp/uniform-disk.png)"),
            "{md}"
        );
    }
}
