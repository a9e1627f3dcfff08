//! Closed-form references for probe scenes, in f64 and independent of the renderer's
//! samplers: the radiance leaving the point the camera's axis meets, towards the camera.
//! Probe cameras have a tiny field of view, so every pixel sees that point.
//!
//! Lambert's polygon formula is evaluated on the f32 vertices the renderer actually uses, so
//! the reference is the exact answer for the rendered geometry, not for the intended one.

use crate::analytic::polygon_irradiance;
use crate::bsdf::fresnel::{fresnel_conductor, fresnel_dielectric};
use crate::bsdf::BsdfKind;
use crate::bsdf::Material;
use crate::experiment::cases::ClosedForm;
use crate::geometry::Ray;
use crate::math::Frame;
use crate::scene::desc::{SceneDesc, ShapeGeometry};
use crate::scene::Scene;
use glam::{DVec3, Vec3};

/// Grid of the quadrature: 1024 x 1024 midpoints over the light.
pub const QUADRATURE_CELLS: usize = 1024;

/// The receiver the camera's axis meets: point, unit normal facing the camera, shape index.
struct Receiver {
    x: Vec3,
    n: Vec3,
    eye: Vec3,
    shape: usize,
}

fn receiver(scene: &Scene) -> Result<Receiver, String> {
    let m = scene.desc.camera.to_world;
    let (o, d) = (m.transform_point3(Vec3::ZERO), m.transform_vector3(Vec3::Z));
    let hit = scene
        .intersect(&Ray::new(o, d.normalize()))
        .ok_or("the camera's axis meets no surface")?;
    let shape = hit.sp.shape as usize;
    let ShapeGeometry::Mesh {
        positions, indices, ..
    } = &scene.desc.shapes[shape].geometry
    else {
        return Err("the receiver must be a mesh".into());
    };
    let [a, b, c] = indices[hit.sp.prim as usize].map(|i| positions[i as usize]);
    let mut n = (b - a).cross(c - a).normalize();
    if n.dot(o - a) < 0.0 {
        n = -n;
    }
    // The ray meets the triangle's plane in f32 exactly as the probe's own rays do, so that
    // for a floor at z = 0 the point is o - d (o.z / d.z), independent of the hit's rounding.
    let t = (a - o).dot(n) / d.dot(n);
    Ok(Receiver {
        x: o + d * t,
        n,
        eye: o,
        shape,
    })
}

/// The closed form `form` of a probe scene's camera-axis radiance (channel 0).
pub fn evaluate(scene: &Scene, form: ClosedForm) -> Result<f64, String> {
    let r = receiver(scene)?;
    let bsdf = &scene.desc.shapes[r.shape].bsdf;
    let inner = &bsdf.kind;
    match form {
        ClosedForm::Lambert => {
            let BsdfKind::Diffuse(d) = inner else {
                return Err(format!("lambert needs a diffuse receiver, found {bsdf:?}"));
            };
            let reflectance = d.reflectance;
            let e = lambert_irradiance(&scene.desc, r.x, r.n)?;
            Ok(reflectance.x as f64 / std::f64::consts::PI * e)
        }
        ClosedForm::Fresnel => {
            let wo = (r.eye - r.x).normalize();
            let cos = wo.dot(r.n);
            let f = match inner {
                BsdfKind::Conductor(c) => {
                    (fresnel_conductor(cos, c.eta, c.k) * c.specular_reflectance).x
                }
                BsdfKind::RoughConductor(c) => {
                    (fresnel_conductor(cos, c.eta, c.k) * c.specular_reflectance).x
                }
                BsdfKind::Dielectric(d) => fresnel_dielectric(cos, d.eta).0,
                b => {
                    return Err(format!(
                        "fresnel needs a conductor or dielectric, found {b:?}"
                    ))
                }
            };
            Ok(f as f64 * mirror_radiance(scene, &r, wo)?)
        }
        ClosedForm::Quadrature => {
            let (corners, l) = single_quad_light(&scene.desc)?;
            Ok(quad_quadrature(
                &scene.materials[r.shape],
                &r,
                corners,
                l,
                QUADRATURE_CELLS,
            ))
        }
    }
}

/// Radiance (channel 0) of the emitter seen in the mirror direction of `wo`.
fn mirror_radiance(scene: &Scene, r: &Receiver, wo: Vec3) -> Result<f64, String> {
    let wi = 2.0 * wo.dot(r.n) * r.n - wo;
    let hit = scene
        .intersect(&Ray::new(r.x + r.n * 1e-4 * r.eye.distance(r.x), wi))
        .ok_or("the mirror direction meets no surface")?;
    let e = scene.desc.shapes[hit.sp.shape as usize]
        .emitter
        .as_ref()
        .ok_or("the mirror direction meets no light")?;
    Ok(e.radiance.x as f64)
}

/// The scene's only emitter, a parallelogram given by its first four vertices in winding
/// order (as `rectangle` writes them), and its radiance.
fn single_quad_light(desc: &SceneDesc) -> Result<([Vec3; 4], f64), String> {
    let lights: Vec<_> = desc.shapes.iter().filter(|s| s.emitter.is_some()).collect();
    let [s] = lights.as_slice() else {
        return Err(format!(
            "quadrature needs exactly one emitter, found {}",
            lights.len()
        ));
    };
    match &s.geometry {
        ShapeGeometry::Mesh { positions, .. } if positions.len() == 4 => Ok((
            [positions[0], positions[1], positions[2], positions[3]],
            s.emitter.as_ref().expect("filtered").radiance.x as f64,
        )),
        _ => Err("quadrature needs a light with four vertices (a rectangle)".into()),
    }
}

/// Irradiance at `x` (normal `n`) from every emitter of the scene, assuming nothing occludes
/// them. One-sided emission follows the winding, as in the renderer when the mesh has no (or
/// degenerate) vertex normals; zero-area triangles add 0.
pub fn lambert_irradiance(desc: &SceneDesc, x: Vec3, n: Vec3) -> Result<f64, String> {
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
                        .map_err(|err| format!("{}: {err}", s.origin))?;
                }
            }
            ShapeGeometry::Sphere { center, radius, .. } => {
                let c = center.as_dvec3() - x;
                let d = c.length();
                let r = *radius as f64;
                if c.dot(n) < r {
                    return Err(format!("{}: sphere light below the horizon", s.origin));
                }
                e += std::f64::consts::PI * l * (r / d).powi(2) * c.dot(n) / d;
            }
        }
    }
    Ok(e)
}

/// Radiance reflected towards the eye at the receiver from a quad light of radiance `l`, by
/// the midpoint rule on a `k` x `k` grid over the light's area:
/// sum f(wi, wo) |cos_o| L cos_light / d^2 dA. Only for lobes that are smooth on the scale
/// of a grid cell as seen from `x` (alpha = 1), never for near-specular ones.
fn quad_quadrature(m: &Material, r: &Receiver, corners: [Vec3; 4], l: f64, k: usize) -> f64 {
    let frame = Frame::from_normal(r.n);
    let wo = frame.to_local((r.eye - r.x).normalize());
    let [a, b, _, d] = corners.map(|c| c.as_dvec3());
    let (eu, ev) = (b - a, d - a);
    let ng = eu.cross(ev);
    let cell = ng.length() / (k * k) as f64;
    let ng = ng.normalize();
    let (xd, nd) = (r.x.as_dvec3(), r.n.as_dvec3());
    let mut sum = 0.0;
    for j in 0..k {
        for i in 0..k {
            let p = a + eu * ((i as f64 + 0.5) / k as f64) + ev * ((j as f64 + 0.5) / k as f64);
            let w: DVec3 = p - xd;
            let d2 = w.length_squared();
            let w = w / d2.sqrt();
            let cos_l = -w.dot(ng);
            if cos_l <= 0.0 || w.dot(nd) <= 0.0 {
                continue;
            }
            let f = m.eval(wo, frame.to_local(w.as_vec3())).x as f64;
            sum += f * cos_l / d2;
        }
    }
    sum * l * cell
}
