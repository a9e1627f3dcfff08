//! The two sides of a comparison: read from seeds' EXRs or a render with its variance, or
//! rendered here from two configurations.

use crate::render_cmd::RenderArgs;
use crate::stats::welch_map::Side;
use std::path::{Path, PathBuf};

/// Loads one side.
/// What a single render's side comes with: its variance image, and its spp from `render
/// --stats` (which also names its sampler) or given by hand.
pub(super) struct Single<'a> {
    pub variance: Option<&'a Path>,
    pub stats: Option<&'a Path>,
    pub spp: Option<u64>,
}

impl<'a> Single<'a> {
    pub fn of(variance: &'a Option<PathBuf>, stats: &'a Option<PathBuf>, spp: Option<u64>) -> Self {
        Single {
            variance: variance.as_deref(),
            stats: stats.as_deref(),
            spp,
        }
    }
}

/// The spp of a single render from its `render --stats`, refusing a correlated sampler.
fn stats_spp(stats: &Path, spp: Option<u64>, name: &str) -> Result<u64, String> {
    let text = std::fs::read_to_string(stats).map_err(|e| format!("{}: {e}", stats.display()))?;
    let v: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| format!("{}: not `render --stats` JSON: {e}", stats.display()))?;
    let (Some(sampler), Some(n)) = (v["sampler"].as_str(), v["spp"].as_u64()) else {
        return Err(format!(
            "{}: expected `render --stats` JSON with 'sampler' and 'spp'",
            stats.display()
        ));
    };
    if sampler != "independent" {
        return Err(format!(
            "{}: side {name} was rendered with the {sampler} sampler, whose samples in a pixel \
             are correlated: its per-pixel variance is not the variance of its mean. Compare \
             seeds instead (a directory of one EXR per seed, or --render-{name})",
            stats.display()
        ));
    }
    match spp {
        Some(s) if s != n => Err(format!(
            "--spp-{name} {s}, but {} says {n}",
            stats.display()
        )),
        _ => Ok(n),
    }
}

/// An RGB(A) EXR, with what was expected when it has other channels.
fn read_exr(path: &Path) -> Result<crate::film::Image, String> {
    crate::film::read_exr(path).map_err(|e| match e.contains("no layer") {
        true => format!("{e}: expected R, G and B channels (an RGB or RGBA image)"),
        false => e,
    })
}

pub(super) fn side(path: &Path, single: Single, name: &str) -> Result<Side, String> {
    let Single {
        variance,
        stats,
        spp,
    } = single;
    if !path.exists() {
        return Err(format!(
            "{}: no such file or directory (side {name}: a directory of seeds' EXRs, or one EXR)",
            path.display()
        ));
    }
    if path.is_dir() {
        let mut files: Vec<PathBuf> = std::fs::read_dir(path)
            .map_err(|e| format!("{}: {e}", path.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x.eq_ignore_ascii_case("exr")))
            // Hidden files are writers' temporaries (experiments/mitsuba_compare.py).
            .filter(|p| {
                !p.file_name()
                    .unwrap_or_default()
                    .to_string_lossy()
                    .starts_with('.')
            })
            .collect();
        files.sort();
        if files.len() < 2 {
            return Err(format!(
                "{}: side {name} needs at least two seeds' EXRs for a variance, found {}",
                path.display(),
                files.len()
            ));
        }
        let images = files
            .iter()
            .map(|f| read_exr(f))
            .collect::<Result<Vec<_>, _>>()?;
        let (w, h) = (images[0].width, images[0].height);
        if let Some((f, i)) = files
            .iter()
            .zip(&images)
            .find(|(_, i)| (i.width, i.height) != (w, h))
        {
            return Err(format!(
                "{}: {}x{}, but {} is {w}x{h}: side {name}'s seeds differ in size",
                f.display(),
                i.width,
                i.height,
                files[0].display()
            ));
        }
        let seeds = images.into_iter().map(|i| i.data).collect();
        return Ok(Side::from_seeds(w as usize, h as usize, seeds));
    }
    let spp = match stats {
        Some(st) => Some(stats_spp(st, spp, name)?),
        None => spp,
    };
    let (Some(var), Some(n)) = (variance, spp) else {
        return Err(format!(
            "{}: a single render as side {name} needs --variance-{name} and --stats-{name} \
             (or --spp-{name}); or give a directory of seeds' EXRs",
            path.display()
        ));
    };
    if n < 2 {
        return Err(format!(
            "--spp-{name} {n}: a variance needs at least 2 samples"
        ));
    }
    let (mean, v) = (read_exr(path)?, read_exr(var)?);
    if (mean.width, mean.height) != (v.width, v.height) {
        return Err(format!(
            "{}: {}x{}, but its image {} is {}x{}",
            var.display(),
            v.width,
            v.height,
            path.display(),
            mean.width,
            mean.height
        ));
    }
    if let Some(i) = v.data.iter().position(|p| p.iter().any(|x| *x < 0.0)) {
        return Err(format!(
            "{}: negative variance at pixel ({}, {}): not a variance image",
            var.display(),
            i % v.width as usize,
            i / v.width as usize
        ));
    }
    Ok(Side {
        width: mean.width as usize,
        height: mean.height as usize,
        mean: mean.data,
        var_mean: v.data,
        n,
        seeds: Vec::new(),
    })
}

/// Parses a side's render options, `directlab render`'s command line without the command
/// (`scenes/cbox/cbox.xml --strategy light --spp 16`), split at white space (no quoting).
/// `flag` says how the user gave it; the seed and the outputs are the caller's to choose,
/// and so is the spp where `spp_ours`.
pub(super) fn render_line(line: &str, flag: &str, spp_ours: bool) -> Result<RenderArgs, String> {
    #[derive(clap::Parser)]
    #[command(name = "render")]
    struct Line {
        #[command(flatten)]
        args: RenderArgs,
    }
    let words = line.split_whitespace();
    let parsed = <Line as clap::Parser>::try_parse_from(std::iter::once("render").chain(words))
        .map_err(|e| {
            let text = e.render().to_string();
            let first = text.lines().next().unwrap_or("");
            let first = first.trim_start_matches("error: ");
            format!("{flag} {line:?}: {first} (expected a scene and `directlab render`'s options)")
        })?;
    let a = parsed.args;
    for (given, opt) in [
        (a.out.is_some(), "--out"),
        (a.variance.is_some(), "--variance"),
        (a.stats.is_some(), "--stats"),
        (a.seed.is_some(), "--seed"),
        (a.aov.is_some(), "--aov"),
        (spp_ours && a.spp.is_some(), "--spp"),
    ] {
        if given {
            return Err(format!(
                "{flag} {line:?}: {opt} is compare's to choose (it renders the seeds{} and \
                 writes the outputs itself)",
                if spp_ours { " at each spp" } else { "" }
            ));
        }
    }
    Ok(a)
}

/// Renders `seeds` seeds of `a`, seeds `first..`, as one side; with `dir`, also writes them
/// there (`seed-000.exr`, ..., after removing an earlier run's). A non-finite sample is an
/// error: such a render is not an estimate to test. Returns the side and a line on what ran.
pub(super) fn render_seeds(
    a: &RenderArgs,
    first: u64,
    seeds: u64,
    dir: Option<&Path>,
) -> Result<(Side, String), String> {
    if let Some(dir) = dir {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        // Seeds of an earlier, longer run would join this one's: remove them.
        for e in std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))? {
            let p = e.map_err(|e| format!("{}: {e}", dir.display()))?.path();
            let ours = p
                .file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("seed-") && n.ends_with(".exr"));
            if ours {
                std::fs::remove_file(&p).map_err(|e| format!("{}: {e}", p.display()))?;
            }
        }
    }
    let mut images = Vec::new();
    let mut seconds = 0.0;
    let mut line = String::new();
    for i in 0..seeds {
        let seed = first + i;
        let (out, stats, _) = crate::render_cmd::render_args(a, Some(seed), false)?;
        if out.non_finite_samples > 0 {
            return Err(format!(
                "{}, seed {seed}: {} non-finite samples: the render is not an estimate to test",
                a.scene.display(),
                out.non_finite_samples
            ));
        }
        if let Some(dir) = dir {
            crate::film::write_exr(&dir.join(format!("seed-{i:03}.exr")), &out.mean)?;
        }
        seconds += stats.seconds;
        if i == 0 {
            line = format!(
                "{} with {}, {} spp, sampler {}",
                stats.scene, stats.strategy, stats.spp, stats.sampler
            );
        }
        images.push(out.mean);
    }
    let (w, h) = (images[0].width as usize, images[0].height as usize);
    let side = Side::from_seeds(w, h, images.into_iter().map(|i| i.data).collect());
    let last = first + seeds - 1;
    Ok((
        side,
        format!("{line}; seeds {first}..{last} in {seconds:.2} s"),
    ))
}
