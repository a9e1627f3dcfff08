//! The direct-lighting estimator for one camera ray: the techniques (light and BSDF samples
//! with their MIS weights, RIS) that the strategies of `strategies/` combine.
//!
//! All densities are in solid angle. The light technique's density of a direction is
//! pmf(emitter) * pdf_emitter(direction); the BSDF technique's is the BSDF's pdf. Multi-sample
//! MIS weights each technique with h(n_i p_i, n_j p_j) (Veach's heuristics); one-sample MIS
//! picks a technique with probability c_i and weights by h(c_i p_i, c_j p_j) / c_i.

use super::Strategy;
use crate::bsdf::{BsdfSample, Material};
use crate::counts::Counts;
use crate::emitter::{EmitterSelector, LightSample};
use crate::geometry::{Hit, SurfacePoint};
use crate::math::{luminance, Frame, Rgb};
use crate::sampler::{LightDims, Sampler};
use crate::scene::desc::Heuristic;
use crate::scene::Scene;
use glam::Vec3;

/// The direct-illumination estimator of one strategy on one scene (the scalar path).
pub struct Direct<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// The strategy it estimates with.
    pub strategy: Strategy,
    pub(super) selector: EmitterSelector,
    has_delta_lights: bool,
    /// RIS's candidate count, if it is above 1 (`ris:1` is its source strategy, power).
    pub(super) ris: Option<u32>,
}

/// A light sample drawn: the point, its emitter's choice pmf and the density the estimate
/// divides by (pmf * pdf, or RIS's 1 / W). MIS weights use pmf * pdf in every case: for RIS
/// that is the density of its candidates, which BSDF-sampled hits also use (any density
/// both techniques compute alike keeps the weights a partition of unity, and the RIS
/// estimate f W stays unbiased for every weighted integrand).
#[derive(Clone, Copy)]
pub(super) struct LightDraw {
    ls: LightSample,
    pmf: f32,
    p_div: f32,
}

#[inline]
pub(super) fn heuristic(h: Heuristic, a: f32, b: f32) -> f32 {
    let (a, b) = match h {
        Heuristic::Balance => (a, b),
        Heuristic::Power => (a * a, b * b),
    };
    if a == 0.0 || b.is_infinite() {
        0.0
    } else {
        a / (a + b)
    }
}

/// A sample's weight given its own technique's density p and the other's q (its MIS weight
/// divided by the technique's selection probability). A value, not a closure: the steps
/// that apply it are compiled once for every strategy, not once per weight.
#[derive(Clone, Copy, Debug)]
pub(super) enum Weight {
    /// 1 (a pure strategy's own technique).
    One,
    /// A pure strategy's fallback to the other technique, for the paths only it can produce
    /// (delta BSDFs for light sampling, delta lights for BSDF sampling): 1 where the
    /// strategy's own technique (the sample's other) has density 0, else 0. Nothing is lost
    /// or counted twice.
    OnlyOther,
    /// Multi-sample MIS: h(own p, other q) with the two techniques' sample counts.
    Mis { h: Heuristic, own: f32, other: f32 },
    /// One-sample MIS: h(own p, other q) / own with the techniques' probabilities.
    OneSample { h: Heuristic, own: f32, other: f32 },
}

impl Weight {
    /// The weight of a sample of densities p (its technique) and q (the other).
    #[inline(always)]
    pub(super) fn at(self, p: f32, q: f32) -> f32 {
        match self {
            Weight::One => 1.0,
            Weight::OnlyOther => {
                if q == 0.0 {
                    1.0
                } else {
                    0.0
                }
            }
            Weight::Mis { h, own, other } => heuristic(h, own * p, other * q),
            Weight::OneSample { h, own, other } => heuristic(h, own * p, other * q) / own,
        }
    }

    /// The MIS weight in a weight `w = self.at(p, q)`: w without one-sample MIS's division
    /// by the technique's probability.
    pub(super) fn mis_part(self, w: f32) -> f32 {
        match self {
            Weight::OneSample { own, .. } => w * own,
            _ => w,
        }
    }
}

/// A sample that carries light, before its weight: `f * (w / div)` with w = weight(p, q),
/// p its own technique's density and q the other's (`div` is 1 for BSDF samples, whose `f`
/// is already divided by their density).
#[derive(Clone, Copy, Debug)]
pub(super) struct Term {
    pub(super) f: Rgb,
    pub(super) div: f32,
    pub(super) p: f32,
    pub(super) q: f32,
}

impl Term {
    /// The weighted value and the weight.
    #[inline(always)]
    pub(super) fn weighted(self, weight: Weight) -> (Rgb, f32) {
        let w = weight.at(self.p, self.q);
        (self.f * (w / self.div), w)
    }
}

/// Runs `$body` with `$w` the closure `|p, q| weight.at(p, q)` of `$weight`'s kind and
/// heuristic fixed, so that the match is made once, outside the lane loops that call `$w`:
/// matched per lane inside them, it kept the loops from compiling to vector code (Cornell
/// box renders ran at 0.78x).
macro_rules! by_weight {
    ($weight:expr, |$w:ident| $body:expr) => {{
        use $crate::integrator::direct::Weight::{Mis, One, OneSample, OnlyOther};
        use $crate::scene::desc::Heuristic::{Balance, Power};
        match $weight {
            One => {
                let $w = |p: f32, q: f32| One.at(p, q);
                $body
            }
            OnlyOther => {
                let $w = |p: f32, q: f32| OnlyOther.at(p, q);
                $body
            }
            Mis {
                h: Power,
                own,
                other,
            } => {
                let $w = move |p: f32, q: f32| {
                    Mis {
                        h: Power,
                        own,
                        other,
                    }
                    .at(p, q)
                };
                $body
            }
            Mis {
                h: Balance,
                own,
                other,
            } => {
                let $w = move |p: f32, q: f32| {
                    Mis {
                        h: Balance,
                        own,
                        other,
                    }
                    .at(p, q)
                };
                $body
            }
            OneSample {
                h: Power,
                own,
                other,
            } => {
                let $w = move |p: f32, q: f32| {
                    OneSample {
                        h: Power,
                        own,
                        other,
                    }
                    .at(p, q)
                };
                $body
            }
            OneSample {
                h: Balance,
                own,
                other,
            } => {
                let $w = move |p: f32, q: f32| {
                    OneSample {
                        h: Balance,
                        own,
                        other,
                    }
                    .at(p, q)
                };
                $body
            }
        }
    }};
}
pub(super) use by_weight;

/// Shading context at a camera-ray hit.
pub(super) struct Shading<'m> {
    pub(super) sp: SurfacePoint,
    pub(super) frame: Frame,
    pub(super) wi: Vec3,
    pub(super) mat: &'m Material,
}

impl<'a> Direct<'a> {
    /// The estimator of `strategy` on `scene`, with its emitter choice built.
    pub fn new(scene: &'a Scene, strategy: Strategy) -> Self {
        let selector = EmitterSelector::new(&scene.emitters, &scene.shapes, strategy.selection);
        Direct {
            scene,
            strategy,
            has_delta_lights: scene.emitters.iter().any(|e| e.is_delta()),
            selector,
            ris: strategy.selection.ris().filter(|&m| m > 1),
        }
    }

    /// Whether the scene has delta (point) lights, which BSDF samples never hit.
    #[inline(always)]
    pub(super) fn has_delta_lights(&self) -> bool {
        self.has_delta_lights
    }

    /// The shading context of a camera ray of direction `d` that hit `sp`.
    #[inline(always)]
    pub(super) fn shading(&self, sp: &SurfacePoint, d: Vec3) -> Shading<'_> {
        let frame = Frame::from_normal(sp.ns);
        Shading {
            sp: *sp,
            frame,
            wi: frame.to_local(-d),
            mat: self.scene.material(sp),
        }
    }

    /// The random half of a light sample: the emitter, its point and density.
    #[inline(always)]
    pub(super) fn light_draw(
        &self,
        sh: &Shading,
        rng: &mut impl Sampler,
        c: &mut Counts,
    ) -> Option<LightDraw> {
        if let Some(m) = self.ris {
            return self.ris_draw(sh, rng, m, c).map(|(d, _)| d);
        }
        c.light_samples += 1;
        c.choice_evals += self.selector.evaluations();
        let (ls, pmf) = self.candidate(&sh.sp, rng.light())?;
        Some(LightDraw {
            ls,
            pmf,
            p_div: pmf * ls.pdf,
        })
    }

    /// An emitter chosen at the shading point `sp` and a point drawn on it, with numbers `u`.
    #[inline(always)]
    pub(super) fn candidate(&self, sp: &SurfacePoint, u: LightDims) -> Option<(LightSample, f32)> {
        let scene = self.scene;
        let (ei, pmf) = self.selector.sample(sp.p, sp.ns, u.select)?;
        let ls = scene.emitters[ei].sample(
            &scene.shapes,
            sp.p,
            u.primitive,
            u.point,
            self.strategy.light_sampling,
        )?;
        Some((ls, pmf))
    }

    /// Resampled importance sampling (Talbot 2005; Bitterli et al. 2020's weight): `m`
    /// candidates drawn by power, one kept with probability proportional to
    /// w = p_hat / (pmf * pdf), where p_hat is the luminance of its unshadowed contribution;
    /// the estimate divides by m p_hat / sum(w). One number chooses (drawn first, with the
    /// technique's dimension), rescaled after each candidate as a reservoir of one; each
    /// candidate takes a light sample's numbers whether it is kept or not. Also returns the
    /// kept candidate's numbers, from which the lane kernel draws it again.
    #[inline(never)]
    fn ris_draw(
        &self,
        sh: &Shading,
        rng: &mut impl Sampler,
        m: u32,
        c: &mut Counts,
    ) -> Option<(LightDraw, LightDims)> {
        const BELOW_ONE: f64 = 1.0 - f64::EPSILON / 2.0;
        let mut u = rng.technique() as f64;
        let mut w_sum = 0.0f64;
        let mut kept: Option<(LightSample, f32, f32, LightDims)> = None;
        for _ in 0..m {
            let dims = rng.light();
            c.light_samples += 1;
            c.choice_evals += self.selector.evaluations();
            let Some((ls, pmf)) = self.candidate(&sh.sp, dims) else {
                continue;
            };
            c.bsdf_evals += 1;
            let (f, _) = sh.mat.eval_pdf(sh.wi, sh.frame.to_local(ls.wi));
            let p_hat = luminance(f * ls.li);
            let w = p_hat as f64 / (pmf as f64 * ls.pdf as f64);
            if !(p_hat > 0.0 && w.is_finite()) {
                continue;
            }
            w_sum += w;
            let q = w / w_sum;
            if u < q {
                u = (u / q).min(BELOW_ONE);
                kept = Some((ls, pmf, p_hat, dims));
            } else {
                u = ((u - q) / (1.0 - q)).min(BELOW_ONE);
            }
        }
        let (ls, pmf, p_hat, dims) = kept?;
        let drawn = LightDraw {
            ls,
            pmf,
            p_div: (m as f64 * p_hat as f64 / w_sum) as f32,
        };
        Some((drawn, dims))
    }

    /// For the lane kernel, RIS's draw at a camera ray's hit `sp` (direction `d`), with `rng`
    /// where `li` would receive it: the kept candidate's numbers and the density the estimate
    /// divides by, or None if no candidate was kept. `rng` is left where `li` draws its BSDF
    /// sample. Only for `ris:M` with M > 1.
    pub(super) fn ris_for_lane(
        &self,
        sp: &SurfacePoint,
        d: Vec3,
        rng: &mut impl Sampler,
        c: &mut Counts,
    ) -> Option<(LightDims, f32)> {
        let m = self.ris.expect("RIS over several candidates");
        let sh = self.shading(sp, d);
        self.ris_draw(&sh, rng, m, c)
            .map(|(drawn, dims)| (dims, drawn.p_div))
    }

    /// The rest of a light sample: BSDF and visibility; its term before the weight
    /// `weight(p_light, p_bsdf)` (its MIS weight divided by the technique's selection
    /// probability; a delta light has p_bsdf = 0, since no other technique can produce it).
    /// None: it carries no light.
    #[inline(always)]
    pub(super) fn light_term(
        &self,
        sh: &Shading,
        drawn: Option<LightDraw>,
        c: &mut Counts,
    ) -> Option<Term> {
        let LightDraw { ls, pmf, p_div } = drawn?;
        let wo = sh.frame.to_local(ls.wi);
        c.bsdf_evals += 1;
        let (f, pdf) = sh.mat.eval_pdf(sh.wi, wo);
        if f == Rgb::ZERO || ls.li == Rgb::ZERO {
            return None;
        }
        c.shadow_rays += 1;
        if !self.scene.visible(&sh.sp, &ls) {
            return None;
        }
        Some(Term {
            f: f * ls.li,
            div: p_div,
            p: pmf * ls.pdf,
            q: if ls.delta { 0.0 } else { pdf },
        })
    }

    /// The random half of a BSDF sample.
    #[inline(always)]
    pub(super) fn bsdf_draw(
        &self,
        sh: &Shading,
        rng: &mut impl Sampler,
        c: &mut Counts,
    ) -> Option<BsdfSample> {
        c.bsdf_samples += 1;
        let u = rng.bsdf();
        sh.mat.sample(sh.wi, u.lobe, u.direction)
    }

    /// The rest of a BSDF sample: its ray and the emitter it reaches; its term before the
    /// weight `weight(p_bsdf, p_light)` (a delta lobe has p_light = 0: light sampling cannot
    /// hit it). None: it carries no light.
    #[inline(always)]
    pub(super) fn bsdf_term(
        &self,
        sh: &Shading,
        drawn: Option<BsdfSample>,
        c: &mut Counts,
    ) -> Option<Term> {
        let scene = self.scene;
        let bs = drawn?;
        let d = sh.frame.to_world(bs.wo);
        let (ray, emitter_skip) = scene.bsdf_ray(&sh.sp, d);
        if !scene.bsdf_ray_may_hit(&ray) {
            c.bsdf_rejected += 1;
            return None;
        }
        c.bsdf_rays += 1;
        let hit = scene.bsdf_ray_hit_traced(&ray, emitter_skip)?;
        self.bsdf_emission_term(&sh.sp, ray.d, &hit, &bs, c)
    }

    /// `bsdf_term` once its ray (from `from`, direction `d`) has hit `hit`.
    #[inline(always)]
    fn bsdf_emission_term(
        &self,
        from: &SurfacePoint,
        d: Vec3,
        hit: &Hit,
        bs: &BsdfSample,
        c: &mut Counts,
    ) -> Option<Term> {
        let scene = self.scene;
        let (ei, e) = scene.emitter_at(&hit.sp)?;
        let le = e.le(&hit.sp, -d);
        if le == Rgb::ZERO {
            return None;
        }
        let p_light = if bs.delta {
            0.0
        } else {
            c.light_pdf_evals += 1;
            c.choice_evals += self.selector.evaluations();
            self.selector.pmf(from.p, from.ns, ei)
                * e.pdf(&scene.shapes, from.p, &hit.sp, self.strategy.light_sampling)
        };
        Some(Term {
            f: bs.weight * le,
            div: 1.0,
            p: bs.pdf,
            q: p_light,
        })
    }

    /// `bsdf_emission_term` weighted (for the lanes that finish a BSDF sample one by one).
    #[inline(always)]
    pub(super) fn bsdf_emission(
        &self,
        from: &SurfacePoint,
        d: Vec3,
        hit: &Hit,
        bs: &BsdfSample,
        weight: Weight,
        c: &mut Counts,
    ) -> Rgb {
        self.bsdf_emission_term(from, d, hit, bs, c)
            .map_or(Rgb::ZERO, |t| t.weighted(weight).0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heuristics() {
        assert_eq!(heuristic(Heuristic::Balance, 1.0, 3.0), 0.25);
        assert_eq!(heuristic(Heuristic::Power, 1.0, 3.0), 0.1);
        assert_eq!(heuristic(Heuristic::Balance, 0.0, 0.0), 0.0);
        assert_eq!(heuristic(Heuristic::Balance, 2.0, 0.0), 1.0);
    }
}
