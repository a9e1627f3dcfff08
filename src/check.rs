//! Checking your own samplers: the chi-square, t-test and furnace helpers that directlab's
//! own tests use, behind a small interface you implement.
//!
//! Implement [`DirectionSampler`] (directions on the unit sphere, densities in solid angle)
//! or [`SquareSampler`] (points of the unit square), then call [`chi2_directions`] or
//! [`chi2_square`]: a Pearson chi-square of the sampled histogram against the pdf's integral
//! over each cell (cells on the support's edge refined), plus the check that the pdf
//! integrates to the probability that sampling succeeds. [`Outcome::write_heatmap`] draws
//! observed, expected and residual counts side by side: the picture of a failure.
//! [`ttest_mean`] compares an estimator's mean with a reference (for instance a BSDF's
//! albedo, [`albedo`]).
//!
//! ```
//! use directlab::check::{chi2_directions, DirectionSampler, Options};
//! use glam::{Vec2, Vec3};
//!
//! /// Cosine-weighted hemisphere, written by hand.
//! struct Cosine;
//! impl DirectionSampler for Cosine {
//!     fn sample(&self, u: Vec2) -> Option<Vec3> {
//!         let (r, phi) = (u.x.sqrt(), std::f32::consts::TAU * u.y);
//!         Some(Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u.x).max(0.0).sqrt()))
//!     }
//!     fn pdf(&self, d: Vec3) -> f64 {
//!         (d.z.max(0.0) / std::f32::consts::PI) as f64
//!     }
//! }
//! let outcome = chi2_directions(&Cosine, &Options { samples: 100_000, ..Options::default() });
//! assert!(outcome.passed(), "{}", outcome.summary());
//! ```

#![warn(missing_docs)]

use crate::chi2cases::{run_continuous, CaseConfig};
use crate::rng::Rng;
use crate::stats::{Sphere, TTest, UnitSquare, Welford};
use glam::{Vec2, Vec3};
use std::path::Path;

pub use crate::chi2cases::Outcome;

/// A sampler of directions (unit vectors) with its solid-angle density.
pub trait DirectionSampler {
    /// A direction from two uniform numbers in [0, 1), or None where sampling fails (that
    /// probability must be missing from [`DirectionSampler::pdf`]'s integral).
    fn sample(&self, u: Vec2) -> Option<Vec3>;
    /// The density of direction `d` per unit solid angle.
    fn pdf(&self, d: Vec3) -> f64;
}

/// A sampler of points of the unit square [0, 1)^2 with its density per unit area.
pub trait SquareSampler {
    /// A point from two uniform numbers in [0, 1), or None where sampling fails.
    fn sample(&self, u: Vec2) -> Option<Vec2>;
    /// The density of point `p` per unit area.
    fn pdf(&self, p: Vec2) -> f64;
}

/// Size and significance of a check.
#[derive(Clone, Copy, Debug)]
pub struct Options {
    /// Samples drawn.
    pub samples: u64,
    /// Cells along the domain's v axis (the sphere gets 2R - 1 rows of cos(theta) and R
    /// columns of phi; the square R x R).
    pub resolution: usize,
    /// Seed of the uniform numbers.
    pub seed: u64,
    /// Significance level of the check as a whole (chi-square and integral together).
    pub alpha: f64,
}

impl Default for Options {
    /// One million samples, resolution 51, seed 0, alpha 0.01 (Nori's and Mitsuba's level).
    fn default() -> Self {
        Options {
            samples: 1_000_000,
            resolution: 51,
            seed: 0,
            alpha: 0.01,
        }
    }
}

impl Options {
    fn config(&self) -> CaseConfig {
        CaseConfig {
            samples: self.samples,
            resolution: self.resolution.max(3),
            seed: self.seed,
            alpha: self.alpha,
            ..CaseConfig::default()
        }
    }
}

/// Chi-square of a direction sampler against its pdf on the whole sphere.
pub fn chi2_directions(s: &impl DirectionSampler, o: &Options) -> Outcome {
    let cfg = o.config();
    let domain: Sphere = cfg.sphere();
    let sample = |r: &mut Rng| s.sample(r.next_2d());
    run_continuous("directions", &domain, sample, |d| s.pdf(d), &cfg, vec![])
}

/// Chi-square of a unit-square sampler against its pdf.
///
/// ```
/// use directlab::check::{chi2_square, Options, SquareSampler};
/// use glam::Vec2;
///
/// /// x with density 2x by inversion (x = sqrt(u)); `claimed` is the pdf it reports.
/// struct Linear { claimed: fn(Vec2) -> f64 }
/// impl SquareSampler for Linear {
///     fn sample(&self, u: Vec2) -> Option<Vec2> { Some(Vec2::new(u.x.sqrt(), u.y)) }
///     fn pdf(&self, p: Vec2) -> f64 { (self.claimed)(p) }
/// }
/// let o = Options { samples: 50_000, resolution: 11, ..Options::default() };
/// assert!(chi2_square(&Linear { claimed: |p| 2.0 * p.x as f64 }, &o).passed());
/// // A uniform pdf claimed for the same samples is rejected.
/// assert!(!chi2_square(&Linear { claimed: |_| 1.0 }, &o).passed());
/// ```
pub fn chi2_square(s: &impl SquareSampler, o: &Options) -> Outcome {
    let cfg = o.config();
    let domain: UnitSquare = cfg.square();
    let sample = |r: &mut Rng| s.sample(r.next_2d());
    run_continuous("square", &domain, sample, |p| s.pdf(p), &cfg, vec![])
}

impl Outcome {
    /// Writes the heat map of the histogram (observed | expected | residual) as PNG.
    pub fn write_heatmap(&self, path: &Path) -> Result<(), String> {
        let (c, r) = (self.chi2.observed.cols, self.chi2.observed.rows);
        let cell_px = (360 / c.max(r).max(1)).clamp(2, 24) as u32;
        crate::stats::heatmap::write(path, &self.chi2, cell_px)
    }
}

/// One-sample Student t-test of the mean of `n` values of `estimate` (each given its own
/// uniform-number generator) against `reference`; pass it when `p_value >= alpha`.
pub fn ttest_mean(
    n: u64,
    seed: u64,
    reference: f64,
    mut estimate: impl FnMut(&mut Rng) -> f64,
) -> TTest {
    let mut rng = Rng::new(seed, 3);
    let mut w = Welford::new();
    for _ in 0..n {
        w.push(estimate(&mut rng));
    }
    crate::stats::one_sample_welford(&w, reference)
}

/// A BSDF sampler for the albedo (furnace) check: the weight f cos / pdf of one sample for
/// incident direction `wi`, or 0 where sampling fails.
pub trait WeightSampler {
    /// The sample weight's luminance for incidence `wi` and uniform numbers `u`.
    fn weight(&self, wi: Vec3, u: Vec2) -> f64;
}

/// The albedo at `wi` by sampling: the t-test of the mean weight against `reference` (a
/// lossless BSDF's is 1: the white furnace).
///
/// ```
/// use directlab::check::{albedo, WeightSampler};
/// use glam::{Vec2, Vec3};
///
/// /// Lambert of reflectance 0.7 sampled uniformly over the hemisphere: weight
/// /// (0.7 / pi) cos / (1 / 2 pi) = 1.4 cos, with cos = u.x uniform.
/// struct Uniform;
/// impl WeightSampler for Uniform {
///     fn weight(&self, _wi: Vec3, u: Vec2) -> f64 { 1.4 * u.x as f64 }
/// }
/// let t = albedo(&Uniform, Vec3::Z, 100_000, 1, 0.7);
/// assert!(t.passes(0.01), "p = {}", t.p_value);
/// assert!(!albedo(&Uniform, Vec3::Z, 100_000, 1, 0.75).passes(0.01));
/// ```
pub fn albedo(s: &impl WeightSampler, wi: Vec3, n: u64, seed: u64, reference: f64) -> TTest {
    ttest_mean(n, seed, reference, |r| s.weight(wi, r.next_2d()))
}
