//! The techniques in lanes: `Lanes` runs an estimator's light and BSDF samples
//! (`strategies::Techniques`) for the covered lanes of a batch at once, with one instance of
//! its code per BSDF type: the draws of each step's numbers, its shading and traversal
//! (`steps`), and each lane's term added as `Direct` adds it.

// Lane loops index a dozen structure-of-arrays fields by the same lane number; iterators
// over one of them would hide that symmetry.
#![allow(clippy::needless_range_loop)]

use super::steps::{bsdf_step, light_step, pair_step, ris_numbers, setup, Setup};
use super::tables::LaneTables;
#[cfg(test)]
use super::Path;
use super::{CameraHits, LaneKernel, LightDraws, Shaded};
use crate::bsdf::{Bsdf, Registered};
use crate::counts::Counts;
use crate::geometry::ray_packet::bits;
use crate::integrator::direct::Weight;
use crate::integrator::strategies::{self, First, Techniques};
use crate::integrator::Strategy;
use crate::math::{Rgb, V3x8};
use crate::rng::LANES;
use crate::sampler::{Sampler, SamplerLanes};

/// The numbers of the estimator's first call (`First`), drawn before the camera rays are
/// traced: drawn after, their chain of dependent 64-bit multiplications (about 15 cycles
/// each) started only once traversal ended.
#[derive(Default)]
pub(super) struct Pre {
    light: Option<[[f32; LANES]; 4]>,
    bsdf: Option<[[f32; LANES]; 3]>,
}

impl Pre {
    /// The numbers `first` draws, from `rng`, which is left after them.
    #[inline(always)]
    pub(super) fn draw<L: SamplerLanes>(first: First, rng: &mut L) -> Pre {
        let light = matches!(first, First::Light | First::LightAndBsdf).then(|| rng.light());
        let bsdf = matches!(first, First::Bsdf | First::LightAndBsdf).then(|| rng.bsdf());
        Pre { light, bsdf }
    }
}

/// A batch's working state, for the techniques of its covered lanes: the sampler lanes
/// `rng` standing after the camera's numbers (or after `pre`'s) and `at_hit` a copy of them
/// from before `pre`.
pub(super) struct Lanes<'k, 'a, L: SamplerLanes, const SPHERES: bool> {
    pub(super) kernel: &'k LaneKernel<'a>,
    pub(super) tables: &'k LaneTables<'a>,
    pub(super) h: &'k CameraHits,
    pub(super) rng: &'k mut L,
    pub(super) at_hit: &'k L,
    pub(super) pre: Pre,
    pub(super) draws: &'k mut LightDraws,
    pub(super) o: &'k mut Shaded,
    pub(super) c: &'k mut Counts,
}

impl<'k, 'a, L: SamplerLanes, const SPHERES: bool> Lanes<'k, 'a, L, SPHERES> {
    /// Runs the strategy's estimator for the covered lanes, lane i with BSDF `b[i]` (all of
    /// type `B`; `b[0]` for all if `U`, see `lane_bsdf`), and writes their estimates to `out`.
    #[inline(always)]
    fn run<B: Bsdf, const U: bool>(self, b: &[B; LANES], out: &mut [Rgb; LANES]) {
        let h = self.h;
        let mut t = Techniques8::<B, L, SPHERES, U> {
            setup: setup::<B, U>(b, h),
            l: h.le,
            lanes: self,
            b,
        };
        strategies::li(&mut t, false);
        for i in bits(h.covered) {
            out[i] = t.l.get(i);
        }
    }
}

/// `Lanes` with its lanes' BSDFs, its per-batch setup and its estimates so far.
struct Techniques8<'k, 'a, B, L: SamplerLanes, const SPHERES: bool, const U: bool> {
    lanes: Lanes<'k, 'a, L, SPHERES>,
    b: &'k [B; LANES],
    setup: Setup,
    l: V3x8,
}

impl<B: Bsdf, L: SamplerLanes, const SPHERES: bool, const U: bool>
    Techniques8<'_, '_, B, L, SPHERES, U>
{
    /// `pre`'s numbers if the call that wants them is the first and runs for every lane
    /// (`light`, `bsdf`: which numbers it draws); otherwise None, with `rng` put back to
    /// where the hit left it if `pre` drew numbers that this call does not take.
    #[inline(always)]
    fn take_pre(&mut self, light: bool, bsdf: bool, full: bool) -> Option<Pre> {
        let x = &mut self.lanes;
        let has = (x.pre.light.is_some(), x.pre.bsdf.is_some());
        if has == (false, false) {
            return None;
        }
        let pre = std::mem::take(&mut x.pre);
        if full && has == (light, bsdf) {
            return Some(pre);
        }
        x.rng.clone_from(x.at_hit);
        None
    }

    /// The light numbers of the lanes in `live` (RIS: those of each lane's kept candidate,
    /// with the density it divides by in `draws.p_div`); other covered lanes' samplers stay.
    #[inline(always)]
    fn light_numbers(&mut self, live: u32) -> [[f32; LANES]; 4] {
        let x = &mut self.lanes;
        let h = x.h;
        #[cfg(test)]
        x.kernel
            .paths
            .note(Path::MaskedDraw, (h.covered & !live != 0) as u64);
        let direct = &x.kernel.direct;
        if direct.ris.is_some() {
            let mut u = [[0.0; LANES]; 4];
            ris_numbers(direct, x.rng, h, live, &mut u, &mut x.draws.p_div, x.c);
            return u;
        }
        masked(x.rng, live, h.covered, |r| r.light())
    }

    /// The BSDF numbers of the lanes in `live`.
    #[inline(always)]
    fn bsdf_numbers(&mut self, live: u32) -> [[f32; LANES]; 3] {
        let x = &mut self.lanes;
        #[cfg(test)]
        x.kernel
            .paths
            .note(Path::MaskedDraw, (x.h.covered & !live != 0) as u64);
        masked(x.rng, live, x.h.covered, |r| r.bsdf())
    }
}

/// Adds `x / n` to the estimate `l` of each lane of `m`, `x` zero outside `lit`. x / 1 is x
/// exactly: a division by one is left out.
#[inline(always)]
fn add(l: &mut V3x8, x: &V3x8, lit: u32, m: u32, n: f32) {
    let mut t = V3x8::default();
    for i in 0..LANES {
        t.set(
            i,
            if lit >> i & 1 != 0 {
                x.get(i)
            } else {
                Rgb::ZERO
            },
        );
    }
    if n != 1.0 {
        for i in 0..LANES {
            t.set(i, t.get(i) / n);
        }
    }
    for i in 0..LANES {
        let (keep, sum) = (l.get(i), l.get(i) + t.get(i));
        l.set(i, if m >> i & 1 != 0 { sum } else { keep });
    }
}

impl<B: Bsdf, L: SamplerLanes, const SPHERES: bool, const U: bool> Techniques
    for Techniques8<'_, '_, B, L, SPHERES, U>
{
    type Mask = u32;

    #[inline(always)]
    fn strategy(&self) -> &Strategy {
        &self.lanes.kernel.direct.strategy
    }

    #[inline(always)]
    fn has_delta_lights(&self) -> bool {
        self.lanes.kernel.direct.has_delta_lights()
    }

    #[inline(always)]
    fn has_delta_lobe(&self) -> bool {
        B::DELTA_LOBE
    }

    #[inline(always)]
    fn all(&self) -> u32 {
        self.lanes.h.covered
    }

    #[inline(always)]
    fn light(&mut self, m: u32, weight: Weight, n: f32) {
        let live = m & self.lanes.h.covered;
        if live == 0 {
            return;
        }
        let u = match self.take_pre(true, false, live == self.lanes.h.covered) {
            Some(pre) => pre.light.expect("the first call's light numbers"),
            None => self.light_numbers(live),
        };
        let x = &mut self.lanes;
        let (k, h, s) = (x.kernel, x.h, &self.setup);
        let lit = light_step::<B, SPHERES, U>(
            k, x.tables, self.b, h, s, &u, x.draws, x.o, x.c, live, weight,
        );
        add(&mut self.l, &x.o.light, lit, live, n);
    }

    #[inline(always)]
    fn bsdf(&mut self, m: u32, weight: Weight, n: f32) {
        let live = m & self.lanes.h.covered;
        if live == 0 {
            return;
        }
        let u = match self.take_pre(false, true, live == self.lanes.h.covered) {
            Some(pre) => pre.bsdf.expect("the first call's BSDF numbers"),
            None => self.bsdf_numbers(live),
        };
        let x = &mut self.lanes;
        let (k, h, s) = (x.kernel, x.h, &self.setup);
        let bsdf = bsdf_step::<B, SPHERES, U>(k, self.b, h, s, &u, x.o, x.c, live, weight);
        add(&mut self.l, &bsdf, !0, live, n);
    }

    #[inline(always)]
    fn light_and_bsdf(&mut self, light_weight: Weight, ne: f32, bsdf_weight: Weight, nb: f32) {
        let live = self.lanes.h.covered;
        let (ul, ub) = match self.take_pre(true, true, true) {
            Some(pre) => (
                pre.light.expect("the first call's light numbers"),
                pre.bsdf.expect("the first call's BSDF numbers"),
            ),
            None => {
                let ul = self.light_numbers(live);
                (ul, self.bsdf_numbers(live))
            }
        };
        let x = &mut self.lanes;
        let (k, h, s) = (x.kernel, x.h, &self.setup);
        let (lit, bsdf) = pair_step::<B, SPHERES, U>(
            k,
            x.tables,
            self.b,
            h,
            s,
            &ul,
            &ub,
            x.draws,
            x.o,
            x.c,
            light_weight,
            bsdf_weight,
        );
        add(&mut self.l, &x.o.light, lit, live, ne);
        add(&mut self.l, &bsdf, !0, live, nb);
    }

    #[inline(always)]
    fn split(&mut self, c: f32) -> (u32, u32) {
        #[cfg(test)]
        self.lanes.kernel.paths.note(Path::Split, 1);
        self.take_pre(false, false, false);
        let x = &mut self.lanes;
        let mut below = 0;
        for i in bits(x.h.covered) {
            let mut one = x.rng.lane(i);
            below |= ((one.technique() < c) as u32) << i;
            x.rng.set_lane(i, &one);
        }
        (below, x.h.covered & !below)
    }
}

/// `draw(rng)` for the lanes in `live`: covered lanes outside it keep their samplers.
#[inline(always)]
fn masked<L: SamplerLanes, T>(
    rng: &mut L,
    live: u32,
    covered: u32,
    draw: impl FnOnce(&mut L) -> T,
) -> T {
    let keep = covered & !live;
    if keep == 0 {
        return draw(rng);
    }
    let before = rng.clone();
    let u = draw(rng);
    for i in bits(keep) {
        rng.set_lane(i, &before.lane(i));
    }
    u
}

/// A batch's estimator with its BSDF type resolved (`LaneKernel::li_lanes`).
impl LaneKernel<'_> {
    /// The estimates of the covered lanes of a batch whose first material has BSDF type
    /// `B`: its BSDFs copied next to the working arrays, where the compiler can see that no
    /// store of the kernel changes them (read where the scene keeps them, their fields were
    /// reloaded in every lane).
    #[inline(always)]
    pub(super) fn shade_batch<'k, B: Bsdf + Registered, L: SamplerLanes, const SPHERES: bool>(
        &'k self,
        x: Lanes<'k, '_, L, SPHERES>,
        out: &mut [Rgb; LANES],
    ) {
        let materials = &self.direct.scene.materials;
        let first = *B::view(&materials[x.h.first as usize].kind)
            .expect("the batch's first material has the batch's type");
        #[cfg(test)]
        self.paths.note(
            match x.h.uniform {
                true => Path::UniformBatch,
                false => Path::MixedBatch,
            },
            1,
        );
        match x.h.uniform {
            true => x.run::<B, true>(&[first; LANES], out),
            false => {
                let Lanes {
                    tables,
                    h,
                    rng,
                    at_hit,
                    pre,
                    draws,
                    o,
                    c,
                    ..
                } = x;
                self.shade_mixed::<B, L, SPHERES>(
                    tables, h, rng, at_hit, pre, draws, o, c, first, out,
                )
            }
        }
    }

    /// `shade_batch`, out of line (see `li_lanes`). Its arrays are separate reference
    /// arguments, as `shade_mixed`'s: passed gathered in one structure (`Lanes`) they lose
    /// `noalias`, and the shading loops stopped compiling to vector code (Veach 0.7x).
    #[inline(never)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn shade_batch_out_of_line<
        B: Bsdf + Registered,
        L: SamplerLanes,
        const SPHERES: bool,
    >(
        &self,
        tables: &LaneTables,
        h: &CameraHits,
        rng: &mut L,
        at_hit: &L,
        pre: Pre,
        draws: &mut LightDraws,
        o: &mut Shaded,
        c: &mut Counts,
        out: &mut [Rgb; LANES],
    ) {
        let x = Lanes::<L, SPHERES> {
            kernel: self,
            tables,
            h,
            rng,
            at_hit,
            pre,
            draws,
            o,
            c,
        };
        self.shade_batch::<B, L, SPHERES>(x, out)
    }

    /// `shade_batch` for a batch of several materials (at a pixel straddling two), out of
    /// line, so that the instance for one material, which nearly every batch takes,
    /// compiles as it would alone.
    #[inline(never)]
    #[allow(clippy::too_many_arguments)]
    fn shade_mixed<B: Bsdf + Registered, L: SamplerLanes, const SPHERES: bool>(
        &self,
        tables: &LaneTables,
        h: &CameraHits,
        rng: &mut L,
        at_hit: &L,
        pre: Pre,
        draws: &mut LightDraws,
        o: &mut Shaded,
        c: &mut Counts,
        first: B,
        out: &mut [Rgb; LANES],
    ) {
        let x = Lanes::<L, SPHERES> {
            kernel: self,
            tables,
            h,
            rng,
            at_hit,
            pre,
            draws,
            o,
            c,
        };
        let materials = &self.direct.scene.materials;
        // Each lane's BSDF; the first material's for lanes not covered.
        let mut b = [first; LANES];
        for i in bits(x.h.covered) {
            b[i] = *B::view(&materials[x.h.material[i] as usize].kind).unwrap_or(&first);
        }
        x.run::<B, false>(&b, out)
    }
}
