//! directlab's renderer: Monte Carlo direct illumination of Mitsuba 3, Mitsuba 0.6 and Nori
//! scenes, with every estimator of the study (light, BSDF and MIS sampling, emitter choice,
//! samplers) and the per-pixel statistics the harness measures convergence with.
//!
//! Everything that decides a pixel's value lives here and nothing else: the `directlab`
//! harness (experiments, statistics, reports) depends on this crate, never the reverse, and
//! the build hashes this crate's sources and its dependencies' versions into
//! [`RENDERER_HASH`], the key of cached reference images.
//!
//! # Example
//!
//! Load a Mitsuba 3 scene (Mitsuba 0.6 and Nori files load the same way), render it with MIS
//! under the power heuristic, emitter choice by power and the Sobol' sampler, and read a
//! pixel's mean and the variance of that mean:
//!
//! ```
//! use directlab_render::emitter::EmitterSelection;
//! use directlab_render::integrator::{Strategy, StrategyOverrides};
//! use directlab_render::render::{render, RenderSettings};
//! use directlab_render::sampler::{SamplerKind, Sampling};
//! use directlab_render::scene::desc::{Heuristic, StrategyKind};
//!
//! let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/cbox/cbox.xml");
//! // `-D res=32`: the scene's <default name="res"> overridden, as on the command line.
//! let scene = directlab_render::scene::open(path.as_ref(), &[("res".into(), "32".into())])?;
//! let strategy = StrategyOverrides {
//!     strategy: Some(StrategyKind::Mis),
//!     heuristic: Some(Heuristic::Power),
//!     emitter_selection: Some(EmitterSelection::Power),
//!     ..Default::default()
//! }
//! .apply(Strategy::from_desc(&scene.desc.integrator))?;
//! let settings = RenderSettings {
//!     spp: 16,
//!     seed: 7,
//!     first_sample: 0,
//!     threads: None,
//!     progress: None,
//!     sampling: Sampling { kind: SamplerKind::Sobol, ..Default::default() },
//! };
//! let out = render(&scene, strategy, &settings);
//! let (mean, var) = (out.mean.get(16, 16), out.variance.get(16, 16));
//! assert!(mean[0] > 0.0 && var[0] >= 0.0);
//! println!("{}: pixel (16, 16) = {mean:?} +- {:?}", strategy.label(), var.map(f64::sqrt));
//! # Ok::<(), String>(())
//! ```

// `!(x > 0.0)` is how this crate rejects NaN together with non-positive values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
#![deny(missing_docs)]

pub mod aov;
pub mod bsdf;
pub mod build_key;
pub mod camera;
pub mod counts;
pub mod emitter;
pub mod film;
pub mod fnv;
pub mod geometry;
pub mod integrator;
pub mod limits;
pub mod math;
pub mod memory;
pub mod named;
pub mod output;
pub mod render;
pub mod rng;
pub mod sampler;
pub mod sampling;
pub mod scene;
pub mod seeded;

/// Hash of this crate's source files and of the resolved versions of the crates it depends
/// on (from `Cargo.lock`), computed by `build.rs`: two builds with the same hash render the
/// same pixels, so a cached reference is valid exactly while it matches.
pub const RENDERER_HASH: &str = env!("DIRECTLAB_RENDERER_HASH");
