//! Experiment files (`experiments/*.toml`): what to render, how often, against which reference,
//! and which figures to draw. `experiments/README.md` documents every field with an example.
//!
//! Unknown keys are errors (a misspelt `sps = [...]` must not silently fall back to a default).
//! Paths are relative to the experiment file, so an experiment runs from any working directory.
//! A file names one `scene`, or several `[[case]]`s (see `cases.rs`).

use super::cases::{AccumulationSpec, Case, CaseSpec, ClosedForm, InvalidSpec, ProbeSpec};
use super::method::SamplerSpec;
use crate::emitter::{EmitterSelection, LightSampling};
use crate::integrator::StrategyOverrides;
use crate::scene::desc::{Heuristic, StrategyKind};
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
    /// Scene file, relative to the experiment file (or `[[case]]` entries instead).
    pub scene: Option<PathBuf>,
    #[serde(rename = "case", default)]
    pub cases: Vec<CaseSpec>,
    /// `-D name=value` overrides of the scene's `<default>`s (of every case's scene).
    #[serde(default)]
    pub defines: BTreeMap<String, String>,
    /// `"direct"`: read a scene whose integrator is a path tracer or Whitted's as its direct
    /// illumination (the CLI's `--integrator direct`); the report says the images are the
    /// direct part only.
    pub integrator: Option<crate::scene::loader::IntegratorMode>,
    /// Samples per pixel of the sweep (in probe mode: the batch sizes).
    pub spp: Vec<u32>,
    /// Independent repetitions of every (strategy, spp); seeds are 0..seeds.
    #[serde(default = "default_seeds")]
    pub seeds: u32,
    #[serde(rename = "strategy")]
    pub strategies: Vec<StrategySpec>,
    /// Samplers every strategy is run with (`"sobol"`, `"sobol:padded"`, ...): the
    /// strategies crossed with these are the experiment's columns. Default: independent.
    #[serde(default = "default_samplers")]
    pub samplers: Vec<SamplerSpec>,
    #[serde(default)]
    pub reference: ReferenceSpec,
    #[serde(default)]
    pub metrics: MetricsSpec,
    pub probe: Option<ProbeSpec>,
    #[serde(rename = "invalid", default)]
    pub invalid: Vec<InvalidSpec>,
    pub accumulation: Option<AccumulationSpec>,
    #[serde(default)]
    pub equal_time: Option<EqualTimeSpec>,
    #[serde(default)]
    pub figures: FiguresSpec,
    /// Overrides applied by `--quick` (tests, smoke runs).
    #[serde(default)]
    pub quick: Option<QuickSpec>,
}

fn default_samplers() -> Vec<SamplerSpec> {
    vec![SamplerSpec::default()]
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
    pub strategy: Option<StrategyKind>,
    pub emitter_selection: Option<EmitterSelection>,
    pub light_sampling: Option<LightSampling>,
    pub heuristic: Option<Heuristic>,
    pub emitter_samples: Option<u32>,
    pub bsdf_samples: Option<u32>,
}

impl StrategySpec {
    pub fn args(&self) -> StrategyOverrides {
        StrategyOverrides {
            strategy: self.strategy,
            emitter_selection: self.emitter_selection,
            light_sampling: self.light_sampling,
            heuristic: self.heuristic,
            emitter_samples: self.emitter_samples,
            bsdf_samples: self.bsdf_samples,
        }
    }

    /// The strategy this entry names, on the scene's own settings `base`.
    pub fn on(
        &self,
        base: crate::integrator::Strategy,
    ) -> Result<crate::integrator::Strategy, String> {
        self.args()
            .apply(base)
            .map_err(|e| format!("strategy '{}': {e}", self.name))
    }
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceSpec {
    /// Samples per pixel of a rendered reference.
    pub spp: Option<u32>,
    /// A closed-form value instead: a constant reference image with no noise.
    pub value: Option<f64>,
    /// The formula that checks `value` (see `cases::ClosedForm`).
    pub closed_form: Option<ClosedForm>,
    /// Estimator of the reference (CLI names); unset fields keep the scene's integrator.
    #[serde(default)]
    pub strategy: StrategyOverrides,
    /// Must differ from the sweep's seeds 0..seeds, or the reference would share samples
    /// with a run and their errors would be correlated.
    #[serde(default = "default_reference_seed")]
    pub seed: u64,
}

fn default_reference_seed() -> u64 {
    0x5EED_0000_0000
}

impl Default for ReferenceSpec {
    fn default() -> Self {
        ReferenceSpec {
            spp: None,
            value: None,
            closed_form: None,
            strategy: StrategyOverrides::default(),
            seed: default_reference_seed(),
        }
    }
}

pub use super::metric::ErrorMetric;

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MetricsSpec {
    /// relMSE = mean((x - r)^2 / (r^2 + epsilon)).
    #[serde(default = "default_eps")]
    pub relmse_epsilon: f64,
    /// The error the plots and tables use: "mse" or "relmse".
    #[serde(default = "default_metric")]
    pub primary: ErrorMetric,
    /// Metrics reported beside MSE and relMSE (CSV columns, metrics.csv, a convergence plot
    /// each): "trimmed-relmse", "mape", "smape", "ssim" (as 1 - SSIM), "flip".
    #[serde(default = "default_report")]
    pub report: Vec<ErrorMetric>,
    /// epsilon of MAPE and SMAPE.
    #[serde(default = "default_eps")]
    pub mape_epsilon: f64,
}

fn default_report() -> Vec<ErrorMetric> {
    ErrorMetric::extra()
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
            report: default_report(),
            mape_epsilon: default_eps(),
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
    /// Probe mode: the cases drawn as panels of `convergence.png`.
    #[serde(default)]
    pub panels: Vec<String>,
    /// Keep every seed's image at the comparison spp (not only seed 0's), for the viewer.
    #[serde(default)]
    pub seed_images: bool,
    /// The viewer's page budget in MB: images are embedded at full resolution up to it and
    /// box-averaged beyond it (default [`PAGE_MB`]).
    pub page_mb: Option<f64>,
}

/// The viewer's default page budget in MB (of embedded image data).
pub const PAGE_MB: f64 = 32.0;

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
    pub probe_samples: Option<u32>,
    pub accumulation_spp: Option<u32>,
}

/// An experiment ready to run: quick overrides applied, paths resolved, values checked.
#[derive(Clone, Debug)]
pub struct Resolved {
    pub name: String,
    pub file: PathBuf,
    pub quick: bool,
    pub exp: Experiment,
    /// At least one; exactly one unless in probe mode.
    pub cases: Vec<Case>,
}

impl Resolved {
    /// The scene of an image sweep (which has exactly one case).
    pub fn scene(&self) -> &Path {
        &self.cases[0].scene
    }

    pub fn defines(&self) -> &[(String, String)] {
        &self.cases[0].defines
    }

    /// Resolves a path written in the experiment file.
    pub fn path(&self, p: &Path) -> PathBuf {
        self.file.parent().unwrap_or(Path::new(".")).join(p)
    }

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

#[cfg(test)]
#[path = "schema_tests.rs"]
mod tests;
