//! `directlab render`: one image of a scene, with its variance and statistics; and the same
//! render for other commands (`compare` renders seeds of two configurations through it).

use crate::aov::Aov;
use crate::choices::{named, StrategyArgs};
use crate::film;
use crate::integrator::Strategy;
use crate::named::Named;
use crate::render::{render, RenderOutput, RenderSettings};
use clap::Args;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

#[derive(Args, Debug, Clone)]
pub struct RenderArgs {
    /// Scene file (XML).
    pub scene: PathBuf,
    /// Samples per pixel (default: the scene's sampler).
    #[arg(long, short = 's', value_parser = crate::limits::parse_spp)]
    pub spp: Option<u32>,
    /// Seed (default: the scene's sampler seed).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Worker threads (default: all cores). The image does not depend on it.
    #[arg(long, short = 't', value_parser = crate::render::parse_threads)]
    pub threads: Option<usize>,
    /// Sampler (default: the scene's <sampler type>, mapped to the nearest directlab one).
    #[arg(long, value_parser = named::<crate::sampler::SamplerKind>())]
    pub sampler: Option<crate::sampler::SamplerKind>,
    /// Dimension allocation: a light or BSDF sample's numbers as one joint point, or padded
    /// 1D/2D draws (only the Sobol' samplers draw jointly).
    #[arg(long, value_parser = named::<crate::sampler::DimAlloc>(), default_value_t)]
    pub dims: crate::sampler::DimAlloc,
    /// Output EXR (default: <scene name>.exr in the current directory); a PNG preview is
    /// written beside it.
    #[arg(long, short = 'o')]
    pub out: Option<PathBuf>,
    /// Also write the per-pixel variance of the estimate (sample variance / spp) as EXR.
    #[arg(long)]
    pub variance: Option<PathBuf>,
    /// Also write what each pixel's estimate is made of into this directory, as EXR with PNG
    /// previews: emitted, light and bsdf (the parts of the image from the emission seen, the
    /// light and the BSDF technique; they add up to it), weight-light and weight-bsdf (the
    /// mean MIS weight of each technique's samples that carry light) and second-moment. A
    /// second, scalar pass over the same samples.
    #[arg(long)]
    pub aov: Option<PathBuf>,
    /// Set a scene parameter declared with <default>: -D name=value (repeatable).
    #[arg(short = 'D', value_parser = crate::scene::loader::parse_define)]
    pub define: Vec<(String, String)>,
    /// Write render statistics as JSON.
    #[arg(long)]
    pub stats: Option<PathBuf>,
    /// `direct`: render the direct illumination of a scene whose integrator is a path tracer
    /// or Whitted's (refused without it); the image is the direct part only.
    #[arg(long, value_parser = named::<crate::scene::loader::IntegratorMode>())]
    pub integrator: Option<crate::scene::loader::IntegratorMode>,
    #[command(flatten)]
    pub strategy: StrategyArgs,
}

/// What `render --stats` writes.
#[derive(serde::Serialize)]
pub struct RenderStats {
    pub scene: String,
    pub strategy: String,
    pub spp: u32,
    pub seed: u64,
    pub sampler: &'static str,
    pub dims: &'static str,
    pub threads: usize,
    pub width: u32,
    pub height: u32,
    pub seconds: f64,
    pub samples_per_second: f64,
    pub non_finite_samples: u64,
    pub mean_rgb: [f64; 3],
    /// The global-illumination integrator the scene names, when the image is its direct part.
    pub direct_part_of: Option<String>,
}

/// The files `render` writes, checked before the scene is even loaded: each can be written,
/// and no two are the same file (the PNG preview sits beside the EXR, so `--out x.png` would
/// have the preview overwrite the image).
fn render_outputs(a: &RenderArgs) -> Result<PathBuf, String> {
    let out = a.out.clone().unwrap_or_else(|| {
        let stem = a
            .scene
            .file_stem()
            .unwrap_or_default()
            .to_string_lossy()
            .to_string();
        PathBuf::from(format!("{stem}.exr"))
    });
    let is_exr = out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    if !is_exr {
        return Err(format!(
            "--out {}: expected a file name ending in .exr (the PNG preview is written beside \
             it, with .png)",
            out.display()
        ));
    }
    let png = out.with_extension("png");
    let mut outputs: Vec<(&str, &Path)> = vec![("--out", &out), ("the PNG preview", &png)];
    if let Some(v) = &a.variance {
        outputs.push(("--variance", v));
    }
    if let Some(s) = &a.stats {
        outputs.push(("--stats", s));
    }
    crate::output::check_distinct(&outputs)?;
    if let Some(d) = a.aov.as_deref().filter(|d| d.exists() && !d.is_dir()) {
        return Err(format!(
            "--aov {}: a file; expected a directory for the images",
            d.display()
        ));
    }
    for (_, p) in &outputs {
        crate::output::check_writable(p)?;
    }
    Ok(out)
}

/// Renders `a`'s scene as `a` says, at `seed` in place of `a`'s (for `compare`'s seeds);
/// `progress`: draw the tile bar on a terminal.
pub fn render_args(
    a: &RenderArgs,
    seed: Option<u64>,
    progress: bool,
) -> Result<(RenderOutput, RenderStats, Option<Aov>), String> {
    let scene = crate::scene::open_with(&a.scene, &a.define, a.integrator)?;
    let strategy = a
        .strategy
        .overrides()
        .apply(Strategy::from_desc(&scene.desc.integrator))?;
    let settings = RenderSettings {
        spp: a.spp.unwrap_or(scene.desc.sampler.sample_count),
        seed: seed.or(a.seed).unwrap_or(scene.desc.sampler.seed),
        first_sample: 0,
        threads: a.threads,
        progress: crate::progress::tiles(progress && std::io::stderr().is_terminal()),
        sampling: crate::sampler::Sampling {
            kind: a.sampler.unwrap_or(scene.desc.sampler.kind),
            dims: a.dims,
            run_samples: None,
        },
    };
    settings.sampler_config((scene.camera.width, scene.camera.height))?;
    let result = render(&scene, strategy, &settings);
    let aov = a
        .aov
        .is_some()
        .then(|| crate::aov::render_aov(&scene, strategy, &settings));
    let stats = RenderStats {
        scene: a.scene.display().to_string(),
        strategy: strategy.label(),
        spp: settings.spp,
        seed: settings.seed,
        sampler: settings.sampling.kind.name(),
        dims: settings.sampling.dims.name(),
        threads: settings.threads.unwrap_or_else(rayon::current_num_threads),
        width: result.mean.width,
        height: result.mean.height,
        seconds: result.seconds,
        samples_per_second: result.samples_per_second(),
        non_finite_samples: result.non_finite_samples,
        mean_rgb: result.mean.mean_rgb(),
        direct_part_of: scene.desc.integrator.direct_part_of.clone(),
    };
    Ok((result, stats, aov))
}

/// The command.
pub fn command(a: &RenderArgs) -> Result<(), String> {
    let out = render_outputs(a)?;
    let (result, stats, aov) = render_args(a, None, true)?;
    // The image, its preview, variance and statistics replace the old ones as one set: a
    // disk that fills part-way leaves the old files, never a new EXR beside an old PNG.
    crate::output::as_one_set(|| {
        film::write_exr(&out, &result.mean)?;
        film::write_png(&out.with_extension("png"), &result.mean)?;
        if let Some(v) = &a.variance {
            film::write_exr(v, &result.variance)?;
        }
        if let (Some(dir), Some(aov)) = (&a.aov, &aov) {
            std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
            for (name, img) in aov.images() {
                film::write_exr(&dir.join(format!("{name}.exr")), img)?;
                film::write_png(&dir.join(format!("{name}.png")), img)?;
            }
        }
        if let Some(p) = &a.stats {
            let json = serde_json::to_string_pretty(&stats).map_err(|e| e.to_string())?;
            crate::output::write_atomic(p, |tmp| {
                std::fs::write(tmp, json).map_err(|e| format!("{}: {e}", p.display()))
            })?;
        }
        Ok(())
    })?;
    eprintln!(
        "{}: {}x{} at {} spp with {} in {:.2} s ({:.2} M samples/s) -> {}",
        a.scene.display(),
        stats.width,
        stats.height,
        stats.spp,
        stats.strategy,
        stats.seconds,
        stats.samples_per_second / 1e6,
        out.display()
    );
    if result.non_finite_samples > 0 {
        eprintln!(
            "warning: {} non-finite samples were replaced by 0",
            result.non_finite_samples
        );
    }
    Ok(())
}
