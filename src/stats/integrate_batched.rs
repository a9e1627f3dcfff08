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
}
