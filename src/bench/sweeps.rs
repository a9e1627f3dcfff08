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
    for sel in [EmitterSelection::Uniform, EmitterSelection::Power] {
        let s = Strategy {
            selection: sel,
            ..mis
        };
        let counts: Vec<usize> = [1usize, 10, 100, 1_000, 10_000]
            .into_iter()
            .filter(|&n| n <= a.max_emitters)
            .collect();
        let (scenes, costs) = sweep(&counts, scaling::many_lights, s, a, max_threads)?;
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
        // The choice alone: the render's cost above also grows with the BVH (n lights are 2n
        // more triangles), which is not the selector's doing.
        let selectors: Vec<_> = scenes
            .iter()
            .map(|scene| crate::emitter::EmitterSelector::new(&scene.emitters, &scene.shapes, sel))
            .collect();
        for (n, ns) in counts.into_iter().zip(choice_ns(&selectors)) {
            println!(
                "  {:>9} emitters ({:?} choice alone): {:>8.2} ns/choice",
                n, sel, ns
            );
            rows.push(Row {
                section: "emitter_choice",
                scene: "floor under a grid of quad lights".into(),
                strategy: format!("{sel:?}").to_lowercase(),
                threads: 1,
                n: n as u64,
                value: ns,
                unit: "ns/choice",
            });
        }
    }
    Ok(())
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

/// Nanoseconds per emitter choice (one uniform number in, emitter and pmf out) of each
/// selector, best of 7 runs of 2^22 choices (10 ms each). The selectors take turns, run by
/// run: timed one selector after another, all seven runs of a count fitted inside one slow
/// spell of this VM, and in two bench runs one count read 2.0 ns where the others read 1.3
/// (best of 3 once read 3.8 ns for a table that costs 2.4). The numbers jump around the unit
/// interval (golden-ratio sequence) as a render's do, so table lookups are not sequential.
fn choice_ns(selectors: &[crate::emitter::EmitterSelector]) -> Vec<f64> {
    let mut best = vec![f64::INFINITY; selectors.len()];
    for _ in 0..7 {
        for (selector, best) in selectors.iter().zip(&mut best) {
            *best = best.min(choice_run_ns(selector));
        }
    }
    best
}

/// One run of 2^22 choices, on a copy of the selector made before the clock starts: a local
/// whose address never escapes stays in registers across `black_box`, while behind the
/// reference every choice reloaded it after the barrier (uniform 2.0 ns and power 4.7 ns,
/// against 1.3 and 2.5-2.7 from the copy, back to back).
#[inline(never)]
fn choice_run_ns(selector: &crate::emitter::EmitterSelector) -> f64 {
    let selector = selector.clone();
    let n = 1u32 << 22;
    let start = std::time::Instant::now();
    let mut sink = 0usize;
    for i in 0..n {
        let u = std::hint::black_box((i as f64 * 0.618_033_988_749_895).fract() as f32);
        // Shading points spread over the lights' floor (the point-independent rules
        // ignore them).
        let v = (i as f64 * 0.754_877_666_246_693).fract() as f32;
        let p = glam::Vec3::new(6.0 * u - 3.0, 6.0 * v - 3.0, 0.0);
        if let Some((e, pmf)) = selector.sample(p, glam::Vec3::Z, u) {
            sink = sink.wrapping_add(e).wrapping_add(pmf.to_bits() as usize);
        }
    }
    std::hint::black_box(sink);
    start.elapsed().as_secs_f64() * 1e9 / n as f64
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
