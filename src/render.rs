//! The render loop: tiles in parallel, every camera sample seeded from (seed, pixel, sample)
//! so the image is bitwise identical for any thread count.

use crate::film::Image;
use crate::integrator::{Direct, Strategy};
use crate::rng::Rng;
use crate::scene::Scene;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use std::time::Instant;

const TILE: u32 = 16;

#[derive(Clone, Debug)]
pub struct RenderSettings {
    pub spp: u32,
    pub seed: u64,
    /// Worker threads; None uses rayon's default (all cores).
    pub threads: Option<usize>,
    pub progress: bool,
}

/// Per-pixel sample mean and the variance of that mean (sample variance / spp), both f64.
pub struct RenderOutput {
    pub mean: Image,
    pub variance: Image,
    pub spp: u32,
    pub seconds: f64,
    pub non_finite_samples: u64,
}

impl RenderOutput {
    pub fn samples_per_second(&self) -> f64 {
        let n = self.mean.width as f64 * self.mean.height as f64 * self.spp as f64;
        n / self.seconds.max(1e-9)
    }
}

struct PixelResult {
    mean: [f64; 3],
    var_of_mean: [f64; 3],
    non_finite: u64,
}

fn render_pixel(direct: &Direct, x: u32, y: u32, settings: &RenderSettings) -> PixelResult {
    let cam = &direct.scene.camera;
    let pixel = y as u64 * cam.width as u64 + x as u64;
    // Welford's update in f64: stable for millions of samples of very different size.
    let (mut mean, mut m2) = ([0.0f64; 3], [0.0f64; 3]);
    let mut non_finite = 0;
    let key = Rng::pixel_key(settings.seed, pixel);
    let camera_sample = |s: u32| {
        let mut rng = Rng::for_pixel_sample(key, s as u64);
        (cam.generate_ray(x, y, &mut rng), rng)
    };
    // One sample ahead: the next camera ray's hashing, division and square root run while
    // this sample traces, instead of ahead of its traversal on the critical path.
    let mut next = (settings.spp > 0).then(|| camera_sample(0));
    for s in 0..settings.spp {
        let (ray, mut rng) = next.take().expect("drawn one sample ahead");
        if s + 1 < settings.spp {
            next = Some(camera_sample(s + 1));
        }
        let mut v = direct.li(&ray, &mut rng);
        if !v.is_finite() {
            // Counted and reported; a correct estimator never gets here (tests assert 0).
            non_finite += 1;
            v = glam::Vec3::ZERO;
        }
        let n = (s + 1) as f64;
        for c in 0..3 {
            let x = v[c] as f64;
            let d = x - mean[c];
            mean[c] += d / n;
            m2[c] += d * (x - mean[c]);
        }
    }
    let n = settings.spp as f64;
    let var_of_mean = if settings.spp > 1 {
        m2.map(|m| m / (n - 1.0) / n)
    } else {
        [0.0; 3]
    };
    PixelResult {
        mean,
        var_of_mean,
        non_finite,
    }
}

pub fn render(scene: &Scene, strategy: Strategy, settings: &RenderSettings) -> RenderOutput {
    let (w, h) = (scene.camera.width, scene.camera.height);
    let direct = Direct::new(scene, strategy);
    let tiles: Vec<(u32, u32)> = (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE)))
        .collect();
    let bar = if settings.progress {
        let b = ProgressBar::new(tiles.len() as u64);
        b.set_style(
            ProgressStyle::with_template(
                "{spinner} rendering [{bar:30}] {pos}/{len} tiles, {elapsed} (eta {eta})",
            )
            .expect("static template")
            .progress_chars("=> "),
        );
        b
    } else {
        ProgressBar::hidden()
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(settings.threads.unwrap_or(0))
        .build()
        .expect("thread pool");
    let start = Instant::now();
    let results: Vec<Vec<(u32, u32, PixelResult)>> = pool.install(|| {
        tiles
            .par_iter()
            .map(|&(x0, y0)| {
                let mut out = Vec::with_capacity((TILE * TILE) as usize);
                for y in y0..(y0 + TILE).min(h) {
                    for x in x0..(x0 + TILE).min(w) {
                        out.push((x, y, render_pixel(&direct, x, y, settings)));
                    }
                }
                bar.inc(1);
                out
            })
            .collect()
    });
    let seconds = start.elapsed().as_secs_f64();
    bar.finish_and_clear();
    let mut mean = Image::new(w, h);
    let mut variance = Image::new(w, h);
    let mut non_finite_samples = 0;
    for (x, y, r) in results.into_iter().flatten() {
        mean.set(x, y, r.mean);
        variance.set(x, y, r.var_of_mean);
        non_finite_samples += r.non_finite;
    }
    RenderOutput {
        mean,
        variance,
        spp: settings.spp,
        seconds,
        non_finite_samples,
    }
}
