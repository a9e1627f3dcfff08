//! Experiment files (`experiments/*.toml`): what to render, how often, against which reference,
//! and which figures to draw. `experiments/README.md` documents every field with an example.
//!
//! Unknown keys are errors (a misspelt `sps = [...]` must not silently fall back to a default).
//! Paths are relative to the experiment file, so an experiment runs from any working directory.

use crate::cli::{HeuristicArg, LightSamplingArg, SelectionArg, StrategyArg, StrategyArgs};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Experiment {
    /// Output folder name under the reports directory; defaults to the file stem.
    pub name: Option<String>,
    pub title: Option<String>,
    /// Markdown paragraph put at the top of the report.
    #[serde(default)]
    pub description: String,
    /// Scene file, relative to the experiment file.
    pub scene: PathBuf,
    /// `-D name=value` overrides of the scene's `<default>`s.
    #[serde(default)]
    pub defines: BTreeMap<String, String>,
    /// Samples per pixel of the sweep.
    pub spp: Vec<u32>,
    /// Independent repetitions of every (strategy, spp); seeds are 0..seeds.
    #[serde(default = "default_seeds")]
    pub seeds: u32,
    #[serde(rename = "strategy")]
    pub strategies: Vec<StrategySpec>,
    pub reference: ReferenceSpec,
    #[serde(default)]
    pub metrics: MetricsSpec,
    #[serde(default)]
    pub equal_time: Option<EqualTimeSpec>,
    #[serde(default)]
    pub figures: FiguresSpec,
    /// Overrides applied by `--quick` (tests, smoke runs).
    #[serde(default)]
    pub quick: Option<QuickSpec>,
}

fn default_seeds() -> u32 {
    3
}

/// One named estimator, with the CLI's option names and values.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StrategySpec {
    /// Legend name; the CSV and file names use the strategy's stable label instead.
    pub name: String,
    pub strategy: Option<StrategyArg>,
    pub emitter_selection: Option<SelectionArg>,
    pub light_sampling: Option<LightSamplingArg>,
    pub heuristic: Option<HeuristicArg>,
    pub emitter_samples: Option<u32>,
    pub bsdf_samples: Option<u32>,
}

impl StrategySpec {
    pub fn args(&self) -> StrategyArgs {
        StrategyArgs {
            strategy: self.strategy,
            emitter_selection: self.emitter_selection,
            light_sampling: self.light_sampling,
            heuristic: self.heuristic,
            emitter_samples: self.emitter_samples,
            bsdf_samples: self.bsdf_samples,
        }
    }
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceSpec {
    pub spp: u32,
    /// Estimator of the reference (CLI names); unset fields keep the scene's integrator.
    #[serde(default)]
    pub strategy: StrategyArgs,
    /// Must differ from the sweep's seeds 0..seeds, or the reference would share samples
    /// with a run and their errors would be correlated.
    #[serde(default = "default_reference_seed")]
    pub seed: u64,
}

fn default_reference_seed() -> u64 {
    0x5EED_0000_0000
}

#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum ErrorMetric {
    Mse,
    Relmse,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MetricsSpec {
    /// relMSE = mean((x - r)^2 / (r^2 + epsilon)).
    #[serde(default = "default_eps")]
    pub relmse_epsilon: f64,
    /// The error the plots and tables use.
    #[serde(default = "default_metric")]
    pub primary: ErrorMetric,
}

fn default_eps() -> f64 {
    0.01
}

fn default_metric() -> ErrorMetric {
    ErrorMetric::Relmse
}

impl Default for MetricsSpec {
    fn default() -> Self {
        MetricsSpec {
            relmse_epsilon: default_eps(),
            primary: default_metric(),
        }
    }
}

/// Equal-time comparisons: every strategy gets the same render-time budget; its spp is set
/// from its sample rate measured in the sweep.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EqualTimeSpec {
    pub seconds: Vec<f64>,
    #[serde(default = "one")]
    pub seeds: u32,
}

fn one() -> u32 {
    1
}

/// A zoomed region, in fractions of the image width/height so it survives `--quick`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Crop {
    pub name: String,
    pub x: f64,
    pub y: f64,
    pub width: f64,
    pub height: f64,
}

#[derive(Clone, Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct FiguresSpec {
    /// spp of the side-by-side comparison (default: the middle sweep spp).
    pub equal_spp: Option<u32>,
    /// spp of the variance and efficiency maps (default: the highest sweep spp, where the
    /// per-pixel variance estimates are least noisy).
    pub variance_spp: Option<u32>,
    /// spp values shown as an image row per strategy, each with its error printed under it.
    #[serde(default)]
    pub progression: Vec<u32>,
    #[serde(default)]
    pub crops: Vec<Crop>,
    /// Multiplies radiance before sRGB display (1 = as rendered).
    pub exposure: Option<f64>,
}

/// What `--quick` replaces. Crops are fractional and need no override.
#[derive(Clone, Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct QuickSpec {
    #[serde(default)]
    pub defines: BTreeMap<String, String>,
    pub spp: Option<Vec<u32>>,
    pub seeds: Option<u32>,
    pub reference_spp: Option<u32>,
    pub equal_time_seconds: Option<Vec<f64>>,
    pub equal_spp: Option<u32>,
    pub progression: Option<Vec<u32>>,
}

/// An experiment ready to run: quick overrides applied, paths resolved, values checked.
#[derive(Clone, Debug)]
pub struct Resolved {
    pub name: String,
    pub file: PathBuf,
    pub scene: PathBuf,
    pub defines: Vec<(String, String)>,
    pub quick: bool,
    pub exp: Experiment,
}

impl Resolved {
    pub fn equal_spp(&self) -> u32 {
        self.exp
            .figures
            .equal_spp
            .unwrap_or(self.exp.spp[self.exp.spp.len() / 2])
    }

    pub fn variance_spp(&self) -> u32 {
        self.exp
            .figures
            .variance_spp
            .unwrap_or_else(|| *self.exp.spp.iter().max().expect("validated non-empty"))
    }
}

pub fn parse(text: &str, file: &Path) -> Result<Experiment, String> {
    toml::from_str(text).map_err(|e| format!("{}: {e}", file.display()))
}

/// Reads, applies `--quick` and validates an experiment file.
pub fn load(file: &Path, quick: bool) -> Result<Resolved, String> {
    let text = std::fs::read_to_string(file)
        .map_err(|e| format!("{}: cannot read experiment: {e}", file.display()))?;
    resolve(parse(&text, file)?, file, quick)
}

pub fn resolve(mut exp: Experiment, file: &Path, quick: bool) -> Result<Resolved, String> {
    let stem = file
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "experiment".into());
    let mut name = exp.name.clone().unwrap_or(stem);
    if quick {
        let q = exp.quick.clone().unwrap_or_default();
        exp.defines.extend(q.defines);
        if let Some(s) = q.spp {
            exp.spp = s;
        }
        if let Some(s) = q.seeds {
            exp.seeds = s;
        }
        if let Some(s) = q.reference_spp {
            exp.reference.spp = s;
        }
        if let (Some(t), Some(et)) = (q.equal_time_seconds, exp.equal_time.as_mut()) {
            et.seconds = t;
        }
        if q.equal_spp.is_some() {
            exp.figures.equal_spp = q.equal_spp;
        }
        // The full run's variance spp is rarely in the quick sweep: use the quick maximum.
        exp.figures.variance_spp = None;
        if let Some(p) = q.progression {
            exp.figures.progression = p;
        }
        // Quick results live apart, so they never mix with (or resume into) the full run.
        name.push_str("-quick");
    }
    validate(&exp, file)?;
    let scene = file.parent().unwrap_or(Path::new(".")).join(&exp.scene);
    let defines = exp
        .defines
        .iter()
        .map(|(k, v)| (k.clone(), v.clone()))
        .collect();
    Ok(Resolved {
        name,
        file: file.to_path_buf(),
        scene,
        defines,
        quick,
        exp,
    })
}

fn validate(exp: &Experiment, file: &Path) -> Result<(), String> {
    let fail = |m: String| Err(format!("{}: {m}", file.display()));
    if exp.spp.is_empty() || exp.spp.contains(&0) {
        return fail("`spp` needs at least one value, all positive".into());
    }
    if exp.seeds == 0 {
        return fail("`seeds` must be at least 1".into());
    }
    for (what, v) in [
        ("figures.equal_spp", exp.figures.equal_spp),
        ("figures.variance_spp", exp.figures.variance_spp),
    ] {
        if let Some(v) = v.filter(|v| !exp.spp.contains(v)) {
            return fail(format!(
                "{what} = {v} is not one of the sweep's spp {:?}",
                exp.spp
            ));
        }
    }
    if exp.strategies.is_empty() {
        return fail("at least one [[strategy]] is needed".into());
    }
    if exp.reference.spp < 2 {
        return fail("reference.spp must be at least 2 (its noise is measured from it)".into());
    }
    if exp.reference.seed < exp.seeds as u64 {
        return fail(format!(
            "reference.seed {} is one of the sweep's seeds 0..{}; the reference must be independent",
            exp.reference.seed, exp.seeds
        ));
    }
    if !(exp.metrics.relmse_epsilon > 0.0) {
        return fail("metrics.relmse_epsilon must be positive".into());
    }
    let mut names: Vec<&str> = exp.strategies.iter().map(|s| s.name.as_str()).collect();
    names.sort();
    if let Some(w) = names.windows(2).find(|w| w[0] == w[1]) {
        return fail(format!("strategy name '{}' is used twice", w[0]));
    }
    if let Some(et) = &exp.equal_time {
        if et.seconds.iter().any(|s| !(*s > 0.0)) || et.seeds == 0 {
            return fail("equal_time needs positive seconds and seeds >= 1".into());
        }
    }
    for c in &exp.figures.crops {
        let ok = c.x >= 0.0
            && c.y >= 0.0
            && c.width > 0.0
            && c.height > 0.0
            && c.x + c.width <= 1.0
            && c.y + c.height <= 1.0;
        if !ok {
            return fail(format!(
                "crop '{}' must lie inside the image (fractions in [0, 1])",
                c.name
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const EXAMPLE: &str = r#"
        title = "demo"
        scene = "../scenes/cbox/cbox.xml"
        defines = { res = "64" }
        spp = [1, 4, 16]
        seeds = 2
        [reference]
        spp = 256
        strategy = { strategy = "mis", heuristic = "balance" }
        [metrics]
        relmse_epsilon = 0.001
        [[strategy]]
        name = "light"
        strategy = "light"
        emitter_selection = "power"
        light_sampling = "solid-angle"
        [[strategy]]
        name = "one-sample"
        strategy = "mis-onesample"
        [equal_time]
        seconds = [0.5]
        [figures]
        crops = [{ name = "corner", x = 0.0, y = 0.0, width = 0.25, height = 0.25 }]
        [quick]
        defines = { res = "16" }
        spp = [1, 2]
        reference_spp = 8
    "#;

    fn file() -> PathBuf {
        PathBuf::from("experiments/demo.toml")
    }

    #[test]
    fn parses_the_example_and_applies_quick() {
        let exp = parse(EXAMPLE, &file()).unwrap();
        assert_eq!(exp.strategies.len(), 2);
        assert!(matches!(
            exp.strategies[0].strategy,
            Some(StrategyArg::Light)
        ));
        assert!(matches!(
            exp.strategies[0].light_sampling,
            Some(LightSamplingArg::SolidAngle)
        ));
        assert!(matches!(
            exp.strategies[1].strategy,
            Some(StrategyArg::MisOnesample)
        ));
        assert!(matches!(
            exp.reference.strategy.heuristic,
            Some(HeuristicArg::Balance)
        ));
        assert_eq!(exp.metrics.relmse_epsilon, 0.001);

        let full = resolve(exp.clone(), &file(), false).unwrap();
        assert_eq!(full.name, "demo");
        assert_eq!(
            full.scene,
            PathBuf::from("experiments/../scenes/cbox/cbox.xml")
        );
        assert_eq!(full.defines, vec![("res".into(), "64".into())]);
        assert_eq!(full.equal_spp(), 4);
        assert_eq!(full.variance_spp(), 16);

        let quick = resolve(exp, &file(), true).unwrap();
        assert_eq!(quick.name, "demo-quick");
        assert_eq!(quick.exp.spp, vec![1, 2]);
        assert_eq!(quick.exp.reference.spp, 8);
        assert_eq!(quick.defines, vec![("res".into(), "16".into())]);
    }

    #[test]
    fn rejects_typos_and_bad_values() {
        let typo = EXAMPLE.replace("seeds = 2", "sedes = 2");
        assert!(parse(&typo, &file()).unwrap_err().contains("sedes"));
        let bad_name = EXAMPLE.replace("\"solid-angle\"", "\"solid_angle\"");
        assert!(parse(&bad_name, &file()).is_err());
        let zero = EXAMPLE.replace("spp = [1, 4, 16]", "spp = [0, 4]");
        let e = resolve(parse(&zero, &file()).unwrap(), &file(), false).unwrap_err();
        assert!(e.contains("spp"), "{e}");
        let shared_seed = EXAMPLE.replace("spp = 256", "spp = 256\nseed = 1");
        let e = resolve(parse(&shared_seed, &file()).unwrap(), &file(), false).unwrap_err();
        assert!(e.contains("independent"), "{e}");
        let off = EXAMPLE.replace("[figures]", "[figures]\nequal_spp = 8");
        let e = resolve(parse(&off, &file()).unwrap(), &file(), false).unwrap_err();
        assert!(e.contains("equal_spp = 8 is not one of"), "{e}");
        let crop = EXAMPLE.replace("width = 0.25", "width = 1.25");
        let e = resolve(parse(&crop, &file()).unwrap(), &file(), false).unwrap_err();
        assert!(e.contains("crop"), "{e}");
    }
}
