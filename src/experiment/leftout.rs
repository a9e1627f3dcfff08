//! Leaving out what a scene does not need. Before a sweep, every strategy is reduced to the
//! estimator it actually is on this scene (a choice among one emitter is no choice; MIS with
//! only delta lights is light sampling, ...). Strategies that reduce to one listed earlier are
//! identical in distribution and dropped; strategies that cannot see the scene's light at all
//! are dropped too. Every omission carries its reason for the report.

use crate::emitter::{EmitterSelection, LightSampling};
use crate::integrator::Strategy;
use crate::scene::desc::{Heuristic, StrategyKind};
use crate::scene::Scene;

/// What the rules need to know about a scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneTraits {
    pub emitters: usize,
    /// All emitters have the same power (to 1e-6 relative): power choice is then uniform.
    pub equal_power: bool,
    pub all_lights_delta: bool,
    pub all_bsdfs_delta: bool,
}

impl SceneTraits {
    pub fn of(scene: &Scene) -> Self {
        let powers: Vec<f64> = scene.emitters.iter().map(|e| e.power()).collect();
        let max = powers.iter().cloned().fold(0.0, f64::max);
        let min = powers.iter().cloned().fold(f64::INFINITY, f64::min);
        SceneTraits {
            emitters: powers.len(),
            equal_power: max > 0.0 && (max - min) <= 1e-6 * max,
            all_lights_delta: scene.emitters.iter().all(|e| e.is_delta()),
            all_bsdfs_delta: scene.materials.iter().all(|m| m.is_delta()),
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Omission {
    pub name: String,
    pub label: String,
    pub reason: String,
}

/// The estimator `s` is on a scene with `t`, with every setting that cannot matter fixed to
/// one value, plus the reasons for each simplification; `None` if it cannot see any light.
fn effective(s: &Strategy, t: &SceneTraits) -> Result<(Strategy, Vec<String>), String> {
    let mut e = *s;
    let mut why = Vec::new();
    if t.all_bsdfs_delta && e.kind == StrategyKind::Light {
        return Err(
            "every BSDF is a delta: light samples carry zero throughput, so light \
                    sampling shows only directly visible emitters"
                .into(),
        );
    }
    if t.all_lights_delta && e.kind == StrategyKind::Bsdf {
        return Err(
            "every light is a delta (point light): BSDF samples never hit one, so the \
                    image would be black"
                .into(),
        );
    }
    if t.all_bsdfs_delta && matches!(e.kind, StrategyKind::Mis | StrategyKind::MisOneSample) {
        e.kind = StrategyKind::Bsdf;
        e.bsdf_samples = if s.kind == StrategyKind::MisOneSample {
            1
        } else {
            s.bsdf_samples
        };
        why.push("every BSDF is a delta, so MIS gives all weight to BSDF samples".to_string());
    }
    if t.all_lights_delta && matches!(e.kind, StrategyKind::Mis | StrategyKind::MisOneSample) {
        // One-sample MIS still spends a share of its samples on the useless BSDF technique,
        // so only the multi-sample form reduces to plain light sampling.
        if e.kind == StrategyKind::Mis {
            e.kind = StrategyKind::Light;
            why.push(
                "every light is a delta, so MIS gives all weight to light samples".to_string(),
            );
        }
    }
    // Settings a technique never reads.
    match e.kind {
        StrategyKind::Bsdf => {
            e.emitter_samples = 1;
            e.heuristic = Heuristic::Balance;
            e.selection = EmitterSelection::Uniform;
            e.light_sampling = LightSampling::Area;
        }
        StrategyKind::Light => {
            e.bsdf_samples = 1;
            e.heuristic = Heuristic::Balance;
        }
        _ => {}
    }
    if e.selection == EmitterSelection::Ris(1) {
        e.selection = EmitterSelection::Power;
        why.push("ris:1 keeps its only candidate, drawn by power: power choice".into());
    }
    if t.emitters == 1 && e.selection != EmitterSelection::Uniform {
        // Every rule (power, the light tree, exhaustive, RIS) picks the only emitter with
        // pmf 1: one estimator, whatever its name.
        why.push(format!(
            "with one emitter, {} and uniform choice pick it with pmf 1",
            e.selection.name()
        ));
        e.selection = EmitterSelection::Uniform;
    }
    if e.selection == EmitterSelection::Power && t.equal_power {
        e.selection = EmitterSelection::Uniform;
        why.push("all emitters have equal power, so the power pmf is uniform".into());
    }
    if t.all_lights_delta && e.light_sampling == LightSampling::SolidAngle {
        e.light_sampling = LightSampling::Area;
        why.push("only point lights: area and solid-angle sampling do not apply".into());
    }
    Ok((e, why))
}

/// Why every sampler is one estimator here: a film of one pixel whose every run takes one
/// sample draws a single point, which every sampler makes uniform in the unit cube (a
/// stratum, a scrambled first point and an independent point alike); None otherwise.
pub fn samplers_collapse(pixels: u64, spp: &[u32], equal_time: bool) -> Option<String> {
    (pixels == 1 && !equal_time && spp.iter().all(|&s| s == 1)).then(|| {
        "a film of one pixel at one sample per run draws one point, uniform under every \
         sampler"
            .to_string()
    })
}

/// Splits `strategies` (name, strategy) into those to run and those left out.
pub fn leave_out(
    strategies: &[(String, Strategy)],
    t: &SceneTraits,
) -> (Vec<(String, Strategy)>, Vec<Omission>) {
    let mut kept: Vec<(String, Strategy, Strategy)> = Vec::new();
    let mut omitted = Vec::new();
    for (name, s) in strategies {
        match effective(s, t) {
            Err(reason) => omitted.push(Omission {
                name: name.clone(),
                label: s.label(),
                reason,
            }),
            Ok((e, why)) => {
                if let Some((other, _, _)) = kept.iter().find(|(_, _, ke)| *ke == e) {
                    let because = if why.is_empty() {
                        "the same settings".to_string()
                    } else {
                        why.join("; ")
                    };
                    omitted.push(Omission {
                        name: name.clone(),
                        label: s.label(),
                        reason: format!("identical to '{other}' on this scene: {because}"),
                    });
                } else {
                    kept.push((name.clone(), *s, e));
                }
            }
        }
    }
    (kept.into_iter().map(|(n, s, _)| (n, s)).collect(), omitted)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(kind: StrategyKind) -> Strategy {
        Strategy {
            kind,
            heuristic: Heuristic::Balance,
            emitter_samples: 1,
            bsdf_samples: 1,
            selection: EmitterSelection::Uniform,
            light_sampling: LightSampling::Area,
            hide_emitters: false,
        }
    }

    fn traits(emitters: usize) -> SceneTraits {
        SceneTraits {
            emitters,
            equal_power: false,
            all_lights_delta: false,
            all_bsdfs_delta: false,
        }
    }

    fn names(v: &[(String, Strategy)]) -> Vec<&str> {
        v.iter().map(|(n, _)| n.as_str()).collect()
    }

    #[test]
    fn emitter_choice_matters_only_with_unequal_emitters() {
        let uni = s(StrategyKind::Light);
        let pow = Strategy {
            selection: EmitterSelection::Power,
            ..uni
        };
        let list = vec![("uniform".to_string(), uni), ("power".to_string(), pow)];
        let (kept, out) = leave_out(&list, &traits(2));
        assert_eq!(names(&kept), ["uniform", "power"]);
        assert!(out.is_empty());
        let (kept, out) = leave_out(&list, &traits(1));
        assert_eq!(names(&kept), ["uniform"]);
        assert_eq!(out[0].name, "power");
        assert!(out[0].reason.contains("one emitter"), "{}", out[0].reason);
        // Every rule is one estimator with one emitter: kept once, the others named.
        let mut every = list.clone();
        for sel in [
            EmitterSelection::Bvh,
            EmitterSelection::Exhaustive,
            EmitterSelection::Ris(8),
        ] {
            every.push((
                sel.name(),
                Strategy {
                    selection: sel,
                    ..uni
                },
            ));
        }
        let (kept, out) = leave_out(&every, &traits(1));
        assert_eq!(names(&kept), ["uniform"]);
        assert_eq!(out.len(), 4);
        assert!(
            out.iter()
                .all(|o| o.reason.contains("identical to 'uniform'") && o.reason.contains("pmf 1")),
            "{out:?}"
        );
        let (kept, _) = leave_out(&every, &traits(2));
        assert_eq!(kept.len(), 5);
        let equal = SceneTraits {
            equal_power: true,
            ..traits(3)
        };
        let (kept, out) = leave_out(&list, &equal);
        assert_eq!(names(&kept), ["uniform"]);
        assert!(out[0].reason.contains("equal power"));
    }

    #[test]
    fn point_lights_drop_bsdf_sampling_and_collapse_mis_and_light_sampling_modes() {
        let point = SceneTraits {
            all_lights_delta: true,
            ..traits(2)
        };
        let light = s(StrategyKind::Light);
        let list = vec![
            ("light".to_string(), light),
            (
                "light-sa".to_string(),
                Strategy {
                    light_sampling: LightSampling::SolidAngle,
                    ..light
                },
            ),
            ("bsdf".to_string(), s(StrategyKind::Bsdf)),
            ("mis".to_string(), s(StrategyKind::Mis)),
            ("mis1".to_string(), s(StrategyKind::MisOneSample)),
        ];
        let (kept, out) = leave_out(&list, &point);
        assert_eq!(names(&kept), ["light", "mis1"]);
        let reasons: Vec<(&str, &str)> = out
            .iter()
            .map(|o| (o.name.as_str(), o.reason.as_str()))
            .collect();
        assert_eq!(reasons.len(), 3);
        assert!(reasons[0].0 == "light-sa" && reasons[0].1.contains("point lights"));
        assert!(reasons[1].0 == "bsdf" && reasons[1].1.contains("black"));
        assert!(reasons[2].0 == "mis" && reasons[2].1.contains("identical to 'light'"));
    }

    #[test]
    fn delta_bsdfs_drop_light_sampling_and_reduce_mis_to_bsdf_sampling() {
        let mirror = SceneTraits {
            all_bsdfs_delta: true,
            ..traits(1)
        };
        let list = vec![
            ("bsdf".to_string(), s(StrategyKind::Bsdf)),
            ("light".to_string(), s(StrategyKind::Light)),
            (
                "mis-power".to_string(),
                Strategy {
                    heuristic: Heuristic::Power,
                    ..s(StrategyKind::Mis)
                },
            ),
        ];
        let (kept, out) = leave_out(&list, &mirror);
        assert_eq!(names(&kept), ["bsdf"]);
        assert!(out[0].reason.contains("delta"));
        assert!(out[1].reason.contains("identical to 'bsdf'"));
        // On an ordinary scene all three are different estimators.
        let (kept, _) = leave_out(&list, &traits(1));
        assert_eq!(kept.len(), 3);
    }

    #[test]
    fn samplers_collapse_only_on_a_single_sample_film() {
        assert!(samplers_collapse(1, &[1], false).is_some());
        assert!(samplers_collapse(1, &[1, 1], false).is_some());
        assert!(
            samplers_collapse(2, &[1], false).is_none(),
            "pixels are two draws"
        );
        assert!(
            samplers_collapse(1, &[1, 4], false).is_none(),
            "4 points can stratify"
        );
        assert!(
            samplers_collapse(1, &[1], true).is_none(),
            "equal time takes many"
        );
    }

    #[test]
    fn duplicates_are_dropped_even_without_a_rule() {
        let list = vec![
            ("a".to_string(), s(StrategyKind::Mis)),
            ("b".to_string(), s(StrategyKind::Mis)),
        ];
        let (kept, out) = leave_out(&list, &traits(2));
        assert_eq!(names(&kept), ["a"]);
        assert!(out[0].reason.contains("same settings"));
    }
}
