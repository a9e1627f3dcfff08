//! Nori's `ttest`: scenes against reference values, per strategy, and BSDF albedos at
//! incidence angles; one-sample Student t-tests at the file's Sidak-corrected level.

use super::parse::{Item, TestFile};
use super::TestArgs;
use crate::bsdf::Material;
use crate::emitter::EmitterSelection;
use crate::integrator::{Direct, Strategy};
use crate::math::luminance;
use crate::rng::Rng;
use crate::scene::desc::{FilterDesc, Heuristic, SceneDesc, StrategyKind};
use crate::scene::Scene;
use crate::stats::{one_sample_welford, sidak, Welford};
use glam::Vec3;
use rayon::prelude::*;

/// Nori's default sample count of a t-test.
pub const DEFAULT_SAMPLES: u64 = 100_000;

/// One t-test: what was tested and its outcome.
pub struct Row {
    pub what: String,
    pub with: String,
    pub reference: f64,
    pub mean: f64,
    pub std_error: f64,
    pub p_value: f64,
    pub passed: bool,
}

/// Every directlab strategy: one of each estimator for each emitter choice and light
/// sampling mode (`Strategy::combinations`), and MIS with the many-light choices.
pub fn every_strategy() -> Vec<Strategy> {
    let mut v = Strategy::combinations();
    let mis = Strategy {
        kind: StrategyKind::Mis,
        heuristic: Heuristic::Power,
        ..v[0]
    };
    for selection in [
        EmitterSelection::Exhaustive,
        EmitterSelection::Bvh,
        EmitterSelection::Ris(8),
    ] {
        v.push(Strategy { selection, ..mis });
    }
    v
}

/// The mean luminance of `samples` camera samples of the scene's film (Nori's test scenes
/// are one pixel; a larger film is averaged over its pixels), each pixel sampled uniformly
/// (a box filter: Nori's t-test averages over the pixel without its reconstruction filter).
fn scene_mean(scene: &Scene, strategy: Strategy, samples: u64, seed: u64) -> Welford {
    let direct = Direct::new(scene, strategy);
    let (w, h) = (scene.camera.width, scene.camera.height);
    let mut rng = Rng::new(seed, 1);
    let mut acc = Welford::new();
    for _ in 0..samples {
        let px = ((rng.next_f32() * w as f32) as u32).min(w - 1);
        let py = ((rng.next_f32() * h as f32) as u32).min(h - 1);
        let ray = scene.camera.generate_ray(px, py, &mut rng);
        acc.push(luminance(direct.li(&ray, &mut rng)) as f64);
    }
    acc
}

/// The albedo at incidence `degrees` (wi in the x-z plane, as Nori's sphericalDirection(theta,
/// 0)) by BSDF sampling: the mean luminance of the sample weights.
fn albedo(m: &Material, degrees: f64, samples: u64, seed: u64) -> Welford {
    let t = degrees.to_radians();
    let wi = Vec3::new(t.sin() as f32, 0.0, t.cos() as f32);
    let mut rng = Rng::new(seed, 2);
    let mut acc = Welford::new();
    for _ in 0..samples {
        let v = m
            .sample(wi, rng.next_f32(), rng.next_2d())
            .map_or(0.0, |s| luminance(s.weight) as f64);
        acc.push(v);
    }
    acc
}

/// A t-test row. An estimator without variance (a diffuse BSDF's cosine-sampled weight is
/// its albedo exactly) has no t statistic: it passes when it equals the reference to f32
/// rounding (1e-6 relative), as an f32 renderer cannot do better.
fn row(what: String, with: String, reference: f64, w: &Welford, level: f64) -> Row {
    let mut t = one_sample_welford(w, reference);
    if w.variance() == 0.0 {
        let close = (w.mean() - reference).abs() <= 1e-6 * reference.abs().max(1e-30);
        t.p_value = if close { 1.0 } else { 0.0 };
    }
    Row {
        what,
        with,
        reference,
        mean: w.mean(),
        std_error: w.std_error(),
        p_value: t.p_value,
        passed: t.passes(level),
    }
}

/// The scene with a box filter, built.
fn build(desc: &SceneDesc, label: &str) -> Result<Scene, String> {
    let mut d = desc.clone();
    d.film.filter = FilterDesc::Box;
    Scene::build(d).map_err(|e| format!("{label}: {e}"))
}

/// Runs a ttest file; prints its table; Ok(true) when every test passed.
pub fn run_file(f: &TestFile, a: &TestArgs) -> Result<bool, String> {
    let samples = a.samples.or(f.samples).unwrap_or(DEFAULT_SAMPLES);
    // (label, reference, job) for every test, before the level is known.
    type Job<'f> = (
        String,
        String,
        f64,
        Box<dyn Fn(u64) -> Result<Welford, String> + Sync + 'f>,
    );
    let mut jobs: Vec<Job> = Vec::new();
    for (k, s) in f.scenes.iter().enumerate() {
        let reference = f.references[k];
        for strategy in strategies(s, a.all_strategies) {
            let item = s;
            jobs.push((
                s.label.clone(),
                strategy.label(),
                reference,
                Box::new(move |seed| {
                    let scene = build(&item.value, &item.label)?;
                    Ok(scene_mean(&scene, strategy, samples, seed))
                }),
            ));
        }
    }
    let per_angle = f.references.len() == f.angles.len();
    for (k, b) in f.bsdfs.iter().enumerate() {
        for (i, &angle) in f.angles.iter().enumerate() {
            let reference = match per_angle {
                true => f.references[i],
                false => f.references[k * f.angles.len() + i],
            };
            let m = &b.value;
            jobs.push((
                b.label.clone(),
                format!("{angle} deg"),
                reference,
                Box::new(move |seed| Ok(albedo(m, angle, samples, seed))),
            ));
        }
    }
    let level = sidak(f.alpha, jobs.len());
    eprintln!(
        "{}: {} t-tests, {samples} samples each; alpha {} Sidak-corrected to {level:.3e} per test",
        f.path.display(),
        jobs.len(),
        f.alpha as f32
    );
    let rows: Vec<Row> = jobs
        .par_iter()
        .enumerate()
        .map(|(i, (what, with, reference, job))| {
            let seed = crate::rng::mix64(a.seed ^ crate::rng::mix64(i as u64));
            job(seed).map(|w| row(what.clone(), with.clone(), *reference, &w, level))
        })
        .collect::<Result<_, _>>()?;
    print!("{}", table(&rows, level));
    Ok(rows.iter().all(|r| r.passed))
}

/// The strategy the scene names, or every strategy for a path tracer's direct part (or when
/// asked).
fn strategies(s: &Item<SceneDesc>, all: bool) -> Vec<Strategy> {
    if all || s.value.integrator.direct_part_of.is_some() {
        every_strategy()
    } else {
        vec![Strategy::from_desc(&s.value.integrator)]
    }
}

/// The printed table of a file's t-tests.
pub fn table(rows: &[Row], level: f64) -> String {
    let w0 = rows.iter().map(|r| r.what.len()).max().unwrap_or(4).max(4);
    let w1 = rows.iter().map(|r| r.with.len()).max().unwrap_or(4).max(4);
    let mut s = format!(
        "{:<w0$}  {:<w1$}  {:>12}  {:>12}  {:>10}  {:>10}  {:>7}\n",
        "test", "with", "reference", "mean", "std error", "p-value", "verdict"
    );
    for r in rows {
        s += &format!(
            "{:<w0$}  {:<w1$}  {:>12.6}  {:>12.6}  {:>10.3e}  {:>10.3e}  {:>7}\n",
            r.what,
            r.with,
            r.reference,
            r.mean,
            r.std_error,
            r.p_value,
            if r.passed { "pass" } else { "FAIL" }
        );
    }
    let failed = rows.iter().filter(|r| !r.passed).count();
    s += &format!(
        "{} of {} t-tests passed (each at level {level:.3e})\n",
        rows.len() - failed,
        rows.len()
    );
    s
}
