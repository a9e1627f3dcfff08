//! The emitter choice alone, per rule, as the emitter count grows from 1 to 1e5: nanoseconds
//! per choice (and per pmf of a given emitter, which MIS asks at BSDF-sampled hits), and the
//! light tree's build time, depth and memory. The render's cost in `sweeps` also grows with
//! the scene's BVH (n lights are 2n more triangles), which is not the choice's doing.

use super::{scaling, BenchArgs, Row};
use crate::emitter::{EmitterSelection, EmitterSelector};
use crate::scene::Scene;
use glam::Vec3;
use std::hint::black_box;
use std::time::Instant;

/// Every registered emitter-choice rule.
fn rules() -> Vec<EmitterSelection> {
    crate::emitter::RULES.iter().map(|r| r.value).collect()
}

/// The choices timed per run: 2^20, or fewer where a choice visits every emitter (about
/// 2^24 importance evaluations a run).
fn choices(rule: EmitterSelection, emitters: usize) -> u32 {
    match rule {
        EmitterSelection::Exhaustive => {
            ((1usize << 24) / emitters.max(1)).clamp(64, 1 << 20) as u32
        }
        _ => 1 << 20,
    }
}

/// Shading point i of a run: spread over the lights' floor ([-3, 3]^2 at z = 0), facing up,
/// in a golden-ratio sequence (the point-independent rules ignore it).
#[inline]
fn point(i: u32) -> (Vec3, f32) {
    let u = (i as f64 * 0.618_033_988_749_895).fract() as f32;
    let v = (i as f64 * 0.754_877_666_246_693).fract() as f32;
    (Vec3::new(6.0 * u - 3.0, 6.0 * v - 3.0, 0.0), u)
}

/// ns per choice and per pmf of one run, on a copy of the selector made before the clock
/// starts (behind a reference every choice reloaded it after `black_box`).
#[inline(never)]
fn run_ns(selector: &EmitterSelector, n: u32) -> (f64, f64) {
    let selector = selector.clone();
    let count = selector.len();
    let mut sink = 0usize;
    let start = Instant::now();
    for i in 0..n {
        let (p, u) = point(i);
        if let Some((e, pmf)) = selector.sample(black_box(p), Vec3::Z, black_box(u)) {
            sink = sink.wrapping_add(e).wrapping_add(pmf.to_bits() as usize);
        }
    }
    let choose = start.elapsed().as_secs_f64() * 1e9 / n as f64;
    let start = Instant::now();
    for i in 0..n {
        let (p, _) = point(i);
        let e = (i as usize).wrapping_mul(2_654_435_761) % count;
        sink = sink.wrapping_add(selector.pmf(black_box(p), Vec3::Z, e).to_bits() as usize);
    }
    let pmf = start.elapsed().as_secs_f64() * 1e9 / n as f64;
    black_box(sink);
    (choose, pmf)
}

pub(super) fn section(a: &BenchArgs, rows: &mut Vec<Row>) -> Result<(), String> {
    let counts: Vec<usize> = [1usize, 10, 100, 1_000, 10_000, 100_000]
        .into_iter()
        .filter(|&n| n <= a.max_choice_emitters)
        .collect();
    println!(
        "emitter choice alone (1 thread, best of {}; points over the floor):",
        a.repeat
    );
    let scene_name = "floor under a grid of quad lights";
    for &n in &counts {
        let scene = Scene::build(scaling::many_lights(n)).map_err(|e| e.to_string())?;
        let (emitters, shapes) = (&scene.emitters, &scene.shapes);
        // Build time of the tree: best of the repetitions.
        let mut build = f64::INFINITY;
        let mut tree = None;
        for _ in 0..a.repeat {
            let start = Instant::now();
            let t = EmitterSelector::new(emitters, shapes, EmitterSelection::Bvh);
            build = build.min(start.elapsed().as_secs_f64() * 1e3);
            tree = Some(t);
        }
        let rules = rules();
        let selectors: Vec<EmitterSelector> = rules
            .iter()
            .map(|&r| match r {
                EmitterSelection::Bvh => tree.clone().expect("built above"),
                r => EmitterSelector::new(emitters, shapes, r),
            })
            .collect();
        let mut best = vec![(f64::INFINITY, f64::INFINITY); rules.len()];
        // The rules take turns, run by run, so that one slow spell of the machine does not
        // fall on one rule.
        for _ in 0..a.repeat {
            for ((rule, sel), b) in rules.iter().zip(&selectors).zip(&mut best) {
                let (c, p) = run_ns(sel, choices(*rule, n));
                *b = (b.0.min(c), b.1.min(p));
            }
        }
        let (depth, bytes) = tree
            .as_ref()
            .and_then(EmitterSelector::tree_stats)
            .expect("the tree");
        let line: Vec<String> = rules
            .iter()
            .zip(&best)
            .map(|(r, (c, p))| format!("{} {c:.1}/{p:.1}", r.name()))
            .collect();
        println!(
            "  {n:>7} emitters: ns per choice/pmf: {}; tree: depth {depth}, {:.1} KiB, built in {build:.2} ms",
            line.join(", "),
            bytes as f64 / 1024.0
        );
        for (r, (c, p)) in rules.iter().zip(&best) {
            for (what, v) in [("choice", c), ("pmf", p)] {
                rows.push(Row {
                    section: "emitter_choice",
                    scene: scene_name.into(),
                    strategy: format!("{}:{what}", r.name()),
                    threads: 1,
                    n: n as u64,
                    value: *v,
                    unit: "ns",
                });
            }
        }
        for (what, v, unit) in [
            ("build", build, "ms"),
            ("bytes", bytes as f64, "bytes"),
            ("depth", depth as f64, "levels"),
        ] {
            rows.push(Row {
                section: "light_tree",
                scene: scene_name.into(),
                strategy: format!("bvh:{what}"),
                threads: 1,
                n: n as u64,
                value: v,
                unit,
            });
        }
    }
    Ok(())
}
