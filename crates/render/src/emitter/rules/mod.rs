//! The emitter-choice rules, one file each, registered in `select.rs` (`rules!`): what a
//! rule is ([`ChoiceRule`]) and the rules themselves.

pub mod exhaustive;
pub mod power;
pub mod uniform;

use super::Emitter;
use crate::geometry::Shape;
use glam::Vec3;

/// A rule for choosing an emitter: a discrete distribution over the scene's emitters,
/// possibly depending on the shading point (p, n), that can also report the pmf of a given
/// emitter (MIS needs it for BSDF-sampled hits). Rules that depend on the point may choose
/// nothing where no emitter can contribute. `count`, the number of emitters, is at least 1
/// in every call (the selector answers for an empty scene itself).
pub trait ChoiceRule: Clone + std::fmt::Debug + Sized {
    /// Whether the choice is the same at every shading point; such a rule must also give
    /// its alias table through [`bin`](ChoiceRule::bin), which the lane kernel reads.
    const POINT_INDEPENDENT: bool;
    /// The rule over `emitters`, with `shapes` for the lights' bounds.
    fn build(emitters: &[Emitter], shapes: &[Shape]) -> Self;
    /// An emitter and its pmf at (p, n), from one uniform number.
    fn sample(&self, count: usize, p: Vec3, n: Vec3, u: f32) -> Option<(usize, f32)>;
    /// The pmf with which `sample` at (p, n) chooses emitter i.
    fn pmf(&self, count: usize, p: Vec3, n: Vec3, i: usize) -> f32;
    /// The probability that `sample` at (p, n) chooses nothing.
    fn none_probability(&self, _p: Vec3, _n: Vec3) -> f64 {
        0.0
    }
    /// Bin i of a point-independent choice: the probability of keeping the bin (against the
    /// fractional part of `u * count`) and its alias; every bin is kept by default.
    fn bin(&self, i: usize) -> (f32, u32) {
        (f32::INFINITY, i as u32)
    }
    /// The depth and size in bytes of its tree, if it has one (the bench).
    fn tree_stats(&self) -> Option<(usize, usize)> {
        None
    }
    /// Emitters (or nodes) it weighs in one draw or one pmf among `count` emitters, the
    /// emitter-choice count of `counts::Counts`: one table lookup by default.
    fn evaluations(&self, _count: usize) -> u64 {
        1
    }
}
