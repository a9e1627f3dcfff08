//! A scene's light sampling as seen from one reference point: the direction sampler the
//! integrator uses (emitter choice, then a point on the emitter) and the density of a
//! direction under it.
//!
//! The density of a direction is not the pdf of one light point: every emitter surface the
//! ray crosses could have produced it, so p(ω) = Σ_e pmf(e) Σ_{x on e along ω} pdf_e(x).
//! A sampler that fails (a back-facing point, a degenerate triangle) returns None; that mass
//! is missing from p(ω), which the chi-square test counts as "lost".

use crate::emitter::{Emitter, EmitterSelection, EmitterSelector, LightSampling};
use crate::geometry::watertight::intersect_triangle;
use crate::geometry::{ShapeKind, SurfacePoint};
use crate::rng::Rng;
use crate::scene::Scene;
use glam::{DVec3, Vec2, Vec3};
use std::sync::Arc;

#[derive(Clone)]
pub struct LightProbe {
    pub scene: Arc<Scene>,
    pub selector: EmitterSelector,
    pub ref_p: Vec3,
    /// The receiver's normal the point-dependent emitter choices see (zero: none).
    pub normal: Vec3,
    pub mode: LightSampling,
}

/// Every point where the ray `o + t d` (t > 0) crosses shape `shape`, nearest first for
/// spheres; meshes in triangle order.
pub fn crossings(scene: &Scene, shape: usize, o: Vec3, d: Vec3, mut f: impl FnMut(SurfacePoint)) {
    match &scene.shapes[shape].kind {
        ShapeKind::Mesh(m) => {
            for tri in 0..m.indices.len() {
                if let Some((_, b1, b2)) =
                    intersect_triangle(o, d, 0.0, f32::INFINITY, m.vertices(tri))
                {
                    f(m.surface_point(tri, Vec2::new(b1, b2), shape as u32));
                }
            }
        }
        ShapeKind::Sphere(s) => {
            // Both roots in f64: the far one matters when the near one faces away.
            let (o, d) = (o.as_dvec3(), d.as_dvec3().normalize());
            let f0 = o - s.center.as_dvec3();
            let b = f0.dot(d);
            let perp = (f0 - b * d).length_squared();
            let r2 = (s.radius as f64).powi(2);
            if perp > r2 {
                return;
            }
            let h = (r2 - perp).sqrt();
            for t in [-b - h, -b + h] {
                if t > 0.0 {
                    f(s.surface_point((o + t * d).as_vec3(), shape as u32));
                }
            }
        }
    }
}

impl LightProbe {
    pub fn new(
        scene: Arc<Scene>,
        selection: EmitterSelection,
        ref_p: Vec3,
        mode: LightSampling,
    ) -> Self {
        let selector = EmitterSelector::new(&scene.emitters, &scene.shapes, selection);
        LightProbe {
            scene,
            selector,
            ref_p,
            normal: Vec3::ZERO,
            mode,
        }
    }

    /// One light sample's direction, drawing random numbers in the integrator's order:
    /// emitter, triangle, point.
    pub fn sample(&self, rng: &mut Rng) -> Option<Vec3> {
        let (ei, _) = self
            .selector
            .sample(self.ref_p, self.normal, rng.next_f32())?;
        let u_prim = rng.next_f32();
        let u = rng.next_2d();
        let s = &self.scene;
        s.emitters[ei]
            .sample(&s.shapes, self.ref_p, u_prim, u, self.mode)
            .map(|ls| ls.wi)
    }

    /// Solid-angle density of direction `d` under [`Self::sample`] (point lights excluded).
    pub fn pdf(&self, d: Vec3) -> f64 {
        let s = &self.scene;
        let mut total = 0.0;
        for (si, shape) in s.shapes.iter().enumerate() {
            let Some(ei) = shape.emitter else { continue };
            let e: &Emitter = &s.emitters[ei as usize];
            let pmf = self.selector.pmf(self.ref_p, self.normal, ei as usize) as f64;
            crossings(s, si, self.ref_p, d, |sp| {
                total += pmf * e.pdf(&s.shapes, self.ref_p, &sp, self.mode) as f64;
            });
        }
        total
    }

    /// Unit directions from the reference point to points bounding every emitter (mesh
    /// vertices; a sphere's silhouette), for fitting a [`super::tangent::Tangent`] window,
    /// and the largest angle any of them makes with their mean direction.
    pub fn extent(&self) -> (DVec3, Vec<DVec3>, f64) {
        let p = self.ref_p.as_dvec3();
        let mut dirs = Vec::new();
        let mut spheres = Vec::new();
        for shape in &self.scene.shapes {
            if shape.emitter.is_none() {
                continue;
            }
            match &shape.kind {
                ShapeKind::Mesh(m) => {
                    dirs.extend(m.positions.iter().map(|v| (v.as_dvec3() - p).normalize()))
                }
                ShapeKind::Sphere(s) => {
                    let to_c = s.center.as_dvec3() - p;
                    let dist = to_c.length();
                    let r = s.radius as f64;
                    // From inside or touching, the sphere surrounds the point.
                    let half = if dist > r {
                        (r / dist).asin()
                    } else {
                        std::f64::consts::PI
                    };
                    spheres.push((to_c / dist, half));
                    dirs.push(to_c / dist);
                }
            }
        }
        let axis = dirs.iter().sum::<DVec3>().normalize();
        let mut max_angle: f64 = dirs
            .iter()
            .map(|d| d.dot(axis).clamp(-1.0, 1.0).acos())
            .fold(0.0, f64::max);
        for (c, half) in spheres {
            max_angle = max_angle.max(c.dot(axis).clamp(-1.0, 1.0).acos() + half);
            // Four rim directions stand for the silhouette in the window fit.
            let s = c.any_orthonormal_vector();
            let t = c.cross(s);
            let (sn, cs) = half.min(1.5).sin_cos();
            dirs.extend([s, -s, t, -t].iter().map(|e| c * cs + *e * sn));
        }
        (axis, dirs, max_angle)
    }
}
