//! Very high sample counts (`[accumulation]`): `render` at ~1e6 spp on a few pixels. The
//! renderer accumulates in f64, so its pixel mean is the exact mean of the f32 samples; an f32
//! running sum of the same samples is shown beside it, to make the size of what f64 avoids
//! visible. Rows are kept in `accumulation.csv`, so a finished render is not redone.

use super::samples::pixel_samples;
use super::stats::z_score;
use crate::integrator::{Direct, Strategy};
use crate::output::write_atomic;
use crate::render::{render, RenderSettings};
use crate::scene::Scene;
use serde::{Deserialize, Serialize};
use std::path::Path;

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Accumulation {
    /// Hash of everything the row depends on but the strategy (see `probe::run`).
    pub context: String,
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
    pub seconds: f64,
}

/// Renders `scene` with `s` at `spp` and compares pixel (0, 0) with its own samples.
pub fn measure(
    scene: &Scene,
    s: Strategy,
    spp: u32,
    seed: u64,
    reference: f64,
    threads: Option<usize>,
) -> Accumulation {
    let settings = RenderSettings {
        spp,
        seed,
        first_sample: 0,
        threads,
        progress: None,
        sampling: Default::default(),
    };
    let out = render(scene, s, &settings);
    let px = out.mean.data.len() as f64;
    let image_mean = out.mean.data.iter().map(|p| p[0]).sum::<f64>() / px;
    let var = out.variance.data.iter().map(|p| p[0]).sum::<f64>() / (px * px);
    let z = z_score(image_mean, var * spp as f64, spp as u64, reference);
    let mut buf = Vec::new();
    pixel_samples(&Direct::new(scene, s), 0, 0, seed, spp, &mut buf);
    let exact = buf.iter().sum::<f64>() / spp as f64;
    let f32_sum = buf.iter().fold(0.0f32, |a, &v| a + v as f32);
    // Relative to the reference, or absolute where it is 0.
    let scale = if reference != 0.0 {
        reference.abs()
    } else {
        1.0
    };
    Accumulation {
        context: String::new(),
        case: String::new(),
        strategy: s.label(),
        spp,
        pixels: out.mean.width * out.mean.height,
        reference,
        non_finite: out.non_finite_samples,
        image_mean,
        z,
        f64_rel_error: (out.mean.get(0, 0)[0] - exact).abs() / scale,
        f32_rel_error: (f32_sum as f64 / spp as f64 - exact).abs() / scale,
        seconds: out.seconds,
    }
}

/// The rows of `path` with this context; a missing or unreadable file has none.
pub fn load(path: &Path, context: &str) -> Vec<Accumulation> {
    let Ok(mut rd) = csv::Reader::from_path(path) else {
        return Vec::new();
    };
    rd.deserialize::<Accumulation>()
        .flatten()
        .filter(|a| a.context == context)
        .collect()
}

pub fn save(path: &Path, rows: &[Accumulation]) -> Result<(), String> {
    write_atomic(path, |tmp| {
        let mut w = csv::Writer::from_path(tmp).map_err(|e| e.to_string())?;
        for r in rows {
            w.serialize(r).map_err(|e| e.to_string())?;
        }
        w.flush().map_err(|e| e.to_string())
    })
}
