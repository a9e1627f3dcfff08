//! Reference values for the probe point, in f64 and independent of the renderer's samplers.
//!
//! Lambert's polygon formula is evaluated on the f32 vertices the renderer actually uses, so
//! the reference is the exact answer for the rendered geometry, not for the intended one.

use crate::analytic::polygon_irradiance;
use crate::bsdf::Material;
use crate::math::Frame;
use crate::scene::desc::{SceneDesc, ShapeGeometry};
use glam::{DVec3, Vec3};

/// Irradiance at `x` (normal `n`) from every emitter of the scene, assuming nothing occludes
/// them and each lies above the tangent plane. One-sided emission follows the winding, as in
/// the renderer when the mesh has no (or degenerate) vertex normals; zero-area triangles add 0.
pub fn lambert_irradiance(desc: &SceneDesc, x: Vec3, n: Vec3) -> f64 {
    let (x, n) = (x.as_dvec3(), n.as_dvec3());
    let mut e = 0.0;
    for s in &desc.shapes {
        let Some(em) = &s.emitter else { continue };
        let l = em.radiance.x as f64;
        match &s.geometry {
            ShapeGeometry::Mesh {
                positions, indices, ..
            } => {
                for t in indices {
                    let v = t.map(|i| positions[i as usize].as_dvec3());
                    e += polygon_irradiance(x, n, &v, l)
                        .unwrap_or_else(|err| panic!("{}: {err}", s.origin));
                }
            }
            ShapeGeometry::Sphere { center, radius, .. } => {
                let c = center.as_dvec3() - x;
                let d = c.length();
                let r = *radius as f64;
                assert!(c.dot(n) >= r, "sphere light must be above the horizon");
                e += std::f64::consts::PI * l * (r / d).powi(2) * c.dot(n) / d;
            }
        }
    }
    e
}

/// Radiance reflected towards `eye` at `x` (normal +z, material `m`) from a quad light of
/// radiance `l`, by the midpoint rule on an `k` x `k` grid over the light's area:
/// sum f(wi, wo) |cos_o| L cos_light / d^2 dA. Only for lobes that are smooth on the scale
/// of a grid cell as seen from `x` (alpha = 1), never for near-specular ones.
pub fn quad_quadrature(
    m: &Material,
    x: Vec3,
    eye: Vec3,
    corners: [Vec3; 4],
    l: f64,
    k: usize,
) -> f64 {
    let frame = Frame::from_normal(Vec3::Z);
    let wi = frame.to_local((eye - x).normalize());
    let [a, b, _, d] = corners.map(|c| c.as_dvec3());
    let (eu, ev) = (b - a, d - a);
    let ng = eu.cross(ev);
    let cell = ng.length() / (k * k) as f64;
    let ng = ng.normalize();
    let xd = x.as_dvec3();
    let mut sum = 0.0;
    for j in 0..k {
        for i in 0..k {
            let p = a + eu * ((i as f64 + 0.5) / k as f64) + ev * ((j as f64 + 0.5) / k as f64);
            let w: DVec3 = p - xd;
            let d2 = w.length_squared();
            let w = w / d2.sqrt();
            let cos_l = -w.dot(ng);
            if cos_l <= 0.0 || w.z <= 0.0 {
                continue;
            }
            let f = m.eval(wi, frame.to_local(w.as_vec3())).x as f64;
            sum += f * cos_l / d2;
        }
    }
    sum * l * cell
}
