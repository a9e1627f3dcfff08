//! Running a probe experiment: load every case (checking its expected warning and its
//! closed form), leave out equivalent strategies, draw the streams not yet in `results.csv`
//! (rewritten atomically after each), then the accumulation renders and the input checks.

use super::accumulate::{self, Accumulation};
use super::closed_form;
use super::invalid::{check, try_scene, Check};
use super::rows::{rows, StreamInfo};
use super::samples::pixel_samples;
use super::stats::{stream, Stream};
use crate::experiment::cache::{self, Fnv};
use crate::experiment::cases::{Case, ProbeSpec};
use crate::experiment::leftout::{leave_out, Omission, SceneTraits};
use crate::experiment::results::{Results, Row};
use crate::experiment::schema::Experiment;
use crate::experiment::{Resolved, RunOptions};
use crate::integrator::{Direct, Strategy};
use crate::scene::Scene;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Mutex;
use std::time::Instant;

/// One case as run.
pub struct CaseRun {
    pub case: Case,
    pub emitters: usize,
    /// The value its closed form gives on the loaded scene (when it names one).
    pub closed_form: Option<f64>,
    /// Kept strategies as (name, strategy), in the experiment's order.
    pub kept: Vec<(String, Strategy)>,
    pub omitted: Vec<Omission>,
    pub context: String,
}

impl CaseRun {
    pub fn reference(&self) -> f64 {
        self.case
            .value
            .expect("validated: probe cases have a value")
    }
}

pub struct ProbeOutcome {
    pub exp: Resolved,
    pub dir: PathBuf,
    pub cases: Vec<CaseRun>,
    pub rows: Vec<Row>,
    /// Streams (case, strategy, seed) in all, and drawn by this invocation.
    pub streams: usize,
    pub drawn: usize,
    pub dropped_rows: usize,
    pub accumulation: Vec<Accumulation>,
    /// Expected errors and warnings: `[[invalid]]` entries, then the cases' `warning`s.
    pub checks: Vec<Check>,
    pub seconds: f64,
}

/// Relative agreement a stated `reference.value` must have with its closed form: far below
/// any test's resolution, above the last-digit differences of libm across platforms.
const VALUE_TOLERANCE: f64 = 1e-9;

/// Draws one stream and measures it (for tests that need more samples than a report).
pub fn measure_stream(
    scene: &Scene,
    s: Strategy,
    pixel: [u32; 2],
    samples: u32,
    seed: u64,
    reference: f64,
) -> Stream {
    let mut buf = Vec::new();
    let d = pixel_samples(
        &Direct::new(scene, s),
        pixel[0],
        pixel[1],
        seed,
        samples,
        &mut buf,
    );
    stream(&buf, d.non_finite, reference)
}

fn open_case(exp: &Resolved, c: &Case) -> Result<(Scene, Option<Check>, Option<f64>), String> {
    let at = |e: String| format!("{}: case '{}': {e}", exp.file.display(), c.name);
    let desc = crate::scene::loader::load_scene_with(&c.scene, &c.defines, c.integrator)
        .map_err(|e| at(e.to_string()))?;
    let scene = Scene::build(desc).map_err(|e| at(e.to_string()))?;
    let warned = c.warning.as_ref().map(|w| {
        check(
            format!("case {}", c.name),
            "warning",
            w,
            Ok(scene.warnings.clone()),
        )
    });
    let value = c.value.expect("validated");
    let computed = match c.closed_form {
        None => None,
        Some(form) => {
            let v = closed_form::evaluate(&scene, form).map_err(at)?;
            let close = (v - value).abs() <= VALUE_TOLERANCE * v.abs().max(value.abs());
            if !close {
                return Err(at(format!(
                    "reference.value = {value:e}, but its closed form ({}) gives {v:e} on the scene",
                    form.describe()
                )));
            }
            Some(v)
        }
    };
    Ok((scene, warned, computed))
}

/// Everything a case's rows depend on: scene files, defines, reference, epsilon, the probe
/// pixel and stream length, the renderer's source.
fn context(exp: &Resolved, c: &Case, base: &Strategy) -> Result<String, String> {
    let p = exp.exp.probe.as_ref().expect("probe mode");
    let key = cache::constant_key(&c.scene, &c.defines, c.value.expect("validated"), base)?;
    let mut h = Fnv::new();
    h.field(key.as_bytes())
        .field(&exp.exp.metrics.relmse_epsilon.to_le_bytes())
        .field(&p.samples.to_le_bytes())
        .field(&p.pixel[0].to_le_bytes())
        .field(&p.pixel[1].to_le_bytes());
    Ok(h.hex())
}

/// `open_cases`' result: the cases, their scenes, and the checks of their warnings.
type OpenCases = (Vec<CaseRun>, Vec<Scene>, Vec<Check>);

/// Each case's scene, with the strategies kept on it, and the checks of the warnings its
/// loading gave; a probe pixel outside a case's film is an error.
fn open_cases(exp: &Resolved, p: &ProbeSpec) -> Result<OpenCases, String> {
    let x = &exp.exp;
    let mut cases = Vec::new();
    let mut scenes = Vec::new();
    let mut warned_checks = Vec::new();
    for c in &exp.cases {
        let (scene, warned, computed) = open_case(exp, c)?;
        let (w, h) = (scene.camera.width, scene.camera.height);
        if p.pixel[0] >= w || p.pixel[1] >= h {
            return Err(format!(
                "{}: probe.pixel {:?} lies outside case '{}' ({w} x {h} pixels)",
                exp.file.display(),
                p.pixel,
                c.name
            ));
        }
        let base = Strategy::from_desc(&scene.desc.integrator);
        let listed: Vec<(String, Strategy)> = x
            .strategies
            .iter()
            .map(|s| Ok((s.name.clone(), s.on(base)?)))
            .collect::<Result<_, String>>()?;
        let (kept, omitted) = leave_out(&listed, &SceneTraits::of(&scene));
        warned_checks.extend(warned);
        cases.push(CaseRun {
            emitters: scene.emitters.len(),
            closed_form: computed,
            kept,
            omitted,
            context: context(exp, c, &base)?,
            case: c.clone(),
        });
        scenes.push(scene);
    }
    Ok((cases, scenes, warned_checks))
}

/// The (case, strategy, seed) streams still to draw, and how many streams there are: a
/// stream is done when every sweep spp has its row.
fn pending_streams(
    cases: &[CaseRun],
    results: &Results,
    x: &Experiment,
) -> (Vec<(usize, usize, u64)>, usize) {
    let mut jobs = Vec::new();
    let mut streams = 0;
    for (ci, c) in cases.iter().enumerate() {
        for (si, (_, s)) in c.kept.iter().enumerate() {
            for seed in 0..x.seeds as u64 {
                streams += 1;
                let label = s.label();
                let have = results
                    .rows
                    .iter()
                    .filter(|r| r.case == c.case.name && r.strategy == label && r.seed == seed)
                    .count();
                if have < x.spp.len() {
                    jobs.push((ci, si, seed));
                }
            }
        }
    }
    (jobs, streams)
}

/// The `[[invalid]]` entries: each scene must fail, or warn, with the given text.
fn invalid_checks(exp: &Resolved) -> Vec<Check> {
    let x = &exp.exp;
    let mut checks = Vec::new();
    for v in &x.invalid {
        let scene = exp.path(&v.scene);
        let defines = crate::experiment::cases::merge_defines(&[&v.defines]);
        let (expect, text) = match (&v.error, &v.warning) {
            (Some(e), _) => ("error", e),
            (None, Some(w)) => ("warning", w),
            (None, None) => unreachable!("validated: one of error and warning"),
        };
        let shown = v.scene.display().to_string();
        checks.push(check(shown, expect, text, try_scene(&scene, &defines)));
    }
    checks
}

/// The rows of `csv` still valid for these cases: rows of other cases, scenes, references,
/// settings or batch sizes no longer swept are dropped (and counted), since the sweep is
/// exactly `spp`.
fn load_results(
    exp: &Resolved,
    cases: &[CaseRun],
    csv: &std::path::Path,
) -> Result<Results, String> {
    let contexts: BTreeMap<&str, &str> = cases
        .iter()
        .map(|c| (c.case.name.as_str(), c.context.as_str()))
        .collect();
    let results = Results::load_where(csv, |r| {
        contexts.get(r.case.as_str()) == Some(&r.context.as_str()) && exp.exp.spp.contains(&r.spp)
    })?;
    if results.dropped > 0 {
        eprintln!(
            "{}: {} rows of results.csv belong to other cases, scenes, references or settings and are dropped",
            exp.name, results.dropped
        );
    }
    Ok(results)
}

pub fn run_probe(exp: Resolved, opts: &RunOptions) -> Result<ProbeOutcome, String> {
    let start = Instant::now();
    let dir = opts.out.join(&exp.name);
    let x = &exp.exp;
    let p = x.probe.clone().expect("probe mode");
    let (cases, scenes, warned_checks) = open_cases(&exp, &p)?;

    let csv = dir.join("results.csv");
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let results = load_results(&exp, &cases, &csv)?;
    let dropped = results.dropped;

    let (jobs, streams) = pending_streams(&cases, &results, x);
    let order: BTreeMap<(String, String), (usize, usize)> = cases
        .iter()
        .enumerate()
        .flat_map(|(ci, c)| {
            c.kept
                .iter()
                .enumerate()
                .map(move |(si, (_, s))| ((c.case.name.clone(), s.label()), (ci, si)))
        })
        .collect();
    eprintln!(
        "{}: {} cases, {streams} streams of {} samples, {} to draw",
        exp.name,
        cases.len(),
        p.samples,
        jobs.len()
    );
    let shared = Mutex::new(results);
    let done = Mutex::new(0usize);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads.unwrap_or(0))
        .build()
        .map_err(|e| e.to_string())?;
    let eps = x.metrics.relmse_epsilon;
    pool.install(|| {
        jobs.par_iter()
            .map_init(Vec::new, |buf, &(ci, si, seed)| {
                let c = &cases[ci];
                let (name, s) = &c.kept[si];
                let t = Instant::now();
                let d = pixel_samples(
                    &Direct::new(&scenes[ci], *s),
                    p.pixel[0],
                    p.pixel[1],
                    seed,
                    p.samples,
                    buf,
                );
                let seconds = t.elapsed().as_secs_f64();
                let st = stream(buf, d.non_finite, c.reference());
                let info = StreamInfo {
                    case: &c.case.name,
                    context: &c.context,
                    name,
                    label: s.label(),
                    seed,
                    reference: c.reference(),
                    eps,
                    seconds,
                };
                let new = rows(&info, buf, &d, &st, &x.spp);
                let mut res = shared.lock().expect("no panics while held");
                res.rows.retain(|r| {
                    !(r.case == c.case.name && r.strategy == info.label && r.seed == seed)
                });
                res.rows.extend(new);
                // Sorted, so the file does not depend on which thread finished first.
                let key = |r: &Row| {
                    let (ci, si) = order
                        .get(&(r.case.clone(), r.strategy.clone()))
                        .copied()
                        .unwrap_or((usize::MAX, usize::MAX));
                    (ci, si, r.seed, r.spp)
                };
                res.rows.sort_by_key(key);
                res.save(&csv)?;
                let mut n = done.lock().expect("no panics while held");
                *n += 1;
                eprintln!(
                    "{}: [{}/{}] {} {} seed {seed}: z {:.2}, {} non-finite, {:.2} s",
                    exp.name,
                    *n,
                    jobs.len(),
                    c.case.name,
                    info.label,
                    st.z,
                    st.non_finite,
                    seconds
                );
                Ok(())
            })
            .collect::<Result<Vec<()>, String>>()
    })?;
    let results = shared.into_inner().expect("no panics while held");

    let accumulation = run_accumulation(&exp, &cases, &dir, opts)?;
    let mut checks = invalid_checks(&exp);
    checks.extend(warned_checks);
    Ok(ProbeOutcome {
        exp: exp.clone(),
        dir,
        rows: results.rows,
        streams,
        drawn: jobs.len(),
        dropped_rows: dropped,
        cases,
        accumulation,
        checks,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// The `[accumulation]` renders, reusing those `accumulation.csv` already has.
fn run_accumulation(
    exp: &Resolved,
    cases: &[CaseRun],
    dir: &std::path::Path,
    opts: &RunOptions,
) -> Result<Vec<Accumulation>, String> {
    let Some(a) = &exp.exp.accumulation else {
        return Ok(Vec::new());
    };
    let c = cases
        .iter()
        .find(|c| c.case.name == a.case)
        .expect("validated: the case exists");
    let own: BTreeMap<String, String> = c.case.defines.iter().cloned().collect();
    let defines = crate::experiment::cases::merge_defines(&[&own, &a.defines]);
    let scene = crate::scene::open_with(&c.case.scene, &defines, c.case.integrator)?;
    let base = Strategy::from_desc(&scene.desc.integrator);
    let mut h = Fnv::new();
    h.field(c.context.as_bytes());
    for (k, v) in &defines {
        h.field(k.as_bytes()).field(v.as_bytes());
    }
    h.field(&a.spp.to_le_bytes()).field(&a.seed.to_le_bytes());
    let ctx = h.hex();
    let path = dir.join("accumulation.csv");
    let old = accumulate::load(&path, &ctx);
    let mut out = Vec::new();
    for name in &a.strategies {
        let spec = exp
            .exp
            .strategies
            .iter()
            .find(|s| &s.name == name)
            .expect("validated: the strategy exists");
        let s = spec.on(base)?;
        if let Some(r) = old.iter().find(|r| r.strategy == s.label()) {
            out.push(r.clone());
            continue;
        }
        let t = Instant::now();
        let mut r = accumulate::measure(&scene, s, a.spp, a.seed, c.reference(), opts.threads);
        r.context = ctx.clone();
        r.case = c.case.name.clone();
        eprintln!(
            "{}: accumulation {} {} at {} spp: z {:.2}, f64 error {:.1e} ({:.1} s)",
            exp.name,
            r.case,
            r.strategy,
            a.spp,
            r.z,
            r.f64_rel_error,
            t.elapsed().as_secs_f64()
        );
        out.push(r);
        accumulate::save(&path, &out)?;
    }
    accumulate::save(&path, &out)?;
    Ok(out)
}
