//! `directlab compare A B`: did a change bias the image? Welch's t-test between two noisy
//! renders, per tile and per pixel, with no reference ([`crate::stats::welch_map`]).
//!
//! A side is a directory of EXRs, one per seed (any renderer's: the seeds are the samples,
//! which is right for correlated samplers too), or one EXR with its per-pixel variance of the
//! mean (`render --variance`) and its spp (independent samples only), or a directlab
//! configuration (`--render-a`, `--render-b`) rendered here at `--seeds` seeds. The verdict is
//! at `--alpha` over every test of the tile map (Sidak); a detected bias exits non-zero.

pub mod guard;
mod page;
pub mod power;
mod sides;

use crate::stats::welch_map::{Side, WelchMap};
use page::{histogram, p_map_png, write_tiles_csv};
use std::fmt::Write;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct CompareArgs {
    /// Side A: a directory of EXRs (one per seed), or one EXR with --variance-a and its spp
    /// (--stats-a or --spp-a; a render of independent samples only: for stratified, Sobol'
    /// or zsobol renders, whose pixels' samples are correlated, give seeds).
    #[arg(required_unless_present = "render_a", conflicts_with = "render_a")]
    pub a: Option<PathBuf>,
    /// Side B, as A.
    #[arg(required_unless_present = "render_b", conflicts_with = "render_b")]
    pub b: Option<PathBuf>,
    /// Render side A here: a scene and `directlab render`'s options, as one string
    /// ("scenes/cbox/cbox.xml --strategy light --spp 16"), at --seeds seeds.
    /// Either side may be files and the other rendered (another renderer's seeds against
    /// directlab's).
    #[arg(long)]
    pub render_a: Option<String>,
    /// Render side B here, as --render-a (with other seeds than A's).
    #[arg(long)]
    pub render_b: Option<String>,
    /// Seeds per side rendered with --render-a/-b (the samples of the test).
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u64).range(2..=10000))]
    pub seeds: u64,
    /// The variance-of-the-mean EXR of a single render A (`render --variance`).
    #[arg(long)]
    pub variance_a: Option<PathBuf>,
    /// The variance-of-the-mean EXR of a single render B.
    #[arg(long)]
    pub variance_b: Option<PathBuf>,
    /// `render --stats` of a single render A: its spp and its sampler, which must be the
    /// independent one (a correlated sampler's per-pixel variance is refused).
    #[arg(long)]
    pub stats_a: Option<PathBuf>,
    /// `render --stats` of a single render B.
    #[arg(long)]
    pub stats_b: Option<PathBuf>,
    /// Samples per pixel of a single render A (without --stats-a: its sampler is then taken
    /// on trust to be independent).
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
    /// Where the p-value maps, the histogram and the page go (and the seeds --render-a/-b
    /// render, in a/ and b/).
    #[arg(long, default_value = "reports/compare")]
    pub out: PathBuf,
}

/// The two sides, and a line saying what each is.
fn load_sides(a: &CompareArgs) -> Result<[(Side, String); 2], String> {
    // Both configurations are parsed, and the file sides read, before anything renders.
    let line = |l: &Option<String>, flag| {
        l.as_deref()
            .map(|l| sides::render_line(l, flag, false))
            .transpose()
    };
    let (ra, rb) = (
        line(&a.render_a, "--render-a")?,
        line(&a.render_b, "--render-b")?,
    );
    let file = |p: &Option<PathBuf>, spec: sides::Single, name: &str| match p {
        Some(p) => sides::side(p, spec, name).map(|s| Some((s, p.display().to_string()))),
        None => Ok(None),
    };
    let fa = file(
        &a.a,
        sides::Single::of(&a.variance_a, &a.stats_a, a.spp_a),
        "a",
    )?;
    let fb = file(
        &a.b,
        sides::Single::of(&a.variance_b, &a.stats_b, a.spp_b),
        "b",
    )?;
    let n = a.seeds;
    let sa = match (fa, &ra) {
        (Some(s), _) => s,
        (None, Some(r)) => sides::render_seeds(r, 0, n, Some(&a.out.join("a")))?,
        (None, None) => return Err("give side A (files) or --render-a".into()),
    };
    let sb = match (fb, &rb) {
        (Some(s), _) => s,
        (None, Some(r)) => sides::render_seeds(r, n, n, Some(&a.out.join("b")))?,
        (None, None) => return Err("give side B (files) or --render-b".into()),
    };
    Ok([sa, sb])
}

/// What a comparison found.
pub struct Verdict {
    pub outcome: Outcome,
    pub summary: String,
}

/// The verdict at `--alpha`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// No significant tile.
    Agree,
    /// A significant region with tiles where both sides vary.
    Biased,
    /// Significant tiles, all one-sided (see `WelchMap::one_sided`).
    Inconclusive,
}

pub fn run(a: &CompareArgs) -> Result<Verdict, String> {
    if !(a.alpha > 0.0 && a.alpha < 1.0) {
        return Err(format!("--alpha {}: expected a level in (0, 1)", a.alpha));
    }
    let [(sa, name_a), (sb, name_b)] = load_sides(a)?;
    if (sa.width, sa.height) != (sb.width, sb.height) {
        return Err(format!(
            "{name_a} is {}x{} but {name_b} is {}x{}: compare renders of the same film",
            sa.width, sa.height, sb.width, sb.height
        ));
    }
    let k = a.tile as usize;
    let pixels = WelchMap::new(&sa, &sb);
    let Tested {
        tiles,
        level,
        regions,
        outcome,
    } = test(&sa, &sb, k, a.alpha);
    std::fs::create_dir_all(&a.out).map_err(|e| format!("{}: {e}", a.out.display()))?;
    p_map_png(&a.out.join("p-pixels.png"), &pixels)?;
    p_map_png(&a.out.join("p-tiles.png"), &tiles)?;
    write_tiles_csv(&a.out.join("tiles.csv"), &tiles)?;
    page::images(&a.out, &sa, &sb)?;
    let tested = tiles.p_values();
    let hist = histogram(&tested, 20);
    let one_sided = tiles.one_sided.iter().filter(|x| **x).count();
    let mut md = format!(
        "# compare: A against B\n\n- A: {name_a}\n- B: {name_b}\n\n{}x{} pixels; side A {} \
         samples, side B {}; {k}x{k} tiles; alpha {} over {} tile tests (Sidak: {level:.3e} \
         each).\n\n**{}**\n\n",
        sa.width,
        sa.height,
        sa.n,
        sb.n,
        a.alpha,
        tested.len(),
        match outcome {
            Outcome::Agree => "No bias detected.",
            Outcome::Biased => "Bias detected.",
            Outcome::Inconclusive => "Inconclusive.",
        }
    );
    if outcome == Outcome::Inconclusive {
        let _ = writeln!(md, "{INCONCLUSIVE}\n");
    }
    for (i, r) in regions.iter().take(5).enumerate() {
        let [x0, y0, x1, y1] = r.bbox;
        let _ = writeln!(
            md,
            "- region {}: {} tiles, pixels x {}..{}, y {}..{}, {}{}",
            i + 1,
            r.units,
            x0 * k,
            ((x1 + 1) * k).min(sa.width) - 1,
            y0 * k,
            ((y1 + 1) * k).min(sa.height) - 1,
            relative(r.rel_diff),
            if r.one_sided {
                " (one-sided: a side's seeds all equal)"
            } else {
                ""
            }
        );
    }
    let _ = writeln!(
        md,
        "\nExcluded (non-finite input): {} pixels, {} tiles; {} tile channels constant and \
         equal on both sides, not tested; {one_sided} tiles one-sided (a channel constant on \
         one side only: its variance is unknown, so the tile alone is no evidence).\n\n\
         Tile p-values, 20 bins from 0 to 1 (uniform when A and B converge to the same image): \
         {hist:?}\n\n## p-value maps\n\nBlack: p near 0; white: p near 1; red: not tested \
         (a non-finite input, or constant).\n\n\
         ![tiles](p-tiles.png)\n\n![pixels](p-pixels.png)\n\n## A, B and A - B\n\n\
         A and B at exposure 1; A - B per pixel in standard errors of the difference (red: A \
         brighter, blue: B brighter, full colour at 4).\n\n\
         ![A](a.png) ![B](b.png) ![A - B](diff.png)",
        pixels.excluded(),
        tiles.excluded(),
        tiles.constant
    );
    crate::report::write_report(&a.out, &md, None, Default::default())?;
    let page = a.out.join("index.html");
    let summary = match (outcome, regions.first()) {
        (Outcome::Agree, _) | (_, None) => format!(
            "no bias detected at alpha {} ({} tile tests; smallest p {:.3e} vs {level:.3e})",
            a.alpha,
            tested.len(),
            tested.iter().copied().fold(1.0, f64::min)
        ),
        (Outcome::Biased, Some(r)) => format!(
            "bias detected: {} region(s); the largest, {} tiles, differs by {}; see {}",
            regions.len(),
            r.units,
            relative(r.rel_diff),
            page.display()
        ),
        (Outcome::Inconclusive, Some(_)) => format!(
            "inconclusive: {} significant region(s), all one-sided. {INCONCLUSIVE} See {}",
            regions.len(),
            page.display()
        ),
    };
    // Non-finite input is excluded, never tested, and said so beside the verdict too.
    let summary = match pixels.excluded() {
        0 => summary,
        n => format!(
            "{summary}\nexcluded: {n} pixel(s) with non-finite input ({} tile(s) not tested; \
             mapped in red on the page)",
            tiles.excluded()
        ),
    };
    Ok(Verdict { outcome, summary })
}

/// The tile map of two sides and its verdict.
pub(crate) struct Tested {
    pub tiles: WelchMap,
    /// The per-test level (Sidak over every tile test).
    pub level: f64,
    /// Significant regions: those with a tile where both sides vary first, largest first.
    pub regions: Vec<crate::stats::welch_map::Region>,
    pub outcome: Outcome,
}

/// Welch's test of `a` against `b` over `k` x `k` tiles at family-wise `alpha`.
pub(crate) fn test(a: &Side, b: &Side, k: usize, alpha: f64) -> Tested {
    let tiles = WelchMap::new(&a.tiled(k), &b.tiled(k));
    let level = tiles.level(alpha);
    let mut regions = tiles.regions(level);
    // Regions whose every tile has a side of all-equal seeds come last: alone they are no
    // evidence (see `WelchMap::one_sided`).
    regions.sort_by_key(|r| (r.one_sided, std::cmp::Reverse(r.units)));
    let outcome = match regions.first() {
        None => Outcome::Agree,
        Some(r) if r.one_sided => Outcome::Inconclusive,
        Some(_) => Outcome::Biased,
    };
    Tested {
        tiles,
        level,
        regions,
        outcome,
    }
}

const INCONCLUSIVE: &str = "Every significant tile has a side whose seeds are \
    all equal there, so its variance is unknown (a contribution too rare to have been seen, or \
    a real difference). Raise the spp or the seeds.";

/// A region's A/B - 1, or what it is when B is 0 there.
pub(crate) fn relative(r: f64) -> String {
    match r.is_nan() {
        true => "B is 0 there".into(),
        false => format!("A/B - 1 = {:+.3} %", 100.0 * r),
    }
}

/// The command: prints the verdict; a detected bias is an error (non-zero exit).
pub fn command(a: &CompareArgs) -> Result<(), String> {
    let v = run(a)?;
    println!("{}", v.summary);
    match v.outcome {
        Outcome::Agree => Ok(()),
        Outcome::Biased => Err("A and B differ by more than their noise".into()),
        Outcome::Inconclusive => Err("too few samples to tell whether A and B differ".into()),
    }
}
