//! Every warp of `sampling::warps` and the spherical-triangle sampler against its pdf.
//!
//! Warps onto [-1,1]^2 (the tent) are tested on the unit square after x -> (x + 1)/2, which
//! scales the density by 4. Microfacet normal distributions are in [`microfacet_cases`].

use super::bsdfs;
use super::lobe::{normal_window, run_windowed};
use super::protocol::{cone_window, disk, spherical_triangle_window, triangle, Target};
use super::{Case, CaseConfig};
use crate::analytic::triangle_solid_angle;
use crate::geometry::watertight::intersect_triangle;
use crate::rng::Rng;
use crate::sampling::microfacet::{Microfacet, MicrofacetDistribution};
use crate::sampling::spherical::sample_spherical_triangle;
use crate::sampling::warps::*;
use glam::{DVec3, Vec2, Vec3};

const CONE_WIDE: f32 = 0.3;
const CONE_NARROW: f32 = 0.999;

/// A triangle seen from the origin that covers ~0.6 sr, tilted so its edges cut cells.
pub fn spherical_triangle_vertices() -> [Vec3; 3] {
    [
        Vec3::new(-0.6, -0.4, 1.0),
        Vec3::new(0.7, -0.2, 1.3),
        Vec3::new(0.1, 0.8, 0.9),
    ]
}

fn spherical_triangle_case() -> Case {
    let v = spherical_triangle_vertices();
    let [a, b, c] = v.map(|p| p.as_dvec3());
    let omega = triangle_solid_angle(DVec3::ZERO, a, b, c);
    Case::new(
        "warp/spherical-triangle",
        format!("uniform direction in a triangle of {omega:.3} sr (Arvo), pdf 1/Omega"),
        move |cfg| {
            let w = spherical_triangle_window(&v, cfg.resolution);
            let pdf = w.plane_pdf(|d| {
                let hit = intersect_triangle(Vec3::ZERO, d, 0.0, f32::INFINITY, v).is_some();
                if hit {
                    1.0 / omega
                } else {
                    0.0
                }
            });
            let sampler =
                |r: &mut Rng| sample_spherical_triangle(Vec3::ZERO, v, r.next_2d()).map(|s| s.0);
            super::run_continuous("warp/spherical-triangle", &w, sampler, pdf, cfg, vec![])
        },
    )
    .with_external(Target::SphericalTriangle { vertices: v })
}

fn narrow_cone_case() -> Case {
    Case::new(
        "warp/uniform-cone-narrow",
        format!("uniform cone, cos(theta_max) = {CONE_NARROW}, in a window around its axis"),
        move |cfg| {
            let w = cone_window(CONE_NARROW, cfg.resolution);
            let pdf = w.plane_pdf(|d| square_to_uniform_cone_pdf(d, CONE_NARROW) as f64);
            let sampler = |r: &mut Rng| Some(square_to_uniform_cone(r.next_2d(), CONE_NARROW));
            super::run_continuous("warp/uniform-cone-narrow", &w, sampler, pdf, cfg, vec![])
        },
    )
    .with_external(Target::Cap {
        cos_theta_max: CONE_NARROW,
    })
}

pub fn cases() -> Vec<Case> {
    let f = |p: f32| p as f64;
    let mut v = vec![
        Case::continuous(
            "warp/uniform-disk",
            "polar map r = sqrt(u), pdf 1/pi",
            disk,
            |r: &mut Rng| Some(square_to_uniform_disk(r.next_2d())),
            move |p| f(square_to_uniform_disk_pdf(p)),
        )
        .with_external(Target::Disk),
        Case::continuous(
            "warp/concentric-disk",
            "Shirley-Chiu concentric map, pdf 1/pi",
            disk,
            |r: &mut Rng| Some(square_to_concentric_disk(r.next_2d())),
            move |p| f(square_to_uniform_disk_pdf(p)),
        )
        .with_external(Target::Disk),
        Case::continuous(
            "warp/tent",
            "separable tent on [-1,1]^2, mapped onto the unit square",
            |c: &CaseConfig| c.square(),
            |r: &mut Rng| Some((square_to_tent(r.next_2d()) + Vec2::ONE) * 0.5),
            move |p: Vec2| 4.0 * f(square_to_tent_pdf(p * 2.0 - Vec2::ONE)),
        )
        .with_external(Target::Square),
        Case::continuous(
            "warp/uniform-triangle",
            "square-root barycentrics, pdf 2 on the unit right triangle",
            triangle,
            |r: &mut Rng| Some(square_to_uniform_triangle(r.next_2d())),
            move |p| f(square_to_uniform_triangle_pdf(p)),
        )
        .with_external(Target::Triangle),
        Case::continuous(
            "warp/uniform-sphere",
            "uniform direction, pdf 1/(4 pi)",
            |c: &CaseConfig| c.sphere(),
            |r: &mut Rng| Some(square_to_uniform_sphere(r.next_2d())),
            move |d| f(square_to_uniform_sphere_pdf(d)),
        )
        .with_external(Target::Sphere),
        Case::continuous(
            "warp/uniform-hemisphere",
            "uniform direction with z > 0, pdf 1/(2 pi)",
            |c: &CaseConfig| c.sphere(),
            |r: &mut Rng| Some(square_to_uniform_hemisphere(r.next_2d())),
            move |d| f(square_to_uniform_hemisphere_pdf(d)),
        )
        .with_external(Target::Hemisphere),
        Case::continuous(
            "warp/cosine-hemisphere",
            "concentric disk lifted to the hemisphere, pdf cos(theta)/pi",
            |c: &CaseConfig| c.sphere(),
            |r: &mut Rng| Some(square_to_cosine_hemisphere(r.next_2d())),
            move |d| f(square_to_cosine_hemisphere_pdf(d)),
        )
        .with_external(Target::Hemisphere),
        Case::continuous(
            "warp/uniform-cone-wide",
            format!("uniform cone, cos(theta_max) = {CONE_WIDE}, on the whole sphere"),
            |c: &CaseConfig| c.sphere(),
            |r: &mut Rng| Some(square_to_uniform_cone(r.next_2d(), CONE_WIDE)),
            move |d| f(square_to_uniform_cone_pdf(d, CONE_WIDE)),
        )
        .with_external(Target::Cap {
            cos_theta_max: CONE_WIDE,
        }),
        narrow_cone_case(),
        spherical_triangle_case(),
    ];
    v.extend(microfacet_cases());
    v
}

/// Beckmann and GGX normal distributions: D(m) cos(theta_m) sampling of all normals, and
/// visible normals seen from normal, oblique and grazing incidence, across the roughness
/// range of [`bsdfs::ROUGHNESS`]. Narrow distributions are tested in a window around +z.
pub fn microfacet_cases() -> Vec<Case> {
    let mut v = Vec::new();
    for d in [
        MicrofacetDistribution::Beckmann,
        MicrofacetDistribution::Ggx,
    ] {
        let dn = format!("{d:?}").to_lowercase();
        for a in bsdfs::ROUGHNESS {
            let mf = Microfacet::new(d, a.0, a.1);
            let name = format!("warp/{dn}-{}-dcos", bsdfs::alpha_name(a));
            let label = name.clone();
            v.push(
                Case::new(
                    name,
                    format!("{dn} normals, density D(m) cos(theta_m), alpha {a:?}"),
                    move |cfg| {
                        let window = normal_window(a, cfg.resolution);
                        run_windowed(
                            &label,
                            window,
                            |r| Some(mf.sample_all(r.next_2d())),
                            |m| mf.pdf_all(m) as f64,
                            cfg,
                            vec![],
                        )
                    },
                )
                .with_external(Target::Normals {
                    distribution: d,
                    alpha: a,
                }),
            );
            for (wname, wi) in bsdfs::incident().into_iter().filter(|(_, w)| w.z > 0.0) {
                let name = format!("warp/{dn}-{}-vndf-{wname}", bsdfs::alpha_name(a));
                let label = name.clone();
                v.push(Case::new(
                    name,
                    format!("{dn} normals visible from {wi}, alpha {a:?}"),
                    move |cfg| {
                        let window = normal_window(a, cfg.resolution);
                        run_windowed(
                            &label,
                            window,
                            |r| Some(mf.sample_visible(wi, r.next_2d())),
                            |m| mf.pdf_visible(wi, m) as f64,
                            cfg,
                            vec![],
                        )
                    },
                ));
            }
        }
    }
    v
}
