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
pub mod permute;
pub mod pure;
pub mod sobol;
pub mod stratified;
pub mod zsobol;

#[cfg(test)]
mod registry_tests;

use crate::named::{Choice, Named};
use crate::rng::LANES;
use glam::Vec2;

pub use independent::IndependentLanes;
pub use pure::{PointSet, PureLanes, PureSample};

/// The registration: one line per sampler, `Variant(lane type) = "name", "help"`. It makes
/// the closed set [`SamplerKind`] (its first line is the default), its names and help for the
/// command line and experiment files ([`Named`]), the dispatch to the lane type
/// ([`SamplerKind::visit`]) and the properties every check reads from the lane type
/// ([`SamplerLanes`]'s constants). Tests that loop over `SamplerKind::all()` then give a new
/// sampler its proofs: lanes against scalar samples, values and strata on odd films, its
/// unbiasedness case and its row of test integrands.
macro_rules! samplers {
    ($first:ident($first_ty:ty) = $first_name:literal, $first_help:literal;
     $($variant:ident($ty:ty) = $name:literal, $help:literal;)*) => {
        /// The samplers a render can draw its numbers from.
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Deserialize)]
        #[serde(try_from = "String")]
        pub enum SamplerKind {
            #[doc = $first_help]
            #[default]
            $first,
            $(#[doc = $help] $variant,)*
        }

        impl Named for SamplerKind {
            const WHAT: &'static str = "sampler";
            const CHOICES: &'static [Choice<Self>] = &[
                Choice { value: SamplerKind::$first, name: $first_name, help: $first_help },
                $(Choice { value: SamplerKind::$variant, name: $name, help: $help },)*
            ];
        }

        impl SamplerKind {
            /// `v.visit` with this sampler's lane type.
            #[inline(always)]
            pub fn visit<V: LanesVisitor>(self, v: V) -> V::Output {
                match self {
                    SamplerKind::$first => v.visit::<$first_ty>(),
                    $(SamplerKind::$variant => v.visit::<$ty>(),)*
                }
            }
        }
    };
}

samplers! {
    Independent(IndependentLanes) = "independent",
        "every number from the sample's own PCG32 generator";
    Stratified(stratified::StratifiedLanes) = "stratified",
        "jittered strata, one permutation of the strata per pixel and dimension (padded)";
    Sobol(sobol::SobolLanes) = "sobol",
        "Owen-scrambled Sobol' points (Burley's hash), re-seeded per group of dimensions";
    SobolXor(sobol::SobolXorLanes) = "sobol-xor",
        "the same Sobol' points with a random digital shift only: what Owen scrambling buys";
    ZSobol(zsobol::ZSobolLanes) = "zsobol",
        "one Owen-scrambled Sobol' sequence for the film in Morton order: blue-noise error (pbrt-v4)";
}
crate::named_impls!(SamplerKind);

/// The kind of point set a sampler draws, which decides the convergence rate theory
/// predicts for it and the sample counts at which its structure is complete.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PointKind {
    /// Independent uniform numbers: error O(N^-1/2) at every N.
    Random,
    /// Jittered strata of a square grid: complete at powers of four.
    Jittered,
    /// An Owen-scrambled (0, 2)-sequence: complete at powers of two.
    ScrambledNet,
    /// A digitally shifted (0, 2)-sequence: complete at powers of two; no published rate.
    ShiftedNet,
}

impl SamplerKind {
    /// Whether the sampler must know the run's sample count in advance (its strata, or
    /// the block of the sequence each pixel takes).
    pub fn needs_sample_count(self) -> bool {
        struct V;
        impl LanesVisitor for V {
            type Output = bool;
            fn visit<L: SamplerLanes>(self) -> bool {
                L::NEEDS_SAMPLE_COUNT
            }
        }
        self.visit(V)
    }

    /// Whether the dimension allocation (`DimAlloc`) changes the sampler's points: the
    /// independent sampler has no sets, the stratified one is always padded.
    pub fn allocates_dims(self) -> bool {
        struct V;
        impl LanesVisitor for V {
            type Output = bool;
            fn visit<L: SamplerLanes>(self) -> bool {
                L::ALLOCATES_DIMS
            }
        }
        self.visit(V)
    }

    /// The kind of point set it draws.
    pub fn points(self) -> PointKind {
        struct V;
        impl LanesVisitor for V {
            type Output = PointKind;
            fn visit<L: SamplerLanes>(self) -> PointKind {
                L::POINTS
            }
        }
        self.visit(V)
    }

    /// Why the sampler cannot draw `run_samples` samples per pixel of a `width` x `height`
    /// film, if it cannot.
    pub fn check_run(self, run_samples: u64, width: u32, height: u32) -> Result<(), String> {
        struct V(u64, u32, u32);
        impl LanesVisitor for V {
            type Output = Result<(), String>;
            fn visit<L: SamplerLanes>(self) -> Result<(), String> {
                L::check_run(self.0, self.1, self.2)
            }
        }
        self.visit(V(run_samples, width, height))
    }
}

/// How a sample's groups of numbers take their dimensions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Deserialize)]
#[serde(try_from = "String")]
pub enum DimAlloc {
    /// Each group (film, light sample, BSDF sample) is one point of a joint set of up to 4
    /// dimensions: a light sample's emitter choice and point on the light are stratified
    /// together.
    #[default]
    Joint,
    /// Each 1D or 2D draw is its own, independently randomised set (pbrt's PaddedSobol and
    /// every stratified sampler): stratified per draw, not jointly.
    Padded,
}

impl Named for DimAlloc {
    const WHAT: &'static str = "dimension allocation";
    const CHOICES: &'static [Choice<Self>] = &[
        Choice {
            value: DimAlloc::Joint,
            name: "joint",
            help: "a light sample's emitter choice and point form one joint set of dimensions",
        },
        Choice {
            value: DimAlloc::Padded,
            name: "padded",
            help: "each 1D or 2D draw is its own, independently randomised set",
        },
    ];
}
crate::named_impls!(DimAlloc);

/// A render's choice of sampler.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Sampling {
    /// Where the numbers come from.
    pub kind: SamplerKind,
    /// How a sample's groups take their dimensions.
    pub dims: DimAlloc,
    /// Samples per pixel of the whole run when a render is one chunk of it (a reference's
    /// chunks); None: the render's own `first_sample + spp`.
    pub run_samples: Option<u64>,
}

impl Sampling {
    /// The configuration of a render of samples `first .. first + spp`, or why the sampler
    /// cannot draw them.
    pub fn config(
        &self,
        seed: u64,
        first: u64,
        spp: u32,
        (width, height): (u32, u32),
    ) -> Result<SamplerConfig, String> {
        let end = first + spp as u64;
        let run_samples = self.run_samples.unwrap_or(end);
        if self.kind.needs_sample_count() {
            if end > run_samples {
                return Err(format!(
                    "the {} sampler's strata are laid out for {run_samples} samples per pixel, \
                     but samples {first}..{end} were asked for",
                    self.kind.name()
                ));
            }
            if run_samples > stratified::MAX_SAMPLES {
                return Err(format!(
                    "the {} sampler takes at most {} samples per pixel ({run_samples} asked for)",
                    self.kind.name(),
                    stratified::MAX_SAMPLES
                ));
            }
        }
        self.kind.check_run(run_samples, width, height)?;
        Ok(SamplerConfig {
            dims: self.dims,
            seed,
            run_samples,
            width,
            height,
        })
    }
}

/// Code generic over the lane sampler, run for a [`SamplerKind`] by
/// [`SamplerKind::visit`]: the one place a sampler is registered for rendering.
pub trait LanesVisitor {
    /// What the operation returns.
    type Output;
    /// Runs the operation, compiled for the lane sampler `L`.
    fn visit<L: SamplerLanes>(self) -> Self::Output;
}

/// What every sampler of a render knows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SamplerConfig {
    /// How a sample's groups take their dimensions.
    pub dims: DimAlloc,
    /// The render's seed.
    pub seed: u64,
    /// Samples per pixel of the whole run (all chunks of a reference): a stratified
    /// sampler's strata.
    pub run_samples: u64,
    /// The film's width, which numbers the pixels.
    pub width: u32,
    /// The film's height (zsobol's Morton codes span the larger side).
    pub height: u32,
}

impl SamplerConfig {
    /// The pixel's index in the film, row by row.
    pub fn pixel_index(&self, x: u32, y: u32) -> u64 {
        y as u64 * self.width as u64 + x as u64
    }
}

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
    /// The film position within the pixel (filter importance sampling).
    fn film(&mut self) -> Vec2;
    /// One-sample MIS's choice of technique.
    fn technique(&mut self) -> f32;
    /// A light sample's numbers: emitter choice, primitive, point.
    fn light(&mut self) -> LightDims;
    /// A BSDF sample's numbers: lobe and direction.
    fn bsdf(&mut self) -> BsdfDims;
}

/// Whether the 2^m points are a (0, m, 2)-net: every 2^i x 2^(m-i) elementary box holds
/// exactly one of them (tests of the Sobol' samplers).
#[cfg(test)]
pub(crate) fn is_02_net(points: &[(f32, f32)], m: u32) -> bool {
    assert_eq!(points.len(), 1 << m);
    (0..=m).all(|i| {
        let (nx, ny) = (1u64 << i, 1u64 << (m - i));
        let mut count = vec![0u32; 1 << m];
        for &(x, y) in points {
            let (bx, by) = ((x as f64 * nx as f64) as u64, (y as f64 * ny as f64) as u64);
            count[(by * nx + bx) as usize] += 1;
        }
        count.iter().all(|&c| c == 1)
    })
}

/// One camera sample's groups in allocation order, as the ten values they hold (tests).
#[cfg(test)]
pub(crate) fn all_values(s: &mut impl Sampler) -> [f32; 10] {
    let (f, t, l, b) = (s.film(), s.technique(), s.light(), s.bsdf());
    [
        f.x,
        f.y,
        t,
        l.select,
        l.primitive,
        l.point.x,
        l.point.y,
        b.lobe,
        b.direction.x,
        b.direction.y,
    ]
}

/// `LANES` consecutive camera samples of one pixel, lane i being sample `s0 + i`; each group
/// gives one array per dimension. Lane i at any point is [`lane`](SamplerLanes::lane)(i), so
/// a lane the kernel does not cover continues on the scalar path with the same numbers.
pub trait SamplerLanes: Clone {
    /// The scalar sampler a lane continues as.
    type One: Sampler;
    /// What the samples of one pixel share, computed once per pixel.
    type Pixel: Copy;
    /// The shared state of pixel (x, y).
    fn pixel(cfg: &SamplerConfig, x: u32, y: u32) -> Self::Pixel;
    /// Samples `s0 .. s0 + LANES` of the pixel.
    fn start(pixel: Self::Pixel, s0: u64) -> Self;
    /// The film positions of the lanes.
    fn film(&mut self) -> [[f32; LANES]; 2];
    /// The light-sample numbers of the lanes.
    fn light(&mut self) -> [[f32; LANES]; 4];
    /// The BSDF-sample numbers of the lanes.
    fn bsdf(&mut self) -> [[f32; LANES]; 3];
    /// Lane i's sample, at the point the lanes have reached.
    fn lane(&self, i: usize) -> Self::One;
    /// Lane i continues from `one` (a lane drawn on the scalar path).
    fn set_lane(&mut self, i: usize, one: &Self::One);
    /// Whether it must know the run's sample count in advance (its strata, or the block of
    /// the sequence each pixel takes).
    const NEEDS_SAMPLE_COUNT: bool = false;
    /// Whether the dimension allocation (`DimAlloc`) changes its points.
    const ALLOCATES_DIMS: bool = false;
    /// The kind of point set it draws.
    const POINTS: PointKind = PointKind::Random;
    /// Why it cannot draw `run_samples` samples per pixel of a `width` x `height` film, if it
    /// cannot (checked before a render starts).
    fn check_run(_run_samples: u64, _width: u32, _height: u32) -> Result<(), String> {
        Ok(())
    }
}
