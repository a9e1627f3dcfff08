//! One-sided diffuse area light on a mesh or a sphere.

use super::{LightSample, LightSampling};
use crate::geometry::{Shape, ShapeKind, SurfacePoint};
use crate::math::Rgb;
use crate::sampling::spherical::{
    ray_plane_barycentrics, sample_spherical_triangle, spherical_triangle_area, use_solid_angle,
};
use crate::sampling::warps::{
    square_to_uniform_cone, square_to_uniform_sphere, square_to_uniform_triangle,
};
use crate::sampling::AliasTable;
use glam::{Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct AreaLight {
    pub shape: u32,
    pub radiance: Rgb,
    pub area: f32,
    /// Triangle choice proportional to area (meshes only).
    pub triangles: Option<AliasTable>,
}

impl AreaLight {
    /// Emission only on the side the shading normal points to, as in Mitsuba and Nori.
    #[inline]
    pub fn le(&self, sp: &SurfacePoint, w: Vec3) -> Rgb {
        if sp.ns.dot(w) > 0.0 {
            self.radiance
        } else {
            Rgb::ZERO
        }
    }

    /// Area density to solid angle: p_w = p_A d^2 / |cos theta_light|, zero when the light
    /// faces away from the reference point.
    #[inline]
    fn area_to_solid_angle(
        &self,
        pdf_area: f32,
        ref_p: Vec3,
        sp: &SurfacePoint,
    ) -> Option<(Vec3, f32, f32)> {
        let d = sp.p - ref_p;
        let dist2 = d.length_squared();
        let dist = dist2.sqrt();
        if !(dist > 0.0) {
            return None;
        }
        let wi = d / dist;
        if sp.ns.dot(-wi) <= 0.0 {
            return None;
        }
        let cos_l = sp.ng.dot(-wi).abs();
        if cos_l == 0.0 {
            return None;
        }
        Some((wi, dist, pdf_area * dist2 / cos_l))
    }

    pub fn sample(
        &self,
        shapes: &[Shape],
        ref_p: Vec3,
        u_prim: f32,
        u: Vec2,
        mode: LightSampling,
    ) -> Option<LightSample> {
        let shape = &shapes[self.shape as usize];
        let sp = match (&shape.kind, mode) {
            (ShapeKind::Sphere(s), LightSampling::SolidAngle) => {
                return self.sample_sphere_cone(s, ref_p, u);
            }
            (ShapeKind::Sphere(s), LightSampling::Area) => s.surface_point(
                s.center + square_to_uniform_sphere(u) * s.radius,
                self.shape,
            ),
            (ShapeKind::Mesh(m), mode) => {
                let table = self.triangles.as_ref()?;
                let tri = table.sample(u_prim);
                if mode == LightSampling::SolidAngle {
                    let v = m.vertices(tri);
                    if let Some((w, pdf)) = sample_spherical_triangle(ref_p, v, u) {
                        let b = ray_plane_barycentrics(ref_p, w, v)?;
                        let sp = m.surface_point(tri, b, self.shape);
                        let d = sp.p - ref_p;
                        let dist = d.length();
                        let wi = d / dist;
                        if !(dist > 0.0) || sp.ns.dot(-wi) <= 0.0 {
                            return None;
                        }
                        return Some(LightSample {
                            p: sp.p,
                            ng: sp.ng,
                            wi,
                            dist,
                            li: self.radiance,
                            pdf: table.pmf(tri) * pdf,
                            delta: false,
                        });
                    }
                }
                m.surface_point(tri, square_to_uniform_triangle(u), self.shape)
            }
        };
        let (wi, dist, pdf) = self.area_to_solid_angle(1.0 / self.area, ref_p, &sp)?;
        Some(LightSample {
            p: sp.p,
            ng: sp.ng,
            wi,
            dist,
            li: self.radiance,
            pdf,
            delta: false,
        })
    }

    pub fn pdf(
        &self,
        shapes: &[Shape],
        ref_p: Vec3,
        sp: &SurfacePoint,
        mode: LightSampling,
    ) -> f32 {
        match (&shapes[self.shape as usize].kind, mode) {
            (ShapeKind::Sphere(s), LightSampling::SolidAngle) => {
                return self.pdf_sphere_cone(s, ref_p, sp)
            }
            (ShapeKind::Mesh(m), LightSampling::SolidAngle) => {
                // Must make the same per-triangle choice as `sample`: solid angle when in range.
                let omega = spherical_triangle_area(ref_p, m.vertices(sp.prim as usize));
                if use_solid_angle(omega) {
                    let wi = (sp.p - ref_p).normalize_or_zero();
                    if sp.ns.dot(-wi) <= 0.0 {
                        return 0.0;
                    }
                    let pmf = self
                        .triangles
                        .as_ref()
                        .map_or(0.0, |t| t.pmf(sp.prim as usize));
                    return pmf / omega;
                }
            }
            _ => {}
        }
        self.area_to_solid_angle(1.0 / self.area, ref_p, sp)
            .map_or(0.0, |x| x.2)
    }

    /// Uniform sampling of the cone of directions the sphere subtends; outside the sphere only
    /// (from inside every direction hits it, and area sampling is used instead).
    fn sample_sphere_cone(
        &self,
        s: &crate::geometry::Sphere,
        ref_p: Vec3,
        u: Vec2,
    ) -> Option<LightSample> {
        let to_c = s.center - ref_p;
        let dc2 = to_c.length_squared();
        let r2 = s.radius * s.radius;
        if dc2 <= r2 * 1.000_01 || s.flip_normals {
            let sp = s.surface_point(
                s.center + square_to_uniform_sphere(u) * s.radius,
                self.shape,
            );
            let (wi, dist, pdf) = self.area_to_solid_angle(1.0 / self.area, ref_p, &sp)?;
            return Some(LightSample {
                p: sp.p,
                ng: sp.ng,
                wi,
                dist,
                li: self.radiance,
                pdf,
                delta: false,
            });
        }
        let dc = dc2.sqrt();
        let sin2_max = r2 / dc2;
        let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
        let frame = crate::math::Frame::from_normal(to_c / dc);
        let wi = frame
            .to_world(square_to_uniform_cone(u, cos_max))
            .normalize();
        // Nearest intersection with the sphere along wi (clamped for directions that graze it).
        let b = to_c.dot(wi);
        let disc = (r2 - (to_c - b * wi).length_squared()).max(0.0);
        let dist = b - disc.sqrt();
        let sp = s.surface_point(ref_p + wi * dist, self.shape);
        let pdf = 1.0 / (2.0 * crate::math::PI * (1.0 - cos_max));
        if !pdf.is_finite() || sp.ns.dot(-wi) <= 0.0 {
            return None;
        }
        Some(LightSample {
            p: sp.p,
            ng: sp.ng,
            wi,
            dist: (sp.p - ref_p).length(),
            li: self.radiance,
            pdf,
            delta: false,
        })
    }

    fn pdf_sphere_cone(&self, s: &crate::geometry::Sphere, ref_p: Vec3, sp: &SurfacePoint) -> f32 {
        let dc2 = (s.center - ref_p).length_squared();
        let r2 = s.radius * s.radius;
        if dc2 <= r2 * 1.000_01 || s.flip_normals {
            return self
                .area_to_solid_angle(1.0 / self.area, ref_p, sp)
                .map_or(0.0, |x| x.2);
        }
        let wi = (sp.p - ref_p).normalize_or_zero();
        if sp.ns.dot(-wi) <= 0.0 {
            return 0.0;
        }
        let cos_max = (1.0 - r2 / dc2).max(0.0).sqrt();
        1.0 / (2.0 * crate::math::PI * (1.0 - cos_max))
    }
}
