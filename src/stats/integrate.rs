//! Integrating a pdf over one grid cell, accurately even where the pdf's support ends inside
//! the cell (a light's silhouette, a cone's rim).
//!
//! Quadtree adaptive Simpson: every rectangle is integrated with a 3x3 Simpson rule and with
//! four 3x3 rules on its quadrants; it is split again while the two disagree, or while its
//! nodes straddle an edge of the support (some zero, some not) or jump by more than
//! `jump_ratio`. Edges thus get resolved down to `cell / 2^max_depth` while smooth regions cost
//! 25 evaluations. A feature narrower than the initial node spacing can be missed entirely:
//! raise `initial_split` for pdfs with tiny support.

/// Knobs of the per-cell integration.
#[derive(Clone, Copy, Debug)]
pub struct Integration {
    /// Each cell starts as `initial_split x initial_split` rectangles (sub-sample count).
    pub initial_split: usize,
    /// Maximum number of quadtree refinements below a starting rectangle.
    pub max_depth: u32,
    /// Relative tolerance on a rectangle's integral.
    pub rel_tol: f64,
    /// Node values differing by more than this factor force refinement.
    pub jump_ratio: f64,
    /// Cells found empty but next to a non-empty cell are integrated again starting from
    /// `boundary_split x boundary_split` rectangles: the tip of a sliver (a grazing light's
    /// far corner) can pass between all nodes of the first pass. 0 (the default) disables
    /// this; `chi2cases` uses 8.
    pub boundary_split: usize,
    /// Cells that received samples but integrate to 0 are integrated again from
    /// `recheck_split x recheck_split` rectangles before their samples are called
    /// impossible (see `chi2::cell_integrals_seen`). 0 or 1 disables this.
    pub recheck_split: usize,
}

impl Default for Integration {
    fn default() -> Self {
        Integration {
            initial_split: 2,
            max_depth: 8,
            rel_tol: 1e-4,
            jump_ratio: 2.0,
            boundary_split: 0,
            recheck_split: 64,
        }
    }
}

impl Integration {
    /// A second look starting from `split x split` rectangles that refines to the same finest
    /// scale as the first.
    pub fn finer(&self, split: usize) -> Integration {
        let levels = (split as f64 / self.initial_split.max(1) as f64)
            .log2()
            .floor() as u32;
        Integration {
            initial_split: split,
            max_depth: self.max_depth.saturating_sub(levels),
            ..*self
        }
    }
}

/// Simpson weights of a 3x3 grid, times 36.
const W3: [f64; 3] = [1.0, 4.0, 1.0];

pub(super) fn simpson3(f: &[[f64; 3]; 3], area: f64) -> f64 {
    let mut s = 0.0;
    for (j, row) in f.iter().enumerate() {
        for (i, x) in row.iter().enumerate() {
            s += W3[j] * W3[i] * x;
        }
    }
    s * area / 36.0
}

/// Integrates `f` over `[u0,u1] x [v0,v1]`. `abs_tol` is the error that no longer matters
/// (rectangles whose whole integral is below it are never refined).
pub fn integrate_rect(
    f: &mut impl FnMut(f64, f64) -> f64,
    u: [f64; 2],
    v: [f64; 2],
    cfg: &Integration,
    abs_tol: f64,
) -> f64 {
    let n = cfg.initial_split.max(1);
    let (du, dv) = ((u[1] - u[0]) / n as f64, (v[1] - v[0]) / n as f64);
    let tol = abs_tol / (n * n) as f64;
    let mut total = 0.0;
    for j in 0..n {
        for i in 0..n {
            let (a, b) = (u[0] + i as f64 * du, v[0] + j as f64 * dv);
            let mut g = [[0.0; 3]; 3];
            for (jj, row) in g.iter_mut().enumerate() {
                for (ii, x) in row.iter_mut().enumerate() {
                    *x = f(a + 0.5 * du * ii as f64, b + 0.5 * dv * jj as f64);
                }
            }
            total += refine(f, [a, a + du], [b, b + dv], g, cfg, tol, cfg.max_depth);
        }
    }
    total
}

/// Whether the nodes suggest an edge or a steep jump that Simpson cannot see as an error.
pub(super) fn looks_discontinuous(nodes: &[[f64; 5]; 5], jump_ratio: f64) -> bool {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for &x in nodes.iter().flatten() {
        lo = lo.min(x);
        hi = hi.max(x);
    }
    hi > 0.0 && (lo <= 0.0 || hi > jump_ratio * lo)
}

pub(super) fn trapezoid5(h: &[[f64; 5]; 5], area: f64) -> f64 {
    const W: [f64; 5] = [1.0, 2.0, 2.0, 2.0, 1.0];
    let mut s = 0.0;
    for (j, row) in h.iter().enumerate() {
        for (i, x) in row.iter().enumerate() {
            s += W[j] * W[i] * x;
        }
    }
    s * area / 64.0
}

/// The four 3x3 node grids of a 5x5 grid's quadrants: (0, 0), (1, 0), (0, 1), (1, 1).
pub(super) fn quadrants(h: &[[f64; 5]; 5]) -> [[[f64; 3]; 3]; 4] {
    let quad = |qi: usize, qj: usize| {
        let mut q = [[0.0; 3]; 3];
        for (j, row) in q.iter_mut().enumerate() {
            for (i, x) in row.iter_mut().enumerate() {
                *x = h[2 * qj + j][2 * qi + i];
            }
        }
        q
    };
    [quad(0, 0), quad(1, 0), quad(0, 1), quad(1, 1)]
}

fn refine(
    f: &mut impl FnMut(f64, f64) -> f64,
    u: [f64; 2],
    v: [f64; 2],
    g: [[f64; 3]; 3],
    cfg: &Integration,
    abs_tol: f64,
    depth: u32,
) -> f64 {
    let area = (u[1] - u[0]) * (v[1] - v[0]);
    let coarse = simpson3(&g, area);
    // 5x5 nodes: the known 3x3 at even indices, 16 new ones in between.
    let mut h = [[0.0; 5]; 5];
    let (du, dv) = ((u[1] - u[0]) / 4.0, (v[1] - v[0]) / 4.0);
    for (j, row) in h.iter_mut().enumerate() {
        for (i, x) in row.iter_mut().enumerate() {
            *x = if i % 2 == 0 && j % 2 == 0 {
                g[j / 2][i / 2]
            } else {
                f(u[0] + du * i as f64, v[0] + dv * j as f64)
            };
        }
    }
    let quads = quadrants(&h);
    let fine: f64 = quads.iter().map(|q| simpson3(q, area / 4.0)).sum();

    let peak = h.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs())) * area;
    let err = (fine - coarse).abs();
    let inaccurate = err > abs_tol.max(cfg.rel_tol * fine.abs());
    let edgy = peak > abs_tol && looks_discontinuous(&h, cfg.jump_ratio);
    if !(inaccurate || edgy) {
        return fine;
    }
    if depth == 0 {
        // At a jump Simpson's 4:2 node weights can misplace up to a third of the leaf;
        // the trapezoid rule's equal interior weights bound that to an eighth.
        return if edgy && inaccurate {
            trapezoid5(&h, area)
        } else {
            fine
        };
    }
    let (um, vm) = (0.5 * (u[0] + u[1]), 0.5 * (v[0] + v[1]));
    let us = [[u[0], um], [um, u[1]]];
    let vs = [[v[0], vm], [vm, v[1]]];
    let mut total = 0.0;
    for (k, q) in quads.into_iter().enumerate() {
        let (qi, qj) = (k % 2, k / 2);
        total += refine(f, us[qi], vs[qj], q, cfg, abs_tol / 4.0, depth - 1);
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smooth_polynomial_exact() {
        // Simpson is exact for cubics in each variable.
        let mut f = |u: f64, v: f64| 1.0 + u * u * u - 2.0 * v * v + u * v;
        let got = integrate_rect(
            &mut f,
            [0.0, 2.0],
            [0.0, 1.0],
            &Integration::default(),
            1e-12,
        );
        let exact = 2.0 + 4.0 - 2.0 * 2.0 / 3.0 + 1.0;
        assert!((got - exact).abs() < 1e-12, "{got} vs {exact}");
    }

    #[test]
    fn disk_indicator_edge() {
        // Indicator of the disk of radius 0.4 centred in the unit square: area 0.16 pi.
        let mut evals = 0usize;
        let mut f = |u: f64, v: f64| {
            evals += 1;
            let (x, y) = (u - 0.5, v - 0.5);
            if x * x + y * y <= 0.16 {
                1.0
            } else {
                0.0
            }
        };
        let cfg = Integration {
            max_depth: 8,
            ..Integration::default()
        };
        let got = integrate_rect(&mut f, [0.0, 1.0], [0.0, 1.0], &cfg, 1e-9);
        let exact = 0.16 * std::f64::consts::PI;
        assert!((got - exact).abs() < 2e-3 * exact, "{got} vs {exact}");
        // Refinement stays near the rim instead of covering the whole square.
        assert!(evals < 200_000, "{evals} evaluations");
    }

    /// Refinement is forced by an edge (a node at 0 beside positive ones) or a jump beyond
    /// the ratio, never by constant or all-zero nodes.
    #[test]
    fn discontinuity_rule() {
        let with = |lo: f64, hi: f64| {
            let mut n = [[hi; 5]; 5];
            n[2][3] = lo;
            n
        };
        assert!(!looks_discontinuous(&[[0.0; 5]; 5], 2.0));
        assert!(!looks_discontinuous(&[[0.7; 5]; 5], 2.0));
        assert!(looks_discontinuous(&with(0.0, 1.0), 2.0));
        assert!(looks_discontinuous(&with(1.0, 3.0), 2.0));
        assert!(!looks_discontinuous(&with(1.0, 1.5), 2.0));
        assert!(!looks_discontinuous(&with(1.0, 2.0), 2.0));
    }
}
