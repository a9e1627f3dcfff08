//! Choosing which emitter to sample: uniformly, in proportion to emitted power, or in
//! proportion to an emitter's importance at the shading point (every emitter: `exhaustive`;
//! a light tree: `bvh`). `ris:M` resamples M candidates drawn by power; the resampling
//! itself needs the BSDF and lives in the integrator, so here it is the power table.

use super::bounds::LightBounds;
use super::tree::LightTree;
use super::Emitter;
use crate::geometry::Shape;
use crate::sampling::discrete::bin_index;
use crate::sampling::AliasTable;
use glam::Vec3;

/// The rule for choosing an emitter. Written `uniform`, `power`, `exhaustive`, `bvh` or
/// `ris:M` (M candidates, 1 to 256) in the CLI and in experiment files.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Deserialize)]
#[serde(try_from = "String")]
pub enum EmitterSelection {
    Uniform,
    Power,
    /// Every emitter's importance at the shading point: O(N) per choice, the oracle.
    Exhaustive,
    /// A light tree (pbrt-v4's BVH light sampler): O(log N) per choice.
    Bvh,
    /// Resampled importance sampling of this many candidates drawn by power.
    Ris(u32),
}

/// The largest RIS candidate count.
pub const RIS_MAX: u32 = 256;

impl EmitterSelection {
    /// The name the CLI and experiment files use.
    pub fn name(self) -> String {
        match self {
            EmitterSelection::Uniform => "uniform".into(),
            EmitterSelection::Power => "power".into(),
            EmitterSelection::Exhaustive => "exhaustive".into(),
            EmitterSelection::Bvh => "bvh".into(),
            EmitterSelection::Ris(m) => format!("ris:{m}"),
        }
    }

    /// The short form in strategy labels.
    pub fn short(self) -> String {
        match self {
            EmitterSelection::Uniform => "uni".into(),
            EmitterSelection::Power => "pow".into(),
            EmitterSelection::Exhaustive => "exh".into(),
            EmitterSelection::Bvh => "bvh".into(),
            EmitterSelection::Ris(m) => format!("ris{m}"),
        }
    }

    /// Whether the choice depends on the shading point.
    pub fn at_point(self) -> bool {
        matches!(self, EmitterSelection::Exhaustive | EmitterSelection::Bvh)
    }

    /// RIS's candidate count, if this is RIS.
    pub fn ris(self) -> Option<u32> {
        match self {
            EmitterSelection::Ris(m) => Some(m),
            _ => None,
        }
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
        Ok(match s {
            "uniform" => EmitterSelection::Uniform,
            "power" => EmitterSelection::Power,
            "exhaustive" => EmitterSelection::Exhaustive,
            "bvh" => EmitterSelection::Bvh,
            _ => {
                let m = s
                    .strip_prefix("ris:")
                    .and_then(|m| m.parse::<u32>().ok())
                    .filter(|m| (1..=RIS_MAX).contains(m));
                match m {
                    Some(m) => EmitterSelection::Ris(m),
                    None => {
                        return Err(format!(
                            "unknown emitter selection '{s}': expected uniform, power, \
                             exhaustive, bvh or ris:M with M from 1 to {RIS_MAX}"
                        ))
                    }
                }
            }
        })
    }
}

impl TryFrom<String> for EmitterSelection {
    type Error = String;
    fn try_from(s: String) -> Result<Self, String> {
        s.parse()
    }
}

#[derive(Clone, Debug)]
enum Rule {
    Uniform,
    /// None when no emitter has positive power: uniform, then (the image is black either
    /// way, and the caller reports it).
    Power(Option<AliasTable>),
    Exhaustive(Vec<Option<LightBounds>>),
    Tree(LightTree),
}

/// A discrete distribution over the scene's emitters, possibly depending on the shading
/// point (p, n), that can also report the pmf of a given emitter, which MIS needs for
/// BSDF-sampled hits. The point-dependent rules may choose nothing where no emitter can
/// contribute.
#[derive(Clone, Debug)]
pub struct EmitterSelector {
    rule: Rule,
    count: usize,
}

impl EmitterSelector {
    pub fn new(emitters: &[Emitter], shapes: &[Shape], mode: EmitterSelection) -> Self {
        let bounds = || -> Vec<Option<LightBounds>> {
            emitters
                .iter()
                .map(|e| LightBounds::of(e, shapes))
                .collect()
        };
        let rule = match mode {
            EmitterSelection::Uniform => Rule::Uniform,
            EmitterSelection::Power | EmitterSelection::Ris(_) => {
                let w: Vec<f64> = emitters.iter().map(Emitter::power).collect();
                Rule::Power(AliasTable::new(&w))
            }
            EmitterSelection::Exhaustive => Rule::Exhaustive(bounds()),
            EmitterSelection::Bvh => Rule::Tree(LightTree::build(&bounds())),
        };
        EmitterSelector {
            rule,
            count: emitters.len(),
        }
    }

    /// Whether the choice is the same at every shading point (`bin` and `single` apply).
    pub fn point_independent(&self) -> bool {
        matches!(self.rule, Rule::Uniform | Rule::Power(_))
    }

    /// An emitter and its pmf at shading point `p` with normal `n` (ignored by the
    /// point-independent rules).
    #[inline]
    pub fn sample(&self, p: Vec3, n: Vec3, u: f32) -> Option<(usize, f32)> {
        if self.count == 0 {
            return None;
        }
        match &self.rule {
            Rule::Power(Some(t)) => {
                let i = t.sample(u);
                Some((i, t.pmf(i)))
            }
            Rule::Uniform | Rule::Power(None) => {
                let i = bin_index(u * self.count as f32, self.count);
                Some((i, 1.0 / self.count as f32))
            }
            Rule::Exhaustive(bounds) => exhaustive_sample(bounds, p, n, u),
            Rule::Tree(t) => t.sample(p, n, u),
        }
    }

    /// The pmf with which `sample` at (p, n) chooses emitter i.
    #[inline]
    pub fn pmf(&self, p: Vec3, n: Vec3, i: usize) -> f32 {
        match &self.rule {
            Rule::Power(Some(t)) => t.pmf(i),
            Rule::Uniform | Rule::Power(None) => 1.0 / self.count as f32,
            Rule::Exhaustive(bounds) => {
                let Some(b) = &bounds[i] else {
                    return 0.0;
                };
                let total = exhaustive_total(bounds, p, n);
                let own = b.importance(p, n);
                if total > 0.0 && own > 0.0 {
                    (own / total) as f32
                } else {
                    0.0
                }
            }
            Rule::Tree(t) => t.pmf(p, n, i),
        }
    }

    /// The probability that `sample` at (p, n) chooses nothing (tests and reports; the
    /// tree's visits every node).
    pub fn none_probability(&self, p: Vec3, n: Vec3) -> f64 {
        match &self.rule {
            _ if self.count == 0 => 1.0,
            Rule::Uniform | Rule::Power(_) => 0.0,
            Rule::Exhaustive(b) => (exhaustive_total(b, p, n) == 0.0) as u8 as f64,
            Rule::Tree(t) => t.none_probability(p, n),
        }
    }

    /// The emitters no shading point can ever choose (no power, or no area).
    pub fn never_chosen(emitters: &[Emitter], shapes: &[Shape]) -> Vec<usize> {
        (0..emitters.len())
            .filter(|&i| LightBounds::of(&emitters[i], shapes).is_none())
            .collect()
    }

    /// The light tree's depth and size in bytes, if this is the tree (the bench).
    pub fn tree_stats(&self) -> Option<(usize, usize)> {
        match &self.rule {
            Rule::Tree(t) => Some((t.depth(), t.bytes())),
            _ => None,
        }
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
        match &self.rule {
            Rule::Power(Some(t)) => t.bin(i),
            _ => (f32::INFINITY, i as u32),
        }
    }

    pub fn len(&self) -> usize {
        self.count
    }

    pub fn is_empty(&self) -> bool {
        self.count == 0
    }
}

/// The sum of the emitters' importances at (p, n), in f64, in emitter order.
#[inline]
fn exhaustive_total(bounds: &[Option<LightBounds>], p: Vec3, n: Vec3) -> f64 {
    bounds.iter().flatten().map(|b| b.importance(p, n)).sum()
}

/// The emitter whose share of the importances holds u; its pmf is computed as `pmf` does.
#[inline]
fn exhaustive_sample(
    bounds: &[Option<LightBounds>],
    p: Vec3,
    n: Vec3,
    u: f32,
) -> Option<(usize, f32)> {
    let total = exhaustive_total(bounds, p, n);
    if !(total > 0.0) {
        return None;
    }
    let target = u as f64 * total;
    let (mut acc, mut last) = (0.0f64, None);
    for (i, b) in bounds.iter().enumerate() {
        let Some(b) = b else { continue };
        let own = b.importance(p, n);
        if own > 0.0 {
            acc += own;
            last = Some((i, own));
            if target < acc {
                break;
            }
        }
    }
    // Rounding can leave the target past the last sum: the last emitter that can contribute.
    let (i, own) = last?;
    Some((i, (own / total) as f32))
}

#[cfg(test)]
#[path = "select_tests.rs"]
mod tests;
