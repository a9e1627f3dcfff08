//! Render throughput of every strategy at every thread count, the speed-up from the fewest
//! to the most threads, and the machine's own limit for that speed-up (`copies`).

use super::timing::{throughputs, Timed};
use super::{bench_strategies, copies, paired_ratio, power_mis, BenchArgs, Row};
use crate::emitter::LightSampling;
use crate::integrator::Strategy;
use crate::scene::desc::StrategyKind;
use crate::scene::Scene;

/// The throughput section for one scene: prints it and adds its rows.
pub(super) fn section(scene: &Scene, name: &str, a: &BenchArgs, rows: &mut Vec<Row>) {
    // The first strategy's thread speed-up, read against the machine's own below.
    let mut first_speed_up = None;
    let strategies = bench_strategies();
    let timed = throughputs(scene, &strategies, a.spp, &a.threads, a.repeat);
    let against_mis = goals_section(name, &strategies, &timed, &a.threads);
    rows.extend(against_mis);
    for (&strategy, all) in strategies.iter().zip(timed) {
        let by_threads: Vec<(usize, Timed)> = a.threads.iter().copied().zip(all).collect();
        for &(threads, ref timed) in &by_threads {
            println!(
                "  {:<34} {:<26} {:>7} {:>12.2}  {:.2} ({:.0}% below)  {:.2} rays/sample",
                name,
                strategy.label(),
                threads,
                timed.samples_per_s / 1e6,
                timed.slowest_samples_per_s / 1e6,
                (1.0 - timed.slowest_samples_per_s / timed.samples_per_s) * 100.0,
                timed.rays_per_sample(),
            );
            for (section, value, unit) in [
                ("throughput", timed.samples_per_s, "samples/s"),
                (
                    "throughput_slowest",
                    timed.slowest_samples_per_s,
                    "samples/s",
                ),
                ("rays_per_sample", timed.rays_per_sample(), "rays/sample"),
            ] {
                rows.push(Row {
                    section,
                    scene: name.to_string(),
                    strategy: strategy.label(),
                    threads,
                    n: 0,
                    value,
                    unit,
                });
            }
        }
        // Speed-up from the fewest to the most threads measured, split into its two
        // causes: the speed-up is t2/t1 x (busy share ratio) / (work per sample ratio).
        let lo = by_threads.iter().min_by_key(|t| t.0);
        let hi = by_threads.iter().max_by_key(|t| t.0);
        if let (Some(&(t1, ref s1)), Some(&(t2, ref s2))) = (lo, hi) {
            if t2 > t1 {
                let speed_up = s2.samples_per_s / s1.samples_per_s;
                // Each repetition's own ratio: its two renders ran back to back.
                let paired = paired_ratio(&s1.runs, &s2.runs);
                first_speed_up.get_or_insert((t2, speed_up));
                let work = s2.work_per_sample / s1.work_per_sample;
                println!(
                    "  {:<34} {:<26} {:>7} {:>11.2}x  (paired median {:.2}x; workers busy {:.1}%, work per sample {:.3}x the {t1}-thread's)",
                    "",
                    "",
                    format!("{t1}->{t2}"),
                    speed_up,
                    paired,
                    s2.busy * 100.0,
                    work,
                );
                for (section, value, unit) in [
                    ("thread_scaling", speed_up, "speed-up"),
                    ("thread_scaling_paired", paired, "speed-up"),
                    ("thread_busy", s2.busy, "fraction"),
                    ("thread_work_per_sample", work, "ratio"),
                ] {
                    rows.push(Row {
                        section,
                        scene: name.to_string(),
                        strategy: strategy.label(),
                        threads: t2,
                        n: t1 as u64,
                        value,
                        unit,
                    });
                }
            }
        }
    }
    let mis = power_mis();
    if let Some((t2, speed_up)) = first_speed_up {
        let c = copies::measure(scene, mis, a.spp, t2, a.repeat);
        println!(
            "  machine limit: {t2} independent 1-thread renders of {} at once run {:.2}x one alone ({:.2} against {:.2} M samples/s); its {t2} threads: {speed_up:.2}x",
            mis.label(),
            c.speed_up(),
            c.together_per_s / 1e6,
            c.alone_per_s / 1e6,
        );
        rows.push(Row {
            section: "machine_scaling",
            scene: name.to_string(),
            strategy: mis.label(),
            threads: t2,
            n: 1,
            value: c.speed_up(),
            unit: "speed-up",
        });
    }
}

/// The speed goal of a bench strategy against power MIS with one sample of each (issue 66):
/// light or BSDF sampling alone at least 1.2x its samples/s, one-sample MIS 1.1x, solid-angle
/// sampling 0.7x of area sampling. None for power MIS itself and strategies without a goal.
fn goal(s: &Strategy) -> Option<(f64, &'static str)> {
    let mis = power_mis();
    let kind = |kind| Strategy { kind, ..mis };
    let solid_angle = Strategy {
        light_sampling: LightSampling::SolidAngle,
        ..mis
    };
    [
        (kind(StrategyKind::Light), 1.2, "light sampling alone"),
        (kind(StrategyKind::Bsdf), 1.2, "BSDF sampling alone"),
        (kind(StrategyKind::MisOneSample), 1.1, "one-sample MIS"),
        (solid_angle, 0.7, "solid angle against area"),
    ]
    .into_iter()
    .find(|(g, _, _)| g == s)
    .map(|(_, want, what)| (want, what))
}

/// Each strategy's samples/s over power MIS's at each thread count, paired by repetition
/// (both timed in the same turn), printed beside its goal; the rows of `throughput_ratio`.
fn goals_section(
    name: &str,
    strategies: &[Strategy],
    timed: &[Vec<Timed>],
    threads: &[usize],
) -> Vec<Row> {
    let mis = power_mis();
    let Some(k_mis) = strategies.iter().position(|s| *s == mis) else {
        return Vec::new();
    };
    let mut rows = Vec::new();
    for (j, &t) in threads.iter().enumerate() {
        let base = &timed[k_mis][j];
        for (s, all) in strategies.iter().zip(timed) {
            let Some((want, what)) = goal(s) else {
                continue;
            };
            let ratio = paired_ratio(&base.runs, &all[j].runs);
            println!(
                "  {name}, {t} thread(s): {what}: {ratio:.2}x the samples/s of {} (paired median; goal {want:.1}x{})",
                mis.label(),
                if ratio >= want { ", met" } else { ", not met" },
            );
            rows.push(Row {
                section: "throughput_ratio",
                scene: name.to_string(),
                strategy: s.label(),
                threads: t,
                n: 0,
                value: ratio,
                unit: "ratio to power MIS",
            });
        }
    }
    rows
}
