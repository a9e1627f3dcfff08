//! Emitters (one-sided diffuse area lights, point lights) and the choice among them.

mod area;
mod bounds;
mod select;
mod tree;

pub use area::AreaLight;
pub(crate) use area::{area_pdf_along, sample_at, sphere_area_point};
pub use bounds::{Cone, LightBounds};
pub use select::{EmitterSelection, EmitterSelector, RIS_MAX};

use crate::geometry::{Shape, SurfacePoint};
use crate::math::{luminance, Rgb, PI};
use glam::{Vec2, Vec3};

/// How a point on an area light is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LightSampling {
    /// Uniform by area (the study's method), converted to solid angle.
    Area,
    /// Uniform in the solid angle the shape subtends (spherical triangles, sphere cones).
    SolidAngle,
}

/// A point drawn on an emitter as seen from a reference point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Point on the light, its geometric normal and error scale (for the shadow ray's end).
    pub p: Vec3,
    pub ng: Vec3,
    pub err_scale: Vec3,
    /// Unit direction from the reference point to `p`, and the distance.
    pub wi: Vec3,
    pub dist: f32,
    /// Radiance arriving at the reference point along `wi` (before visibility).
    pub li: Rgb,
    /// Solid-angle density of `wi` given this emitter (choice pmf not included); 1 for delta.
    pub pdf: f32,
    pub delta: bool,
}

#[derive(Clone, Debug)]
pub struct PointLight {
    pub position: Vec3,
    pub intensity: Rgb,
}

#[derive(Clone, Debug)]
pub enum Emitter {
    Area(AreaLight),
    Point(PointLight),
}

impl Emitter {
    /// Emitted power in luminance units: pi * area * L for one-sided diffuse area lights,
    /// 4 pi * I for point lights.
    pub fn power(&self) -> f64 {
        match self {
            Emitter::Area(a) => PI as f64 * a.area as f64 * luminance(a.radiance) as f64,
            Emitter::Point(p) => 4.0 * PI as f64 * luminance(p.intensity) as f64,
        }
    }

    pub fn is_delta(&self) -> bool {
        matches!(self, Emitter::Point(_))
    }

    /// `u_prim` chooses the triangle, `u` the point: one number per decision.
    #[inline]
    pub fn sample(
        &self,
        shapes: &[Shape],
        ref_p: Vec3,
        u_prim: f32,
        u: Vec2,
        mode: LightSampling,
    ) -> Option<LightSample> {
        match self {
            Emitter::Area(a) => a.sample(shapes, ref_p, u_prim, u, mode),
            Emitter::Point(pl) => {
                let d = pl.position - ref_p;
                let dist2 = d.length_squared();
                if dist2 == 0.0 || !dist2.is_finite() {
                    return None;
                }
                let dist = dist2.sqrt();
                Some(LightSample {
                    p: pl.position,
                    ng: -d / dist,
                    err_scale: Vec3::ZERO,
                    wi: d / dist,
                    dist,
                    li: pl.intensity / dist2,
                    pdf: 1.0,
                    delta: true,
                })
            }
        }
    }

    /// Solid-angle density with which `sample` would produce the point `sp` seen from `ref_p`.
    #[inline]
    pub fn pdf(
        &self,
        shapes: &[Shape],
        ref_p: Vec3,
        sp: &SurfacePoint,
        mode: LightSampling,
    ) -> f32 {
        match self {
            Emitter::Area(a) => a.pdf(shapes, ref_p, sp, mode),
            Emitter::Point(_) => 0.0,
        }
    }

    /// Radiance leaving `sp` towards `w` (unit, pointing away from the surface).
    #[inline]
    pub fn le(&self, sp: &SurfacePoint, w: Vec3) -> Rgb {
        match self {
            Emitter::Area(a) => a.le(sp, w),
            Emitter::Point(_) => Rgb::ZERO,
        }
    }
}

#[cfg(test)]
mod tests;
