//! The render loop: tiles in parallel, every camera sample seeded from (seed, pixel, sample)
//! so the image is bitwise identical for any thread count.

use crate::counts::Counts;
use crate::film::Image;
use crate::integrator::{LaneKernel, LaneScratch, Strategy};
use crate::rng::LANES;
use crate::sampler::{LanesVisitor, SamplerConfig, SamplerLanes, Sampling};
use crate::scene::Scene;
use rayon::prelude::*;
use std::time::Instant;

const TILE: u32 = 16;

/// The most worker threads a render accepts: far beyond any core count this renders on, and
/// low enough that creating the pool takes milliseconds, not minutes.
pub const MAX_THREADS: usize = 1024;

/// Parses `--threads`: 1 to [`MAX_THREADS`]. (0 is not "all cores": leave the option out for
/// that.)
pub fn parse_threads(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(n) if (1..=MAX_THREADS).contains(&n) => Ok(n),
        _ => Err(format!(
            "expected a worker thread count from 1 to {MAX_THREADS}, found '{s}' (leave \
             --threads out to use every core)"
        )),
    }
}

/// How a render draws its samples: count, seed, threads and sampler.
#[derive(Clone, Debug)]
pub struct RenderSettings {
    /// Samples per pixel.
    pub spp: u32,
    /// Seed: the same seed gives a bitwise-identical image for any thread count.
    pub seed: u64,
    /// Index of the first sample of each pixel: a render of samples [k, k + spp) draws the
    /// same random numbers as those samples of one longer render, so renders of consecutive
    /// sample ranges merge into it (the reference's checkpointed chunks).
    pub first_sample: u64,
    /// Worker threads; None uses rayon's default (all cores).
    pub threads: Option<usize>,
    /// Told of each finished tile; None renders silently.
    pub progress: Option<Progress>,
    /// The sampler and its dimension allocation.
    pub sampling: Sampling,
}

/// A render's progress hook: called by the workers after each tile with (tiles done, tiles in
/// all); a progress bar lives behind it, outside the renderer.
#[derive(Clone)]
pub struct Progress(pub std::sync::Arc<dyn Fn(u64, u64) + Send + Sync>);

impl std::fmt::Debug for Progress {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("Progress")
    }
}

impl RenderSettings {
    /// `spp` samples per pixel from `seed` (the first samples of each pixel's stream) with the
    /// independent sampler, on every core, without progress.
    pub fn new(spp: u32, seed: u64) -> Self {
        RenderSettings {
            spp,
            seed,
            first_sample: 0,
            threads: None,
            progress: None,
            sampling: Sampling::default(),
        }
    }

    /// The sampler's configuration for this render, or why it cannot draw its samples.
    pub fn sampler_config(&self, film: (u32, u32)) -> Result<SamplerConfig, String> {
        self.sampling
            .config(self.seed, self.first_sample, self.spp, film)
    }
}

/// Per-pixel sample mean and the variance of that mean (sample variance / spp), both f64.
pub struct RenderOutput {
    /// Per-pixel sample mean.
    pub mean: Image,
    /// Per-pixel variance of the mean (sample variance / spp).
    pub variance: Image,
    /// Samples per pixel.
    pub spp: u32,
    /// Wall-clock seconds of the render.
    pub seconds: f64,
    /// Seconds the workers spent rendering tiles, summed over tiles: `seconds` times the
    /// thread count when no worker waits (it separates idle workers from slower ones).
    pub busy_seconds: f64,
    /// Samples that were NaN or infinite (counted as 0 in the mean).
    pub non_finite_samples: u64,
    /// What the render did, per technique (rays, evaluations): the same for any thread
    /// count, shard or machine.
    pub counts: Counts,
}

impl RenderOutput {
    /// Samples per second of wall-clock time.
    pub fn samples_per_second(&self) -> f64 {
        let n = self.mean.width as f64 * self.mean.height as f64 * self.spp as f64;
        n / self.seconds.max(1e-9)
    }
}

/// A pixel's running sums of x - K in f64, K its first sample ("shifted data"): as stable as
/// Welford's update for values near K, exact 0 variance for constant pixels, and no division
/// per sample. Samples arrive a batch of `LANES` at a time, their channels in the order the
/// lanes return them, and each of the batch's `3 * LANES` values has its own pair of sums,
/// added up per channel only in `finish`: per batch, element-wise vector arithmetic without
/// a dependency between samples or a horizontal sum (pushed one by one, the samples' chains
/// of f64 additions took 5 % of Cornell render time).
#[repr(C, align(64))] // as `PacketHits`, for its vectors
struct PixelStats {
    /// K of each value's channel.
    shift: [f64; BATCH],
    s1: [f64; BATCH],
    s2: [f64; BATCH],
    n: u32,
}

/// Values per batch: each lane's three channels.
const BATCH: usize = 3 * LANES;

impl Default for PixelStats {
    fn default() -> Self {
        PixelStats {
            n: 0,
            shift: [0.0; BATCH],
            s1: [0.0; BATCH],
            s2: [0.0; BATCH],
        }
    }
}

impl PixelStats {
    /// Adds the first `n` samples of a batch; a sample with a non-finite channel counts as 0
    /// and is returned in the count of non-finite samples.
    #[inline]
    fn push_batch(&mut self, v: &[glam::Vec3; LANES], n: usize) -> u64 {
        let mut x = [0.0f32; BATCH];
        for (x, v) in x.chunks_exact_mut(3).zip(v) {
            x.copy_from_slice(&v.to_array());
        }
        let mut non_finite = 0;
        // One test for the whole batch: a value is finite when its exponent bits are not all
        // set. An integer max reduces in vector lanes; a float sum made a chain of 24
        // dependent additions per batch (Rust does not reassociate float sums).
        let top = x.iter().fold(0, |m, v| m.max(v.to_bits() & 0x7fff_ffff));
        if top >= 0x7f80_0000 {
            for i in 0..n {
                if !is_finite(v[i]) {
                    non_finite += 1;
                    x[3 * i..3 * i + 3].fill(0.0);
                }
            }
        }
        if self.n == 0 {
            self.shift = std::array::from_fn(|k| x[k % 3] as f64);
        }
        let mut d: [f64; BATCH] = std::array::from_fn(|k| x[k] as f64 - self.shift[k]);
        if n < LANES {
            d[3 * n..].fill(0.0);
        }
        for ((s1, s2), d) in self.s1.iter_mut().zip(&mut self.s2).zip(d) {
            *s1 += d;
            *s2 += d * d;
        }
        self.n += n as u32;
        non_finite
    }

    /// Sample mean and variance of the mean (sample variance / n).
    fn finish(&self) -> ([f64; 3], [f64; 3]) {
        let n = self.n as f64;
        let (mut mean, mut var_of_mean) = ([0.0; 3], [0.0; 3]);
        let (mut s1, mut s2) = ([0.0; 3], [0.0; 3]);
        for k in 0..BATCH {
            (s1[k % 3], s2[k % 3]) = (s1[k % 3] + self.s1[k], s2[k % 3] + self.s2[k]);
        }
        for c in 0..3 {
            let (s1, s2) = (s1[c], s2[c]);
            if self.n > 0 {
                mean[c] = self.shift[c] + s1 / n;
            }
            if self.n > 1 {
                let m2 = (s2 - s1 * s1 / n).max(0.0);
                var_of_mean[c] = m2 / (n - 1.0) / n;
            }
        }
        (mean, var_of_mean)
    }
}

/// A tile's pixels, the seconds its worker spent on them and what it did.
type TileResult = (Vec<(u32, u32, PixelResult)>, f64, Counts);

struct PixelResult {
    mean: [f64; 3],
    var_of_mean: [f64; 3],
    non_finite: u64,
}

/// `Vec3::is_finite` without its short-circuit branches: x - x is 0 for a finite x and NaN
/// for an infinite or NaN one, and NaN carries through the sum.
#[inline(always)]
#[allow(clippy::eq_op)] // x - x is the test, not a slip
fn is_finite(v: glam::Vec3) -> bool {
    (v.x - v.x) + (v.y - v.y) + (v.z - v.z) == 0.0
}

/// One pixel of a render, for the sampler of its settings.
struct Pixel<'a> {
    kernel: &'a LaneKernel<'a>,
    x: u32,
    y: u32,
    settings: &'a RenderSettings,
    cfg: &'a SamplerConfig,
    scratch: &'a mut LaneScratch,
}

impl LanesVisitor for Pixel<'_> {
    type Output = PixelResult;
    #[inline(always)]
    fn visit<L: SamplerLanes>(self) -> PixelResult {
        render_pixel::<L>(
            self.kernel,
            self.x,
            self.y,
            self.settings,
            self.cfg,
            self.scratch,
        )
    }
}

fn render_any_pixel(
    kernel: &LaneKernel,
    x: u32,
    y: u32,
    settings: &RenderSettings,
    cfg: &SamplerConfig,
    scratch: &mut LaneScratch,
) -> PixelResult {
    settings.sampling.kind.visit(Pixel {
        kernel,
        x,
        y,
        settings,
        cfg,
        scratch,
    })
}

/// One pixel's samples, drawn by the sampler `L`.
fn render_pixel<L: SamplerLanes>(
    kernel: &LaneKernel,
    x: u32,
    y: u32,
    settings: &RenderSettings,
    cfg: &SamplerConfig,
    scratch: &mut LaneScratch,
) -> PixelResult {
    let mut stats = PixelStats::default();
    let mut non_finite = 0;
    let cam = &kernel.direct.scene.camera;
    let key = L::pixel(cfg, x, y);
    // Samples go LANES at a time: their generators and camera rays are computed side by side
    // in vector registers, and `li_lanes` shades them together where it covers the scene;
    // each sample stays bitwise what `for_pixel_sample`, `generate_ray` and `li` give it
    // (lanes past spp are dropped).
    for s0 in (0..settings.spp).step_by(LANES) {
        let mut lanes = L::start(key, settings.first_sample + s0 as u64);
        let rays = cam.generate_rays(x, y, &mut lanes);
        let n = (settings.spp - s0).min(LANES as u32) as usize;
        let values = kernel.li_lanes(&rays, n, &mut lanes, scratch);
        // Counted and reported; a correct estimator has none (tests assert 0).
        non_finite += stats.push_batch(&values, n);
    }
    let (mean, var_of_mean) = stats.finish();
    PixelResult {
        mean,
        var_of_mean,
        non_finite,
    }
}

/// The pixels of image rows `rows`, rendered on this thread as a render's worker renders a
/// tile: the bench times renders band by band against the traversal of the same rays
/// (`bench::raylimit::measure_interleaved`). Returns the sum of their red means, so that no
/// pixel's work can be dropped.
pub fn render_rows(
    kernel: &LaneKernel,
    rows: std::ops::Range<u32>,
    settings: &RenderSettings,
    scratch: &mut LaneScratch,
) -> f64 {
    let cam = &kernel.direct.scene.camera;
    let w = cam.width;
    let cfg = settings
        .sampler_config((w, cam.height))
        .expect("sampler settings checked by the caller");
    rows.flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| render_any_pixel(kernel, x, y, settings, &cfg, scratch).mean[0])
        .sum()
}

/// Renders `scene` with `strategy`: every pixel's mean and variance of the mean.
pub fn render(scene: &Scene, strategy: Strategy, settings: &RenderSettings) -> RenderOutput {
    render_with(&LaneKernel::new(scene, strategy), settings)
}

/// `render` with the estimator `kernel` (its scene and strategy).
pub(crate) fn render_with(kernel: &LaneKernel, settings: &RenderSettings) -> RenderOutput {
    let scene = kernel.direct.scene;
    let (w, h) = (scene.camera.width, scene.camera.height);
    let cfg = settings
        .sampler_config((w, h))
        .expect("sampler settings checked by the caller");
    let tiles: Vec<(u32, u32)> = (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE)))
        .collect();
    let done = std::sync::atomic::AtomicU64::new(0);
    let total = tiles.len() as u64;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(settings.threads.unwrap_or(0))
        .build()
        .expect("thread pool");
    let start = Instant::now();
    let results: Vec<TileResult> = pool.install(|| {
        // One tile per work item: rayon otherwise hands each worker a fixed quarter of the
        // tiles and splits further only on a steal, so a worker that runs slower for a while
        // (a shared VM core) leaves the other one idle at the end.
        tiles
            .par_iter()
            .with_max_len(1)
            .map(|&(x0, y0)| {
                let tile_start = Instant::now();
                let mut out = Vec::with_capacity((TILE * TILE) as usize);
                let mut scratch = LaneScratch::default();
                for y in y0..(y0 + TILE).min(h) {
                    for x in x0..(x0 + TILE).min(w) {
                        let r = render_any_pixel(kernel, x, y, settings, &cfg, &mut scratch);
                        out.push((x, y, r));
                    }
                }
                if let Some(p) = &settings.progress {
                    (p.0)(
                        done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1,
                        total,
                    );
                }
                (out, tile_start.elapsed().as_secs_f64(), scratch.counts)
            })
            .collect()
    });
    let seconds = start.elapsed().as_secs_f64();
    let mut mean = Image::new(w, h);
    let mut variance = Image::new(w, h);
    let mut non_finite_samples = 0;
    let busy_seconds = results.iter().map(|r| r.1).sum();
    let counts = results.iter().map(|r| r.2).sum();
    for (x, y, r) in results.into_iter().flat_map(|r| r.0) {
        mean.set(x, y, r.mean);
        variance.set(x, y, r.var_of_mean);
        non_finite_samples += r.non_finite;
    }
    RenderOutput {
        mean,
        variance,
        spp: settings.spp,
        seconds,
        busy_seconds,
        non_finite_samples,
        counts,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use glam::Vec3;

    #[test]
    fn thread_counts_outside_the_range_are_refused() {
        assert_eq!(parse_threads("2"), Ok(2));
        assert!(parse_threads("0").unwrap_err().contains("from 1 to 1024"));
        assert!(parse_threads("100000").is_err());
        assert!(parse_threads("-1").is_err());
    }

    /// Two-pass mean and variance of the mean in f64, the textbook definition.
    fn two_pass(x: &[f64]) -> (f64, f64) {
        let n = x.len() as f64;
        let m = x.iter().sum::<f64>() / n;
        let v = x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0);
        (m, v / n)
    }

    #[test]
    fn is_finite_is_glams() {
        let xs = [
            0.0,
            -0.0,
            1.0,
            -3.4e38,
            f32::MAX,
            f32::MIN_POSITIVE,
            1e-45,
            f32::INFINITY,
        ];
        let xs = xs
            .into_iter()
            .chain([f32::NEG_INFINITY, f32::NAN, -f32::NAN]);
        let xs: Vec<f32> = xs.collect();
        for &a in &xs {
            for &b in &xs {
                for v in [
                    Vec3::new(a, b, 1.0),
                    Vec3::new(1.0, a, b),
                    Vec3::new(b, 2.0, a),
                ] {
                    assert_eq!(super::is_finite(v), v.is_finite(), "{v:?}");
                }
            }
        }
    }

    #[test]
    fn pixel_stats_match_two_pass_and_give_zero_for_constant_pixels() {
        let mut rng = Rng::new(7, 3);
        // Offset far from 0, a firefly, and a pixel whose first sample is the firefly.
        let cases: Vec<Vec<f32>> = vec![
            (0..256).map(|_| 1e3 + rng.next_f32()).collect(),
            (0..256)
                .map(|i| if i == 100 { 1e6 } else { rng.next_f32() })
                .collect(),
            (0..64)
                .map(|i| if i == 0 { 1e6 } else { rng.next_f32() })
                .collect(),
        ];
        for x in cases {
            let mut st = PixelStats::default();
            for batch in x.chunks(LANES) {
                let v = std::array::from_fn(|i| match batch.get(i) {
                    Some(&v) => Vec3::new(v, 2.0 * v, 0.5),
                    // Past the batch's end: must be ignored, whatever it holds.
                    None => Vec3::splat(f32::NAN),
                });
                assert_eq!(st.push_batch(&v, batch.len()), 0);
            }
            let (mean, var) = st.finish();
            let x64: Vec<f64> = x.iter().map(|&v| v as f64).collect();
            let (m, v) = two_pass(&x64);
            assert!((mean[0] - m).abs() <= 1e-12 * m.abs(), "{} {m}", mean[0]);
            assert!((var[0] - v).abs() <= 1e-9 * v, "{} {v}", var[0]);
            assert!((var[1] - 4.0 * v).abs() <= 1e-9 * v);
            assert_eq!((mean[2], var[2]), (0.5, 0.0), "constant channel");
        }
        let mut one = PixelStats::default();
        assert_eq!(one.push_batch(&[Vec3::splat(3.0); LANES], 1), 0);
        assert_eq!(one.finish(), ([3.0; 3], [0.0; 3]));
        // A sample with a non-finite channel counts as 0, and is counted; lanes past n are
        // neither.
        let mut bad = PixelStats::default();
        let mut v = [Vec3::splat(2.0); LANES];
        (v[1].y, v[4].z, v[6].x) = (f32::INFINITY, f32::NAN, f32::NEG_INFINITY);
        assert_eq!(bad.push_batch(&v, 6), 2);
        let (mean, _) = bad.finish();
        assert!(
            mean.iter().all(|&m| (m - 8.0 / 6.0).abs() < 1e-15),
            "{mean:?}"
        );
        // A batch whose only non-finite value is an infinity (the smallest non-finite
        // magnitude) is caught as well.
        for inf in [f32::INFINITY, f32::NEG_INFINITY] {
            let mut v = [Vec3::splat(2.0); LANES];
            v[3].z = inf;
            assert_eq!(PixelStats::default().push_batch(&v, LANES), 1);
        }
        assert_eq!(PixelStats::default().finish(), ([0.0; 3], [0.0; 3]));
    }

    /// `render_rows` is the render's work: over all bands of rows, the same pixel means.
    #[test]
    fn rendered_rows_are_the_render() {
        let mut desc = crate::scene::bundled_tests::load("veach-mis/veach-mis.xml");
        (desc.film.width, desc.film.height) = (10, 7);
        let scene = Scene::build(desc).unwrap();
        let strategy = crate::integrator::Strategy::combinations()[0];
        let settings = RenderSettings {
            spp: 8,
            seed: 3,
            first_sample: 0,
            threads: Some(2),
            progress: None,
            sampling: Default::default(),
        };
        let out = render(&scene, strategy, &settings);
        let kernel = LaneKernel::new(&scene, strategy);
        let mut scratch = LaneScratch::default();
        for rows in [0..3, 3..4, 4..7] {
            let band = render_rows(&kernel, rows.clone(), &settings, &mut scratch);
            let want: f64 = rows
                .flat_map(|y| (0..10).map(move |x| (x, y)))
                .map(|(x, y)| out.mean.get(x, y)[0])
                .sum();
            assert!(want > 0.0, "a lit band");
            assert_eq!(band.to_bits(), want.to_bits());
        }
    }
}

#[cfg(test)]
#[path = "render_lanes_tests.rs"]
mod lanes_tests;

#[cfg(test)]
#[path = "render_checksums_tests.rs"]
mod checksums_tests;
