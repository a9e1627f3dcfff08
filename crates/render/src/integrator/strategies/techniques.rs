//! What an estimator is written against: the two techniques (a light sample, a BSDF sample)
//! run for a set of hits, and the draw that splits the hits between them. `One` runs them
//! for one hit with `Direct`'s scalar code; the lane kernel runs them for eight hits at
//! once (`lanes::shade`); `First` records which one an estimator calls first, so the lane
//! kernel can draw its numbers before the camera rays are traced.

use super::{Direct, Strategy, Weight};
use crate::counts::Counts;
use crate::integrator::direct::Shading;
use crate::integrator::direct::Term;
use crate::math::Rgb;
use crate::sampler::Sampler;

/// The techniques an estimator combines, for the hits being shaded. Every call adds its
/// samples' terms, each divided by `n`, to the estimate held, in call order.
pub(in crate::integrator) trait Techniques {
    /// A set of the hits: `bool` for one hit, a lane mask for eight.
    type Mask: Copy;
    /// The strategy estimated.
    fn strategy(&self) -> &Strategy;
    /// Whether the scene has delta (point) lights, which BSDF samples never hit.
    fn has_delta_lights(&self) -> bool;
    /// Whether the hits' BSDF has a delta lobe beside lobes with a density (plastic).
    fn has_delta_lobe(&self) -> bool;
    /// Every hit being shaded.
    fn all(&self) -> Self::Mask;
    /// One light sample at each hit of `m`, weighted by `weight(p_light, p_bsdf)`.
    fn light(&mut self, m: Self::Mask, weight: Weight, n: f32);
    /// One BSDF sample at each hit of `m`, weighted by `weight(p_bsdf, p_light)`.
    fn bsdf(&mut self, m: Self::Mask, weight: Weight, n: f32);
    /// A light sample and then a BSDF sample at every hit, both drawn before either traces
    /// its ray (random numbers in the same order as `light` then `bsdf`): their arithmetic
    /// then overlaps instead of waiting behind a traversal.
    fn light_and_bsdf(&mut self, light_weight: Weight, ne: f32, bsdf_weight: Weight, nb: f32);
    /// Draws each hit's technique number: the hits where it is below `c`, and the rest.
    fn split(&mut self, c: f32) -> (Self::Mask, Self::Mask);
}

/// What one camera sample's estimate is made of, for the images of `render --aov`: told
/// each term as the estimate adds it. `()` records nothing (and compiles to nothing).
pub trait Record {
    /// The emission the camera ray sees.
    fn emitted(&mut self, le: Rgb);
    /// A sample of the light (`light`) or BSDF technique that carries light: its term as
    /// added to the estimate, and its MIS weight (without one-sample MIS's division by the
    /// technique's probability).
    fn term(&mut self, light: bool, value: Rgb, mis_weight: f32);
}

impl Record for () {
    #[inline(always)]
    fn emitted(&mut self, _: Rgb) {}
    #[inline(always)]
    fn term(&mut self, _: bool, _: Rgb, _: f32) {}
}

/// The techniques at one hit, with `Direct`'s scalar code; `rec` is told every term.
pub(in crate::integrator) struct One<'r, 'd, 's, S, R> {
    d: &'r Direct<'d>,
    sh: &'r Shading<'s>,
    rng: &'r mut S,
    c: &'r mut Counts,
    rec: &'r mut R,
    /// The estimate so far.
    pub(in crate::integrator) l: Rgb,
}

impl<'r, 'd, 's, S: Sampler, R: Record> One<'r, 'd, 's, S, R> {
    pub(in crate::integrator) fn new(
        d: &'r Direct<'d>,
        sh: &'r Shading<'s>,
        rng: &'r mut S,
        c: &'r mut Counts,
        rec: &'r mut R,
        l: Rgb,
    ) -> Self {
        One {
            d,
            sh,
            rng,
            c,
            rec,
            l,
        }
    }

    /// Adds a sample's term, weighted and divided by `n`, to the estimate.
    #[inline(always)]
    fn add(&mut self, light: bool, term: Option<Term>, weight: Weight, n: f32) {
        let v = match term {
            Some(t) => {
                let (v, w) = t.weighted(weight);
                let v = v / n;
                self.rec.term(light, v, weight.mis_part(w));
                v
            }
            None => Rgb::ZERO,
        };
        self.l += v;
    }
}

impl<S: Sampler, R: Record> Techniques for One<'_, '_, '_, S, R> {
    type Mask = bool;

    #[inline(always)]
    fn strategy(&self) -> &Strategy {
        &self.d.strategy
    }

    #[inline(always)]
    fn has_delta_lights(&self) -> bool {
        self.d.has_delta_lights()
    }

    #[inline(always)]
    fn has_delta_lobe(&self) -> bool {
        self.sh.mat.has_delta_lobe()
    }

    #[inline(always)]
    fn all(&self) -> bool {
        true
    }

    #[inline(always)]
    fn light(&mut self, m: bool, weight: Weight, n: f32) {
        if m {
            let drawn = self.d.light_draw(self.sh, self.rng, self.c);
            let term = self.d.light_term(self.sh, drawn, self.c);
            self.add(true, term, weight, n);
        }
    }

    #[inline(always)]
    fn bsdf(&mut self, m: bool, weight: Weight, n: f32) {
        if m {
            let drawn = self.d.bsdf_draw(self.sh, self.rng, self.c);
            let term = self.d.bsdf_term(self.sh, drawn, self.c);
            self.add(false, term, weight, n);
        }
    }

    #[inline(always)]
    fn light_and_bsdf(&mut self, light_weight: Weight, ne: f32, bsdf_weight: Weight, nb: f32) {
        let (d, sh) = (self.d, self.sh);
        let light = d.light_draw(sh, self.rng, self.c);
        let bsdf = d.bsdf_draw(sh, self.rng, self.c);
        let term = d.light_term(sh, light, self.c);
        self.add(true, term, light_weight, ne);
        let term = d.bsdf_term(sh, bsdf, self.c);
        self.add(false, term, bsdf_weight, nb);
    }

    #[inline(always)]
    fn split(&mut self, c: f32) -> (bool, bool) {
        let below = self.rng.technique() < c;
        (below, !below)
    }
}

/// The first call an estimator makes for every hit of a batch, as `First::of` records it
/// (for a hit whose BSDF has no delta lobe, in a scene without point lights).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(in crate::integrator) enum First {
    /// A light sample at every hit.
    Light,
    /// A BSDF sample at every hit.
    Bsdf,
    /// `light_and_bsdf`.
    LightAndBsdf,
    /// Anything else (a split, a call for some hits only, or none).
    Other,
}

/// Records the first call (see `First`).
struct Recorder {
    strategy: Strategy,
    first: Option<First>,
}

impl Recorder {
    fn note(&mut self, call: First) {
        self.first.get_or_insert(call);
    }
}

impl Techniques for Recorder {
    type Mask = bool;

    fn strategy(&self) -> &Strategy {
        &self.strategy
    }

    fn has_delta_lights(&self) -> bool {
        false
    }

    fn has_delta_lobe(&self) -> bool {
        false
    }

    fn all(&self) -> bool {
        true
    }

    fn light(&mut self, m: bool, _: Weight, _: f32) {
        self.note(if m { First::Light } else { First::Other });
    }

    fn bsdf(&mut self, m: bool, _: Weight, _: f32) {
        self.note(if m { First::Bsdf } else { First::Other });
    }

    fn light_and_bsdf(&mut self, _: Weight, _: f32, _: Weight, _: f32) {
        self.note(First::LightAndBsdf);
    }

    fn split(&mut self, _: f32) -> (bool, bool) {
        self.note(First::Other);
        (true, false)
    }
}

impl First {
    /// The first call of `strategy`'s estimator.
    pub(in crate::integrator) fn of(strategy: Strategy) -> First {
        let mut r = Recorder {
            strategy,
            first: None,
        };
        super::li(&mut r, false);
        r.first.unwrap_or(First::Other)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::desc::StrategyKind;

    #[test]
    fn first_calls_of_the_estimators() {
        let all = Strategy::combinations();
        let find = |k: StrategyKind, e: u32| {
            *all.iter()
                .find(|s| s.kind == k && s.emitter_samples == e)
                .expect("a strategy of the kind")
        };
        assert_eq!(First::of(find(StrategyKind::Mis, 1)), First::LightAndBsdf);
        assert_eq!(First::of(find(StrategyKind::Mis, 2)), First::Light);
        assert_eq!(First::of(find(StrategyKind::Light, 1)), First::Light);
        assert_eq!(First::of(find(StrategyKind::Bsdf, 1)), First::Bsdf);
        assert_eq!(First::of(find(StrategyKind::MisOneSample, 1)), First::Other);
    }
}
