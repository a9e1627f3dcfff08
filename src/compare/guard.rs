//! `directlab guard`: the renderer's regression guard. Renders every bundled scene with its
//! own settings (strategy, sampler; a small film and 64 spp) at eight seeds, and compares the
//! per-tile means with stored ones (`tests/regression/tiles.json`, eight other seeds) by the
//! two-run test: a change that moves an image by more than its noise fails, even when the
//! image checksums were updated on purpose. `--store` rewrites the stored tiles (after a
//! change that is meant to move an image, with the reason in the commit).

use super::{test, Outcome};
use crate::stats::welch_map::Side;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::PathBuf;

/// The bundled scenes the guard renders, with the defines that make their films small.
pub const SCENES: &[(&str, &[(&str, &str)])] = &[
    ("cbox/cbox.xml", &[("res", "32")]),
    ("cbox-meshlight/cbox-meshlight.xml", &[("res", "32")]),
    ("cbox-plastic/cbox-plastic.xml", &[("res", "32")]),
    ("cbox-materials/cbox-materials.xml", &[("res", "32")]),
    ("cbox-twolights/cbox-twolights.xml", &[("res", "32")]),
    ("triangle-light/triangle-light.xml", &[("res", "32")]),
    (
        "veach-mis/veach-mis.xml",
        &[("width", "48"), ("height", "32")],
    ),
    ("many-lights/grid.xml", &[("width", "48"), ("height", "32")]),
];

/// Samples per pixel of each seed's render.
const SPP: u32 = 64;
/// Seeds per side.
const SEEDS: u64 = 8;
/// Tile side in pixels.
const TILE: usize = 8;
/// The stored side's seeds start here, the checked side's at `CHECK_SEED`.
const STORE_SEED: u64 = 10_000;
const CHECK_SEED: u64 = 20_000;

#[derive(clap::Args, Debug)]
pub struct GuardArgs {
    /// Rewrite the stored tiles from this build instead of checking against them.
    #[arg(long)]
    pub store: bool,
    /// The stored tiles.
    #[arg(long, default_value = "tests/regression/tiles.json")]
    pub tiles: PathBuf,
    /// The bundled scenes' directory.
    #[arg(long, default_value = "scenes")]
    pub scenes: PathBuf,
    /// Family-wise significance over every scene (Sidak per scene, then over its tiles).
    #[arg(long, default_value_t = 0.01)]
    pub alpha: f64,
}

/// One scene's stored tiles.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct Tiles {
    pub width: usize,
    pub height: usize,
    pub seeds: u64,
    pub spp: u32,
    pub tile: usize,
    /// Per tile and channel: the mean over seeds and the variance of that mean.
    pub mean: Vec<[f64; 3]>,
    pub var_mean: Vec<[f64; 3]>,
}

impl Tiles {
    fn of(s: &Side) -> Tiles {
        Tiles {
            width: s.width,
            height: s.height,
            seeds: s.n,
            spp: SPP,
            tile: TILE,
            mean: s.mean.clone(),
            var_mean: s.var_mean.clone(),
        }
    }

    fn side(&self) -> Side {
        Side {
            width: self.width,
            height: self.height,
            mean: self.mean.clone(),
            var_mean: self.var_mean.clone(),
            n: self.seeds,
            seeds: Vec::new(),
        }
    }
}

/// A scene's render line for `compare`'s parser.
fn line(a: &GuardArgs, scene: &str, defines: &[(&str, &str)]) -> String {
    let mut l = a.scenes.join(scene).display().to_string();
    for (k, v) in defines {
        let _ = write!(l, " -D {k}={v}");
    }
    format!("{l} --spp {SPP}")
}

/// `SEEDS` renders of `line` from seed `first`, averaged over `TILE` x `TILE` tiles.
pub(crate) fn render_tiles(line: &str, first: u64) -> Result<Side, String> {
    let a = super::sides::render_line(line, "the guard's configuration", false)?;
    let (side, _) = super::sides::render_seeds(&a, first, SEEDS, None)?;
    Ok(side.tiled(TILE))
}

/// The verdict on one scene's tiles against the stored ones at `alpha`.
pub(crate) fn check(stored: &Tiles, now: &Side, alpha: f64) -> Result<(Outcome, String), String> {
    if (stored.width, stored.height) != (now.width, now.height) {
        return Err(format!(
            "{}x{} tiles stored, {}x{} rendered: the guard's settings changed; run --store",
            stored.width, stored.height, now.width, now.height
        ));
    }
    let t = test(&stored.side(), now, 1, alpha);
    let words = match t.regions.first() {
        None => format!(
            "agrees ({} tile tests, smallest p {:.2e} vs {:.2e})",
            t.tiles.p_values().len(),
            t.tiles.p_values().iter().copied().fold(1.0, f64::min),
            t.level
        ),
        Some(r) => format!(
            "{}: {} region(s), the largest {} tiles at tiles x {}..{}, y {}..{}, {}",
            match t.outcome {
                Outcome::Biased => "MOVED",
                _ => "inconclusive",
            },
            t.regions.len(),
            r.units,
            r.bbox[0],
            r.bbox[2],
            r.bbox[1],
            r.bbox[3],
            super::relative(r.rel_diff)
        ),
    };
    Ok((t.outcome, words))
}

/// The command.
pub fn command(a: &GuardArgs) -> Result<(), String> {
    if !(a.alpha > 0.0 && a.alpha < 1.0) {
        return Err(format!("--alpha {}: expected a level in (0, 1)", a.alpha));
    }
    if a.store {
        let mut all = BTreeMap::new();
        for (scene, defines) in SCENES {
            let side = render_tiles(&line(a, scene, defines), STORE_SEED)?;
            all.insert(scene.to_string(), Tiles::of(&side));
        }
        let json = serde_json::to_string(&all).map_err(|e| e.to_string())?;
        if let Some(d) = a.tiles.parent() {
            std::fs::create_dir_all(d).map_err(|e| format!("{}: {e}", d.display()))?;
        }
        crate::output::write_atomic(&a.tiles, |tmp| {
            std::fs::write(tmp, &json).map_err(|e| format!("{}: {e}", a.tiles.display()))
        })?;
        println!(
            "stored {} scenes' tiles in {}",
            all.len(),
            a.tiles.display()
        );
        return Ok(());
    }
    let text = std::fs::read_to_string(&a.tiles).map_err(|e| {
        format!(
            "{}: {e} (directlab guard --store writes it)",
            a.tiles.display()
        )
    })?;
    let stored: BTreeMap<String, Tiles> = serde_json::from_str(&text)
        .map_err(|e| format!("{}: not the guard's tiles: {e}", a.tiles.display()))?;
    let per_scene = crate::stats::ttest::sidak(a.alpha, SCENES.len());
    let mut moved = Vec::new();
    for (scene, defines) in SCENES {
        let Some(s) = stored.get(*scene) else {
            return Err(format!(
                "{}: no tiles for {scene}; run directlab guard --store",
                a.tiles.display()
            ));
        };
        let now = render_tiles(&line(a, scene, defines), CHECK_SEED)?;
        let (outcome, words) = check(s, &now, per_scene)?;
        println!("{scene}: {words}");
        if outcome != Outcome::Agree {
            moved.push(scene.to_string());
        }
    }
    match moved.is_empty() {
        true => Ok(()),
        false => Err(format!(
            "{} of {} bundled scenes differ from the stored tiles by more than their noise \
             (alpha {} over all): {}",
            moved.len(),
            SCENES.len(),
            a.alpha,
            moved.join(", ")
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The guard's own check: the Cornell box rendered at the check seeds agrees with itself
    /// rendered at the store seeds, and is caught when its light is 3 % brighter everywhere
    /// or 10 % brighter on one wall (the left eighth of the film).
    #[test]
    fn the_guard_catches_small_moves() {
        let scenes = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes");
        let a = GuardArgs {
            store: false,
            tiles: PathBuf::new(),
            scenes: scenes.into(),
            alpha: 0.01,
        };
        let l = line(&a, "cbox/cbox.xml", &[("res", "32")]);
        let stored = Tiles::of(&render_tiles(&l, STORE_SEED).unwrap());
        let now = render_tiles(&l, CHECK_SEED).unwrap();
        assert_eq!(check(&stored, &now, 0.01).unwrap().0, Outcome::Agree);
        // The seeds are what the test reads; `scaled` scales tiles where `f` is above 1.
        let scaled = |f: &dyn Fn(usize) -> f64| {
            let seeds = now.seeds.iter().map(|img| {
                img.iter()
                    .enumerate()
                    .map(|(i, p)| p.map(|c| c * f(i)))
                    .collect()
            });
            Side::from_seeds(now.width, now.height, seeds.collect())
        };
        let (o, words) = check(&stored, &scaled(&|_| 1.03), 0.01).unwrap();
        assert_eq!(o, Outcome::Biased, "{words}");
        let w = now.width;
        let wall = scaled(&|i| if i % w == 0 { 1.1 } else { 1.0 });
        let (o, words) = check(&stored, &wall, 0.01).unwrap();
        assert!(
            o == Outcome::Biased && words.contains("tiles at tiles x 0..0"),
            "{words}"
        );
    }
}
