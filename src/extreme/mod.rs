//! `directlab extreme`: the stability suite of issue 6. Probes of one floor point under
//! extreme lights, geometry, lobes, scales and degenerate input, each against a closed form
//! (or quadrature), per strategy: non-finite samples, bias (z), relMSE, the largest sample,
//! the share of squared error in the top 0.1 % of samples, and the convergence slope.
//!
//! Standalone for now; see `report.rs` for how it maps onto the experiment runner.

pub mod accumulate;
pub mod cases;
mod figure;
pub mod invalid;
pub mod measure;
pub mod reference;
mod report;
pub mod samples;
pub mod scenes;

use crate::emitter::{EmitterSelection, LightSampling};
use crate::integrator::{Direct, Strategy};
use crate::scene::desc::{Heuristic, StrategyKind};
use crate::scene::Scene;
use cases::Case;
use clap::Args;
use measure::Measured;
use rayon::prelude::*;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ExtremeArgs {
    /// Small sample counts (2^14 per probe instead of 2^20): a smoke run, not the report.
    #[arg(long)]
    pub quick: bool,
    /// Output folder for index.md, extreme.csv and the figure.
    #[arg(long, default_value = "reports/extreme")]
    pub out: PathBuf,
    /// The folder of the XML cases.
    #[arg(long, default_value = "scenes/extreme")]
    pub scenes: PathBuf,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
}

/// Samples per probe: full and quick.
pub const FULL_SAMPLES: u32 = 1 << 20;
pub const QUICK_SAMPLES: u32 = 1 << 14;

/// The strategies of the report: pure light sampling by area, by solid angle and with
/// power-proportional emitter choice; pure BSDF sampling; MIS with both heuristics;
/// one-sample MIS.
pub fn report_strategies() -> Vec<Strategy> {
    let base = Strategy {
        kind: StrategyKind::Light,
        heuristic: Heuristic::Balance,
        emitter_samples: 1,
        bsdf_samples: 1,
        selection: EmitterSelection::Uniform,
        light_sampling: LightSampling::Area,
        hide_emitters: false,
    };
    vec![
        base,
        Strategy {
            light_sampling: LightSampling::SolidAngle,
            ..base
        },
        Strategy {
            selection: EmitterSelection::Power,
            ..base
        },
        Strategy {
            kind: StrategyKind::Bsdf,
            ..base
        },
        Strategy {
            kind: StrategyKind::Mis,
            ..base
        },
        Strategy {
            kind: StrategyKind::Mis,
            heuristic: Heuristic::Power,
            light_sampling: LightSampling::SolidAngle,
            ..base
        },
        Strategy {
            kind: StrategyKind::MisOneSample,
            ..base
        },
    ]
}

/// One table row.
pub struct Row {
    pub case: String,
    pub group: &'static str,
    pub strategy: Strategy,
    pub reference: f64,
    pub reference_from: &'static str,
    /// Why the strategy is blind to part of this case's integrand, if it is.
    pub blind: Option<&'static str>,
    pub m: Measured,
}

/// Builds every case's scene, checking the warnings each case expects.
pub fn build(cases: &[Case]) -> Result<Vec<Scene>, String> {
    cases
        .iter()
        .map(|c| {
            let scene = Scene::build(c.desc.clone()).map_err(|e| format!("{}: {e}", c.name))?;
            if let Some(w) = c.warning {
                if !scene.warnings.iter().any(|s| s.contains(w)) {
                    return Err(format!(
                        "{}: expected a warning containing '{w}', got {:?}",
                        c.name, scene.warnings
                    ));
                }
            }
            Ok(scene)
        })
        .collect()
}

/// Measures every (case, strategy) with `n` samples of the probe pixel (pixel 0, 0).
pub fn run_cases(
    cases: &[Case],
    scenes: &[Scene],
    strategies: &[Strategy],
    n: u32,
    seed: u64,
) -> Vec<Row> {
    let jobs: Vec<(usize, Strategy)> = (0..cases.len())
        .flat_map(|c| strategies.iter().map(move |s| (c, *s)))
        .collect();
    jobs.par_iter()
        .map_init(Vec::new, |buf, &(ci, s)| {
            let c = &cases[ci];
            let direct = Direct::new(&scenes[ci], s);
            let non_finite = samples::pixel_samples(&direct, 0, 0, seed, n, buf);
            Row {
                case: c.name.clone(),
                group: c.group,
                strategy: s,
                reference: c.reference,
                reference_from: c.reference_from,
                blind: c.blind_for(&s),
                m: measure::measure(buf, non_finite, c.reference),
            }
        })
        .collect()
}

/// The command: measure, then write the report.
pub fn run(a: &ExtremeArgs) -> Result<(), String> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(a.threads.unwrap_or(0))
        .build()
        .map_err(|e| e.to_string())?;
    pool.install(|| {
        let start = std::time::Instant::now();
        let n = if a.quick { QUICK_SAMPLES } else { FULL_SAMPLES };
        let cases = cases::all_cases(&a.scenes);
        let scenes = build(&cases)?;
        let strategies = report_strategies();
        eprintln!(
            "extreme: {} cases x {} strategies x {n} samples",
            cases.len(),
            strategies.len()
        );
        let rows = run_cases(&cases, &scenes, &strategies, n, a.seed);
        let acc = accumulate::run(a.quick, a.seed);
        let invalid = invalid::check_all(&a.scenes);
        let info = report::RunInfo {
            samples: n,
            seed: a.seed,
            quick: a.quick,
            seconds: start.elapsed().as_secs_f64(),
        };
        std::fs::create_dir_all(&a.out).map_err(|e| format!("{}: {e}", a.out.display()))?;
        report::write_csv(&a.out.join("extreme.csv"), &rows)?;
        figure::write(&a.out.join("convergence.png"), &rows)?;
        report::write_index(
            &a.out.join("index.md"),
            &info,
            &cases,
            &rows,
            &acc,
            &invalid,
        )?;
        eprintln!("extreme: wrote {}", a.out.join("index.md").display());
        Ok(())
    })
}
