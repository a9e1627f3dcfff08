//! Render throughput of every strategy at every thread count, the speed-up from the fewest
//! to the most threads, and the machine's own limit for that speed-up (`copies`).

use super::{bench_strategies, copies, least, paired_ratio, power_mis, BenchArgs, Row};
use crate::integrator::Strategy;
use crate::render::{render, RenderSettings};
use crate::scene::Scene;

/// The throughput section for one scene: prints it and adds its rows.
pub(super) fn section(scene: &Scene, name: &str, a: &BenchArgs, rows: &mut Vec<Row>) {
    // The first strategy's thread speed-up, read against the machine's own below.
    let mut first_speed_up = None;
    let strategies = bench_strategies();
    let timed = throughputs(scene, &strategies, a.spp, &a.threads, a.repeat);
    for (&strategy, all) in strategies.iter().zip(timed) {
        let by_threads: Vec<(usize, Timed)> = a.threads.iter().copied().zip(all).collect();
        for &(threads, ref timed) in &by_threads {
            println!(
                "  {:<34} {:<26} {:>7} {:>12.2}  {:.2} ({:.0}% below)",
                name,
                strategy.label(),
                threads,
                timed.samples_per_s / 1e6,
                timed.slowest_samples_per_s / 1e6,
                (1.0 - timed.slowest_samples_per_s / timed.samples_per_s) * 100.0,
            );
            for (section, value) in [
                ("throughput", timed.samples_per_s),
                ("throughput_slowest", timed.slowest_samples_per_s),
            ] {
                rows.push(Row {
                    section,
                    scene: name.to_string(),
                    strategy: strategy.label(),
                    threads,
                    n: 0,
                    value,
                    unit: "samples/s",
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

/// Camera samples per second of `spp` samples per pixel, best of `repeat`.
pub(super) fn throughput(
    scene: &Scene,
    strategy: Strategy,
    spp: u32,
    threads: usize,
    repeat: u32,
) -> f64 {
    throughputs(scene, &[strategy], spp, &[threads], repeat)[0][0].samples_per_s
}

/// The fastest of a thread count's timed renders.
#[derive(Clone)]
struct Timed {
    samples_per_s: f64,
    /// Share of the workers' time spent in tiles (the rest is waiting).
    busy: f64,
    /// Worker seconds per sample.
    work_per_sample: f64,
    /// Samples per second of the slowest repetition: how far this machine's interference
    /// moved the runs.
    slowest_samples_per_s: f64,
    /// Samples per second of every repetition, in order.
    runs: Vec<f64>,
}

/// Samples per second of each strategy at each thread count, best of `repeat`. Every
/// (strategy, thread count) pair takes its turn within each repetition, so a slow spell of a
/// shared machine (minutes long on this VM) hits all of them alike instead of the ones
/// measured during it: the ratio of two thread counts is the scaling, and two strategies
/// compare. Timed one strategy after another, two strategies doing the same work (uniform
/// and power emitter choice with one emitter) once read 1.43x apart.
fn throughputs(
    scene: &Scene,
    strategies: &[Strategy],
    spp: u32,
    threads: &[usize],
    repeat: u32,
) -> Vec<Vec<Timed>> {
    let (w, h) = (scene.camera.width, scene.camera.height);
    let samples = w as f64 * h as f64 * spp as f64;
    best_of_turns(strategies, threads, repeat, samples, |strategy, t| {
        let settings = RenderSettings {
            spp,
            seed: 1,
            first_sample: 0,
            threads: Some(t),
            progress: false,
        };
        let out = render(scene, strategy, &settings);
        (out.seconds, out.busy_seconds)
    })
}

/// `throughputs`' schedule and bookkeeping around `time`, which renders `samples` camera
/// samples with a strategy and thread count and returns (seconds, busy worker seconds).
fn best_of_turns(
    strategies: &[Strategy],
    threads: &[usize],
    repeat: u32,
    samples: f64,
    mut time: impl FnMut(Strategy, usize) -> (f64, f64),
) -> Vec<Vec<Timed>> {
    let mut best: Vec<Vec<Option<Timed>>> = vec![vec![None; threads.len()]; strategies.len()];
    let mut runs = vec![vec![Vec::new(); threads.len()]; strategies.len()];
    for _ in 0..repeat.max(1) {
        for ((&strategy, best), runs) in strategies.iter().zip(&mut best).zip(&mut runs) {
            for ((b, runs), &t) in best.iter_mut().zip(runs.iter_mut()).zip(threads) {
                let (seconds, busy_seconds) = time(strategy, t);
                let samples_per_s = samples / seconds;
                runs.push(samples_per_s);
                if b.as_ref().is_none_or(|b| samples_per_s > b.samples_per_s) {
                    *b = Some(Timed {
                        samples_per_s,
                        busy: busy_seconds / (seconds * t as f64),
                        work_per_sample: busy_seconds / samples,
                        slowest_samples_per_s: samples_per_s,
                        runs: Vec::new(),
                    });
                }
            }
        }
    }
    best.into_iter()
        .zip(runs)
        .map(|(best, runs)| {
            best.into_iter()
                .zip(runs)
                .map(|(b, runs)| Timed {
                    slowest_samples_per_s: least(&runs),
                    runs,
                    ..b.expect("at least one repetition")
                })
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every (strategy, thread count) renders once per repetition, in turn, and keeps its
    /// fastest and slowest: a slow spell (here the whole first repetition, at half speed)
    /// moves every pair's slowest and no pair's best. Timed one strategy after another, the
    /// spell would have fallen on the first strategy alone.
    #[test]
    fn strategies_and_thread_counts_take_turns() {
        let strategies = &bench_strategies()[..3];
        let threads = [1, 2];
        let mut calls = Vec::new();
        let timed = best_of_turns(strategies, &threads, 4, 1e6, |s, t| {
            let spell = if calls.len() < strategies.len() * threads.len() {
                2.0
            } else {
                1.0
            };
            calls.push((s.label(), t));
            // Each pair its own speed: 1 s per 1e6 samples for the first strategy at one
            // thread, faster for later strategies and more threads.
            let k = strategies
                .iter()
                .position(|x| x.label() == s.label())
                .unwrap();
            let seconds = spell / ((k + 1) as f64 * t as f64);
            (seconds, seconds * t as f64 * 0.5)
        });
        let turn: Vec<_> = strategies
            .iter()
            .flat_map(|s| threads.map(|t| (s.label(), t)))
            .collect();
        let turns: Vec<_> = (0..4).flat_map(|_| turn.iter().cloned()).collect();
        assert_eq!(calls, turns);
        for (k, row) in timed.iter().enumerate() {
            for (j, timed) in row.iter().enumerate() {
                let want = 1e6 * (k + 1) as f64 * threads[j] as f64;
                let close = |x: f64, y: f64| (x - y).abs() <= 1e-9 * y;
                assert!(
                    close(timed.samples_per_s, want),
                    "{k} {j}: {}",
                    timed.samples_per_s
                );
                let slowest = timed.slowest_samples_per_s;
                assert!(close(slowest, want / 2.0), "{k} {j}: {slowest}");
                assert!(close(timed.busy, 0.5), "{k} {j}: {}", timed.busy);
                assert_eq!(timed.runs.len(), 4);
            }
            // The slow first repetition slows both thread counts: it cancels in its ratio.
            let paired = paired_ratio(&row[0].runs, &row[1].runs);
            assert!((paired - 2.0).abs() < 1e-12, "{k}: {paired}");
        }
    }
}
