//! The registry of sampling routines proven against their pdfs: every warp, BSDF and emitter
//! sampler of the renderer, each as a named case that `directlab chi2` and the tests run.
//!
//! A case draws N samples, bins them on a domain and compares the histogram with the pdf's
//! integral over each cell (Pearson chi-square, [`crate::stats::chi2`]). Beside that, every
//! continuous case checks that the pdf integrates to the probability that the sampler
//! succeeds ([`checks::integral`]), BSDF cases check each sample's weight against eval/pdf,
//! and discrete cases compare frequencies with the pmf.
//!
//! Names are `group/what-how-where` (e.g. `emitter/quad-area-grazing`); a FILTER selects
//! cases by substring. Groups live in their own modules: [`warps`], [`emitters`],
//! [`discrete`], [`bsdfs`]. To add a case, push it in the group's `cases()`.

pub mod bsdfs;
pub mod checks;
pub mod command;
pub mod discrete;
pub mod emitters;
pub mod exact;
pub mod lobe;
pub mod probe;
pub mod protocol;
pub mod scene;
pub mod tangent;
pub mod warps;

#[cfg(test)]
mod gallery;
#[cfg(test)]
mod tests;

use crate::rng::{mix64, Rng};
use crate::stats::chi2::chi2_test_given;
use crate::stats::{
    chi2_test, Chi2Config, Chi2Result, Domain, Grid, Integration, Sphere, UnitSquare, Verdict,
};

/// Knobs shared by every case of one run.
#[derive(Clone, Copy, Debug)]
pub struct CaseConfig {
    pub samples: u64,
    /// Cells along a domain's v axis: the sphere gets `2R - 1` (odd) rows of cos theta and R
    /// columns of phi, planar domains R x R, tangent-plane windows R along their long side.
    pub resolution: usize,
    pub seed: u64,
    /// Significance level of the case as a whole (already Sidak-corrected over the cases of
    /// the run); a case running k tests gives each `sidak(alpha, k)`.
    pub alpha: f64,
    /// How expected counts are integrated (see [`Integration`]). The default re-integrates
    /// cells on the support's boundary from 8x8 rectangles: without it the thin tip of a
    /// light seen at grazing angles gets too small an expected count and a correct sampler
    /// is rejected (p ~ 1e-40 on `emitter/mesh-area-grazing`).
    pub integration: Integration,
    /// Cells expected to receive fewer samples than this are pooled (Nori's
    /// `minExpFrequency`).
    pub min_expected: f64,
}

impl Default for CaseConfig {
    fn default() -> Self {
        CaseConfig {
            samples: 1_000_000,
            resolution: 51,
            seed: 0,
            alpha: 0.01,
            integration: Integration {
                boundary_split: 8,
                ..Integration::default()
            },
            min_expected: 5.0,
        }
    }
}

impl CaseConfig {
    /// Engine settings for one chi-square test at level `threshold`.
    pub fn chi2(&self, threshold: f64) -> Chi2Config {
        Chi2Config {
            samples: self.samples,
            threshold,
            seed: self.seed,
            integration: self.integration,
            min_expected: self.min_expected,
            ..Chi2Config::default()
        }
    }

    pub fn sphere(&self) -> Sphere {
        let r = self.resolution.max(3);
        Sphere {
            n_phi: r,
            n_cos: 2 * r - 1,
        }
    }

    pub fn square(&self) -> UnitSquare {
        UnitSquare {
            n: self.resolution.max(2),
        }
    }
}

/// A test beside the chi-square one.
#[derive(Clone, Debug)]
pub struct Check {
    pub name: &'static str,
    pub passed: bool,
    pub detail: String,
}

/// Everything a report needs about one case.
#[derive(Clone, Debug)]
pub struct Outcome {
    pub name: String,
    pub chi2: Chi2Result,
    pub checks: Vec<Check>,
}

impl Outcome {
    pub fn passed(&self) -> bool {
        self.chi2.passed() && self.checks.iter().all(|c| c.passed)
    }

    /// The first reason for failing, or the chi-square summary.
    pub fn summary(&self) -> String {
        if !self.chi2.passed() {
            return self.chi2.reason.clone();
        }
        match self.checks.iter().find(|c| !c.passed) {
            Some(c) => format!("{}: {}", c.name, c.detail),
            None => self.chi2.reason.clone(),
        }
    }
}

type RunFn = dyn Fn(&CaseConfig) -> Outcome + Send + Sync;

/// A named sampling routine with everything needed to test it.
pub struct Case {
    pub name: String,
    /// One line saying what is sampled, from where.
    pub about: String,
    /// What an outside program is asked to sample in this case's place (`check-sampler
    /// --case`), when the case has a protocol form.
    pub external: Option<protocol::Target>,
    run: Box<RunFn>,
}

impl Case {
    pub fn new(
        name: impl Into<String>,
        about: impl Into<String>,
        run: impl Fn(&CaseConfig) -> Outcome + Send + Sync + 'static,
    ) -> Case {
        Case {
            name: name.into(),
            about: about.into(),
            external: None,
            run: Box::new(run),
        }
    }

    /// The case with a protocol form (see [`protocol`]).
    pub fn with_external(mut self, target: protocol::Target) -> Case {
        self.external = Some(target);
        self
    }

    /// A sampler of points of `domain(cfg)` against its pdf, plus the integral check.
    pub fn continuous<D, S, P>(
        name: impl Into<String>,
        about: impl Into<String>,
        domain: impl Fn(&CaseConfig) -> D + Send + Sync + 'static,
        sampler: S,
        pdf: P,
    ) -> Case
    where
        D: Domain,
        S: Fn(&mut Rng) -> Option<D::Point> + Send + Sync + 'static,
        P: Fn(D::Point) -> f64 + Send + Sync + 'static,
    {
        let name = name.into();
        let label = name.clone();
        Case::new(name, about, move |cfg| {
            run_continuous(&label, &domain(cfg), &sampler, &pdf, cfg, vec![])
        })
    }

    /// Runs the case on its own random stream, derived from `cfg.seed` and the case's name,
    /// so that the cases of a run are independent (as the Sidak correction assumes).
    pub fn run(&self, cfg: &CaseConfig) -> Outcome {
        (self.run)(&CaseConfig {
            seed: self.seed(cfg.seed),
            ..*cfg
        })
    }

    /// The seed of the case's own random stream in a run of seed `seed`.
    pub fn seed(&self, seed: u64) -> u64 {
        case_seed(&self.name, seed)
    }
}

/// The seed of the stream of the case named `name` in a run of seed `seed`.
pub fn case_seed(name: &str, seed: u64) -> u64 {
    name.bytes().fold(mix64(seed), |h, b| mix64(h ^ b as u64))
}

/// Tests a sampler against a pdf: chi-square and the integral check at `sidak(alpha, 2)`
/// each, plus any `extra` checks already made (which are deterministic).
pub fn run_continuous<D: Domain>(
    name: &str,
    domain: &D,
    sampler: impl Fn(&mut Rng) -> Option<D::Point>,
    pdf: impl Fn(D::Point) -> f64,
    cfg: &CaseConfig,
    extra: Vec<Check>,
) -> Outcome {
    let level = crate::stats::sidak(cfg.alpha, 2);
    let mut chi2 = chi2_test(domain, sampler, pdf, &cfg.chi2(level));
    nothing_to_bin(&mut chi2);
    let mut checks = vec![checks::integral(&chi2, level)];
    checks.extend(extra);
    Outcome {
        name: name.to_string(),
        chi2,
        checks,
    }
}

/// Nothing to bin and nothing claimed (a one-sided BSDF lit from behind, lights that all face
/// away): the sampler agrees with its pdf, and Pearson has no categories to compare.
fn nothing_to_bin(chi2: &mut Chi2Result) {
    if chi2.lost == chi2.samples && chi2.outside == 0 && chi2.pdf_integral == 0.0 {
        chi2.verdict = Verdict::Pass;
        chi2.p_value = 1.0;
        chi2.reason = "sampler never succeeds and the pdf is 0 everywhere".into();
    }
}

/// [`run_continuous`] against cell masses worked out exactly from the density's support.
pub fn run_given<D: Domain>(
    name: &str,
    domain: &D,
    sampler: impl Fn(&mut Rng) -> Option<D::Point>,
    masses: &Grid,
    cfg: &CaseConfig,
) -> Outcome {
    let level = crate::stats::sidak(cfg.alpha, 2);
    let mut chi2 = chi2_test_given(domain, sampler, masses, &cfg.chi2(level));
    nothing_to_bin(&mut chi2);
    Outcome {
        name: name.to_string(),
        checks: vec![checks::integral(&chi2, level)],
        chi2,
    }
}

/// Every case, in report order.
pub fn all_cases() -> Vec<Case> {
    let mut v = warps::cases();
    v.extend(discrete::cases());
    v.extend(bsdfs::cases());
    v.extend(emitters::cases());
    v
}

/// Cases whose name contains `filter` (all when it is empty).
pub fn select(filter: &str) -> Vec<Case> {
    all_cases()
        .into_iter()
        .filter(|c| c.name.contains(filter))
        .collect()
}
