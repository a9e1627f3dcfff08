//! Where a camera sample's random numbers come from.
//!
//! Every number the renderer draws for a camera sample goes through [`Sampler`] (one sample)
//! or [`SamplerLanes`] (`LANES` samples of a pixel side by side, for the lane kernel), in
//! named groups whose place in the sample is fixed. A sampler that gives each group its own
//! dimensions (a low-discrepancy one) therefore sees the same decision in the same dimensions
//! whichever path renders the sample.
//!
//! # Dimension allocation
//!
//! One camera sample draws, in this order:
//!
//! | group | dimensions | what it decides |
//! |---|---|---|
//! | [`film`](Sampler::film) | 2 | the point in the pixel, warped by the filter |
//! | [`technique`](Sampler::technique) | 1 | one-sample MIS only: light or BSDF technique |
//! | [`light`](Sampler::light) | 4 per light sample | emitter (1), primitive of a mesh (1), point on it (2) |
//! | [`bsdf`](Sampler::bsdf) | 3 per BSDF sample | lobe (1), direction (2) |
//!
//! The estimator (`integrator::direct`) draws its light and BSDF groups in the order of its
//! strategy: light sampling takes `emitter_samples` light groups; BSDF sampling takes
//! `bsdf_samples` BSDF groups, then as many light groups again when the scene has delta
//! lights; multi-sample MIS takes its light groups and then its BSDF groups (its last light
//! group and first BSDF group are drawn before either traces a ray, which does not change the
//! order); one-sample MIS takes one technique group and then one group of the technique it
//! picked. A group a sample does not use (a light sample whose emitter choice failed) is
//! still drawn whole, so later groups keep their place.
//!
//! A delta BSDF (light samples would add 0) draws a BSDF group in place of each light group;
//! under light sampling, a BSDF with a delta lobe beside others (`plastic`) draws a BSDF group
//! after each light group, for the paths only its delta lobe makes.

pub mod independent;

use crate::rng::LANES;
use glam::Vec2;

pub use independent::IndependentLanes;

/// The numbers of one light sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightDims {
    /// Picks the emitter.
    pub select: f32,
    /// Picks the primitive (triangle) of a mesh emitter.
    pub primitive: f32,
    /// The point on the primitive (or the direction in a sphere's cone).
    pub point: Vec2,
}

/// The numbers of one BSDF sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfDims {
    /// Picks the lobe (or is unused by a one-lobe BSDF).
    pub lobe: f32,
    /// The direction within the lobe.
    pub direction: Vec2,
}

/// The numbers of one camera sample, group by group; each value lies in [0, 1).
pub trait Sampler {
    fn film(&mut self) -> Vec2;
    fn technique(&mut self) -> f32;
    fn light(&mut self) -> LightDims;
    fn bsdf(&mut self) -> BsdfDims;
}

/// `LANES` consecutive camera samples of one pixel, lane i being sample `s0 + i`; each group
/// gives one array per dimension. Lane i at any point is [`lane`](SamplerLanes::lane)(i), so
/// a lane the kernel does not cover continues on the scalar path with the same numbers.
pub trait SamplerLanes: Clone {
    type One: Sampler;
    /// What the samples of one pixel share, computed once per pixel.
    type Pixel: Copy;
    fn pixel(seed: u64, pixel: u64) -> Self::Pixel;
    /// Samples `s0 .. s0 + LANES` of the pixel.
    fn start(pixel: Self::Pixel, s0: u64) -> Self;
    fn film(&mut self) -> [[f32; LANES]; 2];
    fn light(&mut self) -> [[f32; LANES]; 4];
    fn bsdf(&mut self) -> [[f32; LANES]; 3];
    /// Lane i's sample, at the point the lanes have reached.
    fn lane(&self, i: usize) -> Self::One;
    /// Lane i continues from `one` (a lane drawn on the scalar path).
    fn set_lane(&mut self, i: usize, one: &Self::One);
}
