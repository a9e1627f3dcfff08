//! The protocol form of a sampling case: what an outside program is asked to sample (its
//! domain and parameters) when `directlab check-sampler` checks it in place of directlab's
//! own routine. A built-in case that has one ([`super::Case::external`]) is checked on the same
//! grid, from the same random numbers, so a program implementing the same warp gets the same
//! p-value as the built-in case.

use super::lobe::{narrow, normal_window, WINDOW_MAX_DEPTH};
use super::tangent::Tangent;
use super::CaseConfig;
use crate::sampling::microfacet::MicrofacetDistribution;
use crate::stats::{Disk, Sphere, Triangle, UnitSquare};
use glam::{DVec3, Vec3};
use serde_json::{json, Value};

/// What a program samples, with the parameters it is sent.
#[derive(Clone, Debug)]
pub enum Target {
    /// Points of the unit square [0, 1)^2.
    Square,
    /// Points of the unit disk.
    Disk,
    /// Points (x, y) of the unit right triangle x, y >= 0, x + y <= 1 (barycentrics).
    Triangle,
    /// Unit directions anywhere on the sphere.
    Sphere,
    /// Unit directions with z >= 0 (binned on the whole sphere: a sample below is an error).
    Hemisphere,
    /// Directions within the cap z >= cos_theta_max (Nori's `squareToUniformSphereCap`).
    Cap { cos_theta_max: f32 },
    /// Directions from the origin through the triangle of these vertices, in a window fitted
    /// to it.
    SphericalTriangle { vertices: [Vec3; 3] },
    /// Microfacet normals of density D(m) cos(theta_m) (Nori's `squareToBeckmann`).
    Normals {
        distribution: MicrofacetDistribution,
        alpha: (f32, f32),
    },
    /// Outgoing directions of a BSDF lit from `wi` (local frame, normal +z); the program
    /// also evaluates f cos.
    Bsdf { wi: Vec3 },
}

/// The grid a target is binned on.
pub enum AnyDomain {
    Square(UnitSquare),
    Disk(Disk),
    Triangle(Triangle),
    Sphere(Sphere),
    /// A tangent-plane window: samples outside it count as not drawn, as in the built-in
    /// windowed cases, and the solid-angle pdf is turned into a per-plane-area density.
    Window(Tangent),
}

/// A cap this narrow is tested in a window around its axis, as `warp/uniform-cone-narrow`.
const NARROW_CAP: f32 = 0.99;

impl Target {
    /// The name programs dispatch on (the header's "domain").
    pub fn name(&self) -> &'static str {
        match self {
            Target::Square => "square",
            Target::Disk => "disk",
            Target::Triangle => "triangle",
            Target::Sphere => "sphere",
            Target::Hemisphere => "hemisphere",
            Target::Cap { .. } => "cap",
            Target::SphericalTriangle { .. } => "spherical-triangle",
            Target::Normals { .. } => "microfacet",
            Target::Bsdf { .. } => "bsdf",
        }
    }

    /// Coordinates per point: 2 in the plane, 3 for directions.
    pub fn dim(&self) -> usize {
        match self {
            Target::Square | Target::Disk | Target::Triangle => 2,
            _ => 3,
        }
    }

    /// The parameters sent with every request.
    pub fn params(&self) -> Value {
        let v3 = |v: Vec3| json!([v.x as f64, v.y as f64, v.z as f64]);
        match self {
            Target::Cap { cos_theta_max } => json!({"cos_theta_max": *cos_theta_max as f64}),
            Target::SphericalTriangle { vertices } => {
                json!({"vertices": vertices.map(v3).to_vec()})
            }
            Target::Normals {
                distribution,
                alpha,
            } => json!({
                "distribution": format!("{distribution:?}").to_lowercase(),
                "alpha": alpha.0 as f64,
                "alpha_u": alpha.0 as f64,
                "alpha_v": alpha.1 as f64,
            }),
            Target::Bsdf { wi } => json!({"wi": v3(*wi)}),
            _ => json!({}),
        }
    }

    /// `cfg` as the built-in cases use it on this target: the windows of narrow microfacet
    /// distributions refine no deeper than [`WINDOW_MAX_DEPTH`] (see [`super::lobe`]).
    pub fn config(&self, cfg: &CaseConfig) -> CaseConfig {
        let mut cfg = *cfg;
        if matches!(self, Target::Normals { alpha, .. } if narrow(*alpha)) {
            cfg.integration.max_depth = cfg.integration.max_depth.min(WINDOW_MAX_DEPTH);
        }
        cfg
    }

    /// The grid the target's samples are binned on.
    pub fn domain(&self, cfg: &CaseConfig) -> AnyDomain {
        match self {
            Target::Square => AnyDomain::Square(cfg.square()),
            Target::Disk => AnyDomain::Disk(disk(cfg)),
            Target::Triangle => AnyDomain::Triangle(triangle(cfg)),
            Target::Sphere | Target::Hemisphere | Target::Bsdf { .. } => {
                AnyDomain::Sphere(cfg.sphere())
            }
            Target::Cap { cos_theta_max } if *cos_theta_max >= NARROW_CAP => {
                AnyDomain::Window(cone_window(*cos_theta_max, cfg.resolution))
            }
            Target::Cap { .. } => AnyDomain::Sphere(cfg.sphere()),
            Target::SphericalTriangle { vertices } => {
                AnyDomain::Window(spherical_triangle_window(vertices, cfg.resolution))
            }
            Target::Normals { alpha, .. } => match normal_window(*alpha, cfg.resolution) {
                Some(w) => AnyDomain::Window(w),
                None => AnyDomain::Sphere(cfg.sphere()),
            },
        }
    }
}

/// The disk's grid: `resolution` rings of equal area and as many sectors.
pub fn disk(cfg: &CaseConfig) -> Disk {
    let r = cfg.resolution.max(2);
    Disk { n_phi: r, n_r2: r }
}

/// The unit right triangle's grid.
pub fn triangle(cfg: &CaseConfig) -> Triangle {
    Triangle {
        n: cfg.resolution.max(2),
    }
}

/// A window around +z holding the cap z >= `cos_theta_max`, with a 2 % margin.
pub fn cone_window(cos_theta_max: f32, resolution: usize) -> Tangent {
    let half = (cos_theta_max as f64).acos() * 1.02;
    Tangent::cone(DVec3::Z, half, resolution)
}

/// A window fitted to the triangle `v` as seen from the origin.
pub fn spherical_triangle_window(v: &[Vec3; 3], resolution: usize) -> Tangent {
    let dirs: Vec<DVec3> = v.iter().map(|p| p.as_dvec3().normalize()).collect();
    let axis = dirs.iter().sum::<DVec3>();
    Tangent::fit(axis, &dirs, resolution)
}
