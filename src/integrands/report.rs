//! `directlab integrands`: runs the test integrands and writes `<out>/integrands/`: the
//! RMSE of every (integrand, sampler, N) in results.csv, a log-log chart per integrand, and
//! index.md with the slope table against the published rates.

use super::pixel::{self, PixelCell};
use super::{complete_count, measure, sample_counts, slope, Cell, Integrand, Slope};
use crate::named::Named;
use crate::output::write_atomic;
use crate::plot::{write_chart, Line, LogLogChart};
use crate::sampler::SamplerKind;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

#[derive(clap::Args, Debug, Clone)]
pub struct IntegrandsArgs {
    /// Independent randomisations (seeds) per sample count [default: 256, 32 with --quick].
    #[arg(long)]
    pub seeds: Option<u64>,
    /// Largest sample count N (powers of two from 16, and the off-grid 2^(k + 1/2) between)
    /// [default: 4096, 256 with --quick].
    #[arg(long)]
    pub max_n: Option<u64>,
    /// Samplers to compare, comma-separated (default: all).
    #[arg(long, value_parser = crate::choices::named::<SamplerKind>(), value_delimiter = ',')]
    pub samplers: Vec<SamplerKind>,
    /// Reports folder; the report is written to `<out>/integrands/`.
    #[arg(long, default_value = "reports")]
    pub out: PathBuf,
    /// Reduced size (32 seeds, N up to 256, unless --seeds or --max-n say otherwise; tests
    /// and smoke runs), written to `<out>/integrands-quick/`.
    #[arg(long)]
    pub quick: bool,
    /// `none`: the HTML report links its figures instead of carrying them.
    #[arg(long, value_enum, default_value_t)]
    pub viewer: crate::report::html::Viewer,
}

impl Default for IntegrandsArgs {
    fn default() -> Self {
        IntegrandsArgs {
            seeds: None,
            max_n: None,
            samplers: Vec::new(),
            out: PathBuf::from("reports"),
            quick: false,
            viewer: Default::default(),
        }
    }
}

impl IntegrandsArgs {
    /// Seeds and largest N: as given, else the full or quick defaults; bounded.
    fn size(&self) -> Result<(u64, u32), String> {
        let seeds = self.seeds.unwrap_or(if self.quick { 32 } else { 256 });
        let max_n = self.max_n.unwrap_or(if self.quick { 256 } else { 4096 });
        if seeds < 2 {
            return Err(format!(
                "--seeds {seeds}: the RMSE and its bootstrap interval need at least 2"
            ));
        }
        crate::limits::count(seeds, "--seeds", crate::limits::SEEDS)?;
        if max_n < 32 {
            return Err(format!(
                "--max-n {max_n}: a slope needs two powers of two from 16, so at least 32"
            ));
        }
        let max_n = crate::limits::count(max_n, "--max-n", MAX_N)?;
        Ok((seeds, max_n as u32))
    }
}

/// The largest N: each count is a run of every sampler over every seed.
const MAX_N: crate::limits::Bound = crate::limits::Bound {
    max: 1 << 20,
    why: "the rates settle by N = 4096; a larger N only adds hours",
};

/// A slope agrees with a published one when its interval holds it or they differ by at
/// most this (the paper reads its rates off plots, to about a tenth).
const AGREE: f64 = 0.1;

/// Runs the integrands and writes the report; returns its folder.
pub fn run(a: &IntegrandsArgs) -> Result<PathBuf, String> {
    let name = if a.quick {
        "integrands-quick"
    } else {
        "integrands"
    };
    let (seeds, max_n) = a.size()?;
    if let Some((i, k)) = a
        .samplers
        .iter()
        .enumerate()
        .find(|(i, k)| a.samplers[..*i].contains(k))
    {
        return Err(format!(
            "--samplers lists {} twice (entry {}); each sampler is measured once",
            k.name(),
            i + 1
        ));
    }
    let samplers: Vec<SamplerKind> = if a.samplers.is_empty() {
        SamplerKind::all()
    } else {
        a.samplers.clone()
    };
    let counts = sample_counts(max_n);
    let start = std::time::Instant::now();
    let cells = measure(&samplers, &counts, seeds)?;
    let dir = a.out.join(name);
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    write_csv(&dir.join("results.csv"), &cells)?;
    let mut charts = Vec::new();
    for (i, f) in Integrand::ALL.iter().enumerate() {
        let stem = format!("rmse-{}", f.name().to_lowercase().replace(' ', "-"));
        write_chart(&dir.join(&stem), &chart(&cells, &samplers, i, *f))?;
        charts.push(stem);
    }
    let mut md = index((seeds, max_n), &samplers, &counts, &cells, &charts);
    // The renderer costs more per sample than a 2D pair: the pixel check stops at 1024.
    let pixel_counts = sample_counts(max_n.min(1024));
    let pixel_cells = pixel::measure(&pixel_counts, seeds)?;
    md += &pixel_section(&dir, &pixel_cells, &pixel_counts, seeds)?;
    crate::report::write_report(&dir, &md, None, a.viewer)?;
    let path = dir.join("index.md");
    eprintln!(
        "integrands: {} samplers x {} counts x {} seeds in {:.1} s; report in {}",
        samplers.len(),
        counts.len(),
        seeds,
        start.elapsed().as_secs_f64(),
        path.display()
    );
    Ok(dir)
}

fn write_csv(path: &Path, cells: &[Cell]) -> Result<(), String> {
    let mut text = String::from("integrand,sampler,n,complete,rmse,seeds\n");
    for c in cells {
        for (i, f) in Integrand::ALL.iter().enumerate() {
            let _ = writeln!(
                text,
                "{},{},{},{},{:.6e},{}",
                f.name(),
                c.sampler.name(),
                c.n,
                complete_count(c.sampler, c.n),
                c.rmse(i),
                c.sq_errors[i].len()
            );
        }
    }
    write_atomic(path, |tmp| {
        std::fs::write(tmp, &text).map_err(|e| format!("{}: {e}", path.display()))
    })
}

fn of(cells: &[Cell], kind: SamplerKind) -> Vec<&Cell> {
    cells.iter().filter(|c| c.sampler == kind).collect()
}

/// One line per series through its complete counts, and its off-grid counts as a second
/// line in the same colour's light companion (the palette's index + 10). A series is a
/// label, the sampler whose counts are complete, and its cells; `i` picks the integrand.
fn rmse_chart(
    title: String,
    series: &[(String, SamplerKind, Vec<&Cell>)],
    i: usize,
) -> LogLogChart {
    let line =
        |j: usize, (label, k, cells): &(String, SamplerKind, Vec<&Cell>), complete: bool| Line {
            label: if complete {
                label.clone()
            } else {
                format!("{label} (off-grid)")
            },
            points: cells
                .iter()
                .filter(|c| complete_count(*k, c.n) == complete)
                .map(|c| (c.n as f64, c.rmse(i)))
                .collect(),
            spread: Vec::new(),
            colour: Some(if complete { j } else { j + 10 }),
        };
    let mut lines: Vec<Line> = series
        .iter()
        .enumerate()
        .map(|(j, s)| line(j, s, true))
        .collect();
    lines.extend(series.iter().enumerate().map(|(j, s)| line(j, s, false)));
    LogLogChart {
        title,
        x_label: "samples N".into(),
        y_label: "RMSE over seeds".into(),
        lines,
        hline: None,
    }
}

fn chart(cells: &[Cell], samplers: &[SamplerKind], i: usize, f: Integrand) -> LogLogChart {
    let series: Vec<_> = samplers
        .iter()
        .map(|&k| (k.name().to_string(), k, of(cells, k)))
        .collect();
    rmse_chart(format!("{}: {}", f.name(), f.formula()), &series, i)
}

/// The pixel check's charts (light sampling, one per case) and its report section.
fn pixel_section(
    dir: &Path,
    cells: &[PixelCell],
    counts: &[u32],
    seeds: u64,
) -> Result<String, String> {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "\n## One pixel under an area light\n\n\
         The same samplers in the renderer: one pixel of a diffuse floor (albedo 0.5) under a \
         square light (side 1, radiance 1, 2 above the floor), unoccluded and with a black \
         occluder's edge across the light (a penumbra: 40 % of the light hidden). The closed \
         form is Lambert's polygon formula for the part of the light the pixel sees. Each \
         light sample draws its emitter, triangle and point as one joint 4D set (`:padded`: \
         each its own), so unoccluded the light sample's integrand is smooth and in the \
         penumbra it has an edge. N = {} to {}, {seeds} seeds; error against the closed form \
         across seeds. Samplers that pad (`stratified`, `sobol:padded`) stratify the triangle \
         choice and the point on the triangle separately: unoccluded, this light's two \
         triangles give the same value at the same point of their parametrisation, so the \
         choice costs nothing, but in the penumbra the integrand depends on both jointly and \
         only a joint set keeps a rate faster than Monte Carlo's (a triangulation without \
         that symmetry, or a light of unequal triangles, costs padded draws their rate even \
         unoccluded).\n\n\
         | case | strategy | sampler | slope, complete counts [95 % CI] | off-grid slope | RMSE at N = {} |\n\
         |---|---|---|---|---|---|",
        counts[0],
        counts.last().copied().unwrap_or(0),
        counts.iter().rev().find(|n| n.is_power_of_two()).copied().unwrap_or(0)
    );
    let sampling_names: Vec<String> = pixel::samplings()
        .iter()
        .map(pixel::sampling_name)
        .collect();
    let mut figures = String::new();
    for case in pixel::Case::ALL {
        for strategy in &pixel::STRATEGIES {
            let mut series = Vec::new();
            for (s, name) in pixel::samplings().iter().zip(&sampling_names) {
                let mine: Vec<&Cell> = cells
                    .iter()
                    .filter(|c| c.case == case && c.strategy == *strategy && c.sampling == *s)
                    .map(|c| &c.cell)
                    .collect();
                let k = s.kind;
                let complete = slope(&mine, 0, |n| complete_count(k, n));
                let off = slope(&mine, 0, |n| !n.is_power_of_two());
                let last = mine
                    .iter()
                    .rev()
                    .find(|c| c.n.is_power_of_two())
                    .map_or(f64::NAN, |c| c.rmse(0));
                let _ = writeln!(
                    md,
                    "| {} | {strategy} | {name} | {} | {} | {last:.3e} |",
                    case.name(),
                    fmt_slope(complete),
                    fmt_slope(off)
                );
                series.push((name.clone(), k, mine));
            }
            if *strategy == "light" {
                let stem = format!("pixel-{}", case.name());
                let title = format!("one pixel, {}, light sampling", case.name());
                write_chart(&dir.join(&stem), &rmse_chart(title, &series, 0))?;
                let _ = writeln!(figures, "![{}, light sampling]({stem}.png)\n", case.name());
            }
        }
    }
    Ok(md + "\n" + &figures)
}

fn fmt_slope(s: Option<Slope>) -> String {
    match s {
        None => "–".into(),
        Some(Slope { slope, ci: None }) => format!("{slope:.2}"),
        Some(Slope {
            slope,
            ci: Some((a, b)),
        }) => format!("{slope:.2} [{a:.2}, {b:.2}]"),
    }
}

/// How a measured slope compares with the published one.
fn verdict(s: Option<Slope>, published: Option<f64>) -> (String, bool) {
    let (Some(s), Some(p)) = (s, published) else {
        return ("no published rate".into(), false);
    };
    let held = s.ci.is_some_and(|(a, b)| a <= p && p <= b);
    let d = s.slope - p;
    if held || d.abs() <= AGREE {
        ("agrees".into(), false)
    } else if d < 0.0 {
        (format!("steeper by {:.2}", -d), true)
    } else {
        (format!("shallower by {d:.2}"), true)
    }
}

/// Why a sampler's slope may part from the paper's, for the rows that do.
fn why(k: SamplerKind) -> &'static str {
    match k {
        SamplerKind::Independent => {
            "the Monte Carlo rate is exact for every integrand, so a departure is noise: \
             more seeds narrow the interval"
        }
        _ => {
            "the published rates are asymptotic and read off the paper's plots; a fit over a \
             short range of N (or few seeds) carries the pre-asymptotic bend of the curve and \
             its noise: the chart shows where the rate settles"
        }
    }
}

fn index(
    (seeds, max_n): (u64, u32),
    samplers: &[SamplerKind],
    counts: &[u32],
    cells: &[Cell],
    charts: &[String],
) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Sampler test integrands (Christensen, Kensler and Kilpatrick 2018)\n\n\
         Each sampler's first 2D pair (the film pair of one pixel) integrates five functions \
         over the unit square, N = {} to {} samples, over {} independent randomisations \
         (seeds). The error of a seed is its estimate minus the exact integral; the RMSE is \
         taken across seeds, never from one seed's sample variance, which is wrong for \
         correlated samples. Each N is a run of its own, as a render of N samples per pixel \
         is (stratified strata and zsobol blocks are laid out for N). Slopes are fitted to \
         log RMSE against log N at each sampler's complete counts (powers of two; of four \
         for `stratified`, whose grid is square only there), with a 95 % bootstrap interval \
         over seeds; the off-grid slope is fitted to the counts 2^(k + 1/2) between them \
         (23, 45, 91, ...), where every net is incomplete. Published rates: the paper's RMSE slopes as summarised \
         in REFERENCE.md section 9 (random N^-0.5; jittered N^-0.75 with edges, N^-1 smooth; \
         Owen-scrambled Sobol' and pmj02 N^-0.75 for the disk and triangle, N^-1 for the \
         step, N^-1.5 smooth). `sobol-xor` (a digital shift only) is not in the paper. \
         Written by `directlab integrands --seeds {} --max-n {}` (and by `reproduce`).\n",
        counts[0],
        counts.last().copied().unwrap_or(0),
        seeds,
        seeds,
        max_n
    );
    let _ = writeln!(
        md,
        "| integrand | f(x, y) | exact integral |\n|---|---|---|"
    );
    for f in Integrand::ALL {
        let _ = writeln!(md, "| {} | {} | {:.10} |", f.name(), f.formula(), f.exact());
    }
    let _ = writeln!(
        md,
        "\n## RMSE slopes\n\n\
         | integrand | sampler | slope, complete counts [95 % CI] | off-grid slope | published | vs published | RMSE at N = {} |\n\
         |---|---|---|---|---|---|---|",
        counts.iter().rev().find(|n| n.is_power_of_two()).copied().unwrap_or(0)
    );
    let mut differ = Vec::new();
    for (i, f) in Integrand::ALL.iter().enumerate() {
        for &k in samplers {
            let mine = of(cells, k);
            let complete = slope(&mine, i, |n| complete_count(k, n));
            let off = slope(&mine, i, |n| !n.is_power_of_two());
            let published = f.published(k);
            let (v, differs) = verdict(complete, published);
            if differs {
                differ.push((*f, k, v.clone()));
            }
            let last = mine
                .iter()
                .rev()
                .find(|c| c.n.is_power_of_two())
                .map_or(f64::NAN, |c| c.rmse(i));
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {} | {:.3e} |",
                f.name(),
                k.name(),
                fmt_slope(complete),
                fmt_slope(off),
                published.map_or("–".into(), |p| format!("{p:.2}")),
                v,
                last
            );
        }
    }
    let _ = writeln!(md, "\n## Where the slopes part from the paper's\n");
    if differ.is_empty() {
        let _ = writeln!(
            md,
            "Every measured slope holds the published rate in its interval or lies within \
             {AGREE} of it."
        );
    }
    for (f, k, v) in &differ {
        let _ = writeln!(md, "- {}, `{}`: {v}. {}.", f.name(), k.name(), why(*k));
    }
    let _ = writeln!(md, "\n## RMSE against N\n");
    for (c, f) in charts.iter().zip(Integrand::ALL) {
        let _ = writeln!(md, "![{}]({c}.png)\n", f.name());
    }
    md
}
