//! A column of an experiment: an estimator (`[[strategy]]`) drawn with a sampler
//! (`samplers = [...]`). The experiment crosses the two lists; references and probes stay
//! with the independent sampler.

use crate::integrator::Strategy;
use crate::named::Named;
use crate::sampler::{DimAlloc, SamplerKind, Sampling};
use serde::Deserialize;
use std::fmt;

/// One entry of `samplers = [...]`: `"sobol"`, or `"sobol:padded"` for the Sobol' samplers'
/// padded dimension allocation (the default is joint). The independent sampler has no
/// dimensions to allocate and the stratified one is always padded, so they take no suffix.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Deserialize)]
#[serde(try_from = "String")]
pub struct SamplerSpec {
    pub kind: SamplerKind,
    pub dims: DimAlloc,
}

impl SamplerSpec {
    pub fn parse(s: &str) -> Result<Self, String> {
        let (name, dims) = match s.split_once(':') {
            Some((n, d)) => (n, Some(d)),
            None => (s, None),
        };
        let kind = SamplerKind::from_name(name)?;
        let dims = match dims {
            None => DimAlloc::Joint,
            Some(d) => {
                if !kind.allocates_dims() {
                    return Err(format!(
                        "sampler '{s}': the {} sampler takes no dimension allocation \
                         (only sobol and sobol-xor take ':joint' or ':padded')",
                        kind.name()
                    ));
                }
                DimAlloc::from_name(d).map_err(|e| format!("sampler '{s}': {e}"))?
            }
        };
        Ok(SamplerSpec { kind, dims })
    }

    /// The render settings' sampler; each render is a run of its own spp.
    pub fn sampling(self) -> Sampling {
        Sampling {
            kind: self.kind,
            dims: self.dims,
            run_samples: None,
        }
    }
}

impl TryFrom<String> for SamplerSpec {
    type Error = String;
    fn try_from(s: String) -> Result<Self, String> {
        SamplerSpec::parse(&s)
    }
}

impl fmt::Display for SamplerSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.kind.name())?;
        if self.kind.allocates_dims() && self.dims == DimAlloc::Padded {
            f.write_str(":padded")?;
        }
        Ok(())
    }
}

/// A strategy with its sampler: what one column of the results is measured with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Method {
    pub strategy: Strategy,
    pub sampler: SamplerSpec,
}

impl Method {
    /// The settings of one render of this method (`spp` samples, `seed`), its sampler's
    /// configuration checked against a `width` x `height` film.
    pub fn settings(
        &self,
        spp: u32,
        seed: u64,
        threads: Option<usize>,
        film: (u32, u32),
    ) -> Result<crate::render::RenderSettings, String> {
        let settings = crate::render::RenderSettings {
            spp,
            seed,
            first_sample: 0,
            threads,
            progress: None,
            sampling: self.sampler.sampling(),
        };
        settings
            .sampler_config(film)
            .map_err(|e| format!("{} at {spp} spp: {e}", self.label()))?;
        Ok(settings)
    }

    /// The strategy's stable label, followed by the sampler unless it is the independent
    /// one (so results of experiments from before samplers keep their labels).
    pub fn label(&self) -> String {
        let s = self.strategy.label();
        match self.sampler.kind {
            SamplerKind::Independent => s,
            _ => format!("{s}~{}", self.sampler.to_string().replace(':', "-")),
        }
    }
}

/// The experiment's strategies crossed with its samplers, strategy-major, with legend names:
/// a strategy's own name when there is one sampler, "name, sampler" otherwise.
pub fn cross(strategies: &[(String, Strategy)], samplers: &[SamplerSpec]) -> Vec<(String, Method)> {
    let mut out = Vec::new();
    for (name, strategy) in strategies {
        for &sampler in samplers {
            let name = if samplers.len() == 1 && sampler.kind == SamplerKind::Independent {
                name.clone()
            } else {
                format!("{name}, {sampler}")
            };
            out.push((
                name,
                Method {
                    strategy: *strategy,
                    sampler,
                },
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::desc::StrategyKind;

    /// Light sampling, uniform emitter choice, area points.
    fn strategy() -> Strategy {
        Strategy::combinations()[0]
    }

    #[test]
    fn sampler_specs_parse_and_print() {
        for (text, kind, dims) in [
            ("independent", SamplerKind::Independent, DimAlloc::Joint),
            ("stratified", SamplerKind::Stratified, DimAlloc::Joint),
            ("sobol", SamplerKind::Sobol, DimAlloc::Joint),
            ("sobol:joint", SamplerKind::Sobol, DimAlloc::Joint),
            ("sobol:padded", SamplerKind::Sobol, DimAlloc::Padded),
            ("sobol-xor:padded", SamplerKind::SobolXor, DimAlloc::Padded),
        ] {
            let s = SamplerSpec::parse(text).unwrap();
            assert_eq!((s.kind, s.dims), (kind, dims), "{text}");
            assert_eq!(SamplerSpec::parse(&s.to_string()).unwrap(), s);
        }
        for (bad, says) in [
            (
                "halton",
                "unknown sampler 'halton': expected one of independent",
            ),
            ("sobol:diagonal", "unknown dimension allocation 'diagonal'"),
            ("stratified:padded", "takes no dimension allocation"),
            ("independent:joint", "takes no dimension allocation"),
        ] {
            let e = SamplerSpec::parse(bad).unwrap_err();
            assert!(e.contains(says), "{bad}: {e}");
        }
    }

    #[test]
    fn labels_keep_the_independent_ones_and_name_the_others() {
        let m = |t: &str| Method {
            strategy: strategy(),
            sampler: SamplerSpec::parse(t).unwrap(),
        };
        let base = strategy().label();
        assert_eq!(m("independent").label(), base);
        assert_eq!(m("sobol").label(), format!("{base}~sobol"));
        assert_eq!(m("sobol:padded").label(), format!("{base}~sobol-padded"));
        assert_eq!(m("stratified").label(), format!("{base}~stratified"));
        let labels: std::collections::HashSet<_> = [
            "independent",
            "stratified",
            "sobol",
            "sobol:padded",
            "sobol-xor",
            "sobol-xor:padded",
        ]
        .map(|t| m(t).label())
        .into_iter()
        .collect();
        assert_eq!(labels.len(), 6);
    }

    #[test]
    fn cross_is_strategy_major_with_names() {
        let mut other = strategy();
        other.kind = StrategyKind::Bsdf;
        let list = vec![
            ("light".to_string(), strategy()),
            ("bsdf".to_string(), other),
        ];
        let one = cross(&list, &[SamplerSpec::default()]);
        let names: Vec<_> = one.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["light", "bsdf"]);
        let two = cross(
            &list,
            &[SamplerSpec::default(), SamplerSpec::parse("sobol").unwrap()],
        );
        let names: Vec<_> = two.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(
            names,
            [
                "light, independent",
                "light, sobol",
                "bsdf, independent",
                "bsdf, sobol"
            ]
        );
        assert_eq!(two[3].1.strategy, other);
        assert_eq!(two[3].1.sampler.kind, SamplerKind::Sobol);
    }
}
