//! One-sided diffuse area light on a mesh or a sphere.

use super::{LightSample, LightSampling};
use crate::geometry::{Shape, ShapeKind, Sphere, SurfacePoint};
use crate::math::{Frame, Rgb, PI};
use crate::sampling::spherical::{
    ray_plane_barycentrics, sample_spherical_triangle, spherical_triangle_area, use_solid_angle,
};
use crate::sampling::warps::{
    square_to_uniform_cone_1m, square_to_uniform_sphere, square_to_uniform_triangle,
};
use crate::sampling::AliasTable;
use glam::{Vec2, Vec3};

/// A constant-radiance emitter on a shape (Mitsuba's `area`), one-sided.
#[derive(Clone, Debug)]
pub struct AreaLight {
    /// Index of its shape in the scene.
    pub shape: u32,
    /// Emitted radiance, on the side the shape's normal points to.
    pub radiance: Rgb,
    /// Surface area of the shape (zero-area triangles excluded).
    pub area: f32,
    /// Triangle choice proportional to area (meshes only).
    pub triangles: Option<AliasTable>,
}

/// Direction and distance from `ref_p` to a light point, if the light faces `ref_p`
/// (one-sided emission is decided by the shading normal, as Mitsuba and Nori do). One
/// reciprocal and three scalar products, rather than three divisions or a `Vec3A` (which
/// stays scalar), so that the loop over eight samples in `integrator::lanes` runs this in
/// vector lanes.
#[inline]
fn facing(ref_p: Vec3, sp: &SurfacePoint) -> Option<(Vec3, f32)> {
    let d = sp.p - ref_p;
    let dist = d.length();
    if !(dist > 0.0) {
        return None;
    }
    let inv = dist.recip();
    let wi = Vec3::new(d.x * inv, d.y * inv, d.z * inv);
    let cos = sp.ns.dot(-wi);
    let faces = if crate::seeded::active(crate::seeded::SeededBug::BackFacingLight) {
        cos != 0.0
    } else {
        cos > 0.0
    };
    faces.then_some((wi, dist))
}

/// Uniform-by-area density, in solid angle, of a light point of a light of area `area` that
/// faces the reference point along `wi` at distance `dist`.
#[inline]
pub(crate) fn area_pdf_along(area: f32, sp: &SurfacePoint, wi: Vec3, dist: f32) -> f32 {
    let mut cos_l = sp.ng.dot(wi).abs();
    if crate::seeded::active(crate::seeded::SeededBug::GrazingCosClamp) {
        cos_l = cos_l.max(0.1);
    }
    if cos_l > 0.0 {
        dist * dist / (area * cos_l)
    } else {
        0.0
    }
}

/// The sample at point `sp` of a light of this radiance, if it faces `ref_p` and
/// `pdf(wi, dist)` gives it a usable density.
#[inline]
pub(crate) fn sample_at(
    radiance: Rgb,
    ref_p: Vec3,
    sp: &SurfacePoint,
    pdf: impl FnOnce(Vec3, f32) -> f32,
) -> Option<LightSample> {
    let (wi, dist) = facing(ref_p, sp)?;
    let pdf = pdf(wi, dist);
    (pdf > 0.0 && pdf.is_finite()).then_some(LightSample {
        p: sp.p,
        ng: sp.ng,
        err_scale: sp.err_scale,
        wi,
        dist,
        li: radiance,
        pdf,
        delta: false,
    })
}

/// Area sampling of a sphere light: a uniformly distributed point on the sphere (shared by
/// `AreaLight::sample` and the lane kernel, so both make the same point).
#[inline]
pub(crate) fn sphere_area_point(s: &Sphere, u: Vec2, shape: u32) -> SurfacePoint {
    if crate::seeded::active(crate::seeded::SeededBug::SpherePolarUniform) {
        let (sin, cos) = (std::f32::consts::PI * u.x).sin_cos();
        let phi = std::f32::consts::TAU * u.y;
        let d = Vec3::new(sin * phi.cos(), sin * phi.sin(), cos);
        return s.surface_point_along(d, shape);
    }
    s.surface_point_along(square_to_uniform_sphere(u), shape)
}

/// Whether a sphere is sampled by its visible cone from `ref_p`: only from outside, and only
/// for outward normals (from inside, every direction hits it and area sampling is used).
/// Returns 1 - cos(theta_max) as sin^2 / (1 + cos): from 1e3 radii away the f32 difference
/// 1 - cos would keep no correct digit (`directlab chi2 emitter/sphere-solid-angle-far`).
#[inline]
fn cone_one_minus_cos_max(s: &Sphere, ref_p: Vec3) -> Option<f32> {
    let dc2 = (s.center - ref_p).length_squared();
    let r2 = s.radius * s.radius;
    if s.flip_normals || dc2 <= r2 * 1.000_01 {
        return None;
    }
    let sin2 = r2 / dc2;
    Some(sin2 / (1.0 + (1.0 - sin2).max(0.0).sqrt()))
}

impl AreaLight {
    /// Radiance leaving `sp` in direction `w` (0 from the back side).
    #[inline]
    pub fn le(&self, sp: &SurfacePoint, w: Vec3) -> Rgb {
        if sp.ns.dot(w) > 0.0 {
            self.radiance
        } else {
            Rgb::ZERO
        }
    }

    /// Uniform-by-area density converted to solid angle: p_w = d^2 / (A |cos theta_light|).
    #[inline]
    fn area_pdf(&self, ref_p: Vec3, sp: &SurfacePoint) -> f32 {
        facing(ref_p, sp).map_or(0.0, |(wi, dist)| self.area_pdf_along(sp, wi, dist))
    }

    /// `area_pdf` for a light point already known to face the reference point along `wi`.
    #[inline]
    fn area_pdf_along(&self, sp: &SurfacePoint, wi: Vec3, dist: f32) -> f32 {
        area_pdf_along(self.area, sp, wi, dist)
    }

    /// A point on the light seen from `p`, by area or in solid angle; None when it cannot
    /// light `p`.
    pub fn sample(
        &self,
        shapes: &[Shape],
        ref_p: Vec3,
        u_prim: f32,
        u: Vec2,
        mode: LightSampling,
    ) -> Option<LightSample> {
        let sp = match &shapes[self.shape as usize].kind {
            ShapeKind::Sphere(s) => {
                // The cone is only worked out for solid-angle sampling (a tuple pattern would
                // evaluate it, square root and divisions included, for area sampling too).
                let cone = match mode {
                    LightSampling::SolidAngle => cone_one_minus_cos_max(s, ref_p),
                    LightSampling::Area => None,
                };
                if let Some(one_minus) = cone {
                    let axis = (s.center - ref_p).normalize();
                    let wi =
                        Frame::from_normal(axis).to_world(square_to_uniform_cone_1m(u, one_minus));
                    // First intersection with the sphere; clamped for directions that graze it.
                    let to_c = s.center - ref_p;
                    let b = to_c.dot(wi);
                    let disc = (s.radius * s.radius - (to_c - b * wi).length_squared()).max(0.0);
                    let sp = s.surface_point(ref_p + wi * (b - disc.sqrt()), self.shape);
                    return sample_at(self.radiance, ref_p, &sp, |_, _| {
                        1.0 / (2.0 * PI * one_minus)
                    });
                }
                sphere_area_point(s, u, self.shape)
            }
            ShapeKind::Mesh(m) => {
                let table = self.triangles.as_ref()?;
                let tri = table.sample(u_prim);
                if mode == LightSampling::SolidAngle {
                    let v = m.vertices(tri);
                    if let Some((w, pdf)) = sample_spherical_triangle(ref_p, v, u) {
                        let sp =
                            m.surface_point(tri, ray_plane_barycentrics(ref_p, w, v)?, self.shape);
                        return sample_at(self.radiance, ref_p, &sp, |_, _| table.pmf(tri) * pdf);
                    }
                }
                m.surface_point(tri, square_to_uniform_triangle(u), self.shape)
            }
        };
        sample_at(self.radiance, ref_p, &sp, |wi, dist| {
            self.area_pdf_along(&sp, wi, dist)
        })
    }

    /// The density `sample` has for the light point `sp`; it must make the same choices
    /// (cone or area, spherical triangle or area fallback) from the same inputs.
    pub fn pdf(
        &self,
        shapes: &[Shape],
        ref_p: Vec3,
        sp: &SurfacePoint,
        mode: LightSampling,
    ) -> f32 {
        if mode == LightSampling::SolidAngle {
            match &shapes[self.shape as usize].kind {
                ShapeKind::Sphere(s) => {
                    if let Some(one_minus) = cone_one_minus_cos_max(s, ref_p) {
                        return match facing(ref_p, sp) {
                            Some(_) => 1.0 / (2.0 * PI * one_minus),
                            None => 0.0,
                        };
                    }
                }
                ShapeKind::Mesh(m) => {
                    let omega = spherical_triangle_area(ref_p, m.vertices(sp.prim as usize));
                    if use_solid_angle(omega) {
                        let pmf = self
                            .triangles
                            .as_ref()
                            .map_or(0.0, |t| t.pmf(sp.prim as usize));
                        return match facing(ref_p, sp) {
                            Some(_) => pmf / omega,
                            None => 0.0,
                        };
                    }
                }
            }
        }
        self.area_pdf(ref_p, sp)
    }
}
