//! The 2D test integrands of Christensen, Kensler and Kilpatrick 2018 ("Progressive
//! Multi-Jittered Sample Sequences", section 6), integrated by each sampler's first 2D pair
//! (the film pair of one pixel) over many independent randomisations: the RMSE against N
//! and its slope, to compare with the rates the paper publishes.
//!
//! A seed is one randomisation of the sampler; every sample count N is a run of its own
//! (`run_samples = N`), as a render of N samples per pixel is, so the stratified sampler's
//! strata and zsobol's blocks are laid out for N.

pub mod pixel;
pub mod report;

use crate::sampler::{
    DimAlloc, LanesVisitor, PointKind, SamplerConfig, SamplerKind, SamplerLanes, Sampling,
};
use crate::stats::slope::{bootstrap_slope, fit_slope, SeedErrors, BOOTSTRAP_DRAWS};
use rayon::prelude::*;
use std::f64::consts::PI;

/// The five integrands over [0, 1)^2.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Integrand {
    /// 1 inside the quarter disk x^2 + y^2 < 2 / pi (area 1/2): a curved edge.
    QuarterDisk,
    /// 1 below the diagonal, y < x (area 1/2): a straight edge at 45 degrees.
    Triangle,
    /// 1 where x < 1 / pi: an edge aligned with an axis, at an irrational position so that
    /// no stratum boundary falls on it.
    Step,
    /// exp(-x^2 - y^2): smooth.
    Gaussian,
    /// x y: smooth.
    Bilinear,
}

impl Integrand {
    pub const ALL: [Integrand; 5] = [
        Integrand::QuarterDisk,
        Integrand::Triangle,
        Integrand::Step,
        Integrand::Gaussian,
        Integrand::Bilinear,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Integrand::QuarterDisk => "quarter disk",
            Integrand::Triangle => "triangle",
            Integrand::Step => "step",
            Integrand::Gaussian => "Gaussian",
            Integrand::Bilinear => "bilinear",
        }
    }

    /// The formula, for the report.
    pub fn formula(self) -> &'static str {
        match self {
            Integrand::QuarterDisk => "1 if x² + y² < 2/π",
            Integrand::Triangle => "1 if y < x",
            Integrand::Step => "1 if x < 1/π",
            Integrand::Gaussian => "exp(−x² − y²)",
            Integrand::Bilinear => "x y",
        }
    }

    #[inline]
    pub fn eval(self, x: f64, y: f64) -> f64 {
        let ind = |b: bool| if b { 1.0 } else { 0.0 };
        match self {
            Integrand::QuarterDisk => ind(x * x + y * y < 2.0 / PI),
            Integrand::Triangle => ind(y < x),
            Integrand::Step => ind(x < 1.0 / PI),
            Integrand::Gaussian => (-x * x - y * y).exp(),
            Integrand::Bilinear => x * y,
        }
    }

    /// The exact integral over the unit square.
    pub fn exact(self) -> f64 {
        match self {
            Integrand::QuarterDisk | Integrand::Triangle => 0.5,
            Integrand::Step => 1.0 / PI,
            // (integral of exp(-x^2) over [0, 1])^2, the integral by its Taylor series
            // sum (-1)^n / (n! (2n + 1)), whose terms fall below 1e-17 by n = 18 (statrs's
            // erf(1) is off by 1e-11: harmless here, but an exact constant needs no caveat).
            Integrand::Gaussian => {
                let (mut term, mut sum) = (1.0f64, 0.0);
                for n in 0..20 {
                    if n > 0 {
                        term *= -1.0 / n as f64;
                    }
                    sum += term / (2 * n + 1) as f64;
                }
                sum * sum
            }
            Integrand::Bilinear => 0.25,
        }
    }

    pub fn smooth(self) -> bool {
        matches!(self, Integrand::Gaussian | Integrand::Bilinear)
    }

    /// The RMSE slope the paper reports for a sampler of this kind at its complete sample
    /// counts (powers of two; of four for jittered), as summarised in REFERENCE.md section
    /// 9. None where the paper has no such sampler (a digital shift alone).
    pub fn published(self, kind: SamplerKind) -> Option<f64> {
        match kind.points() {
            PointKind::Random => Some(-0.5),
            PointKind::Jittered => Some(if self.smooth() { -1.0 } else { -0.75 }),
            PointKind::ScrambledNet => Some(match self {
                Integrand::QuarterDisk | Integrand::Triangle => -0.75,
                Integrand::Step => -1.0,
                Integrand::Gaussian | Integrand::Bilinear => -1.5,
            }),
            PointKind::ShiftedNet => None,
        }
    }
}

/// Whether `n` is a count where the sampler's structure is complete: a power of four for
/// jittered strata (a square grid), a power of two for the others.
pub fn complete_count(kind: SamplerKind, n: u32) -> bool {
    n.is_power_of_two()
        && (kind.points() != PointKind::Jittered || n.trailing_zeros().is_multiple_of(2))
}

/// Powers of two from 16 to `max_n`, and off-grid counts between them: 2^(k + 1/2)
/// rounded (23, 45, 91, ...), whose many set bits leave every net incomplete (1.5 x 2^k
/// would be two whole nets).
pub fn sample_counts(max_n: u32) -> Vec<u32> {
    let mut v: Vec<u32> = (4..31)
        .flat_map(|k| [1u32 << k, (2f64.powf(k as f64 + 0.5)).round() as u32])
        .filter(|&n| n <= max_n)
        .collect();
    v.sort();
    v
}

/// The first 2D pair of samples `0 .. n` of the pixel a config describes.
struct FilmPairs<'a> {
    cfg: &'a SamplerConfig,
    n: u32,
    out: &'a mut Vec<[f64; 2]>,
}

impl LanesVisitor for FilmPairs<'_> {
    type Output = ();
    fn visit<L: SamplerLanes>(self) {
        let px = L::pixel(self.cfg, 0, 0);
        self.out.clear();
        for s0 in (0..self.n as u64).step_by(crate::rng::LANES) {
            let [x, y] = L::start(px, s0).film();
            let take = (self.n as u64 - s0).min(crate::rng::LANES as u64) as usize;
            self.out
                .extend((0..take).map(|l| [x[l] as f64, y[l] as f64]));
        }
    }
}

/// Squared errors of one (sampler, N), one per seed, for every integrand.
#[derive(Clone, Debug)]
pub struct Cell {
    pub sampler: SamplerKind,
    pub n: u32,
    /// `[integrand][seed]`, integrands in the order of [`Integrand::ALL`].
    pub sq_errors: Vec<Vec<f64>>,
}

impl Cell {
    pub fn rmse(&self, i: usize) -> f64 {
        let e = &self.sq_errors[i];
        (e.iter().sum::<f64>() / e.len() as f64).sqrt()
    }
}

/// Every sampler at every count over `seeds` randomisations (seed 0 ..), in parallel over
/// (sampler, count); deterministic.
pub fn measure(samplers: &[SamplerKind], counts: &[u32], seeds: u64) -> Result<Vec<Cell>, String> {
    let jobs: Vec<(SamplerKind, u32)> = samplers
        .iter()
        .flat_map(|&k| counts.iter().map(move |&n| (k, n)))
        .collect();
    jobs.par_iter()
        .map(|&(kind, n)| {
            let sampling = Sampling {
                kind,
                dims: DimAlloc::Joint,
                run_samples: None,
            };
            let mut sq = vec![Vec::with_capacity(seeds as usize); Integrand::ALL.len()];
            let mut pts = Vec::with_capacity(n as usize);
            for seed in 0..seeds {
                let cfg = sampling.config(seed, 0, n, (1, 1))?;
                kind.visit(FilmPairs {
                    cfg: &cfg,
                    n,
                    out: &mut pts,
                });
                for (i, f) in Integrand::ALL.iter().enumerate() {
                    let mean = pts.iter().map(|p| f.eval(p[0], p[1])).sum::<f64>() / n as f64;
                    sq[i].push((mean - f.exact()).powi(2));
                }
            }
            Ok(Cell {
                sampler: kind,
                n,
                sq_errors: sq,
            })
        })
        .collect()
}

/// An RMSE slope: the fit to the RMSE over seeds and its 95 % bootstrap interval over seeds.
#[derive(Clone, Copy, Debug)]
pub struct Slope {
    pub slope: f64,
    pub ci: Option<(f64, f64)>,
}

/// The RMSE slope of integrand `i` over the cells of one sampler at the counts `keep`
/// accepts: half the slope of the mean squared error (so that the bootstrap resamples the
/// seeds' squared errors, as the experiments' slopes do).
pub fn slope(cells: &[&Cell], i: usize, keep: impl Fn(u32) -> bool) -> Option<Slope> {
    let pts: Vec<&&Cell> = cells.iter().filter(|c| keep(c.n)).collect();
    let xy: Vec<(f64, f64)> = pts
        .iter()
        .map(|c| ((c.n as f64).ln(), c.rmse(i).ln()))
        .collect();
    let slope = fit_slope(&xy)?;
    let seeds: Vec<SeedErrors> = pts
        .iter()
        .map(|c| SeedErrors {
            spp: c.n,
            errors: c.sq_errors[i].clone(),
        })
        .collect();
    let ci = bootstrap_slope(&seeds, BOOTSTRAP_DRAWS).map(|(a, b)| (a / 2.0, b / 2.0));
    Some(Slope { slope, ci })
}

#[cfg(test)]
mod tests;
