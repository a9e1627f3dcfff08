//! The study's light sampler (uniform emitter choice, triangle by area, uniform point,
//! conversion to solid angle), written out once with a switch for each classic mistake.
//! With `Bug::None` it is the correct sampler, the control of every check.

use super::Bug;
use crate::chi2cases::probe::crossings;
use crate::emitter::Emitter;
use crate::geometry::{ShapeKind, SurfacePoint};
use crate::rng::Rng;
use crate::sampling::warps::square_to_uniform_triangle;
use crate::scene::Scene;
use glam::{Vec2, Vec3};

/// A light sample as the estimator uses it.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    pub wi: Vec3,
    /// Radiance towards the receiver (first channel).
    pub le: f32,
    /// The density the estimator divides by (the choice pmf included unless that is the bug).
    pub pdf: f32,
}

pub struct Lights<'a> {
    pub scene: &'a Scene,
    pub bug: Bug,
}

impl Lights<'_> {
    fn pmf(&self) -> f32 {
        if self.bug == Bug::PmfNotDivided {
            1.0
        } else {
            1.0 / self.scene.emitters.len() as f32
        }
    }

    /// Area density converted to solid angle for light point `sp` seen from `x`, or None
    /// where the light faces away (kept by the back-facing bug, for pdf() only).
    fn density(&self, x: Vec3, sp: &SurfacePoint, area: f32, in_pdf: bool) -> Option<f32> {
        let d = sp.p - x;
        let dist2 = d.length_squared();
        let wi = d / dist2.sqrt();
        let cos_l = -sp.ng.dot(wi);
        let keep_back = in_pdf && self.bug == Bug::BackFacingPdf;
        if !(cos_l > 0.0) && !keep_back {
            return None;
        }
        let jacobian = if self.bug == Bug::MissingCos {
            1.0
        } else {
            cos_l.abs()
        };
        (jacobian > 0.0).then(|| self.pmf() * dist2 / (area * jacobian))
    }

    fn light(&self, e: usize) -> (&crate::emitter::AreaLight, &crate::geometry::Mesh) {
        let Emitter::Area(a) = &self.scene.emitters[e] else {
            panic!("the gallery uses area lights only")
        };
        let ShapeKind::Mesh(m) = &self.scene.shapes[a.shape as usize].kind else {
            panic!("the gallery uses mesh lights only")
        };
        (a, m)
    }

    pub fn sample(&self, x: Vec3, rng: &mut Rng) -> Option<LightSample> {
        let n = self.scene.emitters.len();
        let (u_e, u_tri, mut u) = (rng.next_f32(), rng.next_f32(), rng.next_2d());
        let e = ((u_e * n as f32) as usize).min(n - 1);
        let (a, m) = self.light(e);
        let tris = m.indices.len();
        let tri = match self.bug {
            Bug::SharedRandom => {
                // The same number picks emitter, triangle and the point's first coordinate.
                u = Vec2::new(u_e, u.y);
                a.triangles.as_ref()?.sample(u_e)
            }
            Bug::TrianglesUniform => ((u_tri * tris as f32) as usize).min(tris - 1),
            _ => a.triangles.as_ref()?.sample(u_tri),
        };
        let sp = m.surface_point(tri, square_to_uniform_triangle(u), a.shape);
        let pdf = self.density(x, &sp, a.area, false)?;
        Some(LightSample {
            wi: (sp.p - x).normalize(),
            le: a.radiance.x,
            pdf,
        })
    }

    /// The solid-angle density this sampler claims for direction `wi` from `x`: every light
    /// surface along the ray counts.
    pub fn pdf(&self, x: Vec3, wi: Vec3) -> f64 {
        let mut total = 0.0;
        for e in 0..self.scene.emitters.len() {
            let (a, _) = self.light(e);
            crossings(self.scene, a.shape as usize, x, wi, |sp| {
                total += self.density(x, &sp, a.area, true).unwrap_or(0.0) as f64;
            });
        }
        total
    }
}
