//! `index.md` of a probe experiment (such as `reports/extreme/`): settings, cases, the
//! per-case, per-strategy table (non-finite samples, bias z, relMSE, largest sample,
//! fireflies' share, slope, verdict), the accumulation check and the input checks.

pub use super::probe_table::{
    critical, table, table_spp, PerSample, TableRow, BIASED, NON_FINITE, OK, TAIL,
};
use crate::experiment::analysis::metric_name;
use crate::experiment::probe::run::ProbeOutcome;
use std::fmt::Write as _;

fn sci(x: f64) -> String {
    if x.is_nan() {
        "—".into()
    } else if x == 0.0 {
        "0".into()
    } else {
        format!("{x:.3e}")
    }
}

fn settings(md: &mut String, o: &ProbeOutcome, rows: usize) {
    let x = &o.exp.exp;
    let p = x.probe.as_ref().expect("probe mode");
    let spp = table_spp(o);
    let zc = critical(o, rows);
    let _ = writeln!(md, "## Settings\n");
    let _ = writeln!(
        md,
        "- Experiment file: `{}`{}; {} cases, {} strategies listed.",
        o.exp.file.display(),
        if o.exp.quick { " (`--quick`)" } else { "" },
        o.cases.len(),
        x.strategies.len()
    );
    let _ = writeln!(
        md,
        "- Probe: **{}** samples of pixel ({}, {}) per (case, strategy, seed), drawn exactly as \
         `render` draws them; seeds 0..{}.",
        p.samples, p.pixel[0], p.pixel[1], x.seeds
    );
    let _ = writeln!(
        md,
        "- Error: {} of the means of batches of k samples, averaged over the samples / k \
         independent batches, for k in {:?} (one row of `results.csv` each); the table shows \
         k = {spp}. The reference is the case's closed form, without noise.",
        metric_name(x.metrics.primary, x.metrics.relmse_epsilon),
        x.spp
    );
    let _ = writeln!(
        md,
        "- Bias: z = (mean - reference) / standard error (its f32 rounding floor, 1e-6 relative, \
         included); |z| < {zc:.2} passes (two-sided, family-wise alpha = {} Šidák-corrected \
         over the {rows} rows).",
        p.alpha
    );
    let _ = writeln!(
        md,
        "- This invocation drew {} of {} streams ({} came from `results.csv`{}) in {:.1} s.\n",
        o.drawn,
        o.streams,
        o.streams - o.drawn,
        if o.dropped_rows > 0 {
            format!("; {} outdated rows were dropped", o.dropped_rows)
        } else {
            String::new()
        },
        o.seconds
    );
    let _ = writeln!(
        md,
        "Columns: non-finite samples (must be 0); mean and its z; relMSE at {spp} spp; the \
         largest single sample; the share of the total squared error carried by the top 0.1 % \
         of samples (fireflies; ~0.3 % for a well-behaved estimator); the least-squares slope \
         of log error against log spp over the sweep (-1 expected; — where the error is 0). \
         Verdict: `ok` = finite and |z| below the critical value; `tail unsampled` = |z| too \
         large with the mean too low, and either over half the squared error in 0.1 % of the \
         samples (the sample variance underestimates the true one, so z is not evidence of \
         bias) or a pure technique the case declares blind to part of the integrand (reason \
         given); `BIASED` = anything else.\n"
    );
}

fn cases(md: &mut String, o: &ProbeOutcome) {
    let _ = writeln!(md, "## Cases\n");
    let _ = writeln!(
        md,
        "| case | group | scene | emitters | reference | from | what it stresses |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|");
    for c in &o.cases {
        let file = c
            .case
            .scene
            .file_name()
            .map_or(String::new(), |f| f.to_string_lossy().to_string());
        let defines: Vec<String> = c
            .case
            .defines
            .iter()
            .map(|(k, v)| format!("{k}={v}"))
            .collect();
        let _ = writeln!(
            md,
            "| {} | {} | `{file}`{} | {} | {} | {} | {} |",
            c.case.name,
            c.case.group,
            if defines.is_empty() {
                String::new()
            } else {
                format!(" `-D {}`", defines.join(" -D "))
            },
            c.emitters,
            sci(c.reference()),
            c.case.reference_from(),
            c.case.about
        );
    }
    let omitted: Vec<String> = o
        .cases
        .iter()
        .flat_map(|c| {
            c.omitted
                .iter()
                .map(move |om| format!("{}: {} ({})", c.case.name, om.name, om.reason))
        })
        .collect();
    if !omitted.is_empty() {
        let _ = writeln!(
            md,
            "\nLeft out as the same estimator as a listed one, or blind to the whole scene \
             ({}):\n",
            omitted.len()
        );
        for l in omitted {
            let _ = writeln!(md, "- {l}");
        }
    }
    md.push('\n');
}

/// A counted quantity per sample, or a dash for rows without counts.
fn counted(r: &TableRow, f: fn(&PerSample) -> f64) -> String {
    r.per_sample
        .as_ref()
        .map_or("—".into(), |p| format!("{:.2}", f(p)))
}

fn results(md: &mut String, o: &ProbeOutcome, t: &[TableRow]) {
    let spp = table_spp(o);
    let _ = writeln!(
        md,
        "## Results\n\nns / sample: the time one sample of the strategy's stream takes (mean over \
         seeds); relMSE x time: relMSE at {spp} spp times the seconds those samples take per \
         pixel, the error at equal work (lower is better), which charges a costly emitter \
         choice (exhaustive is O(N)) for its time; counted per sample: rays traced (camera, \
         shadow, BSDF), BSDF and light-density evaluations, and emitters the emitter choice \
         weighed, the same on every machine.\n"
    );
    let _ = writeln!(
        md,
        "| case | strategy | non-finite | mean | z | relMSE@{spp} | ns / sample | relMSE x time | rays / sample | evals / sample | choice evals / sample | max sample | top 0.1 % | slope | verdict |"
    );
    let _ = writeln!(
        md,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for r in t {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {:.2} | {} | {:.0} | {} | {} | {} | {} | {} | {} | {} | {}{} |",
            r.case,
            r.label,
            r.non_finite,
            sci(r.mean),
            r.z,
            sci(r.relmse),
            r.ns_per_sample,
            // The error at equal work: relMSE at spp times the time those samples take.
            sci(r.relmse * r.ns_per_sample * 1e-9 * spp as f64),
            counted(r, |p| p.rays),
            counted(r, |p| p.evals),
            counted(r, |p| p.choice_evals),
            sci(r.max_sample),
            if r.top_share.is_nan() {
                "—".into()
            } else {
                format!("{:.1} %", 100.0 * r.top_share)
            },
            r.slope.map_or("—".into(), |s| format!("{s:.2}")),
            r.verdict,
            r.blind
                .as_ref()
                .map_or(String::new(), |b| format!(" (blind: {b})"))
        );
    }
    let count = |v: &str| t.iter().filter(|r| r.verdict == v).count();
    let _ = writeln!(
        md,
        "\nSummary: {} rows, {} non-finite samples in all; {} ok, {} tail unsampled, {} biased.\n",
        t.len(),
        t.iter().map(|r| r.non_finite).sum::<u64>(),
        count(OK),
        count(TAIL),
        count(BIASED)
    );
}

fn accumulation(md: &mut String, o: &ProbeOutcome) {
    if o.accumulation.is_empty() {
        return;
    }
    let _ = writeln!(md, "## Very high sample counts\n");
    let _ = writeln!(
        md,
        "`render` at very high spp on a small probe. The image mean's z is against the closed \
         form; the f64 column is |render mean − exact mean of the same samples| / reference for \
         pixel (0, 0), the f32 column what a running f32 sum of those samples would be off by. \
         Rows are kept in [accumulation.csv](accumulation.csv).\n"
    );
    let _ = writeln!(
        md,
        "| case | strategy | pixels × spp | non-finite | image mean | reference | z | f64 accumulation error | f32 running sum error |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|");
    for a in &o.accumulation {
        let _ = writeln!(
            md,
            "| {} | {} | {} × {} | {} | {:.6e} | {:.6e} | {:.2} | {} | {} |",
            a.case,
            a.strategy,
            a.pixels,
            a.spp,
            a.non_finite,
            a.image_mean,
            a.reference,
            a.z,
            sci(a.f64_rel_error),
            sci(a.f32_rel_error)
        );
    }
    md.push('\n');
}

fn checks(md: &mut String, o: &ProbeOutcome) {
    if o.checks.is_empty() {
        return;
    }
    let _ = writeln!(md, "## Invalid and degenerate input\n");
    let _ = writeln!(md, "| input | must give | containing | message | ok |");
    let _ = writeln!(md, "|---|---|---|---|---|");
    for c in &o.checks {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} |",
            c.input,
            c.expect,
            c.must_contain,
            c.message.replace('|', "\\|").replace('\n', " "),
            if c.ok { "yes" } else { "NO" }
        );
    }
    md.push('\n');
}

/// Writes `<dir>/index.md` and `<dir>/index.html`.
pub fn write(
    o: &ProbeOutcome,
    figure: Option<&str>,
    viewer: super::html::Viewer,
) -> Result<(), String> {
    let t = table(o);
    let mut md = String::new();
    let x = &o.exp.exp;
    let _ = writeln!(
        md,
        "# {}\n",
        x.title.clone().unwrap_or_else(|| o.exp.name.clone())
    );
    if !x.description.is_empty() {
        let _ = writeln!(md, "{}\n", x.description.trim());
    }
    if x.integrator.is_some() {
        let _ = writeln!(
            md,
            "**Direct illumination only.** `integrator = \"direct\"`: scenes whose integrator \
             is a path tracer or Whitted's are rendered as their direct part.\n"
        );
    }
    settings(&mut md, o, t.len());
    if let Some(f) = figure {
        let _ = writeln!(
            md,
            "![{} against spp]({f})\n",
            crate::experiment::analysis::metric_short(x.metrics.primary)
        );
    }
    cases(&mut md, o);
    results(&mut md, o, &t);
    accumulation(&mut md, o);
    checks(&mut md, o);
    let _ = writeln!(
        md,
        "Raw numbers: [results.csv](results.csv), one row per (case, strategy, seed, spp); \
         reference values and their closed forms: `{}`.",
        o.exp.file.display()
    );
    super::write_report(&o.dir, &md, None, viewer)
}
