//! Test-only integration and goodness-of-fit over the sphere, with a parametrisation that
//! zooms on a lobe: polar angle theta around `axis` is 2 atan(width * t / (1 - t)) for t in
//! [0, 1), so a lobe of angular width ~`width` (down to roughness 1e-3) spans many cells,
//! while t -> 1 still reaches the antipode. The map is plain geometry, independent of the code
//! under test, so integrals of pdfs through it are independent checks of their normalisation.

use crate::math::Frame;
use crate::rng::Rng;
use glam::{DVec3, Vec3};
use statrs::distribution::{ChiSquared, ContinuousCDF};
use std::f64::consts::PI;

#[derive(Clone, Copy, Debug)]
pub struct LobeGrid {
    frame: Frame,
    width: f64,
    /// The t reached at grid coordinate 1/2: with axis z, the horizon's t, so that no cell
    /// straddles the jump many pdfs have there (midpoints converge slowly across a jump).
    t_half: f64,
}

impl LobeGrid {
    pub fn new(axis: Vec3, width: f64) -> Self {
        LobeGrid {
            frame: Frame::from_normal(axis.normalize()),
            width,
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
        let local = DVec3::new(st * cp, st * sp, ct).as_vec3();
        (self.frame.to_world(local), st * dtheta_dt * dt_dtau)
    }

    /// Inverse of `point`: grid coordinates of a direction.
    pub fn coords(&self, d: Vec3) -> (f64, f64) {
        let v = self.frame.to_local(d).as_dvec3();
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

    /// ∫ f dω over the whole sphere by the midpoint rule on an nt x nphi grid.
    pub fn integrate(&self, nt: usize, nphi: usize, f: impl Fn(Vec3) -> f64) -> f64 {
        self.integrate_cell(0.0, 1.0, 0.0, 2.0 * PI, nt, nphi, &f)
    }

    #[allow(clippy::too_many_arguments)]
    fn integrate_cell(
        &self,
        t0: f64,
        t1: f64,
        p0: f64,
        p1: f64,
        nt: usize,
        np: usize,
        f: &impl Fn(Vec3) -> f64,
    ) -> f64 {
        let (dt, dp) = ((t1 - t0) / nt as f64, (p1 - p0) / np as f64);
        let mut sum = 0.0;
        for i in 0..nt {
            let t = t0 + (i as f64 + 0.5) * dt;
            for j in 0..np {
                let (d, jac) = self.point(t, p0 + (j as f64 + 0.5) * dp);
                let v = f(d);
                if v != 0.0 {
                    sum += v * jac;
                }
            }
        }
        sum * dt * dp
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
}

impl Chi2 {
    /// The sampler's success rate minus the pdf's mass, in standard errors of the former.
    pub fn mass_z(&self, n: usize) -> f64 {
        let p = self.produced as f64 / n as f64;
        let se = (p * (1.0 - p) / n as f64).sqrt().max(1.0 / n as f64);
        (p - self.expected_total / n as f64) / se
    }
}

/// Bins `n` draws of `sample` on a (t, phi) grid of `grid` and compares with the counts that
/// `pdf` predicts (each cell integrated with sub x sub midpoints). Cells expecting fewer than
/// 5 are pooled (Nori/Mitsuba practice); a draw where the pdf predicts nothing fails at once.
pub fn chi2_test(
    grid: &LobeGrid,
    n: usize,
    mut sample: impl FnMut(&mut Rng) -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f64,
) -> Chi2 {
    let (nt, np, sub) = (24usize, 48usize, 12usize);
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
    let mut cells: Vec<(f64, f64)> = (0..nt * np)
        .map(|c| {
            let (i, j) = (c / np, c % np);
            let (t0, p0) = (i as f64 / nt as f64, j as f64 / np as f64 * 2.0 * PI);
            let e = grid.integrate_cell(
                t0,
                t0 + 1.0 / nt as f64,
                p0,
                p0 + 2.0 * PI / np as f64,
                sub,
                sub,
                &pdf,
            ) * n as f64;
            (e, obs[c])
        })
        .collect();
    let expected_total = cells.iter().map(|c| c.0).sum();
    for &(e, o) in &cells {
        // Midpoints can miss a sliver of support at a cell edge (the horizon): allow a trace.
        assert!(
            !(e == 0.0 && o > (1e-5 * n as f64).max(1.0)),
            "{o} samples in a cell where the pdf is zero"
        );
    }
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
    }
}

/// Per-test significance keeping the family-wise error at 1 % over `tests` tests (Sidak).
pub fn sidak_alpha(tests: usize) -> f64 {
    1.0 - 0.99f64.powf(1.0 / tests as f64)
}
