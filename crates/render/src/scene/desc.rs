//! Dialect-neutral scene description: what the XML readers produce and the renderer consumes.
//!
//! Everything here is already in world space (transforms applied, meshes loaded), so the
//! renderer never needs to know which dialect a scene came from. `origin` strings name the file
//! and line an element came from, so errors found later (degenerate emitters, ...) can point at it.

use crate::bsdf::Material;
use crate::named::{Choice, Named};
use glam::{Mat4, Vec3};
use std::path::PathBuf;

pub use crate::math::Rgb;

/// A scene as read from XML, in one dialect-neutral form: what `Scene::build` builds from.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneDesc {
    /// The XML file the scene was read from.
    pub source: PathBuf,
    /// The sensor.
    pub camera: CameraDesc,
    /// The film.
    pub film: FilmDesc,
    /// The sampler's settings.
    pub sampler: SamplerDesc,
    /// The integrator's settings.
    pub integrator: IntegratorDesc,
    /// Shapes, with their materials and area emitters.
    pub shapes: Vec<ShapeDesc>,
    /// Point lights.
    pub point_lights: Vec<PointLightDesc>,
    /// Non-fatal findings of the reader (ignored but harmless attributes, defaults applied
    /// where Nori and Mitsuba differ, ...), printed by the CLI.
    pub warnings: Vec<String>,
}

/// Which extent of the film the field of view spans (Mitsuba's `fov_axis`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FovAxis {
    /// The width.
    X,
    /// The height.
    Y,
    /// The diagonal.
    Diagonal,
    /// The smaller of width and height.
    Smaller,
    /// The larger of width and height.
    Larger,
}

/// Perspective pinhole camera. Camera space follows Mitsuba: looks along +z, +y is up and +x
/// points to the image's left (so `lookat` gives the expected, unmirrored picture).
#[derive(Clone, Debug, PartialEq)]
pub struct CameraDesc {
    /// Camera to world.
    pub to_world: Mat4,
    /// Field of view in degrees, along `fov_axis`.
    pub fov_degrees: f32,
    /// The extent the field of view spans.
    pub fov_axis: FovAxis,
    /// Near clip distance.
    pub near_clip: f32,
    /// Far clip distance.
    pub far_clip: f32,
}

/// The film's reconstruction filter (importance-sampled, so pixels are means of their samples).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FilterDesc {
    /// A box of one pixel.
    Box,
    /// Tent of the given radius in pixels (Mitsuba default 1).
    Tent {
        /// Radius in pixels.
        radius: f32,
    },
    /// Gaussian of the given standard deviation in pixels, truncated at `radius`
    /// (Mitsuba 3: stddev 0.5, radius 4*stddev; Nori: stddev 0.5, radius 2).
    Gaussian {
        /// Standard deviation in pixels.
        stddev: f32,
        /// Truncation radius in pixels.
        radius: f32,
    },
}

/// The film.
#[derive(Clone, Debug, PartialEq)]
pub struct FilmDesc {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Reconstruction filter.
    pub filter: FilterDesc,
}

/// The scene's sampler.
#[derive(Clone, Debug, PartialEq)]
pub struct SamplerDesc {
    /// Samples per pixel.
    pub sample_count: u32,
    /// Seed.
    pub seed: u64,
    /// The directlab sampler the scene's `<sampler type>` maps to.
    pub kind: crate::sampler::SamplerKind,
}

/// How a direct-lighting estimator combines its techniques; scenes name one, the CLI may
/// override it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize)]
#[serde(try_from = "String")]
pub enum StrategyKind {
    /// BSDF sampling only (Nori `material`).
    Bsdf,
    /// Light sampling only (Nori `light`).
    Light,
    /// Multi-sample MIS of light and BSDF samples.
    Mis,
    /// One-sample MIS: each sample picks one technique at random.
    MisOneSample,
}

impl Named for StrategyKind {
    const WHAT: &'static str = "strategy";
    const SHORT: &'static [(Self, &'static str)] = &[(StrategyKind::MisOneSample, "mis1")];
    const CHOICES: &'static [Choice<Self>] = &[
        Choice {
            value: StrategyKind::Bsdf,
            name: "bsdf",
            help: "BSDF sampling only (Nori's material)",
        },
        Choice {
            value: StrategyKind::Light,
            name: "light",
            help: "light sampling only (Nori's light)",
        },
        Choice {
            value: StrategyKind::Mis,
            name: "mis",
            help: "multi-sample MIS of light and BSDF samples",
        },
        Choice {
            value: StrategyKind::MisOneSample,
            name: "mis-onesample",
            help: "one-sample MIS: each sample picks one technique at random",
        },
    ];
}
crate::named_impls!(StrategyKind);

impl StrategyKind {
    /// The estimator that `emitter_samples` and `bsdf_samples` leave of this one, with
    /// Mitsuba's meaning of a zero count: MIS without emitter samples is BSDF sampling, MIS
    /// without BSDF samples is light sampling. A pure strategy whose own technique gets no
    /// samples would estimate nothing, and is an error.
    pub fn with_sample_counts(
        self,
        emitter_samples: u32,
        bsdf_samples: u32,
    ) -> Result<Self, String> {
        use StrategyKind::*;
        for (n, what) in [
            (emitter_samples, "emitter_samples"),
            (bsdf_samples, "bsdf_samples"),
        ] {
            crate::limits::count(n as u64, what, crate::limits::TECHNIQUE_SAMPLES)?;
        }
        match (self, emitter_samples, bsdf_samples) {
            (_, 0, 0) => {
                Err("emitter_samples and bsdf_samples are both 0: nothing would be sampled".into())
            }
            (Light, 0, _) => Err("light sampling with emitter_samples = 0 draws no sample".into()),
            (Bsdf, _, 0) => Err("BSDF sampling with bsdf_samples = 0 draws no sample".into()),
            (Mis | MisOneSample, 0, _) => Ok(Bsdf),
            (Mis | MisOneSample, _, 0) => Ok(Light),
            (k, _, _) => Ok(k),
        }
    }
}

/// How MIS weights combine the techniques' densities.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize)]
#[serde(try_from = "String")]
pub enum Heuristic {
    /// Weights proportional to each technique's density (Veach's balance heuristic).
    Balance,
    /// Weights proportional to the densities squared (Veach's power heuristic, beta = 2).
    Power,
}

impl Named for Heuristic {
    const WHAT: &'static str = "heuristic";
    const CHOICES: &'static [Choice<Self>] = &[
        Choice {
            value: Heuristic::Balance,
            name: "balance",
            help: "MIS weights proportional to each technique's density",
        },
        Choice {
            value: Heuristic::Power,
            name: "power",
            help: "MIS weights proportional to the densities squared (beta = 2)",
        },
    ];
}
crate::named_impls!(Heuristic);

/// The scene's integrator settings.
#[derive(Clone, Debug, PartialEq)]
pub struct IntegratorDesc {
    /// The estimator.
    pub strategy: StrategyKind,
    /// MIS weights.
    pub heuristic: Heuristic,
    /// Light samples per camera sample.
    pub emitter_samples: u32,
    /// BSDF samples per camera sample.
    pub bsdf_samples: u32,
    /// Whether emitters seen directly by the camera are left black.
    pub hide_emitters: bool,
    /// The global-illumination integrator (`path_mis`, `path`, ...) this scene names, when it
    /// was read as its direct illumination (`--integrator direct`): the image is the direct
    /// part only.
    pub direct_part_of: Option<String>,
}

/// A shape's geometry, in world space.
#[derive(Clone, Debug, PartialEq)]
pub enum ShapeGeometry {
    /// Triangle mesh in world space. `normals`, when present, has one entry per vertex.
    Mesh {
        /// Vertex positions.
        positions: Vec<Vec3>,
        /// Vertex normals, one per vertex (None: flat shading).
        normals: Option<Vec<Vec3>>,
        /// Triangles as three vertex indices.
        indices: Vec<[u32; 3]>,
    },
    /// Exact sphere in world space. `flip_normals` makes its normal point inwards.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f32,
        /// Whether the normal points inwards.
        flip_normals: bool,
    },
}

/// An area emitter on a shape.
#[derive(Clone, Debug, PartialEq)]
pub struct AreaEmitterDesc {
    /// One-sided constant radiance, emitted on the side the shape normal points to.
    pub radiance: Rgb,
}

/// A shape with its material and, if it emits, its area emitter.
#[derive(Clone, Debug, PartialEq)]
pub struct ShapeDesc {
    /// Its geometry.
    pub geometry: ShapeGeometry,
    /// Its material.
    pub bsdf: Material,
    /// Its area emitter, if it emits.
    pub emitter: Option<AreaEmitterDesc>,
    /// Where the shape was declared, as `file.xml:LINE <shape type=...>`, for messages.
    pub origin: String,
}

/// A point light.
#[derive(Clone, Debug, PartialEq)]
pub struct PointLightDesc {
    /// Position in world space.
    pub position: Vec3,
    /// Radiant intensity in W/sr.
    pub intensity: Rgb,
    /// Where it was declared, for messages.
    pub origin: String,
}
