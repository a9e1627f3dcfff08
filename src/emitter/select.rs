//! Choosing which emitter to sample: uniformly, or in proportion to emitted power.

use super::Emitter;
use crate::sampling::AliasTable;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EmitterSelection {
    Uniform,
    Power,
}

/// A discrete distribution over the scene's emitters that can also report the pmf of a given
/// emitter, which MIS needs for BSDF-sampled hits.
#[derive(Clone, Debug)]
pub struct EmitterSelector {
    table: Option<AliasTable>,
    count: usize,
}

impl EmitterSelector {
    /// Power-proportional choice falls back to uniform when no emitter has positive power
    /// (the image is black either way, and the caller reports it).
    pub fn new(emitters: &[Emitter], mode: EmitterSelection) -> Self {
        let table = match mode {
            EmitterSelection::Uniform => None,
            EmitterSelection::Power => {
                let w: Vec<f64> = emitters.iter().map(Emitter::power).collect();
                AliasTable::new(&w)
            }
        };
        EmitterSelector {
            table,
            count: emitters.len(),
        }
    }

    #[inline]
    pub fn sample(&self, u: f32) -> Option<(usize, f32)> {
        if self.count == 0 {
            return None;
        }
        Some(match &self.table {
            Some(t) => {
                let i = t.sample(u);
                (i, t.pmf(i))
            }
            None => {
                let i = ((u * self.count as f32) as usize).min(self.count - 1);
                (i, 1.0 / self.count as f32)
            }
        })
    }

    #[inline]
    pub fn pmf(&self, i: usize) -> f32 {
        match &self.table {
            Some(t) => t.pmf(i),
            None => 1.0 / self.count as f32,
        }
    }
}
