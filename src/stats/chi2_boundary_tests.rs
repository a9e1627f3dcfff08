//! Tests of the per-cell integration's second looks: the boundary pass that follows a
//! sliver's tip between the first pass's nodes, and the tolerance below which a rectangle is
//! not refined. Everything is deterministic; the exact cell masses come from clipping the
//! support polygon against each cell.

use super::*;
use crate::stats::domain::UnitSquare;
use glam::Vec2;
use std::cell::RefCell;

const N: usize = 8;

/// First pass: 2x2 start rectangles, 5x5 nodes each (spacing 1/64); the boundary pass
/// starts from 8x8 (spacing 1/256) and stops at the same finest scale.
fn config(boundary_split: usize) -> Integration {
    Integration {
        initial_split: 2,
        max_depth: 6,
        rel_tol: 1e-4,
        jump_ratio: 2.0,
        boundary_split,
        recheck_split: 0,
    }
}

/// Area of the convex polygon `poly` clipped to `[u0,u1] x [v0,v1]` (Sutherland-Hodgman).
fn clipped_area(poly: &[[f64; 2]], u: [f64; 2], v: [f64; 2]) -> f64 {
    let mut pts = poly.to_vec();
    // (axis, bound, keep the side >= bound when true)
    for (axis, bound, above) in [
        (0, u[0], true),
        (0, u[1], false),
        (1, v[0], true),
        (1, v[1], false),
    ] {
        let inside = |p: &[f64; 2]| {
            if above {
                p[axis] >= bound
            } else {
                p[axis] <= bound
            }
        };
        let mut out = Vec::new();
        for i in 0..pts.len() {
            let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
            if inside(&a) {
                out.push(a);
            }
            if inside(&a) != inside(&b) {
                let t = (bound - a[axis]) / (b[axis] - a[axis]);
                out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
            }
        }
        pts = out;
        if pts.is_empty() {
            return 0.0;
        }
    }
    let mut twice = 0.0;
    for i in 0..pts.len() {
        let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
        twice += a[0] * b[1] - b[0] * a[1];
    }
    0.5 * twice.abs()
}

fn inside_triangle(t: &[[f64; 2]; 3], p: [f64; 2]) -> bool {
    let side =
        |a: [f64; 2], b: [f64; 2]| (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
    let s = [side(t[0], t[1]), side(t[1], t[2]), side(t[2], t[0])];
    s.iter().all(|&x| x >= 0.0) || s.iter().all(|&x| x <= 0.0)
}

/// A wedge whose tip, at `tip` along the axis it points down, reaches into the first
/// column (or row) by 0.02: less than one first-pass node spacing, and 0.0075 off the
/// nearest node line across, so the first pass sees nothing of it there.
fn wedge(transposed: bool) -> [[f64; 2]; 3] {
    let c = 0.5 + 0.0075;
    let t = [[0.105, c], [0.98, c - 0.3], [0.98, c + 0.3]];
    if transposed {
        t.map(|[a, b]| [b, a])
    } else {
        t
    }
}

struct Run {
    grid: Grid,
    /// Every point the pdf was evaluated at.
    points: Vec<[f64; 2]>,
}

fn integrate(poly: [[f64; 2]; 3], density: f64, cfg: &Integration) -> Run {
    integrate_seen(poly, density, cfg, None)
}

fn integrate_seen(
    poly: [[f64; 2]; 3],
    density: f64,
    cfg: &Integration,
    observed: Option<&Grid>,
) -> Run {
    let points = RefCell::new(Vec::new());
    let pdf = |p: Vec2| {
        let p = [p.x as f64, p.y as f64];
        points.borrow_mut().push(p);
        if inside_triangle(&poly, p) {
            density
        } else {
            0.0
        }
    };
    let (grid, bad) = cell_integrals_seen(&UnitSquare { n: N }, pdf, cfg, observed);
    assert_eq!(bad, 0);
    Run {
        grid,
        points: points.into_inner(),
    }
}

fn cell_of(c: usize, r: usize) -> ([f64; 2], [f64; 2]) {
    let h = 1.0 / N as f64;
    (
        [c as f64 * h, (c + 1) as f64 * h],
        [r as f64 * h, (r + 1) as f64 * h],
    )
}

/// The smallest spacing between the distinct coordinates (`axis` 0: u, 1: v) of the
/// evaluations strictly inside cell (c, r): the finest scale the integration reached.
fn finest_spacing(points: &[[f64; 2]], c: usize, r: usize, axis: usize) -> f64 {
    let mut along: Vec<f64> = evaluations_in(points, c, r)
        .iter()
        .map(|p| p[axis])
        .collect();
    along.sort_by(f64::total_cmp);
    along.dedup();
    along
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(f64::INFINITY, f64::min)
}

/// Evaluations strictly inside cell (c, r) (nodes on its edges are shared with neighbours).
fn evaluations_in(points: &[[f64; 2]], c: usize, r: usize) -> Vec<[f64; 2]> {
    let (u, v) = cell_of(c, r);
    points
        .iter()
        .copied()
        .filter(|p| u[0] < p[0] && p[0] < u[1] && v[0] < p[1] && p[1] < v[1])
        .collect()
}

#[test]
fn boundary_pass_finds_a_tip_between_the_first_nodes() {
    for transposed in [false, true] {
        let poly = wedge(transposed);
        let area = clipped_area(&poly, [0.0, 1.0], [0.0, 1.0]);
        let density = 1.0 / area;
        let exact = |c: usize, r: usize| {
            let (u, v) = cell_of(c, r);
            clipped_area(&poly, u, v) * density
        };
        let (tc, tr) = if transposed { (4, 0) } else { (0, 4) };
        assert!(
            exact(tc, tr) > 3e-4,
            "the tip reaches into cell ({tc}, {tr})"
        );

        let plain = integrate(poly, density, &config(0));
        let looked = integrate(poly, density, &config(8));
        // The precondition that makes this a test: the first pass alone misses the tip.
        assert_eq!(plain.grid.get(tc, tr), 0.0, "transposed {transposed}");
        let got = looked.grid.get(tc, tr);
        assert!(
            (got - exact(tc, tr)).abs() < 0.05 * exact(tc, tr),
            "tip cell ({tc}, {tr}), transposed {transposed}: {got} vs {}",
            exact(tc, tr)
        );
        let (mut untouched, mut inside) = (0, 0);
        for r in 0..N {
            for c in 0..N {
                let (g, e) = (looked.grid.get(c, r), exact(c, r));
                assert!(
                    (g - e).abs() <= 2e-4 + 0.02 * e,
                    "cell ({c}, {r}), transposed {transposed}: {g} vs {e}"
                );
                // Cells whose whole neighbourhood the first pass found empty, or found
                // non-empty, are not looked at again: the same evaluations in both runs.
                let first = &plain.grid;
                let all: Vec<f64> = (r.saturating_sub(1)..=(r + 1).min(N - 1))
                    .flat_map(|rr| {
                        (c.saturating_sub(1)..=(c + 1).min(N - 1)).map(move |cc| first.get(cc, rr))
                    })
                    .collect();
                if all.iter().all(|&x| x == 0.0) || all.iter().all(|&x| x > 0.0) {
                    untouched += 1;
                    inside += usize::from(all[0] > 0.0);
                    assert_eq!(
                        evaluations_in(&plain.points, c, r),
                        evaluations_in(&looked.points, c, r),
                        "cell ({c}, {r}) was integrated again, transposed {transposed}"
                    );
                }
            }
        }
        assert!(
            untouched >= 20 && inside >= 4,
            "{untouched} cells checked, {inside} inside"
        );
        // The boundary pass starts finer but stops at the first pass's finest scale:
        // nodes 1/(cells * initial_split * 2^max_depth * 4) apart.
        let finest = finest_spacing(&looked.points, tc, tr, usize::from(transposed));
        assert_eq!(
            finest,
            1.0 / (N * 2 * 64 * 4) as f64,
            "transposed {transposed}"
        );
    }
}

/// A disk of radius 0.02 on the central node of a start rectangle of cell (3, 3).
fn disk_evaluations(density: f64, initial_split: usize) -> (usize, f64) {
    let (cx, cy) = (0.40625, 0.40625);
    let points = RefCell::new(Vec::new());
    let pdf = |p: Vec2| {
        let (x, y) = (p.x as f64, p.y as f64);
        points.borrow_mut().push([x, y]);
        if (x - cx).powi(2) + (y - cy).powi(2) <= 0.02f64.powi(2) {
            density
        } else {
            0.0
        }
    };
    let cfg = Integration {
        max_depth: 4,
        initial_split,
        ..config(0)
    };
    let (grid, _) = cell_integrals(&UnitSquare { n: N }, pdf, &cfg);
    let n = evaluations_in(&points.into_inner(), 3, 3).len();
    (n, grid.get(3, 3))
}

#[test]
fn rectangles_are_refined_down_to_a_billionth_of_the_total() {
    // The neglect threshold is 1e-9 spread over the cells: a start rectangle (1/16 of a
    // cell here, so 1/1024 of the domain) is refined at an edge when its peak density times
    // its area exceeds 1e-9 / 64 / 4, i.e. when the density exceeds 1e-9.
    let exact = |density: f64| density * std::f64::consts::PI * 0.02f64.powi(2);
    let (n_hi, got_hi) = disk_evaluations(2e-9, 2);
    let (n_lo, _) = disk_evaluations(0.5e-9, 2);
    // Below the threshold a cell costs its 2 x 2 start rectangles' 5 x 5 nodes, of which
    // 4 x 4 each lie inside the cell (a rectangle's nodes on the cell's middle lines are
    // its own, so they count twice).
    assert_eq!(n_lo, 64);
    assert!(
        n_hi > 200,
        "{n_hi} evaluations: the disk's rim was not refined"
    );
    assert!(
        (got_hi - exact(2e-9)).abs() < 0.02 * exact(2e-9),
        "{got_hi} vs {}",
        exact(2e-9)
    );
}

/// The threshold is a density whatever the start split: with 4 x 4 start rectangles (each
/// 1/16 the area) it is still 1e-9, so a disk at 1.5e-9 is refined and one at 0.5e-9 costs
/// only the start rectangles' nodes: along each axis 4 + 5 + 5 + 4 inside the cell (the
/// middle rectangles' nodes on both their sides), 18 x 18.
#[test]
fn the_neglect_threshold_does_not_depend_on_the_start_split() {
    let (n_lo, _) = disk_evaluations(0.5e-9, 4);
    assert_eq!(n_lo, 18 * 18);
    let (n_hi, _) = disk_evaluations(1.5e-9, 4);
    assert!(
        n_hi > 2 * 16 * 16,
        "{n_hi} evaluations: the disk's rim was not refined"
    );
}

/// A wedge so thin (half-width 0.03 at its base) that the first pass misses its last 0.22:
/// the two cells its tip crosses, (0, 4) and (1, 4), are both empty, and (0, 4) has no
/// non-empty neighbour. The boundary pass reaches it only by following the tip from (1, 4).
#[test]
fn the_boundary_pass_follows_a_tip_across_empty_cells() {
    let c = 0.5 + 0.0075;
    let poly = [[0.105, c], [0.98, c - 0.03], [0.98, c + 0.03]];
    let density = 1.0 / clipped_area(&poly, [0.0, 1.0], [0.0, 1.0]);
    let exact = |col: usize, row: usize| {
        let (u, v) = cell_of(col, row);
        clipped_area(&poly, u, v) * density
    };
    let plain = integrate(poly, density, &config(0));
    assert_eq!((plain.grid.get(0, 4), plain.grid.get(1, 4)), (0.0, 0.0));
    assert!(plain.grid.get(2, 4) > 0.0);
    let looked = integrate(poly, density, &config(8));
    // Found, though not exactly: the last 0.02 of the tip (under 0.0007 wide) still falls
    // between the boundary pass's nodes, 17 % of the far cell's small mass.
    for (col, tol) in [(0, 0.25), (1, 0.05)] {
        let (g, e) = (looked.grid.get(col, 4), exact(col, 4));
        assert!(
            g <= e * 1.01 && g > (1.0 - tol) * e,
            "cell ({col}, 4): {g} vs {e}"
        );
    }
}

/// Cells the first pass found empty but the sampler put samples in are integrated again
/// from `recheck_split` rectangles down to the same finest scale; cells without samples,
/// and cells with samples that are not empty, are not touched.
#[test]
fn observed_samples_recheck_empty_cells() {
    let poly = wedge(false);
    let density = 1.0 / clipped_area(&poly, [0.0, 1.0], [0.0, 1.0]);
    let exact = clipped_area(&poly, cell_of(0, 4).0, cell_of(0, 4).1) * density;
    let cfg = Integration {
        recheck_split: 16,
        ..config(0)
    };
    let mut seen = Grid::new(N, N);
    seen.data[4 * N] = 3.0; // the tip cell (0, 4)
    seen.data[4 * N + 5] = 7.0; // (5, 4), inside the wedge
    let plain = integrate(poly, density, &config(0));
    let looked = integrate_seen(poly, density, &cfg, Some(&seen));
    assert_eq!(plain.grid.get(0, 4), 0.0);
    let got = looked.grid.get(0, 4);
    assert!((got - exact).abs() < 0.05 * exact, "{got} vs {exact}");
    for r in 0..N {
        for c in 0..N {
            if (c, r) != (0, 4) {
                assert_eq!(
                    evaluations_in(&plain.points, c, r),
                    evaluations_in(&looked.points, c, r),
                    "cell ({c}, {r})"
                );
                assert_eq!(plain.grid.get(c, r), looked.grid.get(c, r));
            }
        }
    }
    // 16 x 16 start rectangles and max_depth 6 - 3 levels: the first pass's finest scale.
    let finest = finest_spacing(&looked.points, 0, 4, 0);
    assert_eq!(finest, 1.0 / (N * 2 * 64 * 4) as f64);
    // Without the samples (or with recheck off) the tip stays empty.
    let off = Integration {
        recheck_split: 1,
        ..cfg
    };
    assert_eq!(
        integrate_seen(poly, density, &off, Some(&seen))
            .grid
            .get(0, 4),
        0.0
    );
}
