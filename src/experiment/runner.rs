//! Running one experiment: scene, left-out analysis, cached reference, the (strategy, spp,
//! seed) sweep and the equal-time runs, resuming from `results.csv`; then figures and report.

use super::budget::{equal_time_spp, Retime};
use super::cache::{self, Fnv, KeyInputs, Reference, ReferenceRequest};
use super::events::{self, Progress};
use super::leftout::{leave_out, samplers_collapse, Omission, SceneTraits};
use super::measure::{measure, Extra};
use super::method::{cross, Method};
use super::plan::{
    has_image, image_path, plan_sweep, same_run, time_tag, variance_path, Job, Sweep,
};
use super::results::{Results, Row, EQUAL_TIME};
use super::schema::{EqualTimeSpec, Resolved};
use crate::film;
use crate::integrator::Strategy;
use crate::render::{render, RenderOutput};
use crate::scene::Scene;
use serde_json::json;
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
    /// What the HTML reports carry.
    pub viewer: super::args::Viewer,
}

/// Everything the figures and the report need.
pub struct Outcome {
    pub exp: Resolved,
    pub dir: PathBuf,
    /// Kept strategies as (label, name), in the experiment's order.
    pub strategies: Vec<(String, String)>,
    /// The method of each kept strategy, in the same order.
    pub methods: Vec<Method>,
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

pub(crate) struct Ctx<'a> {
    pub(crate) scene: &'a Scene,
    pub(crate) reference: &'a Reference,
    pub(crate) eps: f64,
    pub(crate) extra: &'a Extra,
    pub(crate) context: String,
    pub(crate) threads: Option<usize>,
}

/// Renders `job` and measures it; keeps its image where the job says.
pub(crate) fn execute(ctx: &Ctx, job: &Job) -> Result<Row, String> {
    let (row, out) = render_job(ctx, job)?;
    if let Some(p) = &job.image {
        film::write_exr(p, &out.mean)?;
        film::write_exr(&variance_path(p), &out.variance)?;
    }
    Ok(row)
}

/// Renders `job` and measures it against the reference.
pub(crate) fn render_job(ctx: &Ctx, job: &Job) -> Result<(Row, RenderOutput), String> {
    let cam = &ctx.scene.camera;
    let settings = job
        .method
        .settings(job.spp, job.seed, ctx.threads, (cam.width, cam.height))?;
    let out = render(ctx.scene, job.method.strategy, &settings);
    Ok((
        measure(ctx.reference, ctx.eps, ctx.extra, &ctx.context, job, &out),
        out,
    ))
}

/// The cached reference, or a new render; prints where it came from and its noise floor.
fn rendered_reference(
    s: &Setup,
    opts: &RunOptions,
    strategy: Strategy,
    spp: u32,
    seed: u64,
) -> Result<Reference, String> {
    let reference = cache::get_or_render(
        &s.dir.join("cache"),
        &ReferenceRequest {
            scene: &s.scene,
            key: s.key.clone(),
            strategy,
            spp,
            seed,
            threads: opts.threads,
            relmse_epsilon: s.eps,
            fresh: opts.fresh_reference,
            progress: std::io::stderr().is_terminal(),
        },
    )?;
    print_reference(&s.exp.name, &reference);
    Ok(reference)
}

/// Says where the reference came from and its noise floor.
pub(crate) fn print_reference(name: &str, reference: &Reference) {
    let ri = &reference.info;
    events::emit(
        "reference",
        json!({
            "experiment": name,
            "strategy": ri.strategy,
            "spp": ri.spp,
            "cached": reference.cached,
            "why_rendered": reference.why_rendered,
            "seconds": ri.seconds,
            "mse_floor": ri.mse_floor,
            "relmse_floor": ri.relmse_floor,
        }),
    );
    eprintln!(
        "{name}: reference {} at {} spp ({}, {:.1} s to render); noise floor MSE {:.3e}, relMSE {:.3e}",
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
}

/// Columns (strategy and sampler) with their legend names.
pub(crate) type Named = Vec<(String, Method)>;

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
    let (kept, mut omitted) = leave_out(&listed, &SceneTraits::of(scene));
    let mut samplers = exp.exp.samplers.clone();
    let pixels = scene.camera.width as u64 * scene.camera.height as u64;
    if let Some(why) = samplers_collapse(pixels, &exp.exp.spp, exp.exp.equal_time.is_some())
        .filter(|_| samplers.len() > 1)
    {
        let first = samplers[0];
        for &sampler in &samplers[1..] {
            for (name, strategy) in &kept {
                let strategy = *strategy;
                omitted.push(Omission {
                    name: format!("{name}, {sampler}"),
                    label: Method { strategy, sampler }.label(),
                    reason: format!("identical to '{name}, {first}' on this film: {why}"),
                });
            }
        }
        samplers.truncate(1);
    }
    for o in &omitted {
        eprintln!(
            "{}: leaving out '{}' ({}): {}",
            exp.name, o.name, o.label, o.reason
        );
        events::emit(
            "left_out",
            json!({ "experiment": exp.name, "strategy": o.name, "label": o.label, "reason": o.reason }),
        );
    }
    Ok((cross(&kept, &samplers), omitted))
}

/// The equal-time runs still to do: each budget, seed and strategy without its row and
/// image, at the spp the sweep's measured rate gives the budget.
fn equal_time_jobs(
    et: &EqualTimeSpec,
    kept: &[(String, Method)],
    results: &Results,
    dir: &Path,
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
                    None => equal_time_spp(&results.rows, &label, budget)?,
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

/// Where an experiment's reference comes from.
pub(crate) enum RefSource {
    /// A closed-form value in every pixel.
    Constant(f64),
    /// Rendered by `strategy` at `spp` from `seed`, in [`super::chunks`]' fixed chunks.
    Rendered {
        strategy: Strategy,
        spp: u32,
        seed: u64,
    },
}

/// What every way of running an image sweep needs before it renders: the scene, the kept
/// strategies and the reference's identity. One machine ([`run_experiment`]) and shards
/// ([`super::shard`]) start from it.
pub(crate) struct Setup {
    pub(crate) exp: Resolved,
    pub(crate) dir: PathBuf,
    pub(crate) scene: Scene,
    pub(crate) kept: Named,
    pub(crate) omitted: Vec<Omission>,
    pub(crate) eps: f64,
    /// The metrics measured beside MSE and relMSE.
    pub(crate) extra: Extra,
    pub(crate) source: RefSource,
    /// The reference's cache key.
    pub(crate) key: String,
    /// Rows measured against this reference, epsilon and metric choice carry it
    /// (`Row::context`).
    pub(crate) context: String,
}

impl Setup {
    /// spp values whose seed-0 image the figures need.
    pub(crate) fn keep_spp(&self) -> Vec<u32> {
        let mut keep: Vec<u32> = self.exp.exp.figures.progression.clone();
        keep.push(self.exp.equal_spp());
        keep.push(self.exp.variance_spp());
        keep
    }

    pub(crate) fn pixels(&self) -> u64 {
        self.scene.camera.width as u64 * self.scene.camera.height as u64
    }

    /// The sweep's renders `results` does not hold yet, in the fixed plan order.
    pub(crate) fn sweep_jobs(&self, results: &Results) -> Vec<Job> {
        let x = &self.exp.exp;
        plan_sweep(
            results,
            &self.kept,
            &Sweep {
                spp: &x.spp,
                seeds: x.seeds,
                keep_spp: &self.keep_spp(),
                every_seed: x.figures.seed_images.then(|| self.exp.equal_spp()),
                dir: &self.dir,
            },
        )
    }

    /// The reference if nothing has to be rendered: the closed form, or the cached render.
    pub(crate) fn ready_reference(&self) -> Option<Reference> {
        match self.source {
            RefSource::Constant(v) => Some(cache::constant(
                self.scene.camera.width,
                self.scene.camera.height,
                v,
                self.key.clone(),
            )),
            RefSource::Rendered { .. } => {
                cache::cached(&self.dir.join("cache"), &self.key, self.eps)
            }
        }
    }

    /// The cached reference, rendered now if the cache lacks it (or `--fresh-reference`).
    fn reference(&self, opts: &RunOptions) -> Result<Reference, String> {
        match self.source {
            RefSource::Constant(_) => Ok(self.ready_reference().expect("a closed form is ready")),
            RefSource::Rendered {
                strategy,
                spp,
                seed,
            } => rendered_reference(self, opts, strategy, spp, seed),
        }
    }
}

/// Loads the scene, leaves out what it does not need and fixes the reference's key.
pub(crate) fn setup(exp: Resolved, opts: &RunOptions) -> Result<Setup, String> {
    let dir = opts.out.join(&exp.name);
    let scene = crate::scene::open_with(exp.scene(), exp.defines(), exp.cases[0].integrator)?;
    // The scene's warnings went to stderr as it loaded; under --json they are events too.
    for w in &scene.warnings {
        events::emit(
            "warning",
            json!({ "experiment": exp.name, "scene": exp.scene(), "message": w }),
        );
    }
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
    let (key, source) = match (exp.cases[0].value, x.reference.spp) {
        (Some(v), _) => (
            cache::constant_key(exp.scene(), exp.defines(), v, &base)?,
            RefSource::Constant(v),
        ),
        (None, Some(spp)) => {
            let strategy = x
                .reference
                .strategy
                .apply(base)
                .map_err(|e| format!("[reference]: {e}"))?;
            let seed = x.reference.seed;
            let key = cache::reference_key(&KeyInputs {
                scene: exp.scene(),
                defines: exp.defines(),
                spp,
                seed,
                strategy: &strategy,
            })?;
            (
                key,
                RefSource::Rendered {
                    strategy,
                    spp,
                    seed,
                },
            )
        }
        (None, None) => unreachable!("validated: a reference is rendered or given"),
    };
    let extra = Extra::of(x);
    let mut h = Fnv::new();
    h.field(key.as_bytes()).field(&eps.to_le_bytes());
    // Rows measured before with other metrics are redone, not left without them.
    h.field(extra.key().as_bytes());
    Ok(Setup {
        context: h.hex(),
        extra,
        exp,
        dir,
        scene,
        kept,
        omitted,
        eps,
        source,
        key,
    })
}

impl Outcome {
    /// The experiment's title, or its name.
    pub fn title(&self) -> String {
        self.exp
            .exp
            .title
            .clone()
            .unwrap_or_else(|| self.exp.name.clone())
    }

    /// The outcome of `rows` measured in `s` against `reference`.
    pub(crate) fn of(s: Setup, reference: Reference, rows: Vec<Row>, start: Instant) -> Outcome {
        Outcome {
            strategies: s.kept.iter().map(|(n, m)| (m.label(), n.clone())).collect(),
            methods: s.kept.iter().map(|(_, m)| *m).collect(),
            omitted: s.omitted,
            rows,
            rendered: 0,
            dropped_rows: 0,
            seconds: start.elapsed().as_secs_f64(),
            width: s.scene.camera.width,
            height: s.scene.camera.height,
            direct_part_of: s.scene.desc.integrator.direct_part_of.clone(),
            dir: s.dir,
            exp: s.exp,
            reference,
        }
    }
}

/// The spp that `budget` seconds buy `label` at the rate its sweep rows measured.
pub fn run_experiment(exp: Resolved, opts: &RunOptions) -> Result<Outcome, String> {
    let start = Instant::now();
    let s = setup(exp, opts)?;
    events::emit(
        "experiment_started",
        json!({ "experiment": s.exp.name, "file": s.exp.file, "dir": s.dir }),
    );
    let reference = s.reference(opts)?;
    let (exp, dir, x) = (&s.exp, &s.dir, &s.exp.exp);
    let ctx = Ctx {
        scene: &s.scene,
        reference: &reference,
        eps: s.eps,
        extra: &s.extra,
        context: s.context.clone(),
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

    let pixels = s.pixels();
    let jobs = s.sweep_jobs(&results);
    let kept = &s.kept;
    let equal_time_runs = x
        .equal_time
        .as_ref()
        .map_or(0, |e| e.seconds.len() * e.seeds as usize * kept.len());
    let runs = jobs.len() + equal_time_runs;
    // Counted in camera samples; equal-time runs are added once their spp is known.
    let samples: u64 = jobs.iter().map(|j| j.spp as u64 * pixels).sum();
    events::emit(
        "sweep_started",
        json!({ "experiment": exp.name, "runs": runs, "samples": samples }),
    );
    let mut bar = Progress::new(&exp.name, samples, runs);
    let mut rendered = 0;
    // The file holds exactly the kept rows from here on (rows of another context dropped), so
    // each new run is appended; a run that replaces one rewrites the file.
    results.save(&csv)?;
    let mut commit = |row: Row, spp: u64, results: &mut Results, bar: &mut Progress| {
        let before = results.rows.len();
        results.rows.retain(|r| !same_run(r, &row));
        bar.run_done(spp * pixels);
        rendered += 1;
        events::result(&exp.name, &row);
        if results.rows.len() == before {
            results.push_and_append(row, &csv)
        } else {
            results.push_and_save(row, &csv)
        }
    };
    for job in &jobs {
        commit(execute(&ctx, job)?, job.spp as u64, &mut results, &mut bar)?;
    }

    let timed = match &x.equal_time {
        Some(et) => equal_time_jobs(et, kept, &results, dir)?,
        None => Vec::new(),
    };
    bar.add(timed.iter().map(|j| j.spp as u64 * pixels).sum());
    let mut retime = Retime::default();
    for job in &timed {
        // A row re-rendered for its missing image keeps its spp (and so its figure).
        let fresh = results
            .find_equal_time(&job.method.label(), job.budget, job.seed)
            .is_none();
        // The samples actually rendered: a re-timed run renders twice.
        let mut spp = 0u64;
        let row = if fresh {
            retime.run(job, |j| {
                spp += j.spp as u64;
                execute(&ctx, j)
            })?
        } else {
            spp = job.spp as u64;
            execute(&ctx, job)?
        };
        bar.replan(job.spp as u64 * pixels, spp * pixels);
        commit(row, spp, &mut results, &mut bar)?;
    }
    bar.finish();
    let near = results.rows.iter().filter(|r| r.near_floor).count();
    if near > 0 {
        eprintln!(
            "{}: warning: {near} of {} runs measured an error within 2x of the reference's noise floor; \
             their corrected errors are unreliable (render the reference with more spp)",
            exp.name,
            results.rows.len()
        );
    }
    let dropped = results.dropped;
    let mut o = Outcome::of(s, reference, results.rows, start);
    o.rendered = rendered;
    o.dropped_rows = dropped;
    Ok(o)
}
