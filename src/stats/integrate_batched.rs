//! [`super::integrate::integrate_rect`] over many rectangles at once, with the integrand
//! evaluated one batch per refinement level instead of one call per node.
//!
//! A pdf behind a pipe or a file (a sampler written in another language) answers a few large
//! batches quickly and a million single queries slowly. The refinement is breadth-first: all
//! rectangles of one level send their new nodes together, and each makes the decision the
//! recursive integrator makes (Simpson against its quadrants, the edge and jump rules, the
//! trapezoid fallback at the last level), so both integrate to the same values up to the
//! order of summation.

use super::integrate::{looks_discontinuous, quadrants, simpson3, trapezoid5, Integration};
use super::Grid;

/// A rectangle waiting for its 16 refinement nodes.
struct Pending {
    u: [f64; 2],
    v: [f64; 2],
    g: [[f64; 3]; 3],
    tol: f64,
    depth: u32,
    /// The rectangle of the caller's list whose integral it adds to.
    owner: usize,
}

/// The integral of `f` over each rectangle `(u, v)` of `rects`, as `integrate_rect` with the
/// same `cfg` and `abs_tol` gives it; `f` receives the points of one level at a time and
/// returns their values in order.
pub fn integrate_rects_batched(
    rects: &[([f64; 2], [f64; 2])],
    f: &mut dyn FnMut(&[[f64; 2]]) -> Vec<f64>,
    cfg: &Integration,
    abs_tol: f64,
) -> Vec<f64> {
    let n = cfg.initial_split.max(1);
    let tol = abs_tol / (n * n) as f64;
    let mut totals = vec![0.0; rects.len()];
    // The starting rectangles and their 3x3 nodes, in one batch.
    let mut starts = Vec::new();
    let mut points = Vec::new();
    for (owner, &(u, v)) in rects.iter().enumerate() {
        let (du, dv) = ((u[1] - u[0]) / n as f64, (v[1] - v[0]) / n as f64);
        for j in 0..n {
            for i in 0..n {
                let (a, b) = (u[0] + i as f64 * du, v[0] + j as f64 * dv);
                for jj in 0..3 {
                    for ii in 0..3 {
                        points.push([a + 0.5 * du * ii as f64, b + 0.5 * dv * jj as f64]);
                    }
                }
                starts.push(([a, a + du], [b, b + dv], owner));
            }
        }
    }
    let values = evaluate(f, &points);
    let mut level: Vec<Pending> = starts
        .into_iter()
        .enumerate()
        .map(|(k, (u, v, owner))| {
            let mut g = [[0.0; 3]; 3];
            for (jj, row) in g.iter_mut().enumerate() {
                for (ii, x) in row.iter_mut().enumerate() {
                    *x = values[9 * k + 3 * jj + ii];
                }
            }
            Pending {
                u,
                v,
                g,
                tol,
                depth: cfg.max_depth,
                owner,
            }
        })
        .collect();
    while !level.is_empty() {
        // Every rectangle's 16 new nodes (the 5x5 grid minus the known 3x3), one batch.
        let mut points = Vec::with_capacity(16 * level.len());
        for p in &level {
            let (du, dv) = ((p.u[1] - p.u[0]) / 4.0, (p.v[1] - p.v[0]) / 4.0);
            for j in 0..5 {
                for i in 0..5 {
                    if i % 2 == 1 || j % 2 == 1 {
                        points.push([p.u[0] + du * i as f64, p.v[0] + dv * j as f64]);
                    }
                }
            }
        }
        let values = evaluate(f, &points);
        let mut next = Vec::new();
        for (k, p) in level.into_iter().enumerate() {
            let mut h = [[0.0; 5]; 5];
            let mut fresh = values[16 * k..16 * (k + 1)].iter();
            for (j, row) in h.iter_mut().enumerate() {
                for (i, x) in row.iter_mut().enumerate() {
                    *x = if i % 2 == 0 && j % 2 == 0 {
                        p.g[j / 2][i / 2]
                    } else {
                        *fresh.next().expect("16 new nodes")
                    };
                }
            }
            match step(&p, &h, cfg) {
                Step::Done(x) => totals[p.owner] += x,
                Step::Split(quads) => {
                    let (um, vm) = (0.5 * (p.u[0] + p.u[1]), 0.5 * (p.v[0] + p.v[1]));
                    let us = [[p.u[0], um], [um, p.u[1]]];
                    let vs = [[p.v[0], vm], [vm, p.v[1]]];
                    for (q, g) in quads.into_iter().enumerate() {
                        next.push(Pending {
                            u: us[q % 2],
                            v: vs[q / 2],
                            g,
                            tol: p.tol / 4.0,
                            depth: p.depth - 1,
                            owner: p.owner,
                        });
                    }
                }
            }
        }
        level = next;
    }
    totals
}

/// The first second look of [`crate::stats::chi2::cell_integrals_seen`], batched: cells on
/// the support's boundary again from `cfg.boundary_split` rectangles, in rounds, each round
/// also taking the neighbours of cells found non-empty, so a sliver's tip is followed.
/// `rect(c, r)` is cell (c, r)'s parameter rectangle.
pub fn boundary_pass_batched(
    grid: &mut Grid,
    rect: &impl Fn(usize, usize) -> ([f64; 2], [f64; 2]),
    f: &mut dyn FnMut(&[[f64; 2]]) -> Vec<f64>,
    cfg: &Integration,
    abs_tol: f64,
) {
    if cfg.boundary_split <= cfg.initial_split.max(1) {
        return;
    }
    let cols = grid.cols;
    let fine = cfg.finer(cfg.boundary_split);
    let mut done = vec![false; grid.data.len()];
    let mut todo = grid.boundary_cells();
    while !todo.is_empty() {
        let cells: Vec<(usize, usize)> = todo
            .drain(..)
            .filter(|&(c, r)| !std::mem::replace(&mut done[r * cols + c], true))
            .collect();
        let rects: Vec<_> = cells.iter().map(|&(c, r)| rect(c, r)).collect();
        let now = integrate_rects_batched(&rects, f, &fine, abs_tol);
        for (&(c, r), x) in cells.iter().zip(now) {
            let was = std::mem::replace(&mut grid.data[r * cols + c], x);
            if was == 0.0 && x > 0.0 {
                todo.extend(
                    grid.neighbours(c, r)
                        .filter(|&(cc, rr)| !done[rr * cols + cc]),
                );
            }
        }
    }
}

/// The second one: cells that received samples (`seen`) but integrate to 0, again from
/// `cfg.recheck_split` rectangles, in one batch.
pub fn recheck_batched(
    grid: &mut Grid,
    rect: &impl Fn(usize, usize) -> ([f64; 2], [f64; 2]),
    f: &mut dyn FnMut(&[[f64; 2]]) -> Vec<f64>,
    cfg: &Integration,
    abs_tol: f64,
    seen: &Grid,
) {
    if cfg.recheck_split <= 1 {
        return;
    }
    let cols = grid.cols;
    let cells: Vec<(usize, usize)> = (0..grid.rows)
        .flat_map(|r| (0..cols).map(move |c| (c, r)))
        .filter(|&(c, r)| grid.get(c, r) == 0.0 && seen.get(c, r) > 0.0)
        .collect();
    let rects: Vec<_> = cells.iter().map(|&(c, r)| rect(c, r)).collect();
    let now = integrate_rects_batched(&rects, f, &cfg.finer(cfg.recheck_split), abs_tol);
    for (&(c, r), x) in cells.iter().zip(now) {
        grid.data[r * cols + c] = x;
    }
}

/// The integral of `f` over each rectangle by a fixed `(n + 1) x (n + 1)`-node trapezoid
/// rule, in one batch: what Mitsuba's `ChiSquareTest` does with `ires = n`, kept to show
/// what adaptive integration changes (`check-sampler --ires`).
pub fn integrate_rects_trapezoid(
    rects: &[([f64; 2], [f64; 2])],
    f: &mut dyn FnMut(&[[f64; 2]]) -> Vec<f64>,
    n: usize,
) -> Vec<f64> {
    let n = n.max(1);
    let mut points = Vec::with_capacity(rects.len() * (n + 1) * (n + 1));
    for (u, v) in rects {
        for j in 0..=n {
            for i in 0..=n {
                let (a, b) = (i as f64 / n as f64, j as f64 / n as f64);
                points.push([u[0] + a * (u[1] - u[0]), v[0] + b * (v[1] - v[0])]);
            }
        }
    }
    let values = evaluate(f, &points);
    let w = |i: usize| if i == 0 || i == n { 0.5 } else { 1.0 };
    rects
        .iter()
        .zip(values.chunks_exact((n + 1) * (n + 1)))
        .map(|((u, v), vals)| {
            let area = (u[1] - u[0]) * (v[1] - v[0]);
            let sum: f64 = vals
                .iter()
                .enumerate()
                .map(|(k, x)| w(k % (n + 1)) * w(k / (n + 1)) * x)
                .sum();
            sum * area / (n * n) as f64
        })
        .collect()
}

fn evaluate(f: &mut dyn FnMut(&[[f64; 2]]) -> Vec<f64>, points: &[[f64; 2]]) -> Vec<f64> {
    if points.is_empty() {
        return Vec::new();
    }
    let v = f(points);
    assert_eq!(v.len(), points.len(), "one value per point");
    v
}

// One value per rectangle on the stack, never stored: boxing would only add an allocation.
#[allow(clippy::large_enum_variant)]
enum Step {
    Done(f64),
    Split([[[f64; 3]; 3]; 4]),
}

/// The recursive integrator's decision for one rectangle with its 5x5 nodes `h`.
fn step(p: &Pending, h: &[[f64; 5]; 5], cfg: &Integration) -> Step {
    let area = (p.u[1] - p.u[0]) * (p.v[1] - p.v[0]);
    let coarse = simpson3(&p.g, area);
    let quads = quadrants(h);
    let fine: f64 = quads.iter().map(|q| simpson3(q, area / 4.0)).sum();
    let peak = h.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs())) * area;
    let inaccurate = (fine - coarse).abs() > p.tol.max(cfg.rel_tol * fine.abs());
    let edgy = peak > p.tol && looks_discontinuous(h, cfg.jump_ratio);
    if !(inaccurate || edgy) {
        return Step::Done(fine);
    }
    if p.depth == 0 {
        return Step::Done(if edgy && inaccurate {
            trapezoid5(h, area)
        } else {
            fine
        });
    }
    Step::Split(quads)
}

#[cfg(test)]
mod tests {
    use super::super::integrate::integrate_rect;
    use super::*;

    fn cells(k: usize) -> Vec<([f64; 2], [f64; 2])> {
        let s = 1.0 / k as f64;
        (0..k * k)
            .map(|c| {
                let (i, j) = ((c % k) as f64, (c / k) as f64);
                ([i * s, (i + 1.0) * s], [j * s, (j + 1.0) * s])
            })
            .collect()
    }

    /// Edges (a disk's rim), a jump, a smooth peak: the batched integrals equal the recursive
    /// ones cell by cell (to 1e-12 of the cell's value: only the order of summation differs),
    /// in at most max_depth + 2 batches.
    #[test]
    fn batched_integrals_equal_the_recursive_ones() {
        let disk = |u: f64, v: f64| {
            let (x, y) = (u - 0.5, v - 0.45);
            if x * x + y * y <= 0.1 {
                1.0
            } else {
                0.0
            }
        };
        let jump = |u: f64, v: f64| if u + 0.3 * v > 0.61 { 3.0 } else { 0.5 };
        let peak = |u: f64, v: f64| 1.0 / (1e-3 + (u - 0.3).powi(2) + (v - 0.7).powi(2));
        let cfg = Integration::default();
        for (name, f) in [
            ("disk", &disk as &dyn Fn(f64, f64) -> f64),
            ("jump", &jump),
            ("peak", &peak),
        ] {
            let rects = cells(7);
            let mut batches = 0;
            let mut calls = 0usize;
            let got = integrate_rects_batched(
                &rects,
                &mut |pts| {
                    batches += 1;
                    calls += pts.len();
                    pts.iter().map(|p| f(p[0], p[1])).collect()
                },
                &cfg,
                1e-9,
            );
            let mut single = 0usize;
            for (k, &(u, v)) in rects.iter().enumerate() {
                let mut g = |a: f64, b: f64| {
                    single += 1;
                    f(a, b)
                };
                let want = integrate_rect(&mut g, u, v, &cfg, 1e-9);
                assert!(
                    (got[k] - want).abs() <= 1e-12 * want.abs().max(1e-300),
                    "{name} cell {k}: {} vs {want}",
                    got[k]
                );
            }
            assert_eq!(calls, single, "{name}: the same nodes");
            assert!(
                batches <= cfg.max_depth as usize + 2,
                "{name}: {batches} batches"
            );
        }
    }

    /// A thin wedge whose tip passes between the first pass's nodes, and samples seen where
    /// the wedge is thinnest: the batched second looks give the recursive ones' masses.
    #[test]
    fn boundary_pass_and_recheck_equal_the_recursive_ones() {
        use crate::stats::chi2::cell_integrals_seen;
        use crate::stats::UnitSquare;
        use glam::Vec2;
        // Between v = 0.3 and v = 0.3 + 0.08 u^3: wide enough at u = 1 for the first pass,
        // a tip thinner than its node spacing towards u = 0.
        let wedge = |u: f64, v: f64| {
            let (lo, hi) = (0.3, 0.3 + 0.08 * u * u * u);
            if v >= lo && v <= hi {
                1.0
            } else {
                0.0
            }
        };
        let d = UnitSquare { n: 9 };
        let cfg = Integration {
            boundary_split: 8,
            ..Integration::default()
        };
        let mut seen = Grid::new(9, 9);
        seen.data[2 * 9] = 3.0;
        let pdf = |p: Vec2| wedge(p.x as f64, p.y as f64);
        let (want, _) = cell_integrals_seen(&d, pdf, &cfg, Some(&seen));
        let rects = cells(9);
        // The domain hands the pdf f32 points: round the nodes alike.
        let r32 = |x: f64| x as f32 as f64;
        let mut f = |pts: &[[f64; 2]]| pts.iter().map(|p| wedge(r32(p[0]), r32(p[1]))).collect();
        let abs_tol = 1e-9 / 81.0;
        let mut got = Grid {
            cols: 9,
            rows: 9,
            data: integrate_rects_batched(&rects, &mut f, &cfg, abs_tol),
        };
        let first = got.data.clone();
        let rect = |c: usize, r: usize| rects[r * 9 + c];
        boundary_pass_batched(&mut got, &rect, &mut f, &cfg, abs_tol);
        assert_ne!(
            first, got.data,
            "the first pass alone already had the wedge"
        );
        recheck_batched(&mut got, &rect, &mut f, &cfg, abs_tol, &seen);
        for (k, (a, b)) in got.data.iter().zip(&want.data).enumerate() {
            assert!(
                (a - b).abs() <= 1e-12 * b.abs().max(1e-300),
                "cell {k}: {a} vs {b}"
            );
        }
        assert!(want.sum() > 0.0);
    }

    /// The fixed trapezoid is exact for bilinear integrands and has the error an edge gives
    /// it: on a disk's rim it is off by far more than the adaptive rule.
    #[test]
    fn fixed_trapezoid_is_exact_for_bilinear_and_coarse_on_edges() {
        let rects = cells(3);
        let mut bilinear = |p: &[[f64; 2]]| p.iter().map(|q| 1.0 + q[0] * q[1]).collect();
        let got = integrate_rects_trapezoid(&rects, &mut bilinear, 4);
        for ((u, v), x) in rects.iter().zip(&got) {
            let exact = (u[1] - u[0]) * (v[1] - v[0])
                + (u[1] * u[1] - u[0] * u[0]) * (v[1] * v[1] - v[0] * v[0]) / 4.0;
            assert!((x - exact).abs() < 1e-14, "{x} vs {exact}");
        }
        let rim = |p: &[[f64; 2]]| {
            p.iter()
                .map(|q| ((q[0] - 0.5).powi(2) + (q[1] - 0.5).powi(2) <= 0.1) as u8 as f64)
                .collect::<Vec<_>>()
        };
        let area = std::f64::consts::PI * 0.1;
        let fixed: f64 = integrate_rects_trapezoid(&cells(7), &mut |p| rim(p), 4)
            .iter()
            .sum();
        let cfg = Integration::default();
        let adaptive: f64 = integrate_rects_batched(&cells(7), &mut |p| rim(p), &cfg, 1e-12)
            .iter()
            .sum();
        assert!(
            (adaptive - area).abs() < 1e-4,
            "adaptive {adaptive} vs {area}"
        );
        assert!(
            (fixed - area).abs() > 10.0 * (adaptive - area).abs(),
            "fixed {fixed}"
        );
    }
}
