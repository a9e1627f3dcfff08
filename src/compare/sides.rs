//! The two sides of a comparison: read from seeds' EXRs or a render with its variance, or
//! rendered here from two configurations.

use crate::film::read_exr;
use crate::stats::welch_map::Side;
use std::path::{Path, PathBuf};

/// Loads one side.
pub(super) fn side(
    path: &Path,
    variance: Option<&Path>,
    spp: Option<u64>,
    name: &str,
) -> Result<Side, String> {
    if path.is_dir() {
        let mut files: Vec<PathBuf> = std::fs::read_dir(path)
            .map_err(|e| format!("{}: {e}", path.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x.eq_ignore_ascii_case("exr")))
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
    let (Some(var), Some(n)) = (variance, spp) else {
        return Err(format!(
            "{}: a single render as side {name} needs --variance-{name} and --spp-{name} \
             (or give a directory of seeds' EXRs)",
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

/// How the user gave the render line named `name`.
fn flag(name: &str) -> String {
    match name {
        "power" | "power-run" | "guard" => "the configuration".into(),
        _ => format!("--render-{name}"),
    }
}

/// Parses a side's render options, `directlab render`'s command line without the command
/// (`scenes/cbox/cbox.xml --strategy light --spp 16`): split at white space, so no quoting.
pub(super) fn render_line(line: &str, name: &str) -> Result<crate::render_cmd::RenderArgs, String> {
    #[derive(clap::Parser)]
    #[command(name = "render")]
    struct Line {
        #[command(flatten)]
        args: crate::render_cmd::RenderArgs,
    }
    let words: Vec<&str> = line.split_whitespace().collect();
    let parsed = <Line as clap::Parser>::try_parse_from(std::iter::once("render").chain(words))
        .map_err(|e| {
            let text = e.render().to_string();
            let first = text
                .lines()
                .next()
                .unwrap_or("")
                .trim_start_matches("error: ");
            format!(
                "{} {line:?}: {first} (expected a scene and `directlab render`'s options)",
                flag(name)
            )
        })?;
    let a = parsed.args;
    for (given, opt) in [
        (a.out.is_some(), "--out"),
        (a.variance.is_some(), "--variance"),
        (a.stats.is_some(), "--stats"),
        (a.seed.is_some(), "--seed"),
        (a.aov.is_some(), "--aov"),
        (name == "power" && a.spp.is_some(), "--spp"),
    ] {
        if given {
            return Err(format!(
                "{} {line:?}: {opt} is compare's to choose (it renders --seeds seeds of each \
                 side{})",
                flag(name),
                if name == "power" {
                    " at each --spp"
                } else {
                    " into --out"
                }
            ));
        }
    }
    Ok(a)
}

/// Renders `seeds` seeds of one side into `dir` (`seed-000.exr`, ...), seeds `first..`; a
/// side's seeds differ from the other side's, so the two are independent even when the
/// configurations are equal. Returns the side and a line on what ran.
pub(super) fn render_side(
    a: &crate::render_cmd::RenderArgs,
    dir: &Path,
    first: u64,
    seeds: u64,
    name: &str,
) -> Result<(Side, String), String> {
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
    let mut images = Vec::new();
    let mut seconds = 0.0;
    let mut line = String::new();
    for i in 0..seeds {
        let (out, stats, _) = crate::render_cmd::render_args(a, Some(first + i), false)?;
        if out.non_finite_samples > 0 {
            return Err(format!(
                "side {name}, seed {}: {} non-finite samples: the render is not an estimate \
                 to test",
                first + i,
                out.non_finite_samples
            ));
        }
        crate::film::write_exr(&dir.join(format!("seed-{i:03}.exr")), &out.mean)?;
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
    Ok((
        side,
        format!(
            "{line}; seeds {first}..{} in {seconds:.2} s",
            first + seeds - 1
        ),
    ))
}
