//! Closed forms against published values and against brute-force quadrature.

use super::*;
use crate::rng::Rng;
use glam::dvec3;

fn verts(t: &[[f64; 3]]) -> Vec<DVec3> {
    t.iter().map(|v| DVec3::from_array(*v)).collect()
}

#[test]
fn matches_nori_references() {
    // Nori's obj files print vertices to 6 significant digits, its references to 6 too:
    // agreement to 1e-5 relative is all the inputs allow.
    for (i, (tri, reference)) in NORI_TRIANGLE_TESTS.into_iter().enumerate() {
        let e = polygon_irradiance(DVec3::ZERO, DVec3::Y, &verts(&tri), 1.0).unwrap();
        let lo = diffuse_radiance(0.5, e);
        eprintln!(
            "polylum{}: E = {e:.7}, Lo = {lo:.7}, Nori {reference}",
            i + 1
        );
        assert!(
            (lo - reference).abs() < 1e-5 * reference,
            "{lo} vs {reference}"
        );
    }
}

/// Radon's 7-point rule, exact for degree 5 on a triangle: (barycentric a, weight).
fn radon7() -> [([f64; 3], f64); 7] {
    let s = 15f64.sqrt();
    let (a, b) = ((6.0 - s) / 21.0, (6.0 + s) / 21.0);
    let (wa, wb) = ((155.0 - s) / 1200.0, (155.0 + s) / 1200.0);
    [
        ([1.0 / 3.0; 3], 9.0 / 40.0),
        ([a, a, 1.0 - 2.0 * a], wa),
        ([a, 1.0 - 2.0 * a, a], wa),
        ([1.0 - 2.0 * a, a, a], wa),
        ([b, b, 1.0 - 2.0 * b], wb),
        ([b, 1.0 - 2.0 * b, b], wb),
        ([1.0 - 2.0 * b, b, b], wb),
    ]
}

/// Integral of f over triangle (p0, p1, p2), split into m^2 congruent pieces.
fn integrate_triangle(p: [DVec3; 3], m: usize, f: &impl Fn(DVec3) -> f64) -> f64 {
    let rule = radon7();
    let (e1, e2) = ((p[1] - p[0]) / m as f64, (p[2] - p[0]) / m as f64);
    let area = 0.5 * e1.cross(e2).length();
    let mut total = 0.0;
    let mut piece = |q: [DVec3; 3]| {
        for (bary, w) in rule {
            total += w * area * f(bary[0] * q[0] + bary[1] * q[1] + bary[2] * q[2]);
        }
    };
    for i in 0..m {
        for j in 0..m - i {
            let o = p[0] + i as f64 * e1 + j as f64 * e2;
            piece([o, o + e1, o + e2]);
            if i + j + 1 < m {
                piece([o + e1, o + e1 + e2, o + e2]);
            }
        }
    }
    total
}

/// E = integral over the polygon of L cos(theta_x) cos(theta_y) / d^2 dA, one-sided.
fn irradiance_by_quadrature(x: DVec3, n: DVec3, poly: &[DVec3], radiance: f64) -> f64 {
    let normal = polygon_normal(poly).normalize();
    let f = |y: DVec3| {
        let d = y - x;
        let d2 = d.length_squared();
        let cos_x = d.dot(n) / d2.sqrt();
        let cos_y = -d.dot(normal) / d2.sqrt();
        radiance * cos_x.max(0.0) * cos_y.max(0.0) / d2
    };
    (1..poly.len() - 1)
        .map(|k| integrate_triangle([poly[0], poly[k], poly[k + 1]], 64, &f))
        .sum()
}

/// A random unit vector and an orthonormal frame around it.
fn random_frame(rng: &mut Rng) -> (DVec3, DVec3, DVec3) {
    let z = 2.0 * rng.next_f64() - 1.0;
    let phi = TAU * rng.next_f64();
    let s = (1.0 - z * z).sqrt();
    let n = dvec3(s * phi.cos(), s * phi.sin(), z);
    let t = n.any_orthonormal_vector();
    (n, t, n.cross(t))
}

/// Random convex polygon with `k` vertices in a random plane, above x's tangent plane
/// (every vertex at least 0.2 high) and facing x.
fn random_polygon(rng: &mut Rng, x: DVec3, n: DVec3, k: usize) -> Vec<DVec3> {
    loop {
        let (_, t, b) = random_frame(rng);
        let centre = x + 0.5 * n + 0.4 * random_frame(rng).0;
        let r = 0.1 + 0.4 * rng.next_f64();
        let phase = TAU * rng.next_f64();
        let mut poly: Vec<DVec3> = (0..k)
            .map(|i| {
                // Angles jittered within their own sector keep the polygon convex.
                let a = phase + TAU * (i as f64 + 0.8 * rng.next_f64()) / k as f64;
                centre + r * (a.cos() * t + a.sin() * b)
            })
            .collect();
        if poly.iter().any(|v| (*v - x).dot(n) < 0.2) {
            continue;
        }
        if (x - poly[0]).dot(polygon_normal(&poly)) < 0.0 {
            poly.reverse();
        }
        return poly;
    }
}

#[test]
fn lambert_matches_quadrature_for_random_triangles_and_quads() {
    let mut rng = Rng::new(42, 7);
    for case in 0..24 {
        let x = dvec3(rng.next_f64(), rng.next_f64(), rng.next_f64()) - 0.5;
        let (n, _, _) = random_frame(&mut rng);
        let k = if case % 2 == 0 { 3 } else { 4 };
        let poly = random_polygon(&mut rng, x, n, k);
        let radiance = 0.5 + 2.0 * rng.next_f64();
        let exact = polygon_irradiance(x, n, &poly, radiance).unwrap();
        let quad = irradiance_by_quadrature(x, n, &poly, radiance);
        assert!(exact > 0.0);
        assert!(
            (exact - quad).abs() < 1e-9 * exact,
            "case {case} ({k} vertices): Lambert {exact}, quadrature {quad}"
        );
    }
}

#[test]
fn one_sided_and_horizon() {
    let x = DVec3::ZERO;
    // Counter-clockwise seen from below (from x): faces x.
    let tri = vec![
        dvec3(0.0, 0.0, 1.0),
        dvec3(0.0, 1.0, 1.0),
        dvec3(1.0, 0.0, 1.0),
    ];
    let e = polygon_irradiance(x, DVec3::Z, &tri, 1.0).unwrap();
    assert!(e > 0.0);
    let back: Vec<DVec3> = tri.iter().rev().copied().collect();
    assert_eq!(polygon_irradiance(x, DVec3::Z, &back, 1.0), Ok(0.0));
    // Tilting the receiver so a vertex dips below its horizon is refused.
    let tilted = dvec3(1.0, 0.0, 0.2).normalize();
    let err = polygon_irradiance(x, tilted, &[dvec3(-2.0, 0.0, 0.1), tri[1], tri[2]], 1.0);
    assert!(matches!(
        err,
        Err(AnalyticError::BelowHorizon { index: 0, .. })
    ));
    assert_eq!(
        polygon_irradiance(x, DVec3::Z, &tri[..2], 1.0),
        Err(AnalyticError::Degenerate)
    );
}

#[test]
fn huge_square_gives_pi_l() {
    // An emitter covering (almost) the whole hemisphere: E -> pi L. For a square of
    // half-side s at height 1 the missed fraction is O(1/s), so s = 1e4 is within 1e-3.
    let s = 1e4;
    let sq = [
        dvec3(-s, -s, 1.0),
        dvec3(-s, s, 1.0),
        dvec3(s, s, 1.0),
        dvec3(s, -s, 1.0),
    ];
    let e = polygon_irradiance(DVec3::ZERO, DVec3::Z, &sq, 2.0).unwrap();
    assert!((e - 2.0 * PI).abs() < 2e-3 * 2.0 * PI, "{e}");
}

#[test]
fn triangle_solid_angle_values() {
    // The octant triangle covers one eighth of the sphere.
    let o = DVec3::ZERO;
    let w = triangle_solid_angle(o, DVec3::X, DVec3::Y, DVec3::Z);
    assert!((w - PI / 2.0).abs() < 1e-14);
    assert!((triangle_solid_angle(o, DVec3::X, DVec3::Z, DVec3::Y) - w).abs() < 1e-14);
    // Against quadrature of cos(theta_y) / d^2 over random triangles, including ones whose
    // solid angle exceeds pi (where the plain atan would take the wrong branch).
    let mut rng = Rng::new(5, 1);
    for case in 0..12 {
        let p = dvec3(rng.next_f64(), rng.next_f64(), rng.next_f64()) * 0.2;
        let tri = if case == 0 {
            [
                dvec3(-5.0, -5.0, 0.3),
                dvec3(5.0, -5.0, 0.3),
                dvec3(0.0, 5.0, 0.3),
            ]
        } else {
            let q = random_polygon(&mut rng, p, DVec3::Z, 3);
            [q[0], q[1], q[2]]
        };
        let omega = triangle_solid_angle(p, tri[0], tri[1], tri[2]);
        let normal = polygon_normal(&tri).normalize();
        let f = |y: DVec3| {
            let d = y - p;
            d.dot(normal).abs() / d.length().powi(3)
        };
        let m = if case == 0 { 256 } else { 64 };
        let quad = integrate_triangle(tri, m, &f);
        let tol = if case == 0 { 1e-5 } else { 1e-9 };
        assert!(
            (omega - quad).abs() < tol * omega,
            "case {case}: {omega} vs {quad}"
        );
        if case == 0 {
            assert!(omega > PI);
        }
    }
}

#[test]
fn sphere_cap_solid_angle_values() {
    let c = dvec3(0.0, 0.0, 2.0);
    // sin(theta_max) = 1/2: 2 pi (1 - sqrt(3)/2).
    let w = sphere_cap_solid_angle(DVec3::ZERO, c, 1.0);
    assert!((w - TAU * (1.0 - 0.75f64.sqrt())).abs() < 1e-14);
    assert!((w - cone_solid_angle(0.75f64.sqrt())).abs() < 1e-14);
    // Far away it tends to the disk's pi r^2 / d^2, without cancellation.
    let far = sphere_cap_solid_angle(DVec3::ZERO, dvec3(0.0, 1e6, 0.0), 1.0);
    assert!((far / (PI * 1e-12) - 1.0).abs() < 1e-9);
    assert_eq!(sphere_cap_solid_angle(DVec3::ZERO, c, 3.0), 4.0 * PI);
    assert!((cone_solid_angle(-1.0) - 4.0 * PI).abs() < 1e-15);
}

/// One-sample Monte Carlo estimate of E by uniform area sampling of a triangle light.
fn area_sampled_irradiance(tri: &[DVec3], n: DVec3, rng: &mut Rng, with_cos_light: bool) -> f64 {
    let (u1, u2) = (rng.next_f64(), rng.next_f64());
    let s = u1.sqrt();
    let y = (1.0 - s) * tri[0] + s * (1.0 - u2) * tri[1] + s * u2 * tri[2];
    let normal = polygon_normal(tri);
    let area = normal.length();
    let d = y;
    let d2 = d.length_squared();
    let cos_x = (d.dot(n) / d2.sqrt()).max(0.0);
    let cos_y = if with_cos_light {
        (-d.dot(normal) / (area * d2.sqrt())).max(0.0)
    } else {
        1.0
    };
    cos_x * cos_y / d2 * area
}

#[test]
fn monte_carlo_estimates_pass_t_test_against_lambert() {
    // Nori-style t-test: 100k samples per triangle, two-sided, alpha = 0.01 Sidak-corrected
    // over the 5 triangles. The same estimator without the light's cosine must fail.
    use crate::stats::{one_sample_welford, sidak, Welford};
    let alpha = sidak(0.01, NORI_TRIANGLE_TESTS.len());
    let mut rng = Rng::new(2024, 3);
    for (i, (tri, _)) in NORI_TRIANGLE_TESTS.iter().enumerate() {
        let tri = verts(tri);
        let exact = polygon_irradiance(DVec3::ZERO, DVec3::Y, &tri, 1.0).unwrap();
        let good: Welford = (0..100_000)
            .map(|_| area_sampled_irradiance(&tri, DVec3::Y, &mut rng, true))
            .collect();
        let t = one_sample_welford(&good, exact);
        eprintln!("polylum{}: t = {:.3}, p = {:.4}", i + 1, t.t, t.p_value);
        assert!(t.passes(alpha), "polylum{}: {t:?}", i + 1);
        let bad: Welford = (0..100_000)
            .map(|_| area_sampled_irradiance(&tri, DVec3::Y, &mut rng, false))
            .collect();
        assert!(!one_sample_welford(&bad, exact).passes(alpha));
    }
}
