//! `stratified`: jittered strata, padded per draw as in pbrt-v4 and Mitsuba 3. For a run
//! of N samples per pixel, a 1D draw puts sample s in stratum `permute(s)` of N, a 2D draw
//! in cell `permute(s)` of an a x b grid (a = floor(sqrt N), b = ceil(N / a), so a b >= N;
//! exactly N cells when N is a square or a b = N), jittered uniformly inside. Each pixel and
//! dimension has its own random permutation (Kensler's hashed permutation), so the draws of
//! one sample are independent of one another: stratified per draw, never jointly.
//!
//! When a b > N, the N samples occupy a random subset of the cells; every point is still
//! uniform on the square (its cell is uniform over the cells, its place in the cell too), so
//! the estimator stays unbiased at any N.

use super::permute::{below_one, permute, uniform_f64};
use super::pure::{PointSet, PureLanes};
use super::{PointKind, SamplerConfig};
use crate::rng::{mix64, Rng};

/// Jittered strata, one random permutation of the strata per pixel and dimension.
#[derive(Clone, Copy, Debug)]
pub struct Stratified;

/// The stratified sampler in lanes.
pub type StratifiedLanes = PureLanes<Stratified>;

/// The most samples per pixel the strata can number.
pub const MAX_SAMPLES: u64 = 1 << 31;

/// What the samples of one pixel share: its key and its strata.
#[derive(Clone, Copy, Debug)]
pub struct StrataPixel {
    key: u64,
    /// Strata of a 1D draw: the run's samples per pixel.
    n: u32,
    /// Columns and rows of a 2D draw's grid.
    a: u32,
    b: u32,
}

/// Columns and rows of the 2D grid for `n` samples.
pub fn grid(n: u32) -> (u32, u32) {
    let mut a = (n as f64).sqrt() as u32;
    // The f64 square root of a large square may round below it.
    while (a as u64 + 1) * (a as u64 + 1) <= n as u64 {
        a += 1;
    }
    let a = a.max(1);
    (a, n.div_ceil(a))
}

impl PointSet for Stratified {
    type Pixel = StrataPixel;
    const JOINT: bool = false;
    const NEEDS_SAMPLE_COUNT: bool = true;
    const POINTS: PointKind = PointKind::Jittered;

    fn pixel(cfg: &SamplerConfig, x: u32, y: u32) -> StrataPixel {
        let n = cfg.run_samples.clamp(1, MAX_SAMPLES) as u32;
        let (a, b) = grid(n);
        StrataPixel {
            key: mix64(Rng::pixel_key(cfg.seed, cfg.pixel_index(x, y)) ^ 0x57a7_0000_0000_0001),
            n,
            a,
            b,
        }
    }

    #[inline(always)]
    fn draw(px: &StrataPixel, index: u64, dim: u32, k: usize) -> [f32; 4] {
        // Lanes past the run's last sample (a partial batch) are drawn and dropped; they
        // must not reach `permute` as they are, whose cycle walk need not end for i >= n.
        let i = (index % px.n as u64) as u32;
        let dim_key = mix64(px.key ^ dim as u64);
        let perm_seed = (dim_key >> 32) as u32;
        let jitter = mix64(dim_key ^ index);
        if k == 1 {
            let s = permute(i, px.n, perm_seed);
            let x = (s as f64 + uniform_f64(jitter)) / px.n as f64;
            [below_one(x), 0.0, 0.0, 0.0]
        } else {
            let s = permute(i, px.a * px.b, perm_seed);
            let (sx, sy) = (s % px.a, s / px.a);
            let x = (sx as f64 + uniform_f64(jitter)) / px.a as f64;
            let y = (sy as f64 + uniform_f64(jitter ^ 0x2d)) / px.b as f64;
            [below_one(x), below_one(y), 0.0, 0.0]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::pure::PureSample;
    use crate::sampler::{DimAlloc, Sampler, SamplerLanes};

    fn pixel(n: u64, seed: u64) -> super::super::pure::PurePixel<Stratified> {
        let c = SamplerConfig {
            dims: DimAlloc::Joint,
            seed,
            run_samples: n,
            width: 8,
            height: 8,
        };
        StratifiedLanes::pixel(&c, 3, 4)
    }

    #[test]
    fn grids_cover_the_sample_count() {
        for n in 1..2000u32 {
            let (a, b) = grid(n);
            assert!(a as u64 * b as u64 >= n as u64 && a <= b, "{n}: {a} x {b}");
            // At most one row more than needed.
            assert!((a as u64) * (b as u64 - 1) < n as u64);
        }
        assert_eq!(grid(16), (4, 4));
        assert_eq!(grid(1 << 30), (1 << 15, 1 << 15));
        assert_eq!(grid(12), (3, 4));
    }

    /// One point per stratum: in every 1D draw and every 2D cell, at square, rectangular
    /// and prime counts; a stratified sampler is padded even when joint draws are asked for.
    #[test]
    fn one_point_per_stratum_in_every_draw() {
        for n in [1u64, 4, 12, 16, 17, 64, 100] {
            let px = pixel(n, 9);
            assert!(!px.joint);
            let (a, b) = grid(n as u32);
            let mut film = vec![0u32; (a * b) as usize];
            let mut select = vec![0u32; n as usize];
            let mut point = vec![0u32; (a * b) as usize];
            for s in 0..n {
                let mut one = PureSample::new(px, s);
                let f = one.film();
                let l = one.light();
                for v in [f.x, f.y, l.select, l.primitive, l.point.x, l.point.y] {
                    assert!((0.0..1.0).contains(&v));
                }
                let cell = |p: glam::Vec2| {
                    ((p.y * b as f32) as u32 * a + (p.x * a as f32) as u32) as usize
                };
                film[cell(f)] += 1;
                point[cell(l.point)] += 1;
                select[(l.select * n as f32) as usize] += 1;
            }
            assert!(select.iter().all(|&c| c == 1), "n = {n}: {select:?}");
            assert!(
                film.iter().all(|&c| c <= 1) && point.iter().all(|&c| c <= 1),
                "n = {n}"
            );
            if a as u64 * b as u64 == n {
                assert!(film.iter().all(|&c| c == 1), "n = {n}");
            }
        }
    }

    /// A partial batch draws lanes past the run's samples; they must return (the cycle walk
    /// of the permutation hung on them: 11 spp rendered forever).
    #[test]
    fn lanes_past_the_run_still_draw() {
        for n in [1u64, 3, 11, 17] {
            let px = pixel(n, 4);
            for s in n..n + 8 {
                for dim in 0..40 {
                    for k in [1, 2] {
                        let v = Stratified::draw(&px.inner, s, dim, k);
                        assert!(v.iter().all(|v| (0.0..1.0).contains(v)));
                    }
                }
            }
        }
    }

    #[test]
    fn every_dimension_changes_with_the_seed() {
        let draw = |seed| crate::sampler::all_values(&mut PureSample::new(pixel(16, seed), 5));
        let (a, b) = (draw(1), draw(2));
        for k in 0..a.len() {
            assert_ne!(a[k], b[k], "dimension {k}");
        }
    }
}
