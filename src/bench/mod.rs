//! `directlab bench`: speed goals as measured numbers (printed and written to
//! `reports/bench/bench.csv`), never timed tests. Sections: render throughput per scene,
//! strategy and thread count; the machine's own scaling (independent 1-thread renders side by
//! side); the ray-tracing limit for the same ray mix and the share of render time spent
//! outside traversal (and that time per sample), on one thread and on the most threads;
//! per-sample cost as the triangle and emitter counts grow; peak memory.

mod copies;
mod raylimit;
mod scaling;

use crate::cli::open_scene;
use crate::emitter::{EmitterSelection, LightSampling};
use crate::integrator::Strategy;
use crate::render::{render, RenderSettings};
use crate::scene::desc::{Heuristic, StrategyKind};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Scenes to measure (default: the bundled Cornell box and Veach MIS scene).
    #[arg(long = "scene")]
    pub scenes: Vec<PathBuf>,
    /// Thread counts to measure.
    #[arg(long, value_delimiter = ',', default_value = "1,2")]
    pub threads: Vec<usize>,
    /// Samples per pixel of each timed render.
    #[arg(long, default_value_t = 64)]
    pub spp: u32,
    /// Image resolution of scenes that declare a `res` default (the bundled Cornell box); other
    /// scenes keep their own size (the Veach scene: 768x512).
    #[arg(long, default_value_t = 256)]
    pub res: u32,
    /// Timed repetitions; the fastest is reported (the others measure interference). Five,
    /// because on a shared 2-core VM three still let one slow spell decide a 2-thread number.
    #[arg(long, default_value_t = 5)]
    pub repeat: u32,
    /// Samples per pixel of each timed render of the triangle and emitter sweeps (64x64
    /// pixels). At 64 spp a render lasted 25-60 ms and its speed spread by up to 50 % between
    /// repetitions on this VM (scheduler ticks, thread start-up), which best-of-5 did not
    /// remove; at 512 (0.2-0.4 s) the spread is 3-6 %.
    #[arg(long, default_value_t = 512)]
    pub sweep_spp: u32,
    /// Largest triangle count of the triangle-scaling sweep (1e3, 1e4, ... up to this).
    #[arg(long, default_value_t = 1_000_000)]
    pub max_triangles: usize,
    /// Largest emitter count of the emitter-scaling sweep (1, 10, ... up to this).
    #[arg(long, default_value_t = 10_000)]
    pub max_emitters: usize,
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

/// One measurement. `section` says what it measures; `n` is the swept size where one is.
#[derive(serde::Serialize)]
struct Row {
    section: &'static str,
    scene: String,
    strategy: String,
    threads: usize,
    n: u64,
    value: f64,
    unit: &'static str,
}

/// Camera samples per second of `spp` samples per pixel, best of `repeat`.
fn throughput(
    scene: &crate::scene::Scene,
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
    scene: &crate::scene::Scene,
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
) -> Result<(Vec<crate::scene::Scene>, Vec<Vec<f64>>), String> {
    let scenes = counts
        .iter()
        .map(|&n| crate::scene::Scene::build(desc(n)).map_err(|e| e.to_string()))
        .collect::<Result<Vec<_>, _>>()?;
    let costs = costs_in_turns(&scenes, a.repeat, |scene| {
        1e9 / throughput(scene, strategy, a.sweep_spp, threads, 1)
    });
    Ok((scenes, costs))
}

fn least(x: &[f64]) -> f64 {
    x.iter().copied().fold(f64::INFINITY, f64::min)
}

/// The median over repetitions of `last[k] / first[k]`: both numbers of a ratio were timed in
/// the same repetition, minutes apart at most, so a drift of the machine's speed between
/// repetitions cancels.
fn paired_ratio(first: &[f64], last: &[f64]) -> f64 {
    use statrs::statistics::{Data, Median};
    let ratios: Vec<f64> = first.iter().zip(last).map(|(f, l)| l / f).collect();
    Data::new(ratios).median()
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
        if let Some((e, pmf)) = selector.sample(u) {
            sink = sink.wrapping_add(e).wrapping_add(pmf.to_bits() as usize);
        }
    }
    std::hint::black_box(sink);
    start.elapsed().as_secs_f64() * 1e9 / n as f64
}

/// The CPU's model name, from /proc/cpuinfo where there is one.
fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|info| {
            let line = info.lines().find(|l| l.starts_with("model name"))?;
            Some(line.split_once(':')?.1.trim().to_string())
        })
        .unwrap_or_else(|| format!("unknown {} CPU", std::env::consts::ARCH))
}

/// Peak resident memory of this process in bytes (Linux), if known.
fn peak_memory() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

pub fn run(a: &BenchArgs) -> Result<(), String> {
    let scenes = if a.scenes.is_empty() {
        vec![
            PathBuf::from("scenes/cbox/cbox.xml"),
            PathBuf::from("scenes/veach-mis/veach-mis.xml"),
        ]
    } else {
        a.scenes.clone()
    };
    let mut rows = Vec::new();
    // Every number below is this machine's: the same code has read 35 % apart on two VMs of
    // the same size, and the share outside traversal moves with the CPU too.
    let cpus = std::thread::available_parallelism().map_or(0, |n| n.get());
    let model = cpu_model();
    println!("machine: {model}, {cpus} logical CPUs");
    rows.push(Row {
        section: "machine",
        scene: String::new(),
        strategy: model,
        threads: cpus,
        n: 0,
        value: cpus as f64,
        unit: "logical CPUs",
    });
    let max_threads = a.threads.iter().copied().max().unwrap_or(1);
    println!(
        "render throughput at {} spp (best of {}), each scene at its size:",
        a.spp, a.repeat
    );
    println!(
        "  {:<34} {:<26} {:>7} {:>12}  slowest run",
        "scene", "strategy", "threads", "M samples/s"
    );
    for path in &scenes {
        let scene = open_scene(path, &[("res".into(), a.res.to_string())])?;
        let name = path.display().to_string();
        // `res` sets the size of scenes that declare it; the others keep their own.
        println!("  {name}: {}x{}", scene.camera.width, scene.camera.height);
        // The first strategy's thread speed-up, read against the machine's own below.
        let mut first_speed_up = None;
        let strategies = bench_strategies();
        let timed = throughputs(&scene, &strategies, a.spp, &a.threads, a.repeat);
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
                        scene: name.clone(),
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
                            scene: name.clone(),
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
        let mis = bench_strategies()[0];
        if let Some((t2, speed_up)) = first_speed_up {
            let c = copies::measure(&scene, mis, a.spp, t2, a.repeat);
            println!(
                "  machine limit: {t2} independent 1-thread renders of {} at once run {:.2}x one alone ({:.2} against {:.2} M samples/s); its {t2} threads: {speed_up:.2}x",
                mis.label(),
                c.speed_up(),
                c.together_per_s / 1e6,
                c.alone_per_s / 1e6,
            );
            rows.push(Row {
                section: "machine_scaling",
                scene: name.clone(),
                strategy: mis.label(),
                threads: t2,
                n: 1,
                value: c.speed_up(),
                unit: "speed-up",
            });
        }
        // The ray-tracing limit for the same ray mix, on one thread, against the 1-thread
        // render time of power MIS (which traces that mix). Whole groups of LANES samples per
        // pixel, as the renderer traces them.
        let mix_spp = (a.spp / 16)
            .max(1)
            .next_multiple_of(crate::rng::LANES as u32);
        let mix = raylimit::ray_mix(&scene, mix_spp, mis.selection);
        let limit = raylimit::measure(&scene, &mix, a.repeat, || {
            throughput(&scene, mis, a.spp, 1, 1)
        });
        println!(
            "  ray-tracing limit ({name}, 1 thread): {:.2} M closest-hit rays/s, {:.2} M occlusion rays/s, {:.2} M BSDF-ray emitter queries/s; {:.2} M samples/s if tracing were all ({:.2} M with each ray type traced back to back)",
            limit.by_type.closest_per_s / 1e6,
            limit.by_type.occlusion_per_s / 1e6,
            limit.bsdf_query_per_s / 1e6,
            1.0 / limit.render_order_seconds_per_sample / 1e6,
            1.0 / limit.by_type.seconds_per_sample / 1e6,
        );
        println!(
            "  {} at {:.2} M samples/s: {:.0}% of render time outside traversal ({:.0}% against the traversal by type), {:.1} ns per sample",
            mis.label(),
            limit.render_per_s / 1e6,
            limit.share_outside * 100.0,
            limit.share_outside_by_type * 100.0,
            limit.outside_seconds_per_sample * 1e9,
        );
        // The same with tracing and rendering paired band by band.
        let direct = crate::integrator::Direct::new(&scene, mis);
        let banded = |threads| {
            let spps = (mix_spp, a.spp);
            let (share, outside) =
                raylimit::measure_interleaved(&direct, &mix, spps, threads, a.repeat);
            println!(
                "  traced and rendered band by band ({} rows each) on {threads} thread(s): {:.0}% of render time outside traversal, {:.1} ns of thread time per sample",
                raylimit::BAND_ROWS,
                share * 100.0,
                outside * 1e9,
            );
            (share, outside)
        };
        let (share_banded, outside_banded) = banded(1);
        // The same on the most threads, as Mitsuba's script measures Mitsuba (no fewer
        // than two threads), in thread time per sample.
        let parallel = (max_threads > 1).then(|| {
            let t = max_threads;
            let render = || throughput(&scene, mis, a.spp, t, 1);
            let (share, outside) = raylimit::measure_threads(&scene, &mix, t, a.repeat, render);
            println!(
                "  at {t} threads: {:.0}% of render time outside traversal, {:.1} ns of thread time per sample",
                share * 100.0,
                outside * 1e9,
            );
            (share, outside, banded(t))
        });
        let raw = raylimit::measure_obvhs(&scene, &mix, a.repeat);
        println!(
            "  raw obvhs (its CwBvh traversal and triangle test, same rays): {:.2} M closest-hit rays/s, {:.2} M occlusion rays/s",
            raw.closest_per_s / 1e6,
            raw.occlusion_per_s / 1e6,
        );
        let one_thread = [
            ("closest_hit_rays", limit.by_type.closest_per_s, "rays/s"),
            ("occlusion_rays", limit.by_type.occlusion_per_s, "rays/s"),
            ("bsdf_emitter_query_rays", limit.bsdf_query_per_s, "rays/s"),
            (
                "traversal_only_render_order",
                1.0 / limit.render_order_seconds_per_sample,
                "samples/s",
            ),
            (
                "traversal_only_by_type",
                1.0 / limit.by_type.seconds_per_sample,
                "samples/s",
            ),
            ("render_1_thread", limit.render_per_s, "samples/s"),
            ("share_outside_traversal", limit.share_outside, "fraction"),
            (
                "share_outside_traversal_by_type",
                limit.share_outside_by_type,
                "fraction",
            ),
            (
                "outside_traversal_per_sample",
                limit.outside_seconds_per_sample * 1e9,
                "ns",
            ),
            ("share_outside_traversal_banded", share_banded, "fraction"),
            (
                "outside_traversal_per_sample_banded",
                outside_banded * 1e9,
                "ns",
            ),
            ("obvhs_closest_hit_rays", raw.closest_per_s, "rays/s"),
            ("obvhs_occlusion_rays", raw.occlusion_per_s, "rays/s"),
        ]
        .map(|row| (1, row));
        let most_threads = parallel.into_iter().flat_map(|(share, outside, banded)| {
            [
                ("share_outside_traversal", share, "fraction"),
                (
                    "outside_traversal_per_sample",
                    outside * 1e9,
                    "ns thread time",
                ),
                ("share_outside_traversal_banded", banded.0, "fraction"),
                (
                    "outside_traversal_per_sample_banded",
                    banded.1 * 1e9,
                    "ns thread time",
                ),
            ]
            .map(|row| (max_threads, row))
        });
        for (threads, (what, v, unit)) in one_thread.into_iter().chain(most_threads) {
            rows.push(Row {
                section: "ray_limit",
                scene: name.clone(),
                strategy: format!("{}:{what}", mis.label()),
                threads,
                n: 0,
                value: v,
                unit,
            });
        }
    }
    let mis = bench_strategies()[0];
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
            .map(|scene| crate::emitter::EmitterSelector::new(&scene.emitters, sel))
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
    if let Some(bytes) = peak_memory() {
        println!("peak memory: {:.1} MiB", bytes as f64 / (1 << 20) as f64);
        rows.push(Row {
            section: "peak_memory",
            scene: String::new(),
            strategy: String::new(),
            threads: 0,
            n: 0,
            value: bytes as f64,
            unit: "bytes",
        });
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
