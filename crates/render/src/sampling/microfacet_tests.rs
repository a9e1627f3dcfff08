//! Normalisation of D and of the visible-normal density by independent quadrature, and
//! chi-square goodness of fit of both samplers against their pdfs.

use super::*;
use crate::sampling::quadrature::{chi2_test, sidak_alpha, LobeGrid};
use crate::sampling::warps::square_to_uniform_sphere;

const DISTS: [MicrofacetDistribution; 2] = [
    MicrofacetDistribution::Beckmann,
    MicrofacetDistribution::Ggx,
];

/// Isotropic roughness 1e-3 .. 1 plus anisotropic pairs (narrow either way).
fn roughnesses() -> Vec<(f32, f32)> {
    vec![
        (1e-3, 1e-3),
        (1e-2, 1e-2),
        (0.1, 0.1),
        (0.5, 0.5),
        (1.0, 1.0),
        (0.05, 0.4),
        (0.3, 0.02),
        (1e-3, 0.03),
    ]
}

fn all() -> impl Iterator<Item = Microfacet> {
    DISTS.into_iter().flat_map(|d| {
        roughnesses()
            .into_iter()
            .map(move |(u, v)| Microfacet::new(d, u, v))
    })
}

/// Incident directions from normal to grazing (cos 0.01) at several azimuths.
fn incident() -> Vec<Vec3> {
    [1.0f32, 0.7, 0.3, 0.01]
        .iter()
        .zip([0.0f32, 0.4, 2.0, 4.0])
        .map(|(&c, phi)| {
            let s = (1.0 - c * c).sqrt();
            Vec3::new(s * phi.cos(), s * phi.sin(), c)
        })
        .collect()
}

fn grid(mf: &Microfacet) -> LobeGrid {
    LobeGrid::around_normal(mf.alpha_u.min(mf.alpha_v) as f64)
}

// Quadrature: adaptive on the lobe-zoomed grid (about 1e-6 absolute), so 1e-3 is loose;
// the worst measured error is printed.

#[test]
fn d_integrates_to_one_in_projected_area() {
    let mut worst = 0.0f64;
    for mf in all() {
        let i = grid(&mf).integrate(|m| mf.d(m) as f64 * m.z.max(0.0) as f64);
        worst = worst.max((i - 1.0).abs());
        assert!((i - 1.0).abs() < 1e-3, "{mf:?}: {i}");
    }
    eprintln!("microfacet: worst |∫ D cos - 1| = {worst:.2e}");
}

/// ∫ D(m) (wi.m) dm = cos(theta_i): microsurface and macrosurface project to the same area
/// in every direction, which checks the anisotropic orientation of D too.
#[test]
fn projected_area_matches_macrosurface() {
    for mf in all() {
        for wi in incident() {
            let i = grid(&mf).integrate(|m| mf.d(m) as f64 * wi.dot(m) as f64);
            assert!((i - wi.z as f64).abs() < 1e-3, "{mf:?} {wi}: {i}");
        }
    }
}

#[test]
fn visible_pdf_integrates_to_one() {
    let mut worst = 0.0f64;
    for mf in all() {
        for wi in incident() {
            let i = grid(&mf).integrate(|m| mf.pdf_visible(wi, m) as f64);
            worst = worst.max((i - 1.0).abs());
            assert!((i - 1.0).abs() < 1e-3, "{mf:?} {wi}: {i}");
        }
    }
    eprintln!("microfacet: worst |∫ D_wi - 1| = {worst:.2e}");
}

#[test]
fn smith_g1_bounds_and_beckmann_rational_fit() {
    let mut rng = crate::rng::Rng::new(5, 1);
    for mf in all() {
        for _ in 0..2000 {
            let w = square_to_uniform_sphere(rng.next_2d());
            let m = mf.sample_all(rng.next_2d());
            let g = mf.g1(w, m);
            assert!((0.0..=1.0).contains(&g), "{g}");
            // A facet seen from its back side, or through the macrosurface, is masked.
            assert!(w.dot(m) * w.z > 0.0 || g == 0.0);
        }
        assert!((mf.g1(Vec3::Z, Vec3::Z) - 1.0).abs() < 1e-6);
    }
    // The exact Beckmann G1 against Walter's rational fit, accurate to about 0.3 %.
    let mf = Microfacet::new(MicrofacetDistribution::Beckmann, 0.5, 0.5);
    for i in 1..200 {
        let theta = i as f32 / 200.0 * std::f32::consts::FRAC_PI_2;
        let w = Vec3::new(theta.sin(), 0.0, theta.cos());
        let a = 1.0 / (0.5 * theta.tan());
        let fit = if a < 1.6 {
            (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a)
        } else {
            1.0
        };
        assert!((mf.g1(w, Vec3::Z) - fit).abs() < 5e-3, "theta {theta}");
    }
}

/// 100k samples per case, 24 x 48 cells zoomed on the lobe, cells expecting < 5 pooled;
/// significance 1 % over all cases (Sidak). 40 cases.
#[test]
fn samplers_match_their_pdfs_chi2() {
    let mut cases: Vec<(String, Microfacet, Option<Vec3>)> = Vec::new();
    for d in DISTS {
        for (u, v) in [
            (1e-3, 1e-3),
            (0.05, 0.05),
            (0.3, 0.3),
            (1.0, 1.0),
            (0.05, 0.4),
        ] {
            let mf = Microfacet::new(d, u, v);
            cases.push((format!("{mf:?} all"), mf, None));
            for wi in [1.0f32, 0.5, 0.01].map(|c| Vec3::new((1.0 - c * c).sqrt(), 0.0, c)) {
                cases.push((format!("{mf:?} visible {wi}"), mf, Some(wi)));
            }
        }
    }
    let alpha = sidak_alpha(cases.len());
    let mut worst = 1.0f64;
    for (name, mf, wi) in &cases {
        let r = match wi {
            None => chi2_test(
                &grid(mf),
                100_000,
                |rng| Some(mf.sample_all(rng.next_2d())),
                |m| mf.pdf_all(m) as f64,
            ),
            Some(wi) => chi2_test(
                &grid(mf),
                100_000,
                |rng| Some(mf.sample_visible(*wi, rng.next_2d())),
                |m| mf.pdf_visible(*wi, m) as f64,
            ),
        };
        worst = worst.min(r.p_value);
        assert!(r.p_value > alpha, "{name}: {r:?}");
        // Every draw succeeds, so the pdf's mass must be 1 (midpoint error ~1e-4).
        assert_eq!(r.produced, 100_000);
        assert_eq!(r.in_empty_cells, 0.0, "{name}: {r:?}");
        assert!(
            (r.expected_total / 100_000.0 - 1.0).abs() < 2e-3,
            "{name}: {r:?}"
        );
    }
    eprintln!(
        "microfacet chi2: {} cases, smallest p = {worst:.3e}",
        cases.len()
    );
}

/// Cost guard: the Beckmann visible-slope inversion converges in a few Halley steps, fewer
/// than three on average from normal to grazing incidence (Newton's steps took 3.0 to 3.4).
#[test]
fn beckmann_slope_steps() {
    let mf = Microfacet::new(MicrofacetDistribution::Beckmann, 0.1, 0.1);
    let mut rng = crate::rng::Rng::new(1, 1);
    for c in [1.0f32, 0.7, 0.3, 0.01] {
        let wi = Vec3::new((1.0 - c * c).sqrt(), 0.0, c);
        ITERS.with(|i| i.set(0));
        for _ in 0..10_000 {
            mf.sample_visible(wi, rng.next_2d());
        }
        let per = ITERS.with(|i| i.get()) as f64 / 1e4;
        eprintln!("cos {c}: {per} slope steps per sample");
        assert!(per < 3.0, "{per}");
    }
}

/// The f32 slope inversion against f64 bisection (80 halvings) of the exact CDF (statrs'
/// erfc), from normal to grazing incidence and into both tails. Each slope must be as good
/// as f32 allows: within 4 ulps of the exact root, or else the exact root for a uniform
/// number within 4 eps (relative) of the one drawn. The second covers the top tail, where
/// f32 u cannot tell slopes apart (near u = 1, one ulp of u spans many ulps of x).
#[test]
fn beckmann_slope_inversion_matches_bisection() {
    use statrs::function::erf::erfc;
    let eps = f32::EPSILON as f64;
    let mut worst = 0.0f64;
    for tan_t in [1e-4f32, 0.01, 0.1, 0.5, 1.0, 2.0, 5.0, 20.0, 200.0] {
        let k = tan_t as f64 / std::f64::consts::PI.sqrt();
        let cdf = |x: f64| erfc(-x) + k * (-x * x).exp();
        // The inversion's own upper end, cot(theta) in f32.
        let hi0 = if tan_t > 1.0 / 9.0 { 1.0 / tan_t } else { 9.0 } as f64;
        let norm = cdf(hi0);
        let mut us = vec![1e-10f32, 1e-6, 1e-3, 1.0 - 1e-3, 1.0 - 1e-6];
        us.extend((1..40).map(|i| i as f32 / 40.0));
        for u in us {
            let target = u as f64 * norm;
            let (mut lo, mut hi) = (-9.0f64, hi0);
            for _ in 0..80 {
                let mid = 0.5 * (lo + hi);
                if cdf(mid) > target {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            let root = 0.5 * (lo + hi);
            let x = beckmann_visible_slope(tan_t, u) as f64;
            let in_x = (x - root).abs() / (eps * root.abs().max(f32::MIN_POSITIVE as f64));
            let in_u = (cdf(x) / target - 1.0).abs() / eps;
            let err = in_x.min(in_u);
            assert!(
                err <= 4.0,
                "tan {tan_t}, u {u}: {x} vs {root} ({in_x:.1} ulp, u off by {in_u:.1} eps)"
            );
            worst = worst.max(err);
        }
    }
    eprintln!("slope inversion: worst {worst:.2} ulp of x or eps of u from the exact root");
}

/// Where z^4 underflows f32 (|m.z| below ~1e-11) Beckmann's D is 0, not 0 / 0, and GGX's is
/// the finite limit it tends to; a normal in the plane has D = 0 for both.
#[test]
fn d_is_finite_where_z_to_the_fourth_underflows() {
    for z in [1e-12f32, 1e-20, 1e-30] {
        let m = Vec3::new(1.0, 0.5, z).normalize();
        for d in DISTS {
            let v = Microfacet::new(d, 0.3, 0.3).d(m);
            assert!(v.is_finite() && v >= 0.0, "{d:?} at z = {z}: {v}");
            if d == MicrofacetDistribution::Beckmann {
                assert_eq!(v, 0.0, "Beckmann at z = {z}");
            }
        }
    }
    for d in DISTS {
        assert_eq!(Microfacet::new(d, 0.3, 0.3).d(Vec3::X), 0.0);
    }
}

/// One step of the slope inversion (`slope_step`) on C(x) = erfc(-x) + tan / sqrt(pi)
/// exp(-x^2), with a target whose root r = 0.5 is known (tan(theta) = 1), checked rule by rule:
/// - from r - 0.1 Halley's step lands within 3e-3 of r (Newton's would be 6e-2 off, a wrong
///   second derivative 1.5e-2), inside the bracket, and has not converged;
/// - from r + 1.2e-5 the step is below its bound 1e-5 (1 + |x|) = 1.5e-5 while |f| is far
///   above 4 eps target and the bracket is wide: converged by the step alone, landing on r;
/// - a bracket 0.8 of its bound 4e-6 (1 + |x|) wide that excludes the root: Halley's step
///   leaves it, so the step bisects; converged by the bracket alone.
#[test]
fn slope_step_converges_by_each_rule() {
    use std::f64::consts::PI as PI64;
    let tan_t = 1.0f32;
    let k = tan_t / SQRT_PI;
    let r = 0.5f64;
    let c = |x: f64| statrs::function::erf::erfc(-x) + (k as f64) * (-x * x).exp();
    let target = c(r) as f32;
    let (lo, hi) = (-9.0f32, 1.0 / tan_t);
    assert!(((k as f64) - 1.0 / PI64.sqrt()).abs() < 1e-7);

    let (next, lo1, hi1, done) = slope_step(0.4, lo, hi, target, tan_t, k);
    assert!((next as f64 - r).abs() < 3e-3, "Halley from 0.4: {next}");
    assert!(
        (lo1, hi1) == (0.4, hi) && next > lo1 && next < hi1,
        "{lo1} {hi1}"
    );
    assert!(!done, "a step of 0.1 is not convergence");

    let x = (r + 1.2e-5) as f32;
    let (next, _, hi1, done) = slope_step(x, lo, hi, target, tan_t, k);
    assert_eq!(hi1, x, "C(x) > target moves the upper end");
    assert!(done, "a step of 1.2e-5 converges at x = {x}");
    assert!((next as f64 - r).abs() < 1e-6, "{next}");

    let (lo2, hi2) = (0.2f32, 0.2 + 0.8 * 4e-6 * 1.2);
    let (next, _, _, done) = slope_step(lo2, lo2, hi2, target, tan_t, k);
    assert_eq!(next, 0.5 * (lo2 + hi2), "a step out of the bracket bisects");
    assert!(done, "a bracket below its bound converges");
}

/// The full-distribution sampler's slope-space convention (module doc): slope (x, y) =
/// r (alpha_u cos 2 pi u1, alpha_v sin 2 pi u1) and m = normalize(-x, -y, 1). The density
/// is symmetric, so the chi-square cannot see a flipped sign; images sampled with a seed
/// would change.
#[test]
fn full_sampler_follows_the_slope_convention() {
    for d in DISTS {
        let mf = Microfacet::new(d, 0.3, 0.6);
        for (u0, u1) in [(0.5f32, 0.1f32), (0.2, 0.3), (0.7, 0.6), (0.4, 0.85)] {
            let r = match d {
                MicrofacetDistribution::Beckmann => (-(1.0 - u0 as f64).ln()).sqrt(),
                MicrofacetDistribution::Ggx => (u0 as f64 / (1.0 - u0 as f64)).sqrt(),
            };
            let phi = std::f64::consts::TAU * u1 as f64;
            let want = DVec3::new(-r * phi.cos() * 0.3, -r * phi.sin() * 0.6, 1.0).normalize();
            let m = mf.sample_all(Vec2::new(u0, u1)).as_dvec3();
            assert!(
                (m - want).length() < 1e-6,
                "{d:?} u ({u0}, {u1}): {m} vs {want}"
            );
        }
    }
}

/// Heitz's GGX visible-normal sampler at normal incidence, in closed form: the disk point
/// sqrt(u0) (cos 2 pi u1, sin 2 pi u1) lifted to the hemisphere and unstretched. (Its density
/// is symmetric in the azimuth, so only this pins the sign of the second disk coordinate.)
#[test]
fn ggx_visible_sampler_at_normal_incidence_in_closed_form() {
    let mf = Microfacet::new(MicrofacetDistribution::Ggx, 0.3, 0.6);
    for (u0, u1) in [(0.5f32, 0.1f32), (0.2, 0.3), (0.7, 0.6), (0.4, 0.85)] {
        let r = (u0 as f64).sqrt();
        let phi = std::f64::consts::TAU * u1 as f64;
        let want = DVec3::new(
            0.3 * r * phi.cos(),
            0.6 * r * phi.sin(),
            (1.0 - r * r).sqrt(),
        )
        .normalize();
        let m = mf.sample_visible(Vec3::Z, Vec2::new(u0, u1)).as_dvec3();
        assert!((m - want).length() < 1e-6, "u ({u0}, {u1}): {m} vs {want}");
    }
}
