//! Emitters (one-sided diffuse area lights, point lights) and the choice among them.

mod area;
mod bounds;
pub mod envmap;
pub mod rules;
mod select;
mod tree;

pub use area::AreaLight;
pub(crate) use area::{area_pdf_along, sample_at, sphere_area_point};
pub use bounds::{Cone, LightBounds};
pub use select::{EmitterSelection, EmitterSelector, RuleInfo, RIS_MAX, RULES};

use crate::geometry::{Shape, SurfacePoint};
use crate::math::{luminance, Rgb, PI};
use crate::named::Choice;
use glam::{Vec2, Vec3};

/// How a point on an area light is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize)]
#[serde(try_from = "String")]
pub enum LightSampling {
    /// Uniform by area (the study's method), converted to solid angle.
    Area,
    /// Uniform in the solid angle the shape subtends (spherical triangles, sphere cones).
    SolidAngle,
}

impl crate::named::Named for LightSampling {
    const WHAT: &'static str = "light sampling";
    const SHORT: &'static [(Self, &'static str)] = &[(LightSampling::SolidAngle, "sa")];
    const CHOICES: &'static [Choice<Self>] = &[
        Choice {
            value: LightSampling::Area,
            name: "area",
            help: "light points uniform by area (the study's), converted to solid angle",
        },
        Choice {
            value: LightSampling::SolidAngle,
            name: "solid-angle",
            help: "uniform in the solid angle a light subtends (spherical triangles, sphere cones)",
        },
    ];
}
crate::named_impls!(LightSampling);

/// A point drawn on an emitter as seen from a reference point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Point on the light, its geometric normal and error scale (for the shadow ray's end).
    pub p: Vec3,
    /// Geometric normal at `p`.
    pub ng: Vec3,
    /// Per component, the magnitude `p` was computed from (the shadow ray's offset).
    pub err_scale: Vec3,
    /// Unit direction from the reference point to `p`, and the distance.
    pub wi: Vec3,
    /// Distance from the reference point to `p`.
    pub dist: f32,
    /// Radiance arriving at the reference point along `wi` (before visibility).
    pub li: Rgb,
    /// Solid-angle density of `wi` given this emitter (choice pmf not included); 1 for delta.
    pub pdf: f32,
    /// Whether the light is a delta light (a point light): `pdf` is then 1.
    pub delta: bool,
}

/// An isotropic point light (Mitsuba's `point`).
#[derive(Clone, Debug)]
pub struct PointLight {
    /// Position in world space.
    pub position: Vec3,
    /// Radiant intensity, W/sr per channel.
    pub intensity: Rgb,
}

/// A light of the scene.
#[derive(Clone, Debug)]
pub enum Emitter {
    /// An area light on a shape.
    Area(AreaLight),
    /// A point light.
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

    /// Whether the light has no area (a point light): only light sampling reaches it.
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
