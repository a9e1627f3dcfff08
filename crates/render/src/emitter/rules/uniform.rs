//! Uniform emitter choice: every emitter with probability 1 / N (the study's default).

use super::ChoiceRule;
use crate::emitter::Emitter;
use crate::geometry::Shape;
use crate::sampling::discrete::bin_index;
use glam::Vec3;

/// Every emitter with the same probability.
#[derive(Clone, Debug)]
pub struct Uniform;

impl ChoiceRule for Uniform {
    const POINT_INDEPENDENT: bool = true;

    fn build(_: &[Emitter], _: &[Shape]) -> Self {
        Uniform
    }

    #[inline]
    fn sample(&self, count: usize, _: Vec3, _: Vec3, u: f32) -> Option<(usize, f32)> {
        let i = bin_index(u * count as f32, count);
        Some((i, 1.0 / count as f32))
    }

    #[inline]
    fn pmf(&self, count: usize, _: Vec3, _: Vec3, _: usize) -> f32 {
        1.0 / count as f32
    }
}
