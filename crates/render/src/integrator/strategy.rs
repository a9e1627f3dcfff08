//! The estimator settings a render uses, and their stable short labels.

use crate::emitter::{EmitterSelection, LightSampling};
use crate::scene::desc::{Heuristic, IntegratorDesc, StrategyKind};

/// Everything that decides which estimator a render runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Strategy {
    /// Light, BSDF, MIS or one-sample MIS.
    pub kind: StrategyKind,
    /// MIS weights.
    pub heuristic: Heuristic,
    /// Light samples per camera sample.
    pub emitter_samples: u32,
    /// BSDF samples per camera sample.
    pub bsdf_samples: u32,
    /// The emitter choice.
    pub selection: EmitterSelection,
    /// How points on area lights are drawn.
    pub light_sampling: LightSampling,
    /// Whether emitters seen directly by the camera are left black (Mitsuba's `hide_emitters`).
    pub hide_emitters: bool,
}

impl Strategy {
    /// The scene's own integrator settings, with the study's defaults for what XML cannot say
    /// (uniform emitter choice, area sampling).
    pub fn from_desc(d: &IntegratorDesc) -> Self {
        Strategy {
            kind: d.strategy,
            heuristic: d.heuristic,
            emitter_samples: d.emitter_samples,
            bsdf_samples: d.bsdf_samples,
            selection: EmitterSelection::Uniform,
            light_sampling: LightSampling::Area,
            hide_emitters: d.hide_emitters,
        }
    }

    /// One of each kind of estimator (light, BSDF, balance and power MIS with 1 or 2 light
    /// samples, one-sample MIS) for every emitter choice and light sampling mode: the set the
    /// tests run to show that all strategies estimate the same image.
    pub fn combinations() -> Vec<Strategy> {
        let mut v = Vec::new();
        for selection in [EmitterSelection::Uniform, EmitterSelection::Power] {
            for light_sampling in [LightSampling::Area, LightSampling::SolidAngle] {
                let base = Strategy {
                    kind: StrategyKind::Light,
                    heuristic: Heuristic::Balance,
                    emitter_samples: 1,
                    bsdf_samples: 1,
                    selection,
                    light_sampling,
                    hide_emitters: false,
                };
                v.push(base);
                v.push(Strategy {
                    kind: StrategyKind::Mis,
                    ..base
                });
                v.push(Strategy {
                    kind: StrategyKind::Mis,
                    heuristic: Heuristic::Power,
                    emitter_samples: 2,
                    ..base
                });
                v.push(Strategy {
                    kind: StrategyKind::MisOneSample,
                    ..base
                });
                v.push(Strategy {
                    kind: StrategyKind::MisOneSample,
                    heuristic: Heuristic::Power,
                    ..base
                });
            }
        }
        v.push(Strategy {
            kind: StrategyKind::Bsdf,
            ..v[0]
        });
        v.push(Strategy {
            kind: StrategyKind::Bsdf,
            bsdf_samples: 3,
            ..v[0]
        });
        v
    }

    /// Stable label for file names, CSV rows and plot legends, e.g. `mis-power-e1b1-uni-area`:
    /// the short forms of the kind, then of the settings its estimator uses (heuristic, `eN`
    /// light and `bM` BSDF samples, emitter choice, light sampling).
    pub fn label(&self) -> String {
        super::strategies::label(self)
    }
}

/// Estimator choices on top of a scene's own integrator settings: `render`'s options and an
/// experiment's strategy entries (`strategy = "mis"`, `emitter_selection = "power"`, ...), with
/// the same names in both. Anything not given keeps the scene's setting.
#[derive(Debug, Clone, Default, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StrategyOverrides {
    /// The estimator.
    pub strategy: Option<StrategyKind>,
    /// The emitter choice.
    pub emitter_selection: Option<EmitterSelection>,
    /// How points on area lights are drawn.
    pub light_sampling: Option<LightSampling>,
    /// MIS weights.
    pub heuristic: Option<Heuristic>,
    /// Light samples per camera sample.
    pub emitter_samples: Option<u32>,
    /// BSDF samples per camera sample.
    pub bsdf_samples: Option<u32>,
}

impl StrategyOverrides {
    /// `s` with these choices applied. Zero sample counts keep Mitsuba's meaning (see
    /// [`StrategyKind::with_sample_counts`]); a choice that leaves nothing to sample is an
    /// error.
    pub fn apply(&self, mut s: Strategy) -> Result<Strategy, String> {
        s.kind = self.strategy.unwrap_or(s.kind);
        s.selection = self.emitter_selection.unwrap_or(s.selection);
        s.light_sampling = self.light_sampling.unwrap_or(s.light_sampling);
        s.heuristic = self.heuristic.unwrap_or(s.heuristic);
        s.emitter_samples = self.emitter_samples.unwrap_or(s.emitter_samples);
        s.bsdf_samples = self.bsdf_samples.unwrap_or(s.bsdf_samples);
        s.kind = s
            .kind
            .with_sample_counts(s.emitter_samples, s.bsdf_samples)?;
        Ok(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn combinations_are_the_documented_set() {
        // Written out by hand: a field dropped from one entry of the list makes it a copy of
        // another, which the tests that iterate over it cannot notice.
        let mut want = Vec::new();
        for sel in ["uni", "pow"] {
            for ls in ["area", "sa"] {
                want.push(format!("light-e1-{sel}-{ls}"));
                want.push(format!("mis-balance-e1b1-{sel}-{ls}"));
                want.push(format!("mis-power-e2b1-{sel}-{ls}"));
                want.push(format!("mis1-balance-{sel}-{ls}"));
                want.push(format!("mis1-power-{sel}-{ls}"));
            }
        }
        want.push("bsdf-b1".into());
        want.push("bsdf-b3".into());
        let all = Strategy::combinations();
        let got: Vec<String> = all.iter().map(Strategy::label).collect();
        assert_eq!(got, want);
        assert!(all.iter().all(|s| !s.hide_emitters));
    }

    #[test]
    fn labels_are_distinct_per_setting() {
        let base = Strategy {
            kind: StrategyKind::Mis,
            heuristic: Heuristic::Power,
            emitter_samples: 1,
            bsdf_samples: 1,
            selection: EmitterSelection::Uniform,
            light_sampling: LightSampling::Area,
            hide_emitters: false,
        };
        assert_eq!(base.label(), "mis-power-e1b1-uni-area");
        let variants = [
            Strategy {
                heuristic: Heuristic::Balance,
                ..base
            },
            Strategy {
                selection: EmitterSelection::Power,
                ..base
            },
            Strategy {
                light_sampling: LightSampling::SolidAngle,
                ..base
            },
            Strategy {
                emitter_samples: 4,
                ..base
            },
            Strategy {
                kind: StrategyKind::Light,
                ..base
            },
            Strategy {
                kind: StrategyKind::Bsdf,
                ..base
            },
            Strategy {
                kind: StrategyKind::MisOneSample,
                ..base
            },
            // One-sample MIS picks the light technique with c = ne / (ne + nb): another
            // estimator (it once had the label of the one above).
            Strategy {
                kind: StrategyKind::MisOneSample,
                bsdf_samples: 2,
                ..base
            },
        ];
        let mut labels: Vec<String> = variants.iter().map(Strategy::label).collect();
        labels.push(base.label());
        let n = labels.len();
        labels.sort();
        labels.dedup();
        assert_eq!(labels.len(), n);
    }
}
