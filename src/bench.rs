//! `directlab bench`: render throughput per scene, strategy and thread count, so speed goals
//! are measured numbers (written to `reports/bench/bench.csv`), never timed tests.

use crate::cli::open_scene;
use crate::emitter::{EmitterSelection, LightSampling};
use crate::integrator::Strategy;
use crate::render::{render, RenderSettings};
use crate::scene::desc::{Heuristic, StrategyKind};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Scenes to measure (default: the bundled Cornell box).
    #[arg(long = "scene")]
    pub scenes: Vec<PathBuf>,
    /// Thread counts to measure.
    #[arg(long, value_delimiter = ',', default_value = "1,2")]
    pub threads: Vec<usize>,
    /// Samples per pixel of each timed render.
    #[arg(long, default_value_t = 64)]
    pub spp: u32,
    /// Image resolution (sets the scene's `res` default).
    #[arg(long, default_value_t = 256)]
    pub res: u32,
    /// Timed repetitions; the fastest is reported (the others measure interference).
    #[arg(long, default_value_t = 3)]
    pub repeat: u32,
    /// Output CSV.
    #[arg(long, default_value = "reports/bench/bench.csv")]
    pub out: PathBuf,
}

/// The strategies whose throughput is reported: the study's and the usual MIS settings.
pub fn bench_strategies() -> Vec<Strategy> {
    let base = Strategy {
        kind: StrategyKind::Mis,
        heuristic: Heuristic::Power,
        emitter_samples: 1,
        bsdf_samples: 1,
        selection: EmitterSelection::Uniform,
        light_sampling: LightSampling::Area,
        hide_emitters: false,
    };
    vec![
        base,
        Strategy {
            heuristic: Heuristic::Balance,
            ..base
        },
        Strategy {
            kind: StrategyKind::Light,
            ..base
        },
        Strategy {
            kind: StrategyKind::Bsdf,
            ..base
        },
        Strategy {
            kind: StrategyKind::MisOneSample,
            ..base
        },
        Strategy {
            light_sampling: LightSampling::SolidAngle,
            ..base
        },
        Strategy {
            selection: EmitterSelection::Power,
            ..base
        },
    ]
}

#[derive(serde::Serialize)]
struct Row {
    scene: String,
    strategy: String,
    threads: usize,
    width: u32,
    height: u32,
    spp: u32,
    seconds: f64,
    samples_per_second: f64,
}

pub fn run(a: &BenchArgs) -> Result<(), String> {
    let scenes = if a.scenes.is_empty() {
        vec![PathBuf::from("scenes/cbox/cbox.xml")]
    } else {
        a.scenes.clone()
    };
    let mut rows = Vec::new();
    println!(
        "{:<36} {:<28} {:>7} {:>12}",
        "scene", "strategy", "threads", "M samples/s"
    );
    for path in &scenes {
        let scene = open_scene(path, &[("res".into(), a.res.to_string())])?;
        for strategy in bench_strategies() {
            for &threads in &a.threads {
                let settings = RenderSettings {
                    spp: a.spp,
                    seed: 1,
                    threads: Some(threads),
                    progress: false,
                };
                let best = (0..a.repeat.max(1))
                    .map(|_| render(&scene, strategy, &settings).seconds)
                    .fold(f64::INFINITY, f64::min);
                let (w, h) = (scene.camera.width, scene.camera.height);
                let sps = w as f64 * h as f64 * a.spp as f64 / best;
                println!(
                    "{:<36} {:<28} {:>7} {:>12.2}",
                    path.display(),
                    strategy.label(),
                    threads,
                    sps / 1e6
                );
                rows.push(Row {
                    scene: path.display().to_string(),
                    strategy: strategy.label(),
                    threads,
                    width: w,
                    height: h,
                    spp: a.spp,
                    seconds: best,
                    samples_per_second: sps,
                });
            }
        }
    }
    crate::film::write_atomic(&a.out, |tmp| {
        let mut w = csv::Writer::from_path(tmp).map_err(|e| format!("{}: {e}", a.out.display()))?;
        for r in &rows {
            w.serialize(r).map_err(|e| e.to_string())?;
        }
        w.flush().map_err(|e| e.to_string())
    })?;
    eprintln!("wrote {}", a.out.display());
    Ok(())
}
