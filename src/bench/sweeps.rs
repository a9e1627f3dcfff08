//! Per-sample cost as the scene grows: the triangle and emitter sweeps over the scenes of
//! `scaling`, and the emitter choice alone.

use super::timing::throughput;
use super::{least, paired_ratio, power_mis, scaling, BenchArgs, Row};
use crate::emitter::EmitterSelection;
use crate::integrator::Strategy;
use crate::scene::Scene;

/// The sweeps, on `max_threads` threads: prints them and adds their rows.
pub(super) fn section(
    a: &BenchArgs,
    max_threads: usize,
    rows: &mut Vec<Row>,
) -> Result<(), String> {
    let mis = power_mis();
    println!(
        "per-sample cost as the scene grows ({} threads, power MIS, 64x64 at {} spp, best of {}):",
        max_threads, a.sweep_spp, a.repeat
    );
    let counts: Vec<usize> = [1_000usize, 10_000, 100_000, 1_000_000]
        .into_iter()
        .filter(|&n| n <= a.max_triangles)
        .collect();
    let (scenes, costs) = sweep(&counts, scaling::tessellated, mis, a, max_threads)?;
    for (scene, c) in scenes.iter().zip(&costs) {
        let tris = scene.accel.primitive_count() as u64;
        let best = least(c);
        println!("  {:>9} triangles: {:>8.1} ns/sample", tris, best);
        rows.push(Row {
            section: "scaling_triangles",
            scene: "tessellated sphere".into(),
            strategy: mis.label(),
            threads: max_threads,
            n: tris,
            value: best,
            unit: "ns/sample",
        });
    }
    drop(scenes);
    if let (Some(first), Some(last)) = (costs.first(), costs.last()) {
        let (growth, paired) = (least(last) / least(first), paired_ratio(first, last));
        println!(
            "  growth over the sweep: {growth:.2}x best against best, {paired:.2}x the median of the {} repetitions' own ratios",
            first.len()
        );
        for (what, value) in [("best", growth), ("paired_median", paired)] {
            rows.push(Row {
                section: "scaling_triangles_growth",
                scene: "tessellated sphere".into(),
                strategy: format!("{}:{what}", mis.label()),
                threads: max_threads,
                n: 0,
                value,
                unit: "ratio",
            });
        }
    }
    for sel in [
        EmitterSelection::Uniform,
        EmitterSelection::Power,
        EmitterSelection::Bvh,
        EmitterSelection::Ris(8),
    ] {
        let s = Strategy {
            selection: sel,
            ..mis
        };
        let counts: Vec<usize> = [1usize, 10, 100, 1_000, 10_000]
            .into_iter()
            .filter(|&n| n <= a.max_emitters)
            .collect();
        let (_, costs) = sweep(&counts, scaling::many_lights, s, a, max_threads)?;
        for (&n, c) in counts.iter().zip(&costs) {
            let best = least(c);
            println!(
                "  {:>9} emitters ({}): {:>8.1} ns/sample",
                n,
                s.label(),
                best
            );
            rows.push(Row {
                section: "scaling_emitters",
                scene: "floor under a grid of quad lights".into(),
                strategy: s.label(),
                threads: max_threads,
                n: n as u64,
                value: best,
                unit: "ns/sample",
            });
        }
    }
    super::choice::section(a, rows)
}

/// Each item's cost in each of `repeat` repetitions, the items taking turns within each
/// repetition: timed one size after another, a slow spell of the VM (minutes long) fell on
/// one size of a sweep alone. The triangle sweep's growth read 1.70x to 2.41x in runs of the
/// same renderer that way.
fn costs_in_turns<T>(items: &[T], repeat: u32, mut cost: impl FnMut(&T) -> f64) -> Vec<Vec<f64>> {
    let mut out = vec![Vec::new(); items.len()];
    for _ in 0..repeat.max(1) {
        for (item, c) in items.iter().zip(&mut out) {
            c.push(cost(item));
        }
    }
    out
}

/// A sweep's scenes, one per count, and each one's ns per sample in every repetition
/// (`costs_in_turns`), rendered with `strategy` at `--sweep-spp` on `threads` threads.
fn sweep(
    counts: &[usize],
    desc: fn(usize) -> crate::scene::desc::SceneDesc,
    strategy: Strategy,
    a: &BenchArgs,
    threads: usize,
) -> Result<(Vec<Scene>, Vec<Vec<f64>>), String> {
    let scenes = counts
        .iter()
        .map(|&n| Scene::build(desc(n)).map_err(|e| e.to_string()))
        .collect::<Result<Vec<_>, _>>()?;
    let costs = costs_in_turns(&scenes, a.repeat, |scene| {
        1e9 / throughput(scene, strategy, a.sweep_spp, threads, 1)
    });
    Ok((scenes, costs))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sweep's sizes take turns within each repetition, and the paired growth keeps a
    /// slow spell out: here the first repetition runs at half speed for every size (which
    /// cancels in its ratio), and one later timing of the largest size alone is three times
    /// slow (an outlier among the ratios, which the median passes over).
    #[test]
    fn sweep_sizes_take_turns_and_growth_is_paired() {
        let sizes = [1.0, 10.0, 100.0];
        let mut calls = Vec::new();
        let costs = costs_in_turns(&sizes, 5, |&size| {
            let k = calls.len();
            calls.push(size);
            let spell = match k {
                0..=2 => 2.0,
                8 => 3.0,
                _ => 1.0,
            };
            spell * (100.0 + size)
        });
        assert_eq!(calls, sizes.repeat(5));
        assert_eq!(costs[0], [202.0, 101.0, 101.0, 101.0, 101.0]);
        assert_eq!(costs[2], [400.0, 200.0, 600.0, 200.0, 200.0]);
        assert_eq!(least(&costs[2]), 200.0);
        assert!((paired_ratio(&costs[0], &costs[2]) - 200.0 / 101.0).abs() < 1e-12);
    }
}
