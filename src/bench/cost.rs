//! The cost model of one scene on this machine (`crate::cost`): fitted on one-thread renders
//! of the bench strategies at two sample counts, then asked to predict renders it never saw
//! (more light and BSDF samples per camera sample, solid angle with two light samples) at a
//! third. Its prediction error on those is the honest figure: on the fitted runs it can only
//! look good.

use super::timing::{best_of_turns, timed};
use super::{bench_strategies, BenchArgs, Row};
use crate::cost::{CostModel, Work, TERMS};
use crate::emitter::{EmitterSelection, LightSampling};
use crate::integrator::Strategy;
use crate::sampler::SamplerKind;
use crate::scene::desc::{Heuristic, StrategyKind};
use crate::scene::Scene;

/// Configurations the model is not fitted on: other sample counts per camera sample, other
/// mixes of techniques.
fn held_out() -> Vec<Strategy> {
    let mis = bench_strategies()[0];
    vec![
        Strategy {
            emitter_samples: 2,
            bsdf_samples: 2,
            ..mis
        },
        Strategy {
            kind: StrategyKind::Light,
            emitter_samples: 3,
            ..mis
        },
        Strategy {
            kind: StrategyKind::Bsdf,
            bsdf_samples: 2,
            ..mis
        },
        Strategy {
            emitter_samples: 2,
            light_sampling: LightSampling::SolidAngle,
            ..mis
        },
        Strategy {
            kind: StrategyKind::MisOneSample,
            heuristic: Heuristic::Balance,
            emitter_samples: 2,
            selection: EmitterSelection::Power,
            ..mis
        },
        Strategy {
            heuristic: Heuristic::Balance,
            bsdf_samples: 3,
            ..mis
        },
    ]
}

/// Configurations fitted besides the bench strategies, so that each technique's counts vary
/// apart from the others' (in the bench strategies every estimator takes one sample of each
/// technique, or one alone, and the model could trade one term for another): MIS with two
/// light or two BSDF samples, light sampling with two, BSDF sampling with three, light
/// sampling alone in solid angle (solid-angle samples without solid-angle densities), and
/// one-sample MIS choosing the BSDF technique two times in three.
fn design() -> Vec<Strategy> {
    let mis = bench_strategies()[0];
    let light = Strategy {
        kind: StrategyKind::Light,
        ..mis
    };
    vec![
        Strategy {
            emitter_samples: 2,
            ..mis
        },
        Strategy {
            bsdf_samples: 2,
            ..mis
        },
        Strategy {
            emitter_samples: 2,
            ..light
        },
        Strategy {
            kind: StrategyKind::Bsdf,
            bsdf_samples: 3,
            ..mis
        },
        Strategy {
            light_sampling: LightSampling::SolidAngle,
            ..light
        },
        Strategy {
            kind: StrategyKind::MisOneSample,
            bsdf_samples: 2,
            ..mis
        },
    ]
}

/// One timed configuration: its strategy, spp, what it did and its fastest seconds.
struct Run {
    strategy: Strategy,
    spp: u32,
    work: Work,
    seconds: f64,
}

/// The cost-model section for one scene: every configuration timed on one thread in turns
/// (a drift of the machine's speed falls on fitted and held-out runs alike), best of
/// `a.repeat`.
pub(super) fn section(scene: &Scene, name: &str, a: &BenchArgs, rows: &mut Vec<Row>) {
    let pixels = u64::from(scene.camera.width) * u64::from(scene.camera.height);
    let quarter = (a.spp / 4).max(1);
    let half = (a.spp / 2).max(1);
    let fitted: Vec<(Strategy, u32)> = [quarter, a.spp]
        .into_iter()
        .flat_map(|spp| bench_strategies().into_iter().map(move |s| (s, spp)))
        .chain(design().into_iter().map(|s| (s, quarter)))
        .collect();
    let configs: Vec<(Strategy, u32)> = fitted
        .iter()
        .copied()
        .chain(held_out().into_iter().map(|s| (s, half)))
        .collect();
    let mut fit = time_in_turns(scene, pixels, &configs, a.repeat);
    let held = fit.split_off(fitted.len());
    let Some(model) = CostModel::fit(&fit.iter().map(|r| (r.work, r.seconds)).collect::<Vec<_>>())
    else {
        return;
    };
    println!(
        "  cost model ({name}, 1 thread, fitted on {} renders at {quarter} and {} spp, held out at {half}), ns per unit:",
        model.runs, a.spp
    );
    let terms: Vec<String> = TERMS
        .iter()
        .zip(&model.seconds_per)
        .filter(|(_, c)| **c > 0.0)
        .map(|(t, c)| format!("{t} {}", nanoseconds(*c)))
        .collect();
    println!("    {}", terms.join(", "));
    for (term, c) in TERMS.iter().zip(&model.seconds_per) {
        rows.push(Row {
            section: "cost_model",
            scene: name.to_string(),
            strategy: term.to_string(),
            threads: 1,
            n: model.runs as u64,
            value: *c,
            unit: "s/unit",
        });
    }
    println!(
        "    {:<30} {:>5} {:>10} {:>10} {:>8}",
        "strategy", "spp", "measured s", "modelled s", "error"
    );
    for (runs, section, kind) in [
        (&fit, "cost_prediction_error_fitted", "fitted"),
        (&held, "cost_prediction_error_held_out", "held out"),
    ] {
        for r in runs {
            let error = model.error(&r.work, r.seconds);
            println!(
                "    {:<30} {:>5} {:>10.3} {:>10.3} {:>+7.1}%  {kind}",
                r.strategy.label(),
                r.spp,
                r.seconds,
                model.predict(&r.work),
                error * 100.0
            );
            rows.push(Row {
                section,
                scene: name.to_string(),
                strategy: r.strategy.label(),
                threads: 1,
                n: u64::from(r.spp),
                value: error,
                unit: "fraction",
            });
        }
    }
    let worst_held = held
        .iter()
        .map(|r| model.error(&r.work, r.seconds).abs())
        .fold(0.0, f64::max);
    println!(
        "    worst held-out prediction error {:.1}% (goal: within 10%)",
        worst_held * 100.0
    );
}

/// Each configuration rendered `repeat` times on one thread, in turns (the throughput
/// section's schedule); the fastest time of each.
fn time_in_turns(scene: &Scene, pixels: u64, configs: &[(Strategy, u32)], repeat: u32) -> Vec<Run> {
    let timed = best_of_turns(configs, &[1], repeat, |(strategy, spp), t| {
        timed(scene, strategy, SamplerKind::Independent, spp, t)
    });
    configs
        .iter()
        .zip(timed)
        .map(|(&(strategy, spp), t)| Run {
            strategy,
            spp,
            work: Work {
                pixels,
                counts: t[0].counts,
                kind: strategy.kind,
                light_sampling: strategy.light_sampling,
            },
            seconds: t[0].seconds(),
        })
        .collect()
}

/// Seconds per unit in ns, with enough digits for a per-render constant and a per-ray cost.
fn nanoseconds(s: f64) -> String {
    let ns = s * 1e9;
    if ns >= 1e4 {
        format!("{:.2} ms", ns / 1e6)
    } else {
        format!("{ns:.2}")
    }
}
