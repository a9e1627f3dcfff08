//! Nori's triangle ttest through the whole renderer, against Lambert's closed form.

use super::{settings, ALPHA};
use crate::emitter::EmitterSelection;
use crate::integrator::Strategy;
use crate::render::render;
use crate::scene::{fixtures, Scene};
use glam::Vec3;

/// Nori's ttest, through the whole renderer: a one-pixel render of a diffuse floor under a
/// triangle light, against Lambert's closed form. Nori's five published cases (rotated from
/// y-up to z-up; a rotation keeps the winding) plus triangles at grazing and close range.
/// Two-sided Student t-test per case and strategy, ALPHA Sidak-corrected, 100k
/// samples per render (as Nori).
#[test]
fn triangle_lights_match_lambert_for_every_strategy() {
    use crate::analytic::{diffuse_radiance, polygon_irradiance, NORI_TRIANGLE_TESTS};
    use crate::stats::ttest::{one_sample, sidak};
    let z_up = |v: [f64; 3]| Vec3::new(v[0] as f32, -v[2] as f32, v[1] as f32);
    let mut cases: Vec<([Vec3; 3], f64)> = NORI_TRIANGLE_TESTS
        .iter()
        .map(|(t, r)| (t.map(z_up), *r))
        .collect();
    let extra = [
        [
            Vec3::new(-1.0, -1.0, 0.05),
            Vec3::new(1.0, -1.0, 1.5),
            Vec3::new(0.0, 1.0, 0.01),
        ],
        [
            Vec3::new(0.01, 0.0, 0.01),
            Vec3::new(0.0, 0.02, 0.01),
            Vec3::new(0.0, 0.0, 0.03),
        ],
        [
            Vec3::new(5.0, 0.0, 0.2),
            Vec3::new(5.0, 0.5, 0.2),
            Vec3::new(5.0, 0.0, 0.7),
        ],
    ];
    for mut t in extra {
        let v: Vec<_> = t.iter().map(|p| p.as_dvec3()).collect();
        // Orient each extra light to face the receiver at the origin.
        if (v[1] - v[0]).cross(v[2] - v[0]).dot(-v[0]) < 0.0 {
            t.swap(1, 2);
        }
        let v: Vec<_> = t.iter().map(|p| p.as_dvec3()).collect();
        let e = polygon_irradiance(glam::DVec3::ZERO, glam::DVec3::Z, &v, 1.0).unwrap();
        cases.push((t, diffuse_radiance(0.5, e)));
    }
    let strategies: Vec<Strategy> = Strategy::combinations()
        .into_iter()
        .filter(|s| s.selection == EmitterSelection::Uniform)
        .collect();
    let alpha = sidak(ALPHA, cases.len() * strategies.len());
    for (i, (tri, reference)) in cases.iter().enumerate() {
        let scene = Scene::build(fixtures::triangle_over_floor(
            *tri,
            1.0,
            0.5,
            Vec3::ZERO,
            0.01,
        ))
        .unwrap();
        for s in &strategies {
            let n = 100_000u32;
            let out = render(&scene, *s, &settings(n, 11));
            assert_eq!(out.non_finite_samples, 0);
            let (mean, var_of_mean) = (out.mean.data[0][0], out.variance.data[0][0]);
            let t = one_sample(mean, var_of_mean * n as f64, n as u64, *reference);
            assert!(
                t.passes(alpha),
                "case {i} {}: {mean} vs {reference}: {t:?}",
                s.label()
            );
        }
    }
}
