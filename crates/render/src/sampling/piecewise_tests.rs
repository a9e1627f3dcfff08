//! The piecewise-constant table: its density agrees with its sampler (pointwise and by
//! chi-square), integrates to 1, never draws a cell of value 0, and refuses bad tables; the
//! latitude-longitude mapping and its Jacobian; MIS compensation.

use super::*;
use crate::rng::Rng;
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// 5 x 4 with zero cells and a zero row.
const W: usize = 5;
const H: usize = 4;
const TABLE: [f64; W * H] = [
    1.0, 0.0, 3.0, 0.5, 2.0, //
    0.0, 0.0, 0.0, 0.0, 0.0, //
    4.0, 1.0, 0.0, 0.25, 7.0, //
    0.1, 2.0, 2.0, 0.0, 1.5,
];

#[test]
fn the_density_integrates_to_one_and_matches_the_table() {
    let t = Piecewise2D::new(&TABLE, W, H).unwrap();
    let mean = TABLE.iter().sum::<f64>() / (W * H) as f64;
    let mut integral = 0.0;
    for r in 0..H {
        for c in 0..W {
            let centre = Vec2::new((c as f32 + 0.5) / W as f32, (r as f32 + 0.5) / H as f32);
            let p = t.pdf(centre) as f64;
            assert!(
                (p - TABLE[r * W + c] / mean).abs() < 1e-5,
                "cell ({c}, {r})"
            );
            integral += p / (W * H) as f64;
        }
    }
    assert!((integral - 1.0).abs() < 1e-6, "{integral}");
    assert_eq!(t.pdf(Vec2::new(1.5, 0.5)), 0.0);
}

/// 200,000 samples: each returns the density `pdf` gives its point, none lands in a cell of
/// value 0, each is uniform within its cell (the share in a cell's first quarter per axis,
/// within 4 standard errors of 1/4), and the cell counts fit the table (chi-square over the 14 non-zero cells, alpha
/// 0.01; seeded, so the outcome is fixed).
#[test]
fn samples_follow_the_table() {
    let t = Piecewise2D::new(&TABLE, W, H).unwrap();
    let total: f64 = TABLE.iter().sum();
    let mut rng = Rng::new(21, 7);
    let n = 200_000;
    let mut counts = [0u64; W * H];
    // Within its cell a point is uniform: the share in the cell's first quarter, per axis.
    let mut quarter = [0u64; 2];
    for _ in 0..n {
        let (p, pdf) = t.sample(rng.next_2d());
        quarter[0] += ((p.x * W as f32).fract() < 0.25) as u64;
        quarter[1] += ((p.y * H as f32).fract() < 0.25) as u64;
        assert!(p.x >= 0.0 && p.x < 1.0 && p.y >= 0.0 && p.y < 1.0, "{p}");
        assert_eq!(pdf, t.pdf(p), "{p}");
        let cell = bin(p.y, H) * W + bin(p.x, W);
        assert!(TABLE[cell] > 0.0, "drew cell {cell} of value 0 at {p}");
        counts[cell] += 1;
    }
    let se = (0.25 * 0.75 / n as f64).sqrt();
    for q in quarter {
        let share = q as f64 / n as f64;
        assert!(
            (share - 0.25).abs() < 4.0 * se,
            "share in a cell's first quarter: {share}"
        );
    }
    let mut chi2 = 0.0;
    let mut dof = 0;
    for (c, v) in counts.iter().zip(TABLE) {
        if v > 0.0 {
            let e = n as f64 * v / total;
            chi2 += (*c as f64 - e).powi(2) / e;
            dof += 1;
        }
    }
    let p = 1.0 - ChiSquared::new((dof - 1) as f64).unwrap().cdf(chi2);
    assert!(p > 0.01, "chi-square {chi2} on {} dof: p = {p}", dof - 1);
}

/// Numbers at the ends of bins (0, the CDF's steps, just below 1) stay in cells of value > 0
/// with the density `pdf` gives them, on a table whose edges are 0.
#[test]
fn edges_of_bins_stay_in_their_cells() {
    let t = Piecewise2D::new(&TABLE, W, H).unwrap();
    let below_one = 1.0 - f32::EPSILON / 2.0;
    for ux in [0.0, 0.1, 0.2, 1.0 / 6.5, 0.5, 0.75, below_one] {
        for uy in [0.0, 0.25, 0.5, 0.7, below_one] {
            let (p, pdf) = t.sample(Vec2::new(ux, uy));
            assert!(pdf > 0.0 && pdf == t.pdf(p), "({ux}, {uy}) -> {p}: {pdf}");
        }
    }
}

#[test]
fn bad_tables_are_refused_by_name() {
    let e = Piecewise2D::new(&[0.0; 6], 3, 2).unwrap_err();
    assert!(e.contains("every value is 0"), "{e}");
    let e = Piecewise2D::new(&[1.0, -1.0, 1.0, 1.0], 2, 2).unwrap_err();
    assert!(e.contains("value -1 at column 1, row 0"), "{e}");
    let e = Piecewise2D::new(&[1.0, f64::NAN, 1.0, 1.0], 2, 2).unwrap_err();
    assert!(e.contains("NaN at column 1, row 0"), "{e}");
    let e = Piecewise2D::new(&[1.0; 5], 2, 2).unwrap_err();
    assert!(e.contains("not 2 x 2"), "{e}");
}

/// The mapping is Mitsuba's (up +y; u = 0 at -z, u = 1/4 at +x) and inverts; the
/// solid-angle density of a uniform (u, v) integrates to 1 over the sphere (mean of
/// 4 pi p(w) over uniform directions, 400,000 of them, within 4 standard errors).
#[test]
fn latlong_mapping_and_its_jacobian() {
    assert!((latlong_direction(Vec2::new(0.0, 0.5)) - Vec3::NEG_Z).length() < 1e-6);
    assert!((latlong_direction(Vec2::new(0.25, 0.5)) - Vec3::X).length() < 1e-6);
    assert!((latlong_direction(Vec2::new(0.3, 0.0)) - Vec3::Y).length() < 1e-6);
    let mut rng = Rng::new(5, 9);
    let (mut sum, mut sq) = (0.0f64, 0.0f64);
    let n = 400_000;
    for _ in 0..n {
        let uv = rng.next_2d();
        let d = latlong_direction(uv);
        let back = latlong_uv(d);
        assert!(
            (back - uv).abs().max_element() < 1e-4 || uv.y < 1e-3,
            "{uv} -> {back}"
        );
        let w = crate::sampling::warps::square_to_uniform_sphere(rng.next_2d());
        let v = 4.0 * std::f64::consts::PI * latlong_pdf_solid_angle(1.0, latlong_uv(w).y) as f64;
        sum += v;
        sq += v * v;
    }
    let mean = sum / n as f64;
    let se = ((sq / n as f64 - mean * mean) / n as f64).sqrt();
    assert!((mean - 1.0).abs() < 4.0 * se, "{mean} +- {se}");
}

#[test]
fn compensation_subtracts_the_mean_and_keeps_a_constant_table() {
    assert_eq!(compensated(&[1.0, 2.0, 3.0, 6.0]), vec![0.0, 0.0, 0.0, 3.0]);
    assert_eq!(compensated(&[2.0; 4]), vec![2.0; 4]);
    let t = Piecewise2D::new(&compensated(&TABLE), W, H).unwrap();
    // Only the cells above the mean can be drawn.
    let mean = TABLE.iter().sum::<f64>() / (W * H) as f64;
    let mut rng = Rng::new(2, 2);
    for _ in 0..10_000 {
        let (p, _) = t.sample(rng.next_2d());
        assert!(TABLE[bin(p.y, H) * W + bin(p.x, W)] > mean);
    }
}
