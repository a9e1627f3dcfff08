//! Dialect-neutral scene description: what the XML readers produce and the renderer consumes.
//!
//! Everything here is already in world space (transforms applied, meshes loaded), so the
//! renderer never needs to know which dialect a scene came from. `origin` strings name the file
//! and line an element came from, so errors found later (degenerate emitters, ...) can point at it.

use crate::bsdf::Material;
use glam::{Mat4, Vec3};
use std::path::PathBuf;

pub use crate::math::Rgb;

#[derive(Clone, Debug, PartialEq)]
pub struct SceneDesc {
    /// The XML file the scene was read from.
    pub source: PathBuf,
    pub camera: CameraDesc,
    pub film: FilmDesc,
    pub sampler: SamplerDesc,
    pub integrator: IntegratorDesc,
    pub shapes: Vec<ShapeDesc>,
    pub point_lights: Vec<PointLightDesc>,
    /// Non-fatal findings of the reader (ignored but harmless attributes, defaults applied
    /// where Nori and Mitsuba differ, ...), printed by the CLI.
    pub warnings: Vec<String>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FovAxis {
    X,
    Y,
    Diagonal,
    Smaller,
    Larger,
}

/// Perspective pinhole camera. Camera space follows Mitsuba: looks along +z, +y is up and +x
/// points to the image's left (so `lookat` gives the expected, unmirrored picture).
#[derive(Clone, Debug, PartialEq)]
pub struct CameraDesc {
    pub to_world: Mat4,
    pub fov_degrees: f32,
    pub fov_axis: FovAxis,
    pub near_clip: f32,
    pub far_clip: f32,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FilterDesc {
    Box,
    /// Tent of the given radius in pixels (Mitsuba default 1).
    Tent {
        radius: f32,
    },
    /// Gaussian of the given standard deviation in pixels, truncated at `radius`
    /// (Mitsuba 3: stddev 0.5, radius 4*stddev; Nori: stddev 0.5, radius 2).
    Gaussian {
        stddev: f32,
        radius: f32,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub struct FilmDesc {
    pub width: u32,
    pub height: u32,
    pub filter: FilterDesc,
}

#[derive(Clone, Debug, PartialEq)]
pub struct SamplerDesc {
    pub sample_count: u32,
    pub seed: u64,
    /// The directlab sampler the scene's `<sampler type>` maps to.
    pub kind: crate::sampler::SamplerKind,
}

/// How a direct-lighting estimator combines its techniques; scenes name one, the CLI may
/// override it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum StrategyKind {
    /// BSDF sampling only (Nori `material`).
    Bsdf,
    /// Light sampling only (Nori `light`).
    Light,
    /// Multi-sample MIS of light and BSDF samples.
    Mis,
    /// One-sample MIS: each sample picks one technique at random.
    #[value(name = "mis-onesample")]
    #[serde(rename = "mis-onesample")]
    MisOneSample,
}

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

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Heuristic {
    Balance,
    Power,
}

#[derive(Clone, Debug, PartialEq)]
pub struct IntegratorDesc {
    pub strategy: StrategyKind,
    pub heuristic: Heuristic,
    pub emitter_samples: u32,
    pub bsdf_samples: u32,
    pub hide_emitters: bool,
    /// The global-illumination integrator (`path_mis`, `path`, ...) this scene names, when it
    /// was read as its direct illumination (`--integrator direct`): the image is the direct
    /// part only.
    pub direct_part_of: Option<String>,
}

#[derive(Clone, Debug, PartialEq)]
pub enum ShapeGeometry {
    /// Triangle mesh in world space. `normals`, when present, has one entry per vertex.
    Mesh {
        positions: Vec<Vec3>,
        normals: Option<Vec<Vec3>>,
        indices: Vec<[u32; 3]>,
    },
    /// Exact sphere in world space. `flip_normals` makes its normal point inwards.
    Sphere {
        center: Vec3,
        radius: f32,
        flip_normals: bool,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub struct AreaEmitterDesc {
    /// One-sided constant radiance, emitted on the side the shape normal points to.
    pub radiance: Rgb,
}

#[derive(Clone, Debug, PartialEq)]
pub struct ShapeDesc {
    pub geometry: ShapeGeometry,
    pub bsdf: Material,
    pub emitter: Option<AreaEmitterDesc>,
    /// Where the shape was declared, as "file.xml:LINE <shape type=...>", for messages.
    pub origin: String,
}

#[derive(Clone, Debug, PartialEq)]
pub struct PointLightDesc {
    pub position: Vec3,
    /// Radiant intensity in W/sr.
    pub intensity: Rgb,
    pub origin: String,
}
