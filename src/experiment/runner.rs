//! Running one experiment: scene, left-out analysis, cached reference, the (strategy, spp,
//! seed) sweep and the equal-time runs, resuming from `results.csv`; then figures and report.

use super::cache::{self, Fnv, KeyInputs, Reference, ReferenceRequest};
use super::leftout::{leave_out, Omission, SceneTraits};
use super::measure::measure;
use super::method::{cross, Method};
use super::plan::{
    has_image, image_path, plan_sweep, rate, same_run, time_tag, variance_path, Job, Sweep,
};
use super::results::{Results, Row, EQUAL_TIME};
use super::schema::{EqualTimeSpec, Resolved};
use crate::film;
use crate::integrator::Strategy;
use crate::render::{render, RenderSettings};
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
    /// The global-illumination integrator the scene names, when the images are its direct
    /// part (`integrator = "direct"`).
    pub direct_part_of: Option<String>,
}

struct Ctx<'a> {
    scene: &'a Scene,
    reference: &'a Reference,
    eps: f64,
    context: String,
    threads: Option<usize>,
}

fn execute(ctx: &Ctx, job: &Job) -> Result<Row, String> {
    let settings = RenderSettings {
        spp: job.spp,
        seed: job.seed,
        first_sample: 0,
        threads: ctx.threads,
        progress: false,
        sampling: job.method.sampler.sampling(),
    };
    let cam = &ctx.scene.camera;
    settings
        .sampler_config((cam.width, cam.height))
        .map_err(|e| format!("{} at {} spp: {e}", job.method.label(), job.spp))?;
    let out = render(ctx.scene, job.method.strategy, &settings);
    if let Some(p) = &job.image {
        film::write_exr(p, &out.mean)?;
        film::write_exr(&variance_path(p), &out.variance)?;
    }
    Ok(measure(ctx.reference, ctx.eps, &ctx.context, job, &out))
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

/// The cached reference, or a new render; prints where it came from and its noise floor.
fn rendered_reference(
    exp: &Resolved,
    opts: &RunOptions,
    scene: &Scene,
    strategy: Strategy,
    spp: u32,
    eps: f64,
    dir: &Path,
) -> Result<(String, Reference), String> {
    let seed = exp.exp.reference.seed;
    let key = cache::reference_key(&KeyInputs {
        scene: exp.scene(),
        defines: exp.defines(),
        spp,
        seed,
        strategy: &strategy,
    })?;
    let reference = cache::get_or_render(
        &dir.join("cache"),
        &ReferenceRequest {
            scene,
            key: key.clone(),
            strategy,
            spp,
            seed,
            threads: opts.threads,
            relmse_epsilon: eps,
            fresh: opts.fresh_reference,
            progress: std::io::stderr().is_terminal(),
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
    Ok((key, reference))
}

/// Columns (strategy and sampler) with their legend names.
type Named = Vec<(String, Method)>;

/// The experiment's strategies on the scene's settings `base`, without those that are the
/// same estimator on this scene or cannot see its light (each said on stderr), crossed with
/// its samplers.
fn strategies(
    exp: &Resolved,
    base: Strategy,
    scene: &Scene,
) -> Result<(Named, Vec<Omission>), String> {
    let listed: Vec<(String, Strategy)> = exp
        .exp
        .strategies
        .iter()
        .map(|s| Ok((s.name.clone(), s.on(base)?)))
        .collect::<Result<_, String>>()?;
    let (kept, omitted) = leave_out(&listed, &SceneTraits::of(scene));
    for o in &omitted {
        eprintln!(
            "{}: leaving out '{}' ({}): {}",
            exp.name, o.name, o.label, o.reason
        );
    }
    Ok((cross(&kept, &exp.exp.samplers), omitted))
}

/// The equal-time runs still to do: each budget, seed and strategy without its row and
/// image, at the spp the sweep's measured rate gives the budget.
fn equal_time_jobs(
    et: &EqualTimeSpec,
    kept: &[(String, Method)],
    results: &Results,
    dir: &Path,
    pixels: u64,
) -> Result<Vec<Job>, String> {
    let mut timed = Vec::new();
    for &budget in &et.seconds {
        for seed in 0..et.seeds as u64 {
            for (name, s) in kept {
                let label = s.label();
                let image = Some(image_path(dir, &label, &time_tag(budget), seed));
                let old = results.find_equal_time(&label, budget, seed);
                if old.is_some() && has_image(&image) {
                    continue;
                }
                // Re-rendering a row whose image is missing reuses its spp, so the row
                // and the figure show the same render.
                let spp = match old {
                    Some(r) => r.spp,
                    None => {
                        let r = rate(&results.rows, &label)
                            .ok_or_else(|| format!("no sweep rows for {label} to time it from"))?;
                        ((budget * r / pixels as f64).round() as u32).max(1)
                    }
                };
                timed.push(Job {
                    name: name.clone(),
                    method: *s,
                    kind: EQUAL_TIME,
                    budget,
                    spp,
                    seed,
                    image,
                });
            }
        }
    }
    Ok(timed)
}

pub fn run_experiment(exp: Resolved, opts: &RunOptions) -> Result<Outcome, String> {
    let start = Instant::now();
    let dir = opts.out.join(&exp.name);
    let scene = crate::scene::open_with(exp.scene(), exp.defines(), exp.cases[0].integrator)?;
    let base = Strategy::from_desc(&scene.desc.integrator);
    let (kept, omitted) = strategies(&exp, base, &scene)?;

    let x = &exp.exp;
    // A sampler that cannot draw the sweep's largest run fails before anything renders.
    let film = (scene.camera.width, scene.camera.height);
    let most = x.spp.iter().copied().max().unwrap_or(1);
    for (_, m) in &kept {
        m.sampler
            .sampling()
            .config(0, 0, most, film)
            .map_err(|e| format!("{}: samplers: {e}", exp.file.display()))?;
    }
    let eps = x.metrics.relmse_epsilon;
    let ref_strategy = x
        .reference
        .strategy
        .apply(base)
        .map_err(|e| format!("[reference]: {e}"))?;
    let (key, reference) = match (exp.cases[0].value, x.reference.spp) {
        (Some(v), _) => {
            let key = cache::constant_key(exp.scene(), exp.defines(), v, &base)?;
            let r = cache::constant(scene.camera.width, scene.camera.height, v, key.clone());
            (key, r)
        }
        (None, Some(spp)) => rendered_reference(&exp, opts, &scene, ref_strategy, spp, eps, &dir)?,
        (None, None) => unreachable!("validated: a reference is rendered or given"),
    };
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

    let timed = match &x.equal_time {
        Some(et) => equal_time_jobs(et, &kept, &results, &dir, pixels)?,
        None => Vec::new(),
    };
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
        direct_part_of: scene.desc.integrator.direct_part_of.clone(),
        dir,
        exp,
        reference,
    })
}
