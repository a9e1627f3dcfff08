//! `directlab compare A B`: did a change bias the image? Welch's t-test between two noisy
//! renders, per tile and per pixel, with no reference ([`crate::stats::welch_map`]).
//!
//! A side is a directory of EXRs, one per seed (any renderer's: the seeds are the samples,
//! which is right for correlated samplers too), or one EXR with its per-pixel variance of the
//! mean (`render --variance`) and its spp (independent samples only). The verdict is at
//! `--alpha` over every test of the tile map (Sidak); a detected bias exits non-zero.

use crate::film::{read_exr, write_png_rgb8};
use crate::stats::welch_map::{Side, WelchMap};
use std::fmt::Write;
use std::path::{Path, PathBuf};

#[derive(clap::Args, Debug)]
pub struct CompareArgs {
    /// Side A: a directory of EXRs (one per seed), or one EXR with --variance-a and --spp-a
    /// (a render of independent samples only: for stratified, Sobol' or zsobol renders,
    /// whose pixels' samples are correlated, give seeds).
    pub a: PathBuf,
    /// Side B, as A.
    pub b: PathBuf,
    /// The variance-of-the-mean EXR of a single render A (`render --variance`).
    #[arg(long)]
    pub variance_a: Option<PathBuf>,
    /// The variance-of-the-mean EXR of a single render B.
    #[arg(long)]
    pub variance_b: Option<PathBuf>,
    /// Samples per pixel of a single render A.
    #[arg(long)]
    pub spp_a: Option<u64>,
    /// Samples per pixel of a single render B.
    #[arg(long)]
    pub spp_b: Option<u64>,
    /// Tile side in pixels for the verdict (1: per pixel).
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u64).range(1..=4096))]
    pub tile: u64,
    /// Significance level of the whole comparison.
    #[arg(long, default_value_t = 0.01)]
    pub alpha: f64,
    /// Where the p-value maps, the histogram and the page go.
    #[arg(long, default_value = "reports/compare")]
    pub out: PathBuf,
}

/// Loads one side.
fn side(
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

/// What a comparison found.
pub struct Verdict {
    pub biased: bool,
    pub summary: String,
}

pub fn run(a: &CompareArgs) -> Result<Verdict, String> {
    if !(a.alpha > 0.0 && a.alpha < 1.0) {
        return Err(format!("--alpha {}: expected a level in (0, 1)", a.alpha));
    }
    let sa = side(&a.a, a.variance_a.as_deref(), a.spp_a, "a")?;
    let sb = side(&a.b, a.variance_b.as_deref(), a.spp_b, "b")?;
    if (sa.width, sa.height) != (sb.width, sb.height) {
        return Err(format!(
            "{} is {}x{} but {} is {}x{}: compare renders of the same film",
            a.a.display(),
            sa.width,
            sa.height,
            a.b.display(),
            sb.width,
            sb.height
        ));
    }
    let k = a.tile as usize;
    let pixels = WelchMap::new(&sa, &sb);
    let tiles = WelchMap::new(&sa.tiled(k), &sb.tiled(k));
    let level = tiles.level(a.alpha);
    let regions = tiles.regions(level);
    let biased = !regions.is_empty();
    std::fs::create_dir_all(&a.out).map_err(|e| format!("{}: {e}", a.out.display()))?;
    p_map_png(&a.out.join("p-pixels.png"), &pixels)?;
    p_map_png(&a.out.join("p-tiles.png"), &tiles)?;
    write_tiles_csv(&a.out.join("tiles.csv"), &tiles)?;
    let tested = tiles.p_values();
    let hist = histogram(&tested, 20);
    let mut md =
        format!(
        "# compare: {} against {}\n\n{}x{} pixels; side A {} samples, side B {}; {k}x{k} tiles; \
         alpha {} over {} tile tests (Sidak: {level:.3e} each).\n\n**{}**\n\n",
        a.a.display(),
        a.b.display(),
        sa.width,
        sa.height,
        sa.n,
        sb.n,
        a.alpha,
        tested.len(),
        if biased { "Bias detected." } else { "No bias detected." }
    );
    for (i, r) in regions.iter().take(5).enumerate() {
        let [x0, y0, x1, y1] = r.bbox;
        let _ = writeln!(
            md,
            "- region {}: {} tiles, pixels x {}..{}, y {}..{}, A/B - 1 = {:+.3} %",
            i + 1,
            r.units,
            x0 * k,
            ((x1 + 1) * k).min(sa.width) - 1,
            y0 * k,
            ((y1 + 1) * k).min(sa.height) - 1,
            100.0 * r.rel_diff
        );
    }
    let _ = writeln!(
        md,
        "\nExcluded (non-finite input): {} pixels, {} tiles; {} tile channels constant and \
         equal on both sides, not tested.\n\n\
         Tile p-values, 20 bins from 0 to 1 (uniform when A and B converge to the same image): \
         {hist:?}\n\n## p-value maps\n\nBlack: p near 0; white: p near 1; red: not tested \
         (a non-finite input, or constant).\n\n\
         ![tiles](p-tiles.png)\n\n![pixels](p-pixels.png)",
        pixels.excluded(),
        tiles.excluded(),
        tiles.constant
    );
    crate::report::write_report(&a.out, &md, None, Default::default())?;
    let summary = match regions.first() {
        None => format!(
            "no bias detected at alpha {} ({} tile tests; smallest p {:.3e} vs {level:.3e})",
            a.alpha,
            tested.len(),
            tested.iter().copied().fold(1.0, f64::min)
        ),
        Some(r) => format!(
            "bias detected: {} region(s); the largest, {} tiles, differs by {:+.3} % (A/B - 1); \
             see {}",
            regions.len(),
            r.units,
            100.0 * r.rel_diff,
            a.out.join("index.html").display()
        ),
    };
    Ok(Verdict { biased, summary })
}

/// `tiles.csv`: per tile and channel, the p-value and A - B (empty where excluded).
fn write_tiles_csv(path: &Path, m: &WelchMap) -> Result<(), String> {
    let mut text = String::from("tile_x,tile_y,p_r,p_g,p_b,diff_r,diff_g,diff_b\n");
    let cell = |x: f64| {
        if x.is_nan() {
            String::new()
        } else {
            format!("{x:.6e}")
        }
    };
    for (i, (p, d)) in m.p.iter().zip(&m.diff).enumerate() {
        let _ = writeln!(
            text,
            "{},{},{},{},{},{},{},{}",
            i % m.width,
            i / m.width,
            cell(p[0]),
            cell(p[1]),
            cell(p[2]),
            cell(d[0]),
            cell(d[1]),
            cell(d[2])
        );
    }
    crate::output::write_atomic(path, |tmp| {
        std::fs::write(tmp, &text).map_err(|e| format!("{}: {e}", path.display()))
    })
}

/// Counts of `p` in `bins` equal bins of [0, 1].
fn histogram(p: &[f64], bins: usize) -> Vec<usize> {
    let mut h = vec![0; bins];
    for x in p {
        h[((x * bins as f64) as usize).min(bins - 1)] += 1;
    }
    h
}

/// The smallest p-value of each unit in grey (log scale: black at 1e-6 or below, white at
/// 1), untested units red.
fn p_map_png(path: &Path, m: &WelchMap) -> Result<(), String> {
    let rgb: Vec<u8> = m
        .min_p()
        .iter()
        .flat_map(|p| match p.is_nan() {
            true => [255, 0, 0],
            false => {
                let g = (1.0 + p.max(1e-6).log10() / 6.0).clamp(0.0, 1.0);
                let g = (255.0 * g).round() as u8;
                [g, g, g]
            }
        })
        .collect();
    write_png_rgb8(path, m.width as u32, m.height as u32, &rgb)
}

/// The command: prints the verdict; a detected bias is an error (non-zero exit).
pub fn command(a: &CompareArgs) -> Result<(), String> {
    let v = run(a)?;
    println!("{}", v.summary);
    match v.biased {
        true => Err("A and B differ by more than their noise".into()),
        false => Ok(()),
    }
}
