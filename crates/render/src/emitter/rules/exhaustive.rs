//! Exhaustive emitter choice: every emitter's importance at the shading point (its
//! unshadowed contribution bound, `LightBounds::importance`), O(N) per choice: the oracle the
//! light tree approximates.

use super::ChoiceRule;
use crate::emitter::bounds::LightBounds;
use crate::emitter::Emitter;
use crate::geometry::Shape;
use glam::Vec3;

/// Each emitter in proportion to its importance at the shading point.
#[derive(Clone, Debug)]
pub struct Exhaustive(Vec<Option<LightBounds>>);

/// The sum of the emitters' importances at (p, n), in f64, in emitter order.
#[inline]
fn total(bounds: &[Option<LightBounds>], p: Vec3, n: Vec3) -> f64 {
    bounds.iter().flatten().map(|b| b.importance(p, n)).sum()
}

impl ChoiceRule for Exhaustive {
    const POINT_INDEPENDENT: bool = false;

    fn build(emitters: &[Emitter], shapes: &[Shape]) -> Self {
        Exhaustive(
            emitters
                .iter()
                .map(|e| LightBounds::of(e, shapes))
                .collect(),
        )
    }

    /// The emitter whose share of the importances holds u; its pmf is computed as `pmf` does.
    #[inline]
    fn sample(&self, _: usize, p: Vec3, n: Vec3, u: f32) -> Option<(usize, f32)> {
        let total = total(&self.0, p, n);
        if !(total > 0.0) {
            return None;
        }
        let target = u as f64 * total;
        let (mut acc, mut last) = (0.0f64, None);
        for (i, b) in self.0.iter().enumerate() {
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
        // Rounding can leave the target past the last sum: the last emitter that can
        // contribute.
        let (i, own) = last?;
        Some((i, (own / total) as f32))
    }

    #[inline]
    fn pmf(&self, _: usize, p: Vec3, n: Vec3, i: usize) -> f32 {
        let Some(b) = &self.0[i] else {
            return 0.0;
        };
        let total = total(&self.0, p, n);
        let own = b.importance(p, n);
        if total > 0.0 && own > 0.0 {
            (own / total) as f32
        } else {
            0.0
        }
    }

    fn none_probability(&self, p: Vec3, n: Vec3) -> f64 {
        (total(&self.0, p, n) == 0.0) as u8 as f64
    }

    /// Every emitter's weight, to normalise.
    fn evaluations(&self, count: usize) -> u64 {
        count as u64
    }
}
