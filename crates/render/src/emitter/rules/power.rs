//! Emitter choice in proportion to emitted power (the study's), through an alias table.

use super::uniform::Uniform;
use super::ChoiceRule;
use crate::emitter::Emitter;
use crate::geometry::Shape;
use crate::sampling::AliasTable;
use glam::Vec3;

/// In proportion to emitted power. None when no emitter has positive power: uniform, then
/// (the image is black either way, and the caller reports it).
#[derive(Clone, Debug)]
pub struct Power(Option<AliasTable>);

impl ChoiceRule for Power {
    const POINT_INDEPENDENT: bool = true;

    fn build(emitters: &[Emitter], _: &[Shape]) -> Self {
        let w: Vec<f64> = emitters.iter().map(Emitter::power).collect();
        Power(AliasTable::new(&w))
    }

    #[inline]
    fn sample(&self, count: usize, p: Vec3, n: Vec3, u: f32) -> Option<(usize, f32)> {
        match &self.0 {
            Some(t) => {
                let i = t.sample(u);
                Some((i, t.pmf(i)))
            }
            None => Uniform.sample(count, p, n, u),
        }
    }

    #[inline]
    fn pmf(&self, count: usize, p: Vec3, n: Vec3, i: usize) -> f32 {
        match &self.0 {
            Some(t) => t.pmf(i),
            None => Uniform.pmf(count, p, n, i),
        }
    }

    fn bin(&self, i: usize) -> (f32, u32) {
        match &self.0 {
            Some(t) => t.bin(i),
            None => (f32::INFINITY, i as u32),
        }
    }
}
