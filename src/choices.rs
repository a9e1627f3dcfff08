//! The command line's view of the renderer's named sets ([`crate::named::Named`]): each
//! option's accepted values and their help come from the set's one table, so `--help`, the
//! parser and the error for a wrong value cannot disagree with scene and experiment files.

use crate::emitter::{EmitterSelection, LightSampling};
use crate::integrator::StrategyOverrides;
use crate::named::Named;
use crate::scene::desc::{Heuristic, StrategyKind};
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::Args;
use std::ffi::OsStr;

/// A clap value parser for the set `T`: its names as the possible values, with their help.
pub fn named<T: Named + Clone + Send + Sync>() -> impl TypedValueParser<Value = T> {
    PossibleValuesParser::new(
        T::CHOICES
            .iter()
            .map(|c| PossibleValue::new(c.name).help(c.help)),
    )
    .map(|s| T::from_name(&s).expect("clap accepts only the table's names"))
}

/// The emitter choices' parser: the registered rules' names and help (`emitter::RULES`) and
/// `ris:M`, parsed by `EmitterSelection`'s own `FromStr` (whose error lists them too).
#[derive(Clone, Copy, Debug)]
pub struct EmitterSelectionParser;

impl TypedValueParser for EmitterSelectionParser {
    type Value = EmitterSelection;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &OsStr,
    ) -> Result<EmitterSelection, clap::Error> {
        let text = value.to_string_lossy();
        text.parse().map_err(|e: String| {
            let name = arg.map_or("value".to_string(), |a| a.to_string());
            clap::Error::raw(
                clap::error::ErrorKind::InvalidValue,
                format!("invalid value '{text}' for '{name}': {e}\n"),
            )
            .with_cmd(cmd)
        })
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        let rules = crate::emitter::RULES
            .iter()
            .map(|r| PossibleValue::new(r.name).help(r.help));
        let ris = PossibleValue::new("ris:M").help(format!(
            "resampling of M candidates drawn by power, M from 1 to {}",
            crate::emitter::RIS_MAX
        ));
        Some(Box::new(rules.chain([ris])))
    }
}

/// Estimator choices on top of a scene's own integrator settings (`render`'s options; the
/// experiment files' strategy entries have the same names). Anything not given keeps the
/// scene's setting.
#[derive(Args, Debug, Clone, Default)]
pub struct StrategyArgs {
    /// The estimator (default: the scene's integrator).
    #[arg(long, value_parser = named::<StrategyKind>())]
    pub strategy: Option<StrategyKind>,
    /// Emitter choice (default: uniform, the study's).
    #[arg(long, value_parser = EmitterSelectionParser)]
    pub emitter_selection: Option<EmitterSelection>,
    /// How points on area lights are drawn.
    #[arg(long, value_parser = named::<LightSampling>())]
    pub light_sampling: Option<LightSampling>,
    /// MIS weights (default: the scene's).
    #[arg(long, value_parser = named::<Heuristic>())]
    pub heuristic: Option<Heuristic>,
    /// Light samples per camera sample (0 with MIS: BSDF sampling only, as in Mitsuba).
    #[arg(long)]
    pub emitter_samples: Option<u32>,
    /// BSDF samples per camera sample (0 with MIS: light sampling only).
    #[arg(long)]
    pub bsdf_samples: Option<u32>,
}

impl StrategyArgs {
    /// The renderer's form of these choices.
    pub fn overrides(&self) -> StrategyOverrides {
        StrategyOverrides {
            strategy: self.strategy,
            emitter_selection: self.emitter_selection,
            light_sampling: self.light_sampling,
            heuristic: self.heuristic,
            emitter_samples: self.emitter_samples,
            bsdf_samples: self.bsdf_samples,
        }
    }
}
