//! Very high sample counts: 1e6 samples in each pixel of a 2 x 2 probe. The renderer
//! accumulates in f64, so its mean is the exact mean of the f32 samples; an f32 running sum
//! of the same samples is shown beside it, to make the size of what f64 avoids visible.

use super::cases::{self, Case};
use super::measure::z_score;
use super::samples::pixel_samples;
use crate::integrator::{Direct, Strategy};
use crate::render::{render, RenderSettings};
use crate::scene::Scene;

pub const FULL_SPP: u32 = 1_000_000;
pub const QUICK_SPP: u32 = 20_000;

pub struct Accumulation {
    pub case: String,
    pub strategy: String,
    pub spp: u32,
    pub pixels: u32,
    pub reference: f64,
    pub non_finite: u64,
    /// Mean over the image and its z against the reference.
    pub image_mean: f64,
    pub z: f64,
    /// |render mean - exact f64 sum of the samples / n| / reference, pixel (0, 0).
    pub f64_rel_error: f64,
    /// |f32 running-sum mean - exact mean| / reference, pixel (0, 0).
    pub f32_rel_error: f64,
}

/// The case used: the tiny bright light (large sample values, most variance) on 2 x 2 pixels.
pub fn case() -> Case {
    let mut c = cases::light_size().swap_remove(0);
    c.desc.film.width = 2;
    c.desc.film.height = 2;
    c
}

pub fn run(quick: bool, seed: u64) -> Vec<Accumulation> {
    let c = case();
    let scene = Scene::build(c.desc.clone()).expect("case builds");
    let spp = if quick { QUICK_SPP } else { FULL_SPP };
    let strategies = super::report_strategies();
    // Light sampling by area and MIS: the two that the bright light stresses most.
    [strategies[0], strategies[4]]
        .iter()
        .map(|s| measure(&c, &scene, *s, spp, seed))
        .collect()
}

pub fn measure(c: &Case, scene: &Scene, s: Strategy, spp: u32, seed: u64) -> Accumulation {
    let settings = RenderSettings {
        spp,
        seed,
        threads: None,
        progress: false,
    };
    let out = render(scene, s, &settings);
    let px = out.mean.data.len() as f64;
    let image_mean = out.mean.data.iter().map(|p| p[0]).sum::<f64>() / px;
    let var = out.variance.data.iter().map(|p| p[0]).sum::<f64>() / (px * px);
    let z = z_score(image_mean, var * spp as f64, spp as u64, c.reference);
    let mut buf = Vec::new();
    pixel_samples(&Direct::new(scene, s), 0, 0, seed, spp, &mut buf);
    let exact = buf.iter().sum::<f64>() / spp as f64;
    let f32_sum = buf.iter().fold(0.0f32, |a, &v| a + v as f32);
    let r = c.reference;
    Accumulation {
        case: c.name.clone(),
        strategy: s.label(),
        spp,
        pixels: out.mean.width * out.mean.height,
        reference: r,
        non_finite: out.non_finite_samples,
        image_mean,
        z,
        f64_rel_error: (out.mean.get(0, 0)[0] - exact).abs() / r,
        f32_rel_error: (f32_sum as f64 / spp as f64 - exact).abs() / r,
    }
}
