//! Tests of the chi-square engine on samplers whose distributions are known exactly.
//! Every run is deterministic (fixed seed); thresholds are the significance levels stated.

use super::*;
use crate::stats::domain::{Disk, Sphere, Triangle, UnitSquare};
use crate::stats::ks_uniform;
use glam::{Vec2, Vec3};
use std::f64::consts::PI;

const N: u64 = 200_000;

fn cfg(threshold: f64) -> Chi2Config {
    Chi2Config {
        samples: N,
        threshold,
        seed: 17,
        ..Chi2Config::default()
    }
}

fn square() -> UnitSquare {
    UnitSquare { n: 31 }
}

fn cosine_hemisphere(rng: &mut Rng) -> Option<Vec3> {
    let (u1, u2) = (rng.next_f64(), rng.next_f64());
    let r = u1.sqrt();
    let phi = 2.0 * PI * u2;
    let d = glam::DVec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u1).max(0.0).sqrt());
    Some(d.as_vec3())
}

fn cosine_pdf(d: Vec3) -> f64 {
    (d.z as f64).max(0.0) / PI
}

fn uniform_hemisphere_pdf(d: Vec3) -> f64 {
    if d.z > 0.0 {
        1.0 / (2.0 * PI)
    } else {
        0.0
    }
}

const CAP_DEG: f64 = 20.0;

/// Uniform over the cone of half-angle 20 degrees around +z: a pdf with a sharp rim.
fn cap_sampler(rng: &mut Rng) -> Option<Vec3> {
    let cos_max = CAP_DEG.to_radians().cos();
    let z = 1.0 - rng.next_f64() * (1.0 - cos_max);
    let phi = 2.0 * PI * rng.next_f64();
    let s = (1.0 - z * z).max(0.0).sqrt();
    Some(glam::DVec3::new(s * phi.cos(), s * phi.sin(), z).as_vec3())
}

fn cap_pdf(d: Vec3) -> f64 {
    let cos_max = CAP_DEG.to_radians().cos();
    if d.z as f64 >= cos_max {
        1.0 / (2.0 * PI * (1.0 - cos_max))
    } else {
        0.0
    }
}

/// A failure says which part failed and where: a pdf of the wrong shape (2x, integral 1)
/// fails the histogram at the cells nearest x = 0 and x = 1; a pdf of the right shape but
/// the wrong integral (0.8) fails the integral. alpha = 0.01, N = 200k.
#[test]
fn a_failure_names_the_part_that_failed_and_the_worst_cells() {
    let r = chi2_test(
        &square(),
        |g| Some(g.next_2d()),
        |p| 2.0 * p.x as f64,
        &cfg(0.01),
    );
    assert!(!r.passed());
    assert!(
        r.reason.contains("the histogram's shape failed"),
        "{}",
        r.reason
    );
    let worst = &r.reason[r.reason.find("worst cells: (col ").expect("worst cells")..];
    let col: usize = worst[18..worst.find(',').unwrap()].parse().unwrap();
    assert!(col <= 1 || col >= 29, "{worst}");
    let r = chi2_test(&square(), |g| Some(g.next_2d()), |_| 0.8, &cfg(0.01));
    assert!(!r.passed());
    assert!(
        r.reason.contains("integrates to 0.8000") && r.reason.contains("the integral failed"),
        "{}",
        r.reason
    );
}

#[test]
fn uniform_square_passes() {
    // alpha = 0.01, N = 200k, 31x31 cells.
    let r = chi2_test(&square(), |g| Some(g.next_2d()), |_| 1.0, &cfg(0.01));
    eprintln!("uniform square: {}", r.reason);
    assert!(r.passed(), "{}", r.reason);
    assert_eq!(r.dof, 31 * 31 - 1);
    assert!((r.pdf_integral - 1.0).abs() < 1e-12);
    assert_eq!(r.observed.sum(), N as f64);
}

#[test]
fn sqrt_warp_claimed_uniform_fails() {
    // x = sqrt(u) has density 2x, not 1; must be rejected with p < 1e-6 at N = 200k.
    let r = chi2_test(
        &square(),
        |g| Some(Vec2::new(g.next_f32().sqrt(), g.next_f32())),
        |_| 1.0,
        &cfg(0.01),
    );
    eprintln!("sqrt vs uniform: {}", r.reason);
    assert!(!r.passed());
    assert!(r.p_value < 1e-6, "p = {}", r.p_value);
}

#[test]
fn cosine_hemisphere_passes_on_sphere() {
    // alpha = 0.01, N = 200k, sphere 51x101.
    let r = chi2_test(
        &Sphere::default(),
        cosine_hemisphere,
        cosine_pdf,
        &cfg(0.01),
    );
    eprintln!("cosine vs cosine pdf: {}", r.reason);
    assert!(r.passed(), "{}", r.reason);
    assert!((r.pdf_integral - 1.0).abs() < 1e-5, "{}", r.pdf_integral);
}

#[test]
fn cosine_sampler_with_uniform_pdf_fails() {
    // Same sampler, wrong pdf: rejected at alpha = 0.01 (p far below), N = 200k.
    let r = chi2_test(
        &Sphere::default(),
        cosine_hemisphere,
        uniform_hemisphere_pdf,
        &cfg(0.01),
    );
    eprintln!("cosine vs uniform pdf: {}", r.reason);
    assert!(!r.passed());
    assert!(r.p_value < 1e-6);
}

#[test]
fn spherical_cap_sharp_edge_passes() {
    // The rim at 20 degrees cuts through a row of cells; without edge refinement the
    // expected counts of that row are off by O(10 %) and the test fails.
    // alpha = 0.01, N = 200k, sphere 51x101.
    let r = chi2_test(&Sphere::default(), cap_sampler, cap_pdf, &cfg(0.01));
    eprintln!("cap: {}", r.reason);
    assert!(r.passed(), "{}", r.reason);
    assert!((r.pdf_integral - 1.0).abs() < 1e-4, "{}", r.pdf_integral);
}

#[test]
fn cap_fails_without_edge_refinement() {
    // Control for the test above: plain 5x5 Simpson per cell misjudges the rim row.
    // alpha = 0.01, N = 200k.
    let mut c = cfg(0.01);
    c.integration = Integration {
        initial_split: 1,
        max_depth: 0,
        ..Integration::default()
    };
    let r = chi2_test(&Sphere::default(), cap_sampler, cap_pdf, &c);
    eprintln!(
        "cap, no refinement: {} (integral {})",
        r.reason, r.pdf_integral
    );
    assert!(!r.passed());
}

#[test]
fn samples_where_pdf_is_zero_fail_immediately() {
    // The pdf claims support x < 1/2 only; half the samples land in zero cells.
    let r = chi2_test(
        &square(),
        |g| Some(g.next_2d()),
        |p| if p.x < 0.5 { 2.0 } else { 0.0 },
        &cfg(0.01),
    );
    assert!(!r.passed());
    assert!(r.reason.contains("integrates to 0"), "{}", r.reason);
    assert!(r.statistic.is_nan());
}

#[test]
fn single_stray_sample_fails_with_zero_tolerance() {
    // One sample of 200k in an impossible cell: tolerated by Nori's 1e-5 N rule, fatal at 0.
    let stray = |first: &mut bool, g: &mut Rng| {
        let p = Vec2::new(0.5 * g.next_f32(), g.next_f32());
        Some(if std::mem::take(first) {
            Vec2::new(0.9, 0.5)
        } else {
            p
        })
    };
    let pdf = |p: Vec2| if p.x <= 0.5 { 2.0 } else { 0.0 };
    let mut strict = cfg(0.01);
    strict.zero_tolerance = 0.0;
    let mut first = true;
    let r = chi2_test(&square(), |g| stray(&mut first, g), pdf, &strict);
    assert!(!r.passed());
    assert!(
        r.reason.contains("1 samples in cell (col 27, row 15)"),
        "{}",
        r.reason
    );
    let mut first = true;
    let r = chi2_test(&square(), |g| stray(&mut first, g), pdf, &cfg(0.01));
    eprintln!("stray sample tolerated: {}", r.reason);
    assert!(r.passed(), "{}", r.reason);
}

#[test]
fn lost_samples_must_be_accounted_for_by_the_pdf() {
    // A sampler failing 10 % of the time with a pdf integrating to 0.9 passes (alpha 0.01,
    // N = 200k); the same sampler claiming a normalised pdf fails.
    let lossy = |g: &mut Rng| {
        let p = g.next_2d();
        (g.next_f32() >= 0.1).then_some(p)
    };
    let r = chi2_test(&square(), lossy, |_| 0.9, &cfg(0.01));
    eprintln!("lossy, honest pdf: {}", r.reason);
    assert!(r.passed(), "{}", r.reason);
    assert!(r.lost > 19_000 && r.lost < 21_000);
    assert!((r.pdf_integral - 0.9).abs() < 1e-9);
    let r = chi2_test(&square(), lossy, |_| 1.0, &cfg(0.01));
    assert!(!r.passed());
    assert!(r.reason.contains("returned None"), "{}", r.reason);
}

#[test]
fn outside_domain_fails() {
    let r = chi2_test(
        &Sphere::default(),
        |_| Some(Vec3::new(0.0, 0.0, 2.0)),
        cosine_pdf,
        &cfg(0.01),
    );
    assert!(!r.passed());
    assert!(r.reason.contains("not unit length"), "{}", r.reason);
    assert_eq!(r.outside, N, "every sample is counted outside");
    // One stray sample in three is counted as such.
    let mut k = 0u64;
    let r = chi2_test(
        &Sphere::default(),
        |g| {
            k += 1;
            if k.is_multiple_of(3) {
                Some(Vec3::new(0.0, 0.0, 2.0))
            } else {
                cosine_hemisphere(g)
            }
        },
        cosine_pdf,
        &cfg(0.01),
    );
    assert!(!r.passed());
    assert_eq!(r.outside, N / 3);
}

#[test]
fn uniform_disk_passes() {
    // r = sqrt(u) gives uniform area density 1/pi. alpha = 0.01, N = 200k, 51x51 polar cells.
    let sampler = |g: &mut Rng| {
        let r = g.next_f64().sqrt();
        let phi = 2.0 * PI * g.next_f64();
        Some(glam::DVec2::new(r * phi.cos(), r * phi.sin()).as_vec2())
    };
    let r = chi2_test(&Disk::default(), sampler, |_| 1.0 / PI, &cfg(0.01));
    eprintln!("disk: {}", r.reason);
    assert!(r.passed(), "{}", r.reason);
    assert!((r.pdf_integral - 1.0).abs() < 1e-9);
    // Forgetting the sqrt piles samples at the centre.
    let bad = |g: &mut Rng| {
        let r = g.next_f64();
        let phi = 2.0 * PI * g.next_f64();
        Some(glam::DVec2::new(r * phi.cos(), r * phi.sin()).as_vec2())
    };
    assert!(!chi2_test(&Disk::default(), bad, |_| 1.0 / PI, &cfg(0.01)).passed());
}

#[test]
fn uniform_triangle_passes() {
    // Square-root barycentrics, pdf = 1/area = 2. alpha = 0.01, N = 200k, 51x51 grid whose
    // diagonal cells are half outside the domain.
    let sampler = |g: &mut Rng| {
        let (u1, u2) = (g.next_f64(), g.next_f64());
        let s = u1.sqrt();
        Some(Vec2::new((1.0 - s) as f32, (s * u2) as f32))
    };
    let r = chi2_test(&Triangle::default(), sampler, |_| 2.0, &cfg(0.01));
    eprintln!("triangle: {}", r.reason);
    assert!(r.passed(), "{}", r.reason);
    assert!((r.pdf_integral - 1.0).abs() < 1e-4, "{}", r.pdf_integral);
    // Plain (u1, u2) folded? No: (u1, u2 (1 - u1)) is not uniform and must fail.
    let bad = |g: &mut Rng| {
        let (u1, u2) = (g.next_f32(), g.next_f32());
        Some(Vec2::new(u1, u2 * (1.0 - u1)))
    };
    assert!(!chi2_test(&Triangle::default(), bad, |_| 2.0, &cfg(0.01)).passed());
}

#[test]
fn pooling_follows_nori() {
    // Three small cells (1 + 2 + 3 = 6 >= 5) pool into one; the 10 stands alone.
    let mut cells = vec![(10.0, 10.0), (3.0, 3.0), (1.0, 1.0), (2.0, 2.0)];
    let p = pearson(&mut cells, 5.0).unwrap();
    assert_eq!(p.dof, 1);
    assert_eq!(p.statistic, 0.0);
    // A pool still below 5 absorbs the next larger cell.
    let mut cells = vec![(1.0, 1.0), (9.0, 6.0), (20.0, 20.0)];
    let p = pearson(&mut cells, 5.0).unwrap();
    assert_eq!(p.dof, 1);
    assert!((p.statistic - 9.0 / 7.0).abs() < 1e-12);
    assert!(pearson(&mut [(4.0, 4.0)], 5.0).is_none());
}

#[test]
fn chi2_sf_textbook() {
    // 95th percentiles of chi-square: dof 1 -> 3.841, dof 10 -> 18.307.
    assert!((chi2_sf(3.841, 1) - 0.05).abs() < 1e-4);
    assert!((chi2_sf(18.307, 10) - 0.05).abs() < 1e-4);
}

#[test]
fn refinement_stays_near_edges() {
    // Budget check: a uniform 5x5-node pass over 51x101 cells with split 2 costs ~0.1 M
    // evaluations; edges (the cap's rim, the cosine lobe's horizon) may add some millions,
    // not the 4^8-fold of refining everywhere.
    let count = |pdf: fn(Vec3) -> f64| {
        let n = std::cell::Cell::new(0u64);
        let (grid, _) = cell_integrals(
            &Sphere::default(),
            |d| {
                n.set(n.get() + 1);
                pdf(d)
            },
            &Integration::default(),
        );
        (n.get(), grid.sum())
    };
    for (name, pdf) in [("cap", cap_pdf as fn(Vec3) -> f64), ("cosine", cosine_pdf)] {
        let (evals, total) = count(pdf);
        eprintln!("{name}: {evals} pdf evaluations, integral {total}");
        assert!(evals < 4_000_000, "{name}: {evals}");
    }
}

/// A square area light of side 1 whose centre is 1 above the origin, tilted so its
/// silhouette crosses the (phi, cos theta) grid along curves; normal faces the origin.
struct QuadLight {
    centre: glam::DVec3,
    normal: glam::DVec3,
    t: glam::DVec3,
    b: glam::DVec3,
}

impl QuadLight {
    fn new() -> Self {
        let normal = -glam::DVec3::new(0.3, -0.2, 1.0).normalize();
        let t = normal.any_orthonormal_vector();
        QuadLight {
            centre: glam::DVec3::new(0.2, 0.1, 1.0),
            normal,
            t,
            b: normal.cross(t),
        }
    }

    /// Uniform point on the light, returned as the direction towards it.
    fn sample(&self, rng: &mut Rng) -> Option<Vec3> {
        let (u, v) = (rng.next_f64() - 0.5, rng.next_f64() - 0.5);
        Some(
            (self.centre + u * self.t + v * self.b)
                .normalize()
                .as_vec3(),
        )
    }

    /// Solid-angle pdf of `sample`: d^2 / (area |cos theta_light|) inside the silhouette.
    /// With `jacobian = false` it makes the classic mistake of dropping the cosine.
    fn pdf(&self, d: Vec3, jacobian: bool) -> f64 {
        let d = d.as_dvec3();
        let cos_l = -d.dot(self.normal);
        if cos_l <= 0.0 {
            return 0.0;
        }
        let dist = self.centre.dot(self.normal) / d.dot(self.normal);
        let q = dist * d - self.centre;
        if q.dot(self.t).abs() > 0.5 || q.dot(self.b).abs() > 0.5 {
            return 0.0;
        }
        dist * dist / if jacobian { cos_l } else { 1.0 }
    }
}

#[test]
fn area_light_silhouette_passes_and_missing_cosine_fails() {
    // The light covers ~0.7 sr, about 300 cells, many of them cut by its silhouette.
    // alpha = 0.01, N = 200k.
    let light = QuadLight::new();
    let r = chi2_test(
        &Sphere::default(),
        |g| light.sample(g),
        |d| light.pdf(d, true),
        &cfg(0.01),
    );
    eprintln!("quad light: {}", r.reason);
    assert!(r.passed(), "{}", r.reason);
    assert!((r.pdf_integral - 1.0).abs() < 1e-4, "{}", r.pdf_integral);
    let r = chi2_test(
        &Sphere::default(),
        |g| light.sample(g),
        |d| light.pdf(d, false),
        &cfg(0.01),
    );
    eprintln!("quad light without cos: {}", r.reason);
    assert!(!r.passed());
    assert!(r.p_value < 1e-6);
}

/// The engine is calibrated: for a correct sampler its p-values are uniform. 40 seeds of
/// 20,000 cosine-hemisphere samples on a 10x19 sphere grid: the p-values' KS distance from
/// Uniform(0, 1) is below the alpha = 0.01 critical value for n = 40 (1.628 / sqrt(40) =
/// 0.257), and at most 7 of the 40 fall below 0.05 (binomial(40, 0.05) exceeds 7 with
/// probability 0.0015). An engine with degrees of freedom a quarter too many (as when pooled
/// cells are counted as categories of their own) piles its p-values up near 1 and fails the
/// KS test, which the test checks on the same statistics.
#[test]
fn p_values_are_uniform_for_a_correct_sampler() {
    let domain = Sphere {
        n_phi: 10,
        n_cos: 19,
    };
    let mut p = Vec::new();
    let mut p_wrong_dof = Vec::new();
    for seed in 0..40 {
        let c = Chi2Config {
            samples: 20_000,
            seed: 1000 + seed,
            ..cfg(0.01)
        };
        let r = chi2_test(&domain, cosine_hemisphere, cosine_pdf, &c);
        assert!(r.dof > 0, "{}", r.reason);
        p.push(r.p_value);
        p_wrong_dof.push(chi2_sf(r.statistic, r.dof + r.dof / 4));
    }
    p.sort_by(f64::total_cmp);
    p_wrong_dof.sort_by(f64::total_cmp);
    let (d, d_wrong) = (ks_uniform(&p), ks_uniform(&p_wrong_dof));
    let rejected = p.iter().filter(|&&x| x < 0.05).count();
    eprintln!(
        "chi2 calibration: KS D = {d:.3}, {rejected}/40 below 0.05; dof x 1.25: D = {d_wrong:.3}"
    );
    assert!(d < 0.257, "p-values not uniform: D = {d}, {p:?}");
    assert!(rejected <= 7, "{rejected} of 40 rejected at 0.05");
    assert!(
        d_wrong > 0.257,
        "the KS check cannot see a wrong dof: D = {d_wrong}"
    );
}

/// A pdf that is negative or NaN somewhere fails with the count of such integration nodes,
/// each kind on its own (a uniform sampler, so nothing else can fail first), and those
/// nodes add nothing to the cells.
#[test]
fn negative_or_nan_pdf_values_fail_with_their_count() {
    let uniform = |g: &mut Rng| Some(Vec2::new(g.next_f32(), g.next_f32()));
    for bad in [-1.0, f64::NAN] {
        let pdf = move |p: Vec2| if p.x > 0.9 { bad } else { 1.0 };
        let r = chi2_test(&square(), uniform, pdf, &cfg(0.01));
        assert!(!r.passed(), "{bad}: {}", r.reason);
        let why = &r.reason;
        let count: u64 = why
            .strip_prefix("pdf returned NaN or a negative value at ")
            .and_then(|s| s.strip_suffix(" integration nodes"))
            .unwrap_or_else(|| panic!("{why}"))
            .parse()
            .unwrap();
        assert!(count > 0, "{why}");
        // The count is exactly the number of bad evaluations.
        let seen_bad = std::cell::Cell::new(0u64);
        let counting = |p: Vec2| {
            let x = pdf(p);
            if !(x >= 0.0) {
                seen_bad.set(seen_bad.get() + 1);
            }
            x
        };
        let (grid, n) = cell_integrals_seen(&square(), counting, &Integration::default(), None);
        assert!(
            n > 0 && n == seen_bad.get(),
            "{bad}: {n} vs {}",
            seen_bad.get()
        );
        assert!(grid.data.iter().all(|x| *x >= 0.0 && x.is_finite()));
        // Columns past x = 0.9 lose their mass: the total is about 0.9.
        let total: f64 = grid.data.iter().sum();
        assert!((total - 0.9).abs() < 0.02, "{total}");
    }
}
