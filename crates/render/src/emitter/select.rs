//! Choosing which emitter to sample, and the registry of the rules that do it: each rule is
//! one file in `rules/` (a [`ChoiceRule`]) plus one line of `rules!` below, which gives it
//! its name, its short form in strategy labels and its help; the parser, the error listing
//! the valid names, the dispatch and the lists the tests loop over follow from that line.
//! `ris:M` is not a rule: it resamples M candidates drawn by power, and the resampling itself
//! needs the BSDF and lives in the integrator, so here it is the power rule.

use super::rules::{self, ChoiceRule};
use super::tree::LightTree;
use super::Emitter;
use crate::geometry::Shape;
use glam::Vec3;

/// The registration: one line per rule, `Variant(type) = "name", "short", "help"`. It makes
/// [`EmitterSelection`] (with RIS appended), its names, short forms and help, the parser and
/// the dispatch of [`EmitterSelector`] to the rule's type.
macro_rules! rules {
    ($($variant:ident($ty:ty) = $name:literal, $short:literal, $help:literal;)*) => {
        /// The rule for choosing an emitter. Written by its name (`uniform`, `power`, ...) or
        /// `ris:M` (M candidates, 1 to 256) in the CLI and in experiment files.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Deserialize)]
        #[serde(try_from = "String")]
        pub enum EmitterSelection {
            $(#[doc = $help] $variant,)*
            /// Resampled importance sampling of this many candidates drawn by power.
            Ris(u32),
        }

        /// Every registered rule.
        pub const RULES: &[RuleInfo] = &[$(RuleInfo {
            value: EmitterSelection::$variant,
            name: $name,
            short: $short,
            help: $help,
        },)*];

        #[derive(Clone, Debug)]
        enum Rule {
            $($variant($ty),)*
        }

        impl Rule {
            fn build(mode: EmitterSelection, emitters: &[Emitter], shapes: &[Shape]) -> Rule {
                match mode {
                    $(EmitterSelection::$variant => Rule::$variant(<$ty as ChoiceRule>::build(emitters, shapes)),)*
                    EmitterSelection::Ris(_) => {
                        Rule::Power(<rules::power::Power as ChoiceRule>::build(emitters, shapes))
                    }
                }
            }

            fn point_independent(&self) -> bool {
                match self {
                    $(Rule::$variant(_) => <$ty as ChoiceRule>::POINT_INDEPENDENT,)*
                }
            }

            #[inline]
            fn sample(&self, count: usize, p: Vec3, n: Vec3, u: f32) -> Option<(usize, f32)> {
                match self {
                    $(Rule::$variant(r) => <$ty as ChoiceRule>::sample(r, count, p, n, u),)*
                }
            }

            #[inline]
            fn pmf(&self, count: usize, p: Vec3, n: Vec3, i: usize) -> f32 {
                match self {
                    $(Rule::$variant(r) => <$ty as ChoiceRule>::pmf(r, count, p, n, i),)*
                }
            }

            fn none_probability(&self, p: Vec3, n: Vec3) -> f64 {
                match self {
                    $(Rule::$variant(r) => <$ty as ChoiceRule>::none_probability(r, p, n),)*
                }
            }

            fn bin(&self, i: usize) -> (f32, u32) {
                match self {
                    $(Rule::$variant(r) => <$ty as ChoiceRule>::bin(r, i),)*
                }
            }

            fn tree_stats(&self) -> Option<(usize, usize)> {
                match self {
                    $(Rule::$variant(r) => <$ty as ChoiceRule>::tree_stats(r),)*
                }
            }

            fn evaluations(&self, count: usize) -> u64 {
                match self {
                    $(Rule::$variant(r) => <$ty as ChoiceRule>::evaluations(r, count),)*
                }
            }
        }

        impl EmitterSelection {
            /// Whether the choice depends on the shading point.
            pub fn at_point(self) -> bool {
                match self {
                    $(EmitterSelection::$variant => !<$ty as ChoiceRule>::POINT_INDEPENDENT,)*
                    EmitterSelection::Ris(_) => false,
                }
            }
        }
    };
}

rules! {
    Uniform(rules::uniform::Uniform) = "uniform", "uni", "every emitter with the same probability";
    Power(rules::power::Power) = "power", "pow", "in proportion to emitted power";
    Exhaustive(rules::exhaustive::Exhaustive) = "exhaustive", "exh",
        "each emitter's importance at the shading point: O(N) per choice, the oracle";
    Bvh(LightTree) = "bvh", "bvh",
        "a light tree (pbrt-v4's BVH light sampler): O(log N) per choice";
}

/// A registered rule: its value, the name the CLI and experiment files use, its short form
/// in strategy labels and a line of help.
#[derive(Clone, Copy, Debug)]
pub struct RuleInfo {
    /// The value.
    pub value: EmitterSelection,
    /// Its name.
    pub name: &'static str,
    /// Its short form in labels.
    pub short: &'static str,
    /// What it is.
    pub help: &'static str,
}

/// The largest RIS candidate count.
pub const RIS_MAX: u32 = 256;

impl EmitterSelection {
    fn row(self) -> Option<&'static RuleInfo> {
        RULES.iter().find(|r| r.value == self)
    }

    /// The name the CLI and experiment files use.
    pub fn name(self) -> String {
        match (self, self.row()) {
            (_, Some(r)) => r.name.into(),
            (EmitterSelection::Ris(m), None) => format!("ris:{m}"),
            _ => unreachable!("every rule has a row in RULES"),
        }
    }

    /// The short form in strategy labels.
    pub fn short(self) -> String {
        match (self, self.row()) {
            (_, Some(r)) => r.short.into(),
            (EmitterSelection::Ris(m), None) => format!("ris{m}"),
            _ => unreachable!("every rule has a row in RULES"),
        }
    }

    /// RIS's candidate count, if this is RIS.
    pub fn ris(self) -> Option<u32> {
        match self {
            EmitterSelection::Ris(m) => Some(m),
            _ => None,
        }
    }

    /// Every registered rule and RIS with one and with eight candidates: what the tests and
    /// checks loop over.
    pub fn every() -> Vec<EmitterSelection> {
        RULES
            .iter()
            .map(|r| r.value)
            .chain([EmitterSelection::Ris(1), EmitterSelection::Ris(8)])
            .collect()
    }
}

impl std::fmt::Display for EmitterSelection {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str(&self.name())
    }
}

impl std::str::FromStr for EmitterSelection {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let s = s.trim();
        if let Some(r) = RULES.iter().find(|r| r.name == s) {
            return Ok(r.value);
        }
        s.strip_prefix("ris:")
            .and_then(|m| m.parse::<u32>().ok())
            .filter(|m| (1..=RIS_MAX).contains(m))
            .map(EmitterSelection::Ris)
            .ok_or_else(|| {
                let names: Vec<&str> = RULES.iter().map(|r| r.name).collect();
                format!(
                    "unknown emitter selection '{s}': expected {} or ris:M with M from 1 to \
                     {RIS_MAX}",
                    names.join(", ")
                )
            })
    }
}

impl TryFrom<String> for EmitterSelection {
    type Error = String;
    fn try_from(s: String) -> Result<Self, String> {
        s.parse()
    }
}

/// A discrete distribution over the scene's emitters, possibly depending on the shading
/// point (p, n), that can also report the pmf of a given emitter, which MIS needs for
/// BSDF-sampled hits. The point-dependent rules may choose nothing where no emitter can
/// contribute.
#[derive(Clone, Debug)]
pub struct EmitterSelector {
    rule: Rule,
    count: usize,
    evaluations: u64,
}

impl EmitterSelector {
    /// The rule `mode` over `emitters`, with `shapes` for the lights' bounds.
    pub fn new(emitters: &[Emitter], shapes: &[Shape], mode: EmitterSelection) -> Self {
        let rule = Rule::build(mode, emitters, shapes);
        let count = emitters.len();
        let evaluations = if count == 0 {
            0
        } else {
            rule.evaluations(count)
        };
        EmitterSelector {
            rule,
            count,
            evaluations,
        }
    }

    /// Whether the choice is the same at every shading point (`bin` and `single` apply).
    pub fn point_independent(&self) -> bool {
        self.rule.point_independent()
    }

    /// An emitter and its pmf at shading point `p` with normal `n` (ignored by the
    /// point-independent rules).
    #[inline]
    pub fn sample(&self, p: Vec3, n: Vec3, u: f32) -> Option<(usize, f32)> {
        if self.count == 0 {
            return None;
        }
        self.rule.sample(self.count, p, n, u)
    }

    /// The pmf with which `sample` at (p, n) chooses emitter i.
    #[inline]
    pub fn pmf(&self, p: Vec3, n: Vec3, i: usize) -> f32 {
        self.rule.pmf(self.count, p, n, i)
    }

    /// The probability that `sample` at (p, n) chooses nothing (tests and reports; the
    /// tree's visits every node).
    pub fn none_probability(&self, p: Vec3, n: Vec3) -> f64 {
        if self.count == 0 {
            return 1.0;
        }
        self.rule.none_probability(p, n)
    }

    /// The emitters no shading point can ever choose (no power, or no area).
    pub fn never_chosen(emitters: &[Emitter], shapes: &[Shape]) -> Vec<usize> {
        (0..emitters.len())
            .filter(|&i| super::LightBounds::of(&emitters[i], shapes).is_none())
            .collect()
    }

    /// Emitters (or tree nodes) weighed per `sample` or `pmf` (see `counts::Counts`).
    #[inline(always)]
    pub fn evaluations(&self) -> u64 {
        self.evaluations
    }

    /// The light tree's depth and size in bytes, if this is the tree (the bench).
    pub fn tree_stats(&self) -> Option<(usize, usize)> {
        self.rule.tree_stats()
    }

    /// With exactly one emitter and a point-independent rule, its pmf: `sample` then
    /// returns (0, this) for every u in [0, 1) (a one-bin alias table keeps its bin).
    #[inline]
    pub fn single(&self) -> Option<f32> {
        (self.count == 1 && self.point_independent()).then(|| self.pmf(Vec3::ZERO, Vec3::ZERO, 0))
    }

    /// Bin i of a point-independent choice as `sample` makes it: the probability of keeping
    /// the bin (against the fractional part of `u * count`) and its alias. Uniform choice
    /// keeps every bin.
    pub fn bin(&self, i: usize) -> (f32, u32) {
        self.rule.bin(i)
    }

    /// The number of emitters it chooses among.
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether there is no emitter.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }
}
