//! `directlab bench`: speed goals as measured numbers (printed and written to
//! `reports/bench/bench.csv`), never timed tests. Sections, each a function that prints and
//! adds its rows: render throughput per scene, strategy and thread count with the machine's
//! own scaling (`throughput`, `copies`), and per sampler (`samplers`); the ray-tracing limit for the same ray mix and the
//! share of render time spent outside traversal, on one thread and on the most threads
//! (`ray_limit_section` here, measured by `raylimit`); the cost model of counted work and
//! its prediction error on renders it was not fitted on (`cost`); per-sample cost as the triangle and
//! emitter counts grow (`sweeps`, over the scenes of `scaling`); scene loading as the emitter
//! count grows (`load`); peak memory.

mod choice;
mod copies;
mod cost;
mod load;
mod raylimit;
mod samplers;
pub(crate) use crate::scene::scaling;
mod sweeps;
mod throughput;
mod timing;

use crate::emitter::{EmitterSelection, LightSampling};
use crate::integrator::Strategy;
use crate::scene::desc::{Heuristic, StrategyKind};
use crate::scene::Scene;
use clap::Args;
use std::path::PathBuf;
use timing::throughput;

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Scenes to measure (default: the bundled Cornell box and Veach MIS scene).
    #[arg(long = "scene")]
    pub scenes: Vec<PathBuf>,
    /// Thread counts to measure.
    #[arg(long, value_delimiter = ',', default_value = "1,2", value_parser = crate::render::parse_threads)]
    pub threads: Vec<usize>,
    /// Samples per pixel of each timed render.
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..))]
    pub spp: u32,
    /// Image resolution of scenes that declare a `res` default (the bundled Cornell box); other
    /// scenes keep their own size (the Veach scene: 768x512).
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..))]
    pub res: u32,
    /// Timed repetitions; the fastest is reported (the others measure interference). Five,
    /// because on a shared 2-core VM three still let one slow spell decide a 2-thread number.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..))]
    pub repeat: u32,
    /// Samples per pixel of each timed render of the triangle and emitter sweeps (64x64
    /// pixels): renders much shorter than a scheduler tick's and a thread start-up's noise
    /// spread too widely between repetitions for best-of-N to remove.
    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..))]
    pub sweep_spp: u32,
    /// Largest triangle count of the triangle-scaling sweep (1e3, 1e4, ... up to this).
    #[arg(long, default_value_t = 1_000_000)]
    pub max_triangles: usize,
    /// Largest emitter count of the emitter-scaling sweep (1, 10, ... up to this).
    #[arg(long, default_value_t = 10_000)]
    pub max_emitters: usize,
    /// Largest emitter count of the emitter-choice sweep (1, 10, ... up to this): the cost of
    /// one choice per rule, and the light tree's build time and memory.
    #[arg(long, default_value_t = 100_000)]
    pub max_choice_emitters: usize,
    /// Largest emitter count of the scene-loading sweep (1e3, 1e4, ... up to this; 0 leaves
    /// the sweep out). A million emitters is a 190 MB XML file and about 3 GB of memory.
    #[arg(long, default_value_t = 1_000_000)]
    pub max_load_emitters: usize,
    /// Output CSV.
    #[arg(long, default_value = "reports/bench/bench.csv")]
    pub out: PathBuf,
}

/// The estimator the goals are stated for, and the first of `bench_strategies`: power-heuristic
/// MIS with one light and one BSDF sample, uniform emitter choice, area sampling.
pub fn power_mis() -> Strategy {
    bench_strategies()[0]
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
        let scene = open_at(path, a.res)?;
        let name = path.display().to_string();
        // `res` sets the size of scenes that declare it; the others keep their own.
        println!("  {name}: {}x{}", scene.camera.width, scene.camera.height);
        throughput::section(&scene, &name, a, &mut rows);
        cost::section(&scene, &name, a, &mut rows);
        samplers::section(&scene, &name, a, max_threads, &mut rows);
        ray_limit_section(&scene, &name, a, max_threads, &mut rows);
    }
    sweeps::section(a, max_threads, &mut rows)?;
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
    // After the peak memory, which is the renders' and not the million-emitter file's.
    load::section(a, &mut rows)?;
    crate::output::write_atomic(&a.out, |tmp| {
        let mut w = csv::Writer::from_path(tmp).map_err(|e| format!("{}: {e}", a.out.display()))?;
        for r in &rows {
            w.serialize(r).map_err(|e| e.to_string())?;
        }
        w.flush().map_err(|e| e.to_string())
    })?;
    eprintln!("wrote {}", a.out.display());
    Ok(())
}

/// Opens a bench scene, at resolution `res` where it declares a `res` parameter (the bundled
/// Cornell box); other scenes keep their own size, and a define they do not declare would be
/// refused as a typo.
fn open_at(path: &std::path::Path, res: u32) -> Result<Scene, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let declares = crate::scene::xml::declared_parameters(&text)
        .iter()
        .any(|p| p == "res");
    let defines = if declares {
        vec![("res".to_string(), res.to_string())]
    } else {
        Vec::new()
    };
    crate::scene::open(path, &defines)
}

/// The ray-tracing limit section for one scene: the same ray mix traced alone, the share of
/// render time outside traversal (whole, band by band, on the most threads) and raw obvhs.
fn ray_limit_section(
    scene: &Scene,
    name: &str,
    a: &BenchArgs,
    max_threads: usize,
    rows: &mut Vec<Row>,
) {
    let mis = power_mis();
    // The ray-tracing limit for the same ray mix, on one thread, against the 1-thread
    // render time of power MIS (which traces that mix). Whole groups of LANES samples per
    // pixel, as the renderer traces them.
    let mix_spp = (a.spp / 16)
        .max(1)
        .next_multiple_of(crate::rng::LANES as u32);
    let mix = raylimit::ray_mix(scene, mix_spp, mis.selection);
    let limit = raylimit::measure(scene, &mix, a.repeat, || {
        throughput(scene, mis, a.spp, 1, 1)
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
    let kernel = crate::integrator::LaneKernel::new(scene, mis);
    let banded = |threads| {
        let spps = (mix_spp, a.spp);
        let (share, outside) =
            raylimit::measure_interleaved(&kernel, &mix, spps, threads, a.repeat);
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
        let render = || throughput(scene, mis, a.spp, t, 1);
        let (share, outside) = raylimit::measure_threads(scene, &mix, t, a.repeat, render);
        println!(
            "  at {t} threads: {:.0}% of render time outside traversal, {:.1} ns of thread time per sample",
            share * 100.0,
            outside * 1e9,
        );
        (share, outside, banded(t))
    });
    let raw = raylimit::measure_obvhs(scene, &mix, a.repeat);
    println!(
        "  raw obvhs (its CwBvh traversal and triangle test, same rays): {:.2} M closest-hit rays/s, {:.2} M occlusion rays/s",
        raw.closest_per_s / 1e6,
        raw.occlusion_per_s / 1e6,
    );
    let one_thread =
        one_thread_rows(&limit, (share_banded, outside_banded), &raw).map(|row| (1, row));
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
            scene: name.to_string(),
            strategy: format!("{}:{what}", mis.label()),
            threads,
            n: 0,
            value: v,
            unit,
        });
    }
}

/// The ray-tracing limit's rows on one thread: (name, value, unit).
fn one_thread_rows(
    limit: &raylimit::Limit,
    (share_banded, outside_banded): (f64, f64),
    raw: &raylimit::RayLimit,
) -> [(&'static str, f64, &'static str); 13] {
    [
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bench_scenes_open_at_the_bench_resolution_only_where_declared() {
        // The Cornell box declares `res`; the Veach scene does not and keeps its 768x512
        // (setting `res` there was refused, which stopped `directlab bench` at its second scene).
        let cbox = open_at(std::path::Path::new("scenes/cbox/cbox.xml"), 24).unwrap();
        assert_eq!((cbox.camera.width, cbox.camera.height), (24, 24));
        let veach = open_at(std::path::Path::new("scenes/veach-mis/veach-mis.xml"), 24).unwrap();
        assert_eq!((veach.camera.width, veach.camera.height), (768, 512));
    }
}
