//! Rough conductor: sample/eval/pdf agreement, furnace, pdf mass vs sampling success,
//! reciprocity and chi-square of the sampled directions, from roughness 1e-3 to 1 and
//! incidence from normal to grazing (cos 0.01), for both distributions and both samplers.

use super::super::testing::*;
use super::super::*;
use crate::sampling::microfacet::{Microfacet, MicrofacetDistribution};
use crate::sampling::quadrature::{chi2_test, sidak_alpha, LobeGrid};

const ROUGH: [(f32, f32); 6] = [
    (1e-3, 1e-3),
    (1e-2, 1e-2),
    (0.1, 0.1),
    (0.5, 0.5),
    (1.0, 1.0),
    (0.05, 0.4),
];
const DISTS: [MicrofacetDistribution; 2] = [
    MicrofacetDistribution::Beckmann,
    MicrofacetDistribution::Ggx,
];

/// 'none' conductor (eta 0, k 1): F = 1, so the albedo measures the microfacet model alone.
fn rough(d: MicrofacetDistribution, a: (f32, f32), visible: bool, spec: Rgb) -> Material {
    Material {
        kind: BsdfKind::RoughConductor(RoughConductor {
            mf: Microfacet::new(d, a.0, a.1),
            sample_visible: visible,
            eta: Rgb::ZERO,
            k: Rgb::ONE,
            specular_reflectance: spec,
        }),
        two_sided: false,
    }
}

fn gold(d: MicrofacetDistribution, a: f32, visible: bool) -> Material {
    Material {
        kind: BsdfKind::RoughConductor(RoughConductor {
            mf: Microfacet::new(d, a, a),
            sample_visible: visible,
            eta: Rgb::new(0.143119, 0.374957, 1.44248),
            k: Rgb::new(3.98316, 2.38572, 1.60322),
            specular_reflectance: Rgb::ONE,
        }),
        two_sided: false,
    }
}

fn cases() -> Vec<(String, Material, (f32, f32))> {
    let mut v = Vec::new();
    for d in DISTS {
        for a in ROUGH {
            for vis in [true, false] {
                v.push((
                    format!("{d:?} {a:?} vis={vis}"),
                    rough(d, a, vis, Rgb::ONE),
                    a,
                ));
            }
        }
    }
    v
}

fn incident() -> [Vec3; 4] {
    [(1.0f32, 0.0f32), (0.7, 0.5), (0.3, 2.0), (0.01, 4.0)].map(|(c, phi)| {
        let s = (1.0 - c * c).sqrt();
        Vec3::new(s * phi.cos(), s * phi.sin(), c)
    })
}

/// Grid zoomed on the reflected lobe (2 alpha in the plane of incidence, 2 alpha cos_i
/// across it). Broad lobes (alpha >= 0.3) use a grid around the normal instead, whose cell
/// boundary on the horizon resolves the pdf's jump there.
pub(crate) fn lobe_grid(wi: Vec3, a: (f32, f32)) -> LobeGrid {
    let amin = a.0.min(a.1) as f64;
    if amin >= 0.3 {
        return LobeGrid::around_normal(1.0);
    }
    LobeGrid::around_reflection(wi, 2.0 * amin, (wi.z as f64).max(amin).min(1.0))
}

/// The half vector depends on the directions of wi and wo only, not on their lengths, which
/// f32 `normalize` leaves off by up to ~2e-7: at grazing incidence wi + wo is only ~2 cos_i
/// long, so the lengths tilted it by ~1e-5 rad (a 1e-3-rough lobe is 4e-3 rad wide).
#[test]
fn half_vector_ignores_input_lengths() {
    let mut worst = 0.0f64;
    for (c, phi) in [(0.01f64, 2.0f64), (0.02, 0.3), (0.5, 4.0)] {
        let s = (1.0 - c * c).sqrt();
        let wi = glam::DVec3::new(s * phi.cos(), s * phi.sin(), c);
        for k in 0..16 {
            let a = k as f64 * std::f64::consts::PI / 8.0;
            let m = glam::DVec3::new(-3e-3 * a.cos(), -3e-3 * a.sin(), 1.0).normalize();
            let wo = 2.0 * wi.dot(m) * m - wi;
            for (li, lo) in [
                (1.0 + 2e-7, 1.0 - 2e-7),
                (1.0 - 2e-7, 1.0 + 2e-7),
                (1.0, 1.0),
            ] {
                let (wi32, wo32) = ((wi * li).as_vec3(), (wo * lo).as_vec3());
                // The half vector of exactly the directions the f32 inputs point in.
                let exact = (wi32.as_dvec3().normalize() + wo32.as_dvec3().normalize()).normalize();
                let h = RoughConductor::half(wi32, wo32).as_dvec3();
                worst = worst.max(h.angle_between(exact));
            }
        }
    }
    // What is left is the f32 rounding of the result, ~6e-8 rad.
    assert!(worst < 2e-7, "half vector {worst:.3e} rad off");
}

#[test]
fn sample_eval_pdf_agree() {
    let mut worst = 0.0f32;
    for (_, m, _) in cases() {
        check_sample_consistency(&m, 5_000);
        for wi in incident() {
            worst = worst.max(check_sample_consistency_at(&m, wi, 2_000));
        }
    }
    for d in DISTS {
        for a in [1e-3, 0.2, 1.0] {
            check_sample_consistency(&gold(d, a, true), 5_000);
        }
    }
    eprintln!("roughconductor: worst relative pdf/weight mismatch {worst:.2e}");
}

/// Per case and incident direction: albedo by 40k samples (std error < 3e-3) and by
/// adaptive quadrature of eval, which must agree within 4 standard errors + 2e-3;
/// the albedo of a lossless (F = 1) surface is <= 1 and near 1 where nothing is masked. The
/// pdf's mass by quadrature equals the sampler's success rate (binomial, 4 standard errors +
/// 2e-3): the lost mass is the probability of reflecting below the horizon.
#[test]
fn furnace_and_pdf_mass() {
    let n = 40_000;
    let (mut worst_albedo, mut worst_mass, mut min_albedo) = (0.0f64, 0.0f64, 1.0f32);
    let mut worst_z = 0.0f64;
    for (name, m, a) in cases() {
        for wi in incident() {
            let (mc, se) = albedo(&m, wi, n);
            let (quad, mass) = quadrature(&m, wi, &lobe_grid(wi, a));
            let d = (mc.x - quad.x).abs() as f64;
            worst_albedo = worst_albedo.max(d);
            worst_z = worst_z.max(d / (4.0 * se.x as f64 + 2e-3));
            assert!(
                d < 4.0 * se.x as f64 + 2e-3,
                "{name} {wi}: albedo mc {mc} ± {se}, quadrature {quad}"
            );
            // 1e-4: f32 rounding of wi.h vs wo.h in weight = eval / pdf at grazing angles.
            assert!(
                mc.x <= 1.0 + 4.0 * se.x + 1e-4 && quad.x <= 1.0 + 2e-3,
                "{name} {wi}: mc {mc} quad {quad}"
            );
            min_albedo = min_albedo.min(quad.x);
            if a.0 <= 0.01 && wi.z > 0.1 {
                assert!(quad.x > 0.995, "{name} {wi}: smooth limit {quad}");
            }
            let p = success_rate(&m, wi, n);
            let se_p = (p * (1.0 - p) / n as f64).sqrt();
            worst_mass = worst_mass.max((p - mass).abs());
            assert!(
                (p - mass).abs() < 4.0 * se_p + 2e-3,
                "{name} {wi}: success {p} vs pdf mass {mass}"
            );
        }
    }
    eprintln!(
        "roughconductor: worst |albedo mc - quad| {worst_albedo:.2e} (at most {worst_z:.2} of \
         the tolerance), worst |success - pdf mass| {worst_mass:.2e}, smallest lossless albedo \
         {min_albedo:.4}"
    );
}

#[test]
fn normal_incidence_numbers() {
    // Printed for the report: albedo and success rate at normal incidence, lossless F.
    for (name, m, a) in cases() {
        if a.0 != a.1 {
            continue;
        }
        let (alb, se) = albedo(&m, Vec3::Z, 40_000);
        let p = success_rate(&m, Vec3::Z, 40_000);
        eprintln!("{name}: albedo {:.4} ± {:.4}, success {p:.4}", alb.x, se.x);
    }
}

#[test]
fn eval_is_reciprocal() {
    let mut rng = crate::rng::Rng::new(77, 1);
    for d in DISTS {
        for a in [0.01, 0.3, 1.0] {
            let m = gold(d, a, true);
            for _ in 0..5_000 {
                let wi = crate::sampling::warps::square_to_cosine_hemisphere(rng.next_2d());
                let wo = crate::sampling::warps::square_to_cosine_hemisphere(rng.next_2d());
                let f = m.eval(wi, wo) / wo.z;
                let b = m.eval(wo, wi) / wi.z;
                let tol = 1e-4 * f.max_element() + 1e-30;
                assert!((f - b).abs().max_element() <= tol, "{f} {b}");
            }
        }
    }
}

/// 100k samples per case on 24 x 48 cells zoomed on the lobe; significance 1 % over all
/// cases (Sidak). Checks the sampler's actual distribution, which per-sample checks cannot.
#[test]
fn sampled_directions_match_pdf_chi2() {
    let mut runs = Vec::new();
    for d in DISTS {
        for a in [(1e-3, 1e-3), (0.1, 0.1), (1.0, 1.0), (0.05, 0.4)] {
            for vis in [true, false] {
                for wi in [incident()[0], incident()[2], incident()[3]] {
                    runs.push((rough(d, a, vis, Rgb::ONE), a, wi));
                }
            }
        }
    }
    let alpha = sidak_alpha(runs.len());
    let mut smallest = 1.0f64;
    for (m, a, wi) in &runs {
        let n = 100_000;
        let r = chi2_test(
            &lobe_grid(*wi, *a),
            n,
            |rng| m.sample(*wi, rng.next_f32(), rng.next_2d()).map(|s| s.wo),
            |wo| m.pdf(*wi, wo) as f64,
        );
        smallest = smallest.min(r.p_value);
        assert!(r.p_value > alpha, "{m:?} {wi}: {r:?}");
        assert!(r.mass_agrees(n, 2e-3), "{m:?} {wi}: {r:?}");
    }
    eprintln!(
        "roughconductor chi2: {} cases, smallest p {smallest:.3e}",
        runs.len()
    );
}

/// The pdf that `sample` reports is evaluated at the returned wo; here the density is
/// derived independently from the drawn normal (pdf_m(m) / (4 wi.m), the reflection
/// Jacobian) and compared, away from the grazing f32 limit (cos_i >= 0.1, alpha >= 0.01).
#[test]
fn reported_pdf_matches_drawn_normal_density() {
    let mut rng = crate::rng::Rng::new(4, 4);
    let mut worst = 0.0f32;
    for d in DISTS {
        for a in [(0.01, 0.01), (0.2, 0.2), (1.0, 1.0), (0.05, 0.4)] {
            let mf = Microfacet::new(d, a.0, a.1);
            for vis in [true, false] {
                let m = rough(d, a, vis, Rgb::ONE);
                for wi in incident().into_iter().take(3) {
                    for _ in 0..5_000 {
                        let u = rng.next_2d();
                        let h = if vis {
                            mf.sample_visible(wi, u)
                        } else {
                            mf.sample_all(u)
                        };
                        let Some(s) = m.sample(wi, 0.5, u) else {
                            continue;
                        };
                        let pm = if vis {
                            mf.pdf_visible(wi, h)
                        } else {
                            mf.pdf_all(h)
                        };
                        let want = pm / (4.0 * wi.dot(h));
                        let e = (s.pdf - want).abs() / want;
                        worst = worst.max(e);
                        assert!(e < 1e-3, "{d:?} {a:?} {vis} {wi}: {} vs {want}", s.pdf);
                    }
                }
            }
        }
    }
    eprintln!("roughconductor: worst pdf(wo) vs pdf_m/(4 wi.m) {worst:.2e}");
}

/// Cost per `sample` call (run with --ignored --nocapture; release-like test profile).
#[test]
#[ignore]
fn timing() {
    let wi = Vec3::new(0.3, 0.2, 0.9).normalize();
    for (name, m, _) in cases().into_iter().filter(|c| c.2 .0 == 0.1) {
        let mut rng = crate::rng::Rng::new(1, 2);
        let t = std::time::Instant::now();
        let mut acc = 0.0;
        for _ in 0..1_000_000 {
            if let Some(s) = m.sample(wi, rng.next_f32(), rng.next_2d()) {
                acc += s.weight.x;
            }
        }
        eprintln!(
            "{name}: {:.0} ns/sample ({acc})",
            t.elapsed().as_nanos() as f64 / 1e6
        );
    }
}

/// Eval on its own, against closed forms that share no code with the renderer's Fresnel:
/// at normal incidence a conductor reflects ((n-1)^2 + k^2) / ((n+1)^2 + k^2) per channel
/// (gold: 0.96666 / 0.80219 / 0.32405 for these indices), and the smooth conductor's
/// albedo must equal it. The rough conductor's albedo (by quadrature of eval, which no
/// sampler enters) then tends to the smooth one as alpha -> 0: at alpha = 0.01 it is within
/// 1 % at cos 1, 0.7 and 0.4, per channel, for both distributions. A mistake in eval alone
/// (a wrong D, G or Fresnel factor, a missing 1/(4 cos cos)) leaves sample and pdf in
/// agreement, so chi-square passes it; this does not.
#[test]
fn eval_tends_to_the_smooth_conductor_and_its_closed_form() {
    let (eta, k) = (
        Rgb::new(0.143119, 0.374957, 1.44248),
        Rgb::new(3.98316, 2.38572, 1.60322),
    );
    let normal = |n: f64, k: f64| ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
    let want = [
        normal(eta.x as f64, k.x as f64),
        normal(eta.y as f64, k.y as f64),
        normal(eta.z as f64, k.z as f64),
    ];
    assert!((want[0] - 0.96666).abs() < 1e-5 && (want[1] - 0.80219).abs() < 1e-5);
    let smooth = Material {
        kind: BsdfKind::Conductor(Conductor {
            eta,
            k,
            specular_reflectance: Rgb::ONE,
        }),
        two_sided: false,
    };
    let (a, _) = albedo(&smooth, Vec3::Z, 16);
    for c in 0..3 {
        assert!((a[c] as f64 - want[c]).abs() < 1e-5, "channel {c}: {a}");
    }
    for d in DISTS {
        let m = gold(d, 0.01, true);
        for cos in [1.0f32, 0.7, 0.4] {
            let wi = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos);
            let (quad, _) = quadrature(&m, wi, &lobe_grid(wi, (0.01, 0.01)));
            let (s, _) = albedo(&smooth, wi, 16);
            for c in 0..3 {
                let rel = (quad[c] / s[c] - 1.0).abs();
                assert!(
                    rel < 0.01,
                    "{d:?} cos {cos} channel {c}: rough {quad} smooth {s}"
                );
            }
        }
    }
}

/// Mitsuba 3's roughconductor albedo, lossless Fresnel, from `experiments/mitsuba_albedo.py`:
/// (distribution, alpha, [(cos_i, albedo, standard error)]).
/// (cos_i, albedo, standard error) at four incidences.
type AlbedoRow = [(f32, f64, f64); 4];

#[rustfmt::skip]
const MITSUBA_ALBEDO: [(&str, f32, AlbedoRow); 8] = [
    ("beckmann", 0.3, [(1.0, 0.999764, 3.5e-06), (0.7, 0.966028, 7.4e-05), (0.3, 0.900553, 1.2e-04), (0.1, 0.931867, 9.0e-05)]),
    ("beckmann", 0.5, [(1.0, 0.943378, 8.5e-05), (0.7, 0.874125, 1.4e-04), (0.3, 0.892592, 1.2e-04), (0.1, 0.936489, 8.0e-05)]),
    ("beckmann", 0.8, [(1.0, 0.642004, 1.9e-04), (0.7, 0.750994, 1.7e-04), (0.3, 0.871699, 1.2e-04), (0.1, 0.923603, 8.2e-05)]),
    ("beckmann", 1.0, [(1.0, 0.461634, 2.0e-04), (0.7, 0.652866, 1.8e-04), (0.3, 0.837443, 1.3e-04), (0.1, 0.902212, 8.8e-05)]),
    ("ggx", 0.3, [(1.0, 0.877429, 1.4e-04), (0.7, 0.843541, 1.4e-04), (0.3, 0.806317, 1.4e-04), (0.1, 0.842359, 1.2e-04)]),
    ("ggx", 0.5, [(1.0, 0.687923, 1.9e-04), (0.7, 0.678404, 1.8e-04), (0.3, 0.714139, 1.6e-04), (0.1, 0.772276, 1.4e-04)]),
    ("ggx", 0.8, [(1.0, 0.427085, 2.0e-04), (0.7, 0.469213, 1.9e-04), (0.3, 0.565181, 1.8e-04), (0.1, 0.642594, 1.5e-04)]),
    ("ggx", 1.0, [(1.0, 0.306945, 1.8e-04), (0.7, 0.360961, 1.8e-04), (0.3, 0.472078, 1.7e-04), (0.1, 0.557879, 1.6e-04)]),
];

/// High roughness, where most of a sample's weight is masking and shadowing: the albedo by
/// quadrature of `eval` (no sampler involved) matches Mitsuba 3's independent implementation,
/// within 4 of its standard errors plus 3e-4 for f32 rounding of either. An `eval` that loses
/// a factor (a G1, a cosine) or uses the other distribution's Lambda lands off by far more.
#[test]
fn eval_albedo_matches_mitsuba_at_high_roughness() {
    let mut worst = 0.0f64;
    for (dist, a, row) in MITSUBA_ALBEDO {
        let d = match dist {
            "beckmann" => MicrofacetDistribution::Beckmann,
            _ => MicrofacetDistribution::Ggx,
        };
        let m = rough(d, (a, a), true, Rgb::ONE);
        for (c, want, se) in row {
            let wi = Vec3::new((1.0 - c * c).sqrt(), 0.0, c);
            let (q, _) = quadrature(&m, wi, &LobeGrid::around_normal(1.0));
            let err = (q.x as f64 - want).abs();
            worst = worst.max(err);
            assert!(
                err < 4.0 * se + 3e-4,
                "{dist} alpha {a} cos_i {c}: albedo by quadrature {}, Mitsuba {want} ± {se}",
                q.x
            );
        }
    }
    eprintln!("rough conductor albedo vs Mitsuba 3: worst difference {worst:.1e}");
}

/// specular_reflectance scales eval and the sample weight channel by channel (and leaves the
/// pdf and the sampled direction alone).
#[test]
fn specular_reflectance_scales_eval_and_weight() {
    let spec = Rgb::new(0.5, 0.25, 0.8);
    let wi = Vec3::new(0.3, 0.2, 0.9).normalize();
    let wo = Vec3::new(-0.4, -0.1, 0.8).normalize();
    for d in DISTS {
        let (white, tinted) = (
            rough(d, (0.3, 0.3), true, Rgb::ONE),
            rough(d, (0.3, 0.3), true, spec),
        );
        let (e1, e2) = (white.eval(wi, wo), tinted.eval(wi, wo));
        assert!(e1.min_element() > 0.0);
        assert!(
            (e2 - e1 * spec).abs().max_element() <= 1e-6 * e1.max_element(),
            "{e1} {e2}"
        );
        assert_eq!(white.pdf(wi, wo), tinted.pdf(wi, wo));
        let (s1, s2) = (
            white.sample(wi, 0.3, Vec2::new(0.4, 0.6)).unwrap(),
            tinted.sample(wi, 0.3, Vec2::new(0.4, 0.6)).unwrap(),
        );
        assert_eq!(s1.wo, s2.wo);
        let w = s1.weight * spec;
        assert!((s2.weight - w).abs().max_element() <= 1e-6 * w.max_element());
    }
}
