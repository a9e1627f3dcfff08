//! Timed renders for the bench: samples per second, best of several repetitions in which
//! every (strategy, thread count) takes its turn.

use super::least;
use crate::cost::per_camera_sample;
use crate::counts::Counts;
use crate::integrator::Strategy;
use crate::render::{render, RenderSettings};
use crate::sampler::{SamplerKind, Sampling};
use crate::scene::Scene;

/// Camera samples per second of `spp` samples per pixel, best of `repeat`.
pub fn throughput(scene: &Scene, strategy: Strategy, spp: u32, threads: usize, repeat: u32) -> f64 {
    throughputs(scene, &[strategy], spp, &[threads], repeat)[0][0].samples_per_s
}

/// The fastest of a thread count's timed renders.
#[derive(Clone)]
pub struct Timed {
    pub samples_per_s: f64,
    /// Share of the workers' time spent in tiles (the rest is waiting).
    pub busy: f64,
    /// Worker seconds per sample.
    pub work_per_sample: f64,
    /// Samples per second of the slowest repetition: how far this machine's interference
    /// moved the runs.
    pub slowest_samples_per_s: f64,
    /// Samples per second of every repetition, in order.
    pub runs: Vec<f64>,
    /// What one render did (the same in every repetition).
    pub counts: Counts,
}

impl Timed {
    /// Rays traced per camera sample (camera, shadow and BSDF rays past the bounds test).
    pub fn rays_per_sample(&self) -> f64 {
        per_camera_sample(&self.counts, self.counts.rays())
    }

    /// Seconds of the fastest render.
    pub fn seconds(&self) -> f64 {
        self.counts.camera_rays as f64 / self.samples_per_s
    }
}

/// Samples per second of each strategy at each thread count, best of `repeat`. Every
/// (strategy, thread count) pair takes its turn within each repetition, so a slow spell of a
/// shared machine (minutes long on this VM) hits all of them alike instead of the ones
/// measured during it: the ratio of two thread counts is the scaling, and two strategies
/// compare. Timed one strategy after another, two strategies doing the same work (uniform
/// and power emitter choice with one emitter) once read 1.43x apart.
pub fn throughputs(
    scene: &Scene,
    strategies: &[Strategy],
    spp: u32,
    threads: &[usize],
    repeat: u32,
) -> Vec<Vec<Timed>> {
    best_of_turns(strategies, threads, repeat, |strategy, t| {
        timed(scene, strategy, SamplerKind::Independent, spp, t)
    })
}

/// One timed render at seed 1: (seconds, busy worker seconds, what it did).
pub(super) fn timed(
    scene: &Scene,
    strategy: Strategy,
    kind: SamplerKind,
    spp: u32,
    t: usize,
) -> (f64, f64, Counts) {
    let settings = RenderSettings {
        spp,
        seed: 1,
        first_sample: 0,
        threads: Some(t),
        progress: None,
        sampling: Sampling {
            kind,
            ..Default::default()
        },
    };
    let out = render(scene, strategy, &settings);
    (out.seconds, out.busy_seconds, out.counts)
}

/// Render throughput of `scene` with one strategy and each sampler, timed in turns as
/// `throughputs` (a row per sampler, a column per thread count).
pub fn sampler_throughputs(
    scene: &Scene,
    strategy: Strategy,
    samplers: &[SamplerKind],
    spp: u32,
    threads: &[usize],
    repeat: u32,
) -> Vec<Vec<Timed>> {
    best_of_turns(samplers, threads, repeat, |kind, t| {
        timed(scene, strategy, kind, spp, t)
    })
}

/// `throughputs`' schedule and bookkeeping around `time`, which renders one configuration
/// (a strategy, a sampler, a sample count) with a thread count and returns
/// (seconds, busy worker seconds, what it did).
pub(super) fn best_of_turns<T: Copy>(
    strategies: &[T],
    threads: &[usize],
    repeat: u32,
    mut time: impl FnMut(T, usize) -> (f64, f64, Counts),
) -> Vec<Vec<Timed>> {
    let mut best: Vec<Vec<Option<Timed>>> = vec![vec![None; threads.len()]; strategies.len()];
    let mut runs = vec![vec![Vec::new(); threads.len()]; strategies.len()];
    for _ in 0..repeat.max(1) {
        for ((&strategy, best), runs) in strategies.iter().zip(&mut best).zip(&mut runs) {
            for ((b, runs), &t) in best.iter_mut().zip(runs.iter_mut()).zip(threads) {
                let (seconds, busy_seconds, counts) = time(strategy, t);
                let samples = counts.camera_rays as f64;
                let samples_per_s = samples / seconds;
                runs.push(samples_per_s);
                if b.as_ref().is_none_or(|b| samples_per_s > b.samples_per_s) {
                    *b = Some(Timed {
                        samples_per_s,
                        busy: busy_seconds / (seconds * t as f64),
                        work_per_sample: busy_seconds / samples,
                        slowest_samples_per_s: samples_per_s,
                        runs: Vec::new(),
                        counts,
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
    use crate::bench::{bench_strategies, paired_ratio};

    /// Every (strategy, thread count) renders once per repetition, in turn, and keeps its
    /// fastest and slowest: a slow spell (here the whole first repetition, at half speed)
    /// moves every pair's slowest and no pair's best. Timed one strategy after another, the
    /// spell would have fallen on the first strategy alone.
    #[test]
    fn strategies_and_thread_counts_take_turns() {
        let strategies = &bench_strategies()[..3];
        let threads = [1, 2];
        let mut calls = Vec::new();
        let timed = best_of_turns(strategies, &threads, 4, |s, t| {
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
            // Every render draws 1e6 camera samples.
            let counts = Counts {
                camera_rays: 1_000_000,
                ..Counts::default()
            };
            (seconds, seconds * t as f64 * 0.5, counts)
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
