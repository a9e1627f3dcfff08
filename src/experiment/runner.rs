//! Running one experiment: scene, left-out analysis, cached reference, the (strategy, spp,
//! seed) sweep and the equal-time runs, resuming from `results.csv`; then figures and report.

use super::cache::{self, Fnv, KeyInputs, Reference, ReferenceRequest};
use super::leftout::{leave_out, Omission, SceneTraits};
use super::results::{Results, Row, EQUAL_TIME, SWEEP};
use super::schema::Resolved;
use crate::cli::open_scene;
use crate::film::{self, Image};
use crate::integrator::Strategy;
use crate::metrics;
use crate::render::{render, RenderOutput, RenderSettings};
use crate::scene::Scene;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Reports root; the experiment writes into `<out>/<name>/`.
    pub out: PathBuf,
    pub threads: Option<usize>,
    /// Re-render the reference even if a cached one matches.
    pub fresh_reference: bool,
}

/// Everything the figures and the report need.
pub struct Outcome {
    pub exp: Resolved,
    pub dir: PathBuf,
    /// Kept strategies as (label, name), in the experiment's order.
    pub strategies: Vec<(String, String)>,
    pub omitted: Vec<Omission>,
    pub reference: Reference,
    pub rows: Vec<Row>,
    /// Rows rendered by this invocation (the rest came from `results.csv`).
    pub rendered: usize,
    pub dropped_rows: usize,
    pub seconds: f64,
    pub width: u32,
    pub height: u32,
}

pub fn image_path(dir: &Path, label: &str, tag: &str, seed: u64) -> PathBuf {
    dir.join("cache")
        .join("images")
        .join(format!("{label}-{tag}-s{seed}.exr"))
}

pub fn variance_path(p: &Path) -> PathBuf {
    p.with_extension("var.exr")
}

pub fn spp_tag(spp: u32) -> String {
    format!("spp{spp}")
}

pub fn time_tag(budget: f64) -> String {
    format!("t{budget}")
}

/// One render to do.
struct Job {
    name: String,
    strategy: Strategy,
    kind: &'static str,
    budget: f64,
    spp: u32,
    seed: u64,
    /// Where to keep the image for the figures, if it is needed.
    image: Option<PathBuf>,
}

struct Ctx<'a> {
    scene: &'a Scene,
    reference: &'a Reference,
    eps: f64,
    context: String,
    threads: Option<usize>,
}

fn measure(ctx: &Ctx, job: &Job, out: &RenderOutput) -> Row {
    let r = &ctx.reference;
    let mse = metrics::mse(&out.mean, &r.mean);
    let relmse = metrics::rel_mse(&out.mean, &r.mean, ctx.eps);
    let n = out.mean.data.len() as f64;
    let mut var_sum = [0.0f64; 3];
    let mut rel_var = 0.0f64;
    let (mut z2, mut z2_n) = (0.0f64, 0u64);
    let level = r.mean.mean_rgb().iter().map(|v| v.abs()).sum::<f64>() / 3.0;
    for (((v, m), x), rv) in out
        .variance
        .data
        .iter()
        .zip(&r.mean.data)
        .zip(&out.mean.data)
        .zip(&r.variance.data)
    {
        for c in 0..3 {
            var_sum[c] += v[c];
            rel_var += v[c] / (m[c] * m[c] + ctx.eps);
            // Pixels where neither image varies (background, emitter interiors) carry no
            // information. The cached reference is stored in f32, so its rounding (relative
            // 6e-8) is part of the noise, and differences below 1e-9 of the image's level are
            // immaterial; without these floors near-exact pixels give z^2 = 1e40.
            let floor = 1e-7 * m[c].abs().max(x[c].abs()) + 1e-9 * level;
            let var = v[c] + rv[c] + floor * floor;
            if out.spp > 1 && v[c] + rv[c] > 0.0 {
                z2 += (x[c] - m[c]).powi(2) / var;
                z2_n += 1;
            }
        }
    }
    let mean = out.mean.mean_rgb();
    Row {
        context: ctx.context.clone(),
        strategy: job.strategy.label(),
        name: job.name.clone(),
        kind: job.kind.to_string(),
        budget_s: job.budget,
        spp: job.spp,
        seed: job.seed,
        width: out.mean.width,
        height: out.mean.height,
        seconds: out.seconds,
        samples_per_s: out.samples_per_second(),
        mse,
        mse_corrected: mse - r.info.mse_floor,
        relmse,
        relmse_corrected: relmse - r.info.relmse_floor,
        relmse_eps: ctx.eps,
        mse_predicted: var_sum.iter().sum::<f64>() / (3.0 * n),
        relmse_predicted: rel_var / (3.0 * n),
        mean_z2: if z2_n > 0 { z2 / z2_n as f64 } else { f64::NAN },
        mean_r: mean[0],
        mean_g: mean[1],
        mean_b: mean[2],
        mean_var_r: var_sum[0] / (n * n),
        mean_var_g: var_sum[1] / (n * n),
        mean_var_b: var_sum[2] / (n * n),
        non_finite: out.non_finite_samples,
        near_floor: mse < 2.0 * r.info.mse_floor || relmse < 2.0 * r.info.relmse_floor,
    }
}

fn execute(ctx: &Ctx, job: &Job) -> Result<Row, String> {
    let out = render(
        ctx.scene,
        job.strategy,
        &RenderSettings {
            spp: job.spp,
            seed: job.seed,
            threads: ctx.threads,
            progress: false,
        },
    );
    if let Some(p) = &job.image {
        film::write_exr(p, &out.mean)?;
        film::write_exr(&variance_path(p), &out.variance)?;
    }
    Ok(measure(ctx, job, &out))
}

/// Two rows are the same run (one replaces the other) if their resume keys agree.
fn same_run(a: &Row, b: &Row) -> bool {
    a.kind == b.kind
        && a.strategy == b.strategy
        && a.seed == b.seed
        && if a.is_sweep() {
            a.spp == b.spp
        } else {
            a.budget_s == b.budget_s
        }
}

fn has_image(p: &Option<PathBuf>) -> bool {
    p.as_ref()
        .is_none_or(|p| p.exists() && variance_path(p).exists())
}

fn progress_bar(total_samples: u64, runs: usize) -> ProgressBar {
    if !std::io::stderr().is_terminal() || runs == 0 {
        return ProgressBar::hidden();
    }
    let b = ProgressBar::new(total_samples);
    b.set_style(
        ProgressStyle::with_template(
            "{spinner} {msg} [{bar:30}] {percent}%, {elapsed} (eta {eta})",
        )
        .expect("static template")
        .progress_chars("=> "),
    );
    b.set_message(format!("0/{runs} runs"));
    b
}

/// What the sweep covers, and which seed-0 images the figures need.
struct Sweep<'a> {
    spp: &'a [u32],
    seeds: u32,
    keep_spp: &'a [u32],
    dir: &'a Path,
}

/// The sweep's renders still to do: rows missing from `results`, and rows whose image the
/// figures need but which is missing (seeds give the same image again, so the row is redone).
fn plan_sweep(results: &Results, kept: &[(String, Strategy)], sw: &Sweep) -> Vec<Job> {
    let mut jobs = Vec::new();
    for seed in 0..sw.seeds as u64 {
        for &spp in sw.spp {
            for (name, s) in kept {
                let image = (seed == 0 && sw.keep_spp.contains(&spp))
                    .then(|| image_path(sw.dir, &s.label(), &spp_tag(spp), seed));
                let done = results.find_sweep(&s.label(), spp, seed).is_some();
                if !done || !has_image(&image) {
                    jobs.push(Job {
                        name: name.clone(),
                        strategy: *s,
                        kind: SWEEP,
                        budget: 0.0,
                        spp,
                        seed,
                        image,
                    });
                }
            }
        }
    }
    jobs
}

/// Samples per second of a strategy over its sweep rows (dominated by the long runs, where
/// per-render overhead is negligible).
fn rate(rows: &[Row], label: &str) -> Option<f64> {
    let (mut samples, mut secs) = (0.0, 0.0);
    for r in rows.iter().filter(|r| r.is_sweep() && r.strategy == label) {
        samples += r.samples_per_s * r.seconds;
        secs += r.seconds;
    }
    (secs > 0.0).then(|| samples / secs)
}

pub fn run_experiment(exp: Resolved, opts: &RunOptions) -> Result<Outcome, String> {
    let start = Instant::now();
    let dir = opts.out.join(&exp.name);
    let scene = open_scene(&exp.scene, &exp.defines)?;
    let base = Strategy::from_desc(&scene.desc.integrator);
    let listed: Vec<(String, Strategy)> = exp
        .exp
        .strategies
        .iter()
        .map(|s| (s.name.clone(), s.args().apply(base)))
        .collect();
    let (kept, omitted) = leave_out(&listed, &SceneTraits::of(&scene));
    for o in &omitted {
        eprintln!(
            "{}: leaving out '{}' ({}): {}",
            exp.name, o.name, o.label, o.reason
        );
    }

    let x = &exp.exp;
    let eps = x.metrics.relmse_epsilon;
    let ref_strategy = x.reference.strategy.apply(base);
    let key = cache::reference_key(&KeyInputs {
        scene: &exp.scene,
        defines: &exp.defines,
        spp: x.reference.spp,
        seed: x.reference.seed,
        strategy: &ref_strategy,
    })?;
    let terminal = std::io::stderr().is_terminal();
    let reference = cache::get_or_render(
        &dir.join("cache"),
        &ReferenceRequest {
            scene: &scene,
            key: key.clone(),
            strategy: ref_strategy,
            spp: x.reference.spp,
            seed: x.reference.seed,
            threads: opts.threads,
            relmse_epsilon: eps,
            fresh: opts.fresh_reference,
            progress: terminal,
        },
    )?;
    let ri = &reference.info;
    eprintln!(
        "{}: reference {} at {} spp ({}, {:.1} s to render); noise floor MSE {:.3e}, relMSE {:.3e}",
        exp.name,
        ri.strategy,
        ri.spp,
        if reference.cached {
            "cached"
        } else {
            "rendered now"
        },
        ri.seconds,
        ri.mse_floor,
        ri.relmse_floor
    );

    let mut h = Fnv::new();
    h.field(key.as_bytes()).field(&eps.to_le_bytes());
    let ctx = Ctx {
        scene: &scene,
        reference: &reference,
        eps,
        context: h.hex(),
        threads: opts.threads,
    };
    let csv = dir.join("results.csv");
    let mut results = Results::load(&csv, &ctx.context)?;
    if results.dropped > 0 {
        eprintln!(
            "{}: {} rows of results.csv were made with another scene, reference or epsilon and will be redone",
            exp.name, results.dropped
        );
    }

    let pixels = scene.camera.width as u64 * scene.camera.height as u64;
    let mut keep_spp: Vec<u32> = x.figures.progression.clone();
    keep_spp.push(exp.equal_spp());
    keep_spp.push(exp.variance_spp());
    let jobs = plan_sweep(
        &results,
        &kept,
        &Sweep {
            spp: &x.spp,
            seeds: x.seeds,
            keep_spp: &keep_spp,
            dir: &dir,
        },
    );
    let equal_time_runs = x
        .equal_time
        .as_ref()
        .map_or(0, |e| e.seconds.len() * e.seeds as usize * kept.len());
    let runs = jobs.len() + equal_time_runs;
    // The bar counts camera samples; equal-time runs are added once their spp is known.
    let bar = progress_bar(jobs.iter().map(|j| j.spp as u64 * pixels).sum(), runs);
    let mut rendered = 0;
    let mut run = |job: &Job, results: &mut Results| -> Result<(), String> {
        let row = execute(&ctx, job)?;
        results.rows.retain(|r| !same_run(r, &row));
        bar.inc(job.spp as u64 * pixels);
        rendered += 1;
        if bar.is_hidden() {
            eprintln!(
                "{}: {} {} spp seed {}: relMSE {:.3e} in {:.2} s",
                exp.name, row.strategy, row.spp, row.seed, row.relmse, row.seconds
            );
        }
        bar.set_message(format!("{rendered}/{runs} runs"));
        results.push_and_save(row, &csv)
    };
    for job in &jobs {
        run(job, &mut results)?;
    }

    let mut timed = Vec::new();
    if let Some(et) = &x.equal_time {
        for &budget in &et.seconds {
            for seed in 0..et.seeds as u64 {
                for (name, s) in &kept {
                    let label = s.label();
                    let image = Some(image_path(&dir, &label, &time_tag(budget), seed));
                    let old = results.find_equal_time(&label, budget, seed);
                    if old.is_some() && has_image(&image) {
                        continue;
                    }
                    // Re-rendering a row whose image is missing reuses its spp, so the row
                    // and the figure show the same render.
                    let spp = match old {
                        Some(r) => r.spp,
                        None => {
                            let r = rate(&results.rows, &label).ok_or_else(|| {
                                format!("no sweep rows for {label} to time it from")
                            })?;
                            ((budget * r / pixels as f64).round() as u32).max(1)
                        }
                    };
                    timed.push(Job {
                        name: name.clone(),
                        strategy: *s,
                        kind: EQUAL_TIME,
                        budget,
                        spp,
                        seed,
                        image,
                    });
                }
            }
        }
    }
    bar.inc_length(timed.iter().map(|j| j.spp as u64 * pixels).sum());
    for job in &timed {
        run(job, &mut results)?;
    }
    bar.finish_and_clear();
    let near = results.rows.iter().filter(|r| r.near_floor).count();
    if near > 0 {
        eprintln!(
            "{}: warning: {near} of {} runs measured an error within 2x of the reference's noise floor; \
             their corrected errors are unreliable (render the reference with more spp)",
            exp.name,
            results.rows.len()
        );
    }
    Ok(Outcome {
        strategies: kept.iter().map(|(n, s)| (s.label(), n.clone())).collect(),
        omitted,
        rows: results.rows,
        rendered,
        dropped_rows: results.dropped,
        seconds: start.elapsed().as_secs_f64(),
        width: scene.camera.width,
        height: scene.camera.height,
        dir,
        exp,
        reference,
    })
}

/// Loads a kept image and its variance.
pub fn load_image(p: &Path) -> Result<(Image, Image), String> {
    Ok((film::read_exr(p)?, film::read_exr(&variance_path(p))?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::results::test_row;
    use crate::scene::desc::{Heuristic, StrategyKind};

    #[test]
    fn resume_plans_only_missing_rows_and_missing_images() {
        let dir = std::env::temp_dir().join(format!("directlab-plan-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let s = Strategy {
            kind: StrategyKind::Light,
            heuristic: Heuristic::Balance,
            emitter_samples: 1,
            bsdf_samples: 1,
            selection: crate::emitter::EmitterSelection::Uniform,
            light_sampling: crate::emitter::LightSampling::Area,
            hide_emitters: false,
        };
        let label = s.label();
        let kept = vec![("light".to_string(), s)];
        let sw = Sweep {
            spp: &[1, 4],
            seeds: 2,
            keep_spp: &[4],
            dir: &dir,
        };
        let planned = |res: &Results| -> Vec<(u32, u64)> {
            plan_sweep(res, &kept, &sw)
                .iter()
                .map(|j| (j.spp, j.seed))
                .collect()
        };
        let mut res = Results {
            rows: vec![],
            dropped: 0,
        };
        assert_eq!(planned(&res), [(1, 0), (4, 0), (1, 1), (4, 1)]);
        res.rows = [(1, 0), (4, 0), (4, 1)]
            .iter()
            .map(|&(spp, seed)| test_row(&label, spp, seed))
            .collect();
        // (4, 0) is done but the figures need its image, which is not there yet.
        assert_eq!(planned(&res), [(4, 0), (1, 1)]);
        let img = image_path(&dir, &label, &spp_tag(4), 0);
        std::fs::create_dir_all(img.parent().unwrap()).unwrap();
        std::fs::write(&img, "").unwrap();
        std::fs::write(variance_path(&img), "").unwrap();
        assert_eq!(planned(&res), [(1, 1)]);
        res.rows.push(test_row(&label, 1, 1));
        assert!(planned(&res).is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
