//! Samplers whose every value is a pure function of (pixel, sample index, dimension, seed):
//! stratified and the Sobol' family. A [`PointSet`] says how to draw up to four
//! dimensions of one sample at once; [`PureSample`] and [`PureLanes`] turn it into the
//! renderer's [`Sampler`] and [`SamplerLanes`], numbering dimensions in the order of the
//! allocation table (`sampler/mod.rs`) and choosing between joint and padded draws.

use super::{BsdfDims, DimAlloc, LightDims, PointKind, Sampler, SamplerConfig, SamplerLanes};
use crate::rng::LANES;
use glam::Vec2;

/// A family of point sets indexed by (pixel, sample index, dimension).
pub trait PointSet: Copy + std::fmt::Debug + 'static {
    /// What the samples of one pixel share.
    type Pixel: Copy + std::fmt::Debug;
    /// Whether a group of up to 4 dimensions can be drawn as one joint set; a sampler that
    /// can only stratify 1D and 2D draws (stratified) always pads.
    const JOINT: bool;
    /// [`SamplerLanes::NEEDS_SAMPLE_COUNT`] of its lanes.
    const NEEDS_SAMPLE_COUNT: bool = false;
    /// [`SamplerLanes::ALLOCATES_DIMS`] of its lanes.
    const ALLOCATES_DIMS: bool = false;
    /// [`SamplerLanes::POINTS`] of its lanes.
    const POINTS: PointKind;
    /// [`SamplerLanes::check_run`] of its lanes.
    fn check_run(_run_samples: u64, _width: u32, _height: u32) -> Result<(), String> {
        Ok(())
    }
    /// The shared state of pixel (x, y).
    fn pixel(cfg: &SamplerConfig, x: u32, y: u32) -> Self::Pixel;
    /// Dimensions `dim .. dim + k` (k from 1 to 4) of sample `index`, drawn together as one
    /// set; entries past k are unspecified. Each value lies in [0, 1).
    fn draw(pixel: &Self::Pixel, index: u64, dim: u32, k: usize) -> [f32; 4];
    /// `draw` of samples `s0 .. s0 + LANES` at one dimension, by dimension then lane: a
    /// point set overrides it to share per-group work (a seed's hash) between the lanes and
    /// to compute them side by side.
    #[inline(always)]
    fn draw_lanes(pixel: &Self::Pixel, s0: u64, dim: u32, k: usize) -> [[f32; LANES]; 4] {
        by_dimension(|l| Self::draw(pixel, s0 + l as u64, dim, k))
    }
}

/// Eight lanes' groups, each `lane(l)`, rearranged dimension by dimension.
#[inline(always)]
pub(crate) fn by_dimension(mut lane: impl FnMut(usize) -> [f32; 4]) -> [[f32; LANES]; 4] {
    let mut out = [[0.0; LANES]; 4];
    for l in 0..LANES {
        for (o, v) in out.iter_mut().zip(lane(l)) {
            o[l] = v;
        }
    }
    out
}

/// A pixel's shared state and whether its groups are drawn jointly.
#[derive(Clone, Copy, Debug)]
pub struct PurePixel<P: PointSet> {
    /// The point set's per-pixel state.
    pub inner: P::Pixel,
    /// Whether groups of up to 4 dimensions are drawn as one joint set.
    pub joint: bool,
}

/// One camera sample of a [`PointSet`]: its index and the next dimension it draws.
#[derive(Clone, Copy, Debug)]
pub struct PureSample<P: PointSet> {
    pixel: PurePixel<P>,
    index: u64,
    dim: u32,
}

impl<P: PointSet> PureSample<P> {
    /// Sample `index` of the pixel, at its first dimension.
    pub fn new(pixel: PurePixel<P>, index: u64) -> Self {
        PureSample {
            pixel,
            index,
            dim: 0,
        }
    }

    /// The next dimension this sample will draw.
    pub fn dimension(&self) -> u32 {
        self.dim
    }

    /// The next group: `parts` are its 1D and 2D draws (summing to at most 4), drawn as one
    /// joint set or each on its own, from consecutive dimensions either way.
    #[inline(always)]
    fn group(&mut self, parts: &[usize]) -> [f32; 4] {
        let d = self.dim;
        let k: usize = parts.iter().sum();
        self.dim += k as u32;
        if self.pixel.joint {
            return P::draw(&self.pixel.inner, self.index, d, k);
        }
        let mut out = [0.0; 4];
        let mut at = 0;
        for &n in parts {
            let v = P::draw(&self.pixel.inner, self.index, d + at as u32, n);
            out[at..at + n].copy_from_slice(&v[..n]);
            at += n;
        }
        out
    }
}

impl<P: PointSet> Sampler for PureSample<P> {
    #[inline(always)]
    fn film(&mut self) -> Vec2 {
        let v = self.group(&[2]);
        Vec2::new(v[0], v[1])
    }

    #[inline(always)]
    fn technique(&mut self) -> f32 {
        self.group(&[1])[0]
    }

    #[inline(always)]
    fn light(&mut self) -> LightDims {
        let v = self.group(&[1, 1, 2]);
        LightDims {
            select: v[0],
            primitive: v[1],
            point: Vec2::new(v[2], v[3]),
        }
    }

    #[inline(always)]
    fn bsdf(&mut self) -> BsdfDims {
        let v = self.group(&[1, 2]);
        BsdfDims {
            lobe: v[0],
            direction: Vec2::new(v[1], v[2]),
        }
    }
}

/// `LANES` consecutive samples of a [`PointSet`], each with its own dimension counter (a
/// lane the scalar path continued may have drawn more groups than the others).
#[derive(Clone, Copy, Debug)]
pub struct PureLanes<P: PointSet> {
    pixel: PurePixel<P>,
    s0: u64,
    dim: [u32; LANES],
}

impl<P: PointSet> PureLanes<P> {
    /// The next group of every lane, `N` values each: when every lane is at the same
    /// dimension (they part only where the scalar path continued one), drawn a group at a
    /// time across the lanes; otherwise lane by lane. The same values either way.
    #[inline(always)]
    fn group<const N: usize>(&mut self, parts: &[usize]) -> [[f32; LANES]; N] {
        let d = self.dim[0];
        if self.dim.iter().any(|&x| x != d) {
            return self.each(|s| s.group(parts));
        }
        let mut out = [[0.0; LANES]; N];
        let mut put = |at: usize, n: usize, v: [[f32; LANES]; 4]| {
            out[at..at + n].copy_from_slice(&v[..n]);
        };
        let k: usize = parts.iter().sum();
        if self.pixel.joint {
            put(0, k, P::draw_lanes(&self.pixel.inner, self.s0, d, k));
        } else {
            let mut at = 0;
            for &n in parts {
                put(
                    at,
                    n,
                    P::draw_lanes(&self.pixel.inner, self.s0, d + at as u32, n),
                );
                at += n;
            }
        }
        self.dim = [d + k as u32; LANES];
        out
    }

    #[inline(always)]
    fn each<const N: usize>(
        &mut self,
        f: impl Fn(&mut PureSample<P>) -> [f32; 4],
    ) -> [[f32; LANES]; N] {
        let mut out = [[0.0; LANES]; N];
        for i in 0..LANES {
            let mut one = self.lane(i);
            let v = f(&mut one);
            self.dim[i] = one.dim;
            for (o, v) in out.iter_mut().zip(v) {
                o[i] = v;
            }
        }
        out
    }
}

impl<P: PointSet> SamplerLanes for PureLanes<P> {
    type One = PureSample<P>;
    type Pixel = PurePixel<P>;
    const NEEDS_SAMPLE_COUNT: bool = P::NEEDS_SAMPLE_COUNT;
    const ALLOCATES_DIMS: bool = P::ALLOCATES_DIMS;
    const POINTS: PointKind = P::POINTS;

    fn check_run(run_samples: u64, width: u32, height: u32) -> Result<(), String> {
        P::check_run(run_samples, width, height)
    }

    fn pixel(cfg: &SamplerConfig, x: u32, y: u32) -> PurePixel<P> {
        PurePixel {
            inner: P::pixel(cfg, x, y),
            joint: P::JOINT && cfg.dims == DimAlloc::Joint,
        }
    }

    #[inline]
    fn start(pixel: PurePixel<P>, s0: u64) -> Self {
        PureLanes {
            pixel,
            s0,
            dim: [0; LANES],
        }
    }

    #[inline(always)]
    fn film(&mut self) -> [[f32; LANES]; 2] {
        self.group(&[2])
    }

    #[inline(always)]
    fn light(&mut self) -> [[f32; LANES]; 4] {
        self.group(&[1, 1, 2])
    }

    #[inline(always)]
    fn bsdf(&mut self) -> [[f32; LANES]; 3] {
        self.group(&[1, 2])
    }

    #[inline(always)]
    fn lane(&self, i: usize) -> PureSample<P> {
        PureSample {
            pixel: self.pixel,
            index: self.s0 + i as u64,
            dim: self.dim[i],
        }
    }

    #[inline(always)]
    fn set_lane(&mut self, i: usize, one: &PureSample<P>) {
        self.dim[i] = one.dim;
    }
}
