//! What a sweep still has to render (resuming from `results.csv`), and where the images the
//! figures need are kept.

use super::method::Method;
use super::results::{Results, Row, SWEEP};
use crate::film::{self, Image};
use std::path::{Path, PathBuf};

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
#[derive(Clone)]
pub(crate) struct Job {
    pub(crate) name: String,
    pub(crate) method: Method,
    pub(crate) kind: &'static str,
    pub(crate) budget: f64,
    pub(crate) spp: u32,
    pub(crate) seed: u64,
    /// Where to keep the image for the figures, if it is needed.
    pub(crate) image: Option<PathBuf>,
}

/// Two rows are the same run (one replaces the other) if their resume keys agree.
pub(crate) fn same_run(a: &Row, b: &Row) -> bool {
    a.kind == b.kind
        && a.case == b.case
        && a.strategy == b.strategy
        && a.seed == b.seed
        && if a.is_sweep() {
            a.spp == b.spp
        } else {
            a.budget_s == b.budget_s
        }
}

pub(crate) fn has_image(p: &Option<PathBuf>) -> bool {
    p.as_ref()
        .is_none_or(|p| p.exists() && variance_path(p).exists())
}

/// What the sweep covers, which seed-0 images the figures need and at which spp every
/// seed's image is kept.
pub(crate) struct Sweep<'a> {
    pub(crate) spp: &'a [u32],
    pub(crate) seeds: u32,
    pub(crate) keep_spp: &'a [u32],
    pub(crate) every_seed: Option<u32>,
    pub(crate) dir: &'a Path,
}

/// The sweep's renders still to do: rows missing from `results`, and rows whose image the
/// figures need but which is missing (seeds give the same image again, so the row is redone).
pub(crate) fn plan_sweep(results: &Results, kept: &[(String, Method)], sw: &Sweep) -> Vec<Job> {
    let mut jobs = Vec::new();
    for seed in 0..sw.seeds as u64 {
        for &spp in sw.spp {
            for (name, s) in kept {
                let image = ((seed == 0 && sw.keep_spp.contains(&spp))
                    || sw.every_seed == Some(spp))
                .then(|| image_path(sw.dir, &s.label(), &spp_tag(spp), seed));
                let done = results.find_sweep(&s.label(), spp, seed).is_some();
                if !done || !has_image(&image) {
                    jobs.push(Job {
                        name: name.clone(),
                        method: *s,
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

/// Loads a kept image and its variance (the new versions while a merge writes its outputs as
/// one set).
pub fn load_image(p: &Path) -> Result<(Image, Image), String> {
    let read = |p: &Path| {
        film::read_exr(&crate::output::pending(p)).map_err(|e| {
            let shown = crate::output::pending(p);
            e.replace(&shown.display().to_string(), &p.display().to_string())
        })
    };
    Ok((read(p)?, read(&variance_path(p))?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::results::test_row;
    use crate::integrator::Strategy;
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
        let s = Method {
            strategy: s,
            sampler: Default::default(),
        };
        let label = s.label();
        let kept = vec![("light".to_string(), s)];
        let sw = Sweep {
            spp: &[1, 4],
            seeds: 2,
            keep_spp: &[4],
            every_seed: None,
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
