//! The grammar of strategy labels (`mis-power-e1b1-pow-sa`): what each part means, generated
//! from the registries and from `Strategy::label` itself, so it cannot drift from the labels
//! written to results.csv. `directlab labels` prints it; the README points to it.

use crate::emitter::{EmitterSelection, LightSampling, RULES};
use crate::integrator::Strategy;
use crate::named::Named;
use crate::scene::desc::{Heuristic, StrategyKind};
use std::fmt::Write;

/// One table row per value of a registry: `short = name: help`.
fn table<T: Named>(md: &mut String, title: &str) {
    let _ = writeln!(md, "{title}:");
    for c in T::CHOICES {
        let _ = writeln!(md, "  {:<6} {}: {}", c.value.short(), c.name, c.help);
    }
}

/// The configuration the examples show: 2 light and 3 BSDF samples, the power heuristic,
/// emitter choice by power, solid-angle sampling.
fn example(kind: StrategyKind) -> Strategy {
    Strategy {
        kind,
        heuristic: Heuristic::Power,
        emitter_samples: 2,
        bsdf_samples: 3,
        selection: EmitterSelection::Power,
        light_sampling: LightSampling::SolidAngle,
        hide_emitters: false,
    }
}

/// The grammar, with an example of every estimator's label.
pub fn grammar() -> String {
    let mut md = String::from(
        "Strategy labels name an estimator configuration in results.csv (the `strategy` \
         column), in resume keys and in image file names. A label is the estimator's short \
         name followed by the settings that estimator reads, joined by '-':\n\n",
    );
    for c in StrategyKind::CHOICES {
        let _ = writeln!(md, "  {:<22} {}", example(c.value).label(), c.help);
    }
    let _ = writeln!(
        md,
        "\nin these examples: 2 light samples (e2), 3 BSDF samples (b3), the power heuristic, \
         emitter choice by power and solid-angle sampling. One-sample MIS leaves out e1b1, \
         its default. Parts:\n"
    );
    table::<StrategyKind>(&mut md, "estimator");
    table::<Heuristic>(&mut md, "heuristic (MIS only)");
    let _ = writeln!(md, "emitter choice:");
    for r in RULES {
        let _ = writeln!(md, "  {:<6} {}: {}", r.short, r.name, r.help);
    }
    let _ = writeln!(
        md,
        "  risK   ris:K: resampled importance sampling of K candidates drawn by power"
    );
    table::<LightSampling>(&mut md, "light sampling");
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grammar_shows_every_registered_short_form_and_a_real_label() {
        let g = grammar();
        for c in StrategyKind::CHOICES {
            assert!(
                g.contains(&format!("  {:<6} {}", c.value.short(), c.name)),
                "{g}"
            );
        }
        for r in RULES {
            assert!(g.contains(r.short) && g.contains(r.name), "{g}");
        }
        for c in LightSampling::CHOICES {
            assert!(g.contains(c.value.short()), "{g}");
        }
        let mis = example(StrategyKind::Mis);
        assert!(g.contains(&mis.label()), "{g}");
    }
}
