//! Test-only integration and goodness-of-fit over the sphere, with a parametrisation that
//! zooms on a lobe: polar angle theta around `axis` is 2 atan(width * t / (1 - t)) for t in
//! [0, 1), so a lobe of angular width ~`width` (down to roughness 1e-3) spans many cells,
//! while t -> 1 still reaches the antipode. An optional linear stretch of the tangent plane
//! (direction = normalize(A v), dω = det A / |A v|^3 dω_v) follows lobes that grazing
//! reflection flattens. The map is plain geometry, independent of the code under test, so
//! integrals of pdfs through it are independent checks of their normalisation. Cells are
//! refined adaptively (4x4 midpoints vs 8x8) so jumps such as the horizon cost little.

use crate::rng::Rng;
use glam::{DVec3, Vec3};
use statrs::distribution::{ChiSquared, ContinuousCDF};
use std::f64::consts::PI;

#[derive(Clone, Copy, Debug)]
pub struct LobeGrid {
    s: DVec3,
    t: DVec3,
    n: DVec3,
    width: f64,
    /// Stretch of the s and t tangent axes.
    stretch: (f64, f64),
    /// The t reached at grid coordinate 1/2: with axis z, the horizon's t, so that no cell
    /// straddles the jump many pdfs have there.
    t_half: f64,
}

impl LobeGrid {
    pub fn new(axis: Vec3, width: f64) -> Self {
        let n = axis.as_dvec3().normalize();
        let f = crate::math::Frame::from_normal(n.as_vec3());
        LobeGrid {
            s: f.s.as_dvec3(),
            t: f.t.as_dvec3(),
            n,
            width,
            stretch: (1.0, 1.0),
            t_half: 0.5,
        }
    }

    /// Around the normal (z), with the horizon on a cell boundary.
    pub fn around_normal(width: f64) -> Self {
        LobeGrid {
            t_half: 1.0 / (1.0 + width),
            ..Self::new(Vec3::Z, width)
        }
    }

    /// Around the mirror direction of `wi` (local frame, z = normal), squeezed by `perp`
    /// across the plane of incidence: a facet tilted by d across that plane turns the
    /// reflection by only 2 d cos(theta_i), so grazing lobes are flat.
    pub fn around_reflection(wi: Vec3, width: f64, perp: f64) -> Self {
        let n = DVec3::new(-wi.x as f64, -wi.y as f64, wi.z as f64).normalize();
        let c = DVec3::Z.cross(n);
        let t = if c.length() > 1e-9 {
            c.normalize()
        } else {
            DVec3::Y
        };
        LobeGrid {
            s: t.cross(n),
            t,
            n,
            width,
            stretch: (1.0, perp),
            t_half: 0.5,
        }
    }

    /// Direction at grid coordinates (tau, phi) and the solid-angle Jacobian dω/(dtau dphi).
    pub fn point(&self, tau: f64, phi: f64) -> (Vec3, f64) {
        let (t, dt_dtau) = if tau < 0.5 {
            (2.0 * tau * self.t_half, 2.0 * self.t_half)
        } else {
            let k = 2.0 * (1.0 - self.t_half);
            (self.t_half + (tau - 0.5) * k, k)
        };
        let w = self.width;
        let q = t / (1.0 - t);
        let theta = 2.0 * (w * q).atan();
        let dtheta_dt = 2.0 * w / ((1.0 - t) * (1.0 - t) + w * w * t * t);
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        let (sx, sy) = self.stretch;
        let a = DVec3::new(sx * st * cp, sy * st * sp, ct);
        let len = a.length();
        let d = (self.s * a.x + self.t * a.y + self.n * a.z) / len;
        let jac = st * dtheta_dt * dt_dtau * sx * sy / (len * len * len);
        (d.as_vec3(), jac)
    }

    /// Inverse of `point`: grid coordinates of a direction.
    pub fn coords(&self, d: Vec3) -> (f64, f64) {
        let d = d.as_dvec3();
        let (sx, sy) = self.stretch;
        let v = DVec3::new(d.dot(self.s) / sx, d.dot(self.t) / sy, d.dot(self.n));
        let theta = (v.x * v.x + v.y * v.y).sqrt().atan2(v.z);
        let q = (0.5 * theta).tan() / self.width;
        let t = if q.is_finite() { q / (1.0 + q) } else { 1.0 };
        let tau = if t < self.t_half {
            0.5 * t / self.t_half
        } else {
            0.5 + 0.5 * (t - self.t_half) / (1.0 - self.t_half)
        };
        let phi = v.y.atan2(v.x).rem_euclid(2.0 * PI);
        (tau, phi)
    }

    /// ∫ f dω over the whole sphere: 16 x 32 base cells refined adaptively (depth 7, so a
    /// jump along a curve leaves an error of order 1e-4 of the jump's neighbourhood).
    pub fn integrate(&self, f: impl Fn(Vec3) -> f64) -> f64 {
        self.integrate_n(|d| [f(d)])[0]
    }

    /// Several integrals in one pass (refinement driven by the largest disagreement).
    pub fn integrate_n<const K: usize>(&self, f: impl Fn(Vec3) -> [f64; K]) -> [f64; K] {
        let (nt, np) = (16, 32);
        let mut sum = [0.0; K];
        for i in 0..nt {
            for j in 0..np {
                let c = self.cell(
                    [i as f64 / nt as f64, (i + 1) as f64 / nt as f64],
                    [j, j + 1].map(|j| j as f64 / np as f64 * 2.0 * PI),
                    &f,
                    1e-7,
                    7,
                    false,
                );
                for k in 0..K {
                    sum[k] += c[k];
                }
            }
        }
        sum
    }

    /// Adaptive integral over one (tau, phi) cell, to about `tol` absolute.
    pub fn cell<const K: usize>(
        &self,
        tr: [f64; 2],
        pr: [f64; 2],
        f: &impl Fn(Vec3) -> [f64; K],
        tol: f64,
        depth: u32,
        probe_edges: bool,
    ) -> [f64; K] {
        let coarse = self.midpoints(tr, pr, 4, f);
        let (tm, pm) = (0.5 * (tr[0] + tr[1]), 0.5 * (pr[0] + pr[1]));
        let quads = [
            ([tr[0], tm], [pr[0], pm]),
            ([tm, tr[1]], [pr[0], pm]),
            ([tr[0], tm], [pm, pr[1]]),
            ([tm, tr[1]], [pm, pr[1]]),
        ];
        let parts = quads.map(|(t, p)| self.midpoints(t, p, 4, f));
        let mut fine = [0.0; K];
        for p in &parts {
            for k in 0..K {
                fine[k] += p[k];
            }
        }
        let err = (0..K)
            .map(|k| (fine[k] - coarse[k]).abs())
            .fold(0.0, f64::max);
        // A cell whose midpoints all miss the support may still hold a sliver of it along an
        // edge (the horizon): probe the edges before believing the zero.
        let sliver = probe_edges && fine.iter().all(|&v| v == 0.0) && self.edges_nonzero(tr, pr, f);
        if depth == 0 || (err <= tol && !sliver) {
            return fine;
        }
        let mut sum = [0.0; K];
        for (t, p) in quads {
            let c = self.cell(t, p, f, 0.5 * tol, depth - 1, probe_edges);
            for k in 0..K {
                sum[k] += c[k];
            }
        }
        sum
    }

    fn edges_nonzero<const K: usize>(
        &self,
        tr: [f64; 2],
        pr: [f64; 2],
        f: &impl Fn(Vec3) -> [f64; K],
    ) -> bool {
        let n = 8;
        (0..=n).any(|i| {
            let a = i as f64 / n as f64;
            let t = tr[0] + a * (tr[1] - tr[0]);
            let p = pr[0] + a * (pr[1] - pr[0]);
            [(t, pr[0]), (t, pr[1]), (tr[0], p), (tr[1], p)]
                .iter()
                .any(|&(t, p)| {
                    f(self.point(t.min(1.0 - 1e-12), p).0)
                        .iter()
                        .any(|&v| v != 0.0)
                })
        })
    }

    fn midpoints<const K: usize>(
        &self,
        tr: [f64; 2],
        pr: [f64; 2],
        n: usize,
        f: &impl Fn(Vec3) -> [f64; K],
    ) -> [f64; K] {
        let (dt, dp) = ((tr[1] - tr[0]) / n as f64, (pr[1] - pr[0]) / n as f64);
        let mut sum = [0.0; K];
        for i in 0..n {
            for j in 0..n {
                let (d, jac) =
                    self.point(tr[0] + (i as f64 + 0.5) * dt, pr[0] + (j as f64 + 0.5) * dp);
                let v = f(d);
                for k in 0..K {
                    if v[k] != 0.0 {
                        sum[k] += v[k] * jac * dt * dp;
                    }
                }
            }
        }
        sum
    }
}

/// Outcome of a chi-square test of a sampler against its claimed pdf.
#[derive(Debug)]
pub struct Chi2 {
    pub p_value: f64,
    #[allow(dead_code)] // read through Debug in failure messages
    pub statistic: f64,
    #[allow(dead_code)]
    pub dof: usize,
    /// Samples the sampler produced (others were rejected) and the pdf's total mass times n.
    pub produced: usize,
    pub expected_total: f64,
    /// Draws in cells where the pdf integrates to zero (beyond a trace of 1e-5 n).
    pub in_empty_cells: f64,
}

impl Chi2 {
    /// |success rate - pdf mass| within 5 binomial standard errors plus `quad` for the
    /// quadrature of the expected counts, and no draws where the pdf has no mass.
    pub fn mass_agrees(&self, n: usize, quad: f64) -> bool {
        let p = self.produced as f64 / n as f64;
        let se = (p * (1.0 - p) / n as f64).sqrt();
        (p - self.expected_total / n as f64).abs() < 5.0 * se + quad && self.in_empty_cells == 0.0
    }
}

/// Bins `n` draws of `sample` on a 24 x 48 (t, phi) grid and compares with the counts that
/// `pdf` predicts (adaptive cell integrals, ~0.01 count accuracy). Cells expecting fewer than
/// 5 are pooled (Nori/Mitsuba practice); draws where the pdf predicts nothing fail at once.
pub fn chi2_test(
    grid: &LobeGrid,
    n: usize,
    mut sample: impl FnMut(&mut Rng) -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f64,
) -> Chi2 {
    let (nt, np) = (24usize, 48usize);
    let mut obs = vec![0f64; nt * np];
    let mut rng = Rng::new(99, 7);
    let mut produced = 0;
    for _ in 0..n {
        if let Some(d) = sample(&mut rng) {
            let (t, phi) = grid.coords(d);
            let i = ((t * nt as f64) as usize).min(nt - 1);
            let j = ((phi / (2.0 * PI) * np as f64) as usize).min(np - 1);
            obs[i * np + j] += 1.0;
            produced += 1;
        }
    }
    let f = |d: Vec3| [pdf(d)];
    let mut cells: Vec<(f64, f64)> = (0..nt * np)
        .map(|c| {
            let (i, j) = (c / np, c % np);
            let tr = [i, i + 1].map(|i| i as f64 / nt as f64);
            let pr = [j, j + 1].map(|j| j as f64 / np as f64 * 2.0 * PI);
            // Edge probes: a draw in a cell judged empty fails the test outright.
            let e = grid.cell(tr, pr, &f, 0.01 / n as f64, 7, true)[0] * n as f64;
            (e, obs[c])
        })
        .collect();
    let expected_total = cells.iter().map(|c| c.0).sum();
    let in_empty_cells = cells
        .iter()
        .filter(|c| c.0 == 0.0)
        .map(|c| c.1)
        .sum::<f64>();
    let in_empty_cells = if in_empty_cells > (1e-5 * n as f64).max(1.0) {
        in_empty_cells
    } else {
        0.0
    };
    cells.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (mut stat, mut dof) = (0.0, 0usize);
    let (mut pe, mut po) = (0.0, 0.0);
    for (e, o) in cells {
        if e < 5.0 {
            pe += e;
            po += o;
            if pe >= 5.0 {
                stat += (po - pe) * (po - pe) / pe;
                dof += 1;
                (pe, po) = (0.0, 0.0);
            }
            continue;
        }
        stat += (o - e) * (o - e) / e;
        dof += 1;
    }
    if pe > 0.0 {
        stat += (po - pe) * (po - pe) / pe.max(1.0);
        dof += 1;
    }
    let dof = dof.saturating_sub(1).max(1);
    let p_value = ChiSquared::new(dof as f64).unwrap().sf(stat);
    Chi2 {
        p_value,
        statistic: stat,
        dof,
        produced,
        expected_total,
        in_empty_cells,
    }
}

/// Per-test significance keeping the family-wise error at 1 % over `tests` tests (Sidak).
pub fn sidak_alpha(tests: usize) -> f64 {
    1.0 - 0.99f64.powf(1.0 / tests as f64)
}
