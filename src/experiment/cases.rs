//! The parts of an experiment file that name scenes: the `[[case]]` list (several scenes in
//! one file), closed-form references, the `[probe]` mode that measures one pixel's individual
//! samples, and the input checks (`[[invalid]]`) and f64 accumulation check (`[accumulation]`)
//! of stability suites such as `experiments/extreme.toml`.

use crate::emitter::{EmitterSelection, LightSampling};
use crate::integrator::Strategy;
use crate::integrator::StrategyOverrides;
use crate::scene::desc::{Heuristic, StrategyKind};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// A formula the runner evaluates on the loaded scene, at the point the probe pixel sees, to
/// check a case's `reference.value` before it measures anything against it.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum ClosedForm {
    /// Diffuse receiver: albedo / pi times Lambert's polygon irradiance of every emitter.
    Lambert,
    /// (Near-)specular receiver whose lobe lies wholly inside one light: Fresnel reflectance
    /// (conductor, or a dielectric's reflected share) times that light's radiance.
    Fresnel,
    /// Any BSDF under one parallelogram light: 1024 x 1024 midpoint quadrature over the light.
    Quadrature,
}

impl ClosedForm {
    pub fn describe(self) -> &'static str {
        match self {
            ClosedForm::Lambert => "Lambert",
            ClosedForm::Fresnel => "Fresnel",
            ClosedForm::Quadrature => "quadrature 1024²",
        }
    }
}

/// A case's own reference: a closed-form value, optionally with the formula that checks it.
#[derive(Clone, Debug, Deserialize, Default, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CaseReferenceSpec {
    pub value: Option<f64>,
    pub closed_form: Option<ClosedForm>,
}

/// Techniques that cannot find part of a case's integrand at any affordable sample count:
/// their mean is reported but not tested. A strategy matches if every given field equals its
/// setting.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct BlindSpec {
    pub strategy: Option<StrategyKind>,
    pub light_sampling: Option<LightSampling>,
    pub emitter_selection: Option<EmitterSelection>,
    pub heuristic: Option<Heuristic>,
    /// Why, with the probability of the missed event (for the report).
    pub why: String,
}

impl BlindSpec {
    pub fn covers(&self, s: &Strategy) -> bool {
        let only = StrategyOverrides {
            strategy: self.strategy,
            light_sampling: self.light_sampling,
            emitter_selection: self.emitter_selection,
            heuristic: self.heuristic,
            ..Default::default()
        };
        // Setting the blind fields changes nothing exactly when s already has them.
        only.apply(*s).as_ref() == Ok(s)
    }
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseSpec {
    /// Unique; names the case in tables, figures and `results.csv`.
    pub name: String,
    /// Scene file, relative to the experiment file.
    pub scene: PathBuf,
    /// `-D` overrides for this case, applied over the file's `defines` and `[quick] defines`.
    #[serde(default)]
    pub defines: BTreeMap<String, String>,
    #[serde(default)]
    pub reference: CaseReferenceSpec,
    /// Heading the case belongs to in the report.
    #[serde(default)]
    pub group: String,
    /// What the case stresses, for the report.
    #[serde(default)]
    pub about: String,
    /// A substring the scene build must warn with (degenerate input).
    pub warning: Option<String>,
    #[serde(default)]
    pub blind: Vec<BlindSpec>,
}

/// Probe mode: instead of rendering images, draw the individual samples of one pixel (exactly
/// as `render` draws them) and measure them against a closed-form reference.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeSpec {
    /// The pixel (x, y) whose samples are drawn.
    #[serde(default)]
    pub pixel: [u32; 2],
    /// Samples per (case, strategy, seed). The sweep's spp are batch sizes: the error at spp
    /// k is the mean over the samples/k independent batches of k samples.
    pub samples: u32,
    /// The spp whose relMSE the table shows (default: the largest sweep spp <= 1024).
    pub table_spp: Option<u32>,
    /// Family-wise significance of the table's bias z-tests (Šidák-corrected over its rows).
    #[serde(default = "default_alpha")]
    pub alpha: f64,
}

fn default_alpha() -> f64 {
    1e-3
}

/// Fewest independent batches an error point of a probe sweep is averaged over.
pub const MIN_BATCHES: u32 = 32;

/// Input the loader or the scene build must reject (`error`) or accept with a `warning`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InvalidSpec {
    pub scene: PathBuf,
    #[serde(default)]
    pub defines: BTreeMap<String, String>,
    /// Substring of the expected error message.
    pub error: Option<String>,
    /// Substring of the expected warning (the scene must then load and build).
    pub warning: Option<String>,
}

/// Very high sample counts through `render` on one case: the f64 pixel mean must equal the
/// exact mean of the same samples.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AccumulationSpec {
    /// Name of a `[[case]]`.
    pub case: String,
    /// Extra `-D` overrides (e.g. a larger film) over the case's own.
    #[serde(default)]
    pub defines: BTreeMap<String, String>,
    pub spp: u32,
    /// Names of `[[strategy]]` entries.
    pub strategies: Vec<String>,
    #[serde(default = "default_accumulation_seed")]
    pub seed: u64,
}

fn default_accumulation_seed() -> u64 {
    1
}

/// A case ready to run: paths resolved, defines merged, reference checked for presence.
#[derive(Clone, Debug)]
pub struct Case {
    pub name: String,
    pub scene: PathBuf,
    pub defines: Vec<(String, String)>,
    /// How the scene's integrator is read (the experiment's `integrator`).
    pub integrator: Option<crate::scene::loader::IntegratorMode>,
    pub value: Option<f64>,
    pub closed_form: Option<ClosedForm>,
    pub group: String,
    pub about: String,
    pub warning: Option<String>,
    pub blind: Vec<BlindSpec>,
}

impl Case {
    /// Why strategy `s` is not tested on this case, if it is not.
    pub fn blind_for(&self, s: &Strategy) -> Option<&str> {
        self.blind
            .iter()
            .find(|b| b.covers(s))
            .map(|b| b.why.as_str())
    }

    /// Where the reference comes from, for the report.
    pub fn reference_from(&self) -> &'static str {
        self.closed_form.map_or("given", ClosedForm::describe)
    }
}

/// Merges defines in order (later maps win) into the sorted list the loader takes.
pub fn merge_defines(layers: &[&BTreeMap<String, String>]) -> Vec<(String, String)> {
    let mut all = BTreeMap::new();
    for l in layers {
        all.extend(l.iter().map(|(k, v)| (k.clone(), v.clone())));
    }
    all.into_iter().collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emitter::{EmitterSelection, LightSampling};
    use crate::scene::desc::{Heuristic, StrategyKind};

    #[test]
    fn blind_spec_matches_only_the_strategies_it_names() {
        let light_area = Strategy {
            kind: StrategyKind::Light,
            heuristic: Heuristic::Balance,
            emitter_samples: 1,
            bsdf_samples: 1,
            selection: EmitterSelection::Uniform,
            light_sampling: LightSampling::Area,
            hide_emitters: false,
        };
        let b: BlindSpec =
            toml::from_str("strategy = \"light\"\nlight_sampling = \"area\"\nwhy = \"x\"").unwrap();
        assert!(b.covers(&light_area));
        assert!(!b.covers(&Strategy {
            light_sampling: LightSampling::SolidAngle,
            ..light_area
        }));
        assert!(!b.covers(&Strategy {
            kind: StrategyKind::Mis,
            ..light_area
        }));
        let any_light: BlindSpec = toml::from_str("strategy = \"light\"\nwhy = \"x\"").unwrap();
        assert!(any_light.covers(&Strategy {
            light_sampling: LightSampling::SolidAngle,
            selection: EmitterSelection::Power,
            ..light_area
        }));
    }

    #[test]
    fn later_defines_win() {
        let a = BTreeMap::from([("res".to_string(), "8".to_string())]);
        let b = BTreeMap::from([
            ("res".to_string(), "2".to_string()),
            ("x".to_string(), "0.5".to_string()),
        ]);
        assert_eq!(
            merge_defines(&[&a, &b]),
            vec![("res".into(), "2".into()), ("x".into(), "0.5".into())]
        );
    }
}
