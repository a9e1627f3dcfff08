//! A piecewise-constant density on [0, 1]^2 from a table (pbrt-v4's `PiecewiseConstant2D`,
//! the table behind Mitsuba's `envmap`; issue 71): a marginal CDF over rows and a
//! conditional CDF per row, inverted continuously, so that a point in cell (i, j) has density
//! value(i, j) / mean exactly, and cells of value 0 are never drawn. Also what an environment
//! map needs around it: Mitsuba's latitude-longitude mapping with its solid-angle Jacobian,
//! and Karlik et al.'s (2019) MIS-compensated table.

use crate::math::PI;
use glam::{Vec2, Vec3};

/// The table's density: `w` columns (u) by `h` rows (v), row-major from v = 0.
#[derive(Clone, Debug)]
pub struct Piecewise2D {
    w: usize,
    h: usize,
    /// Per row, its conditional CDF over columns (w + 1 values from 0 to 1).
    conditional: Vec<f64>,
    /// The CDF over rows (h + 1 values from 0 to 1).
    marginal: Vec<f64>,
    /// The density of each cell: value / mean.
    density: Vec<f32>,
}

/// The bin `[cdf[i], cdf[i + 1])` that holds `u`, skipping bins of width 0 (none holds any
/// `u`), and where in it `u` lies (in [0, 1)).
fn invert(cdf: &[f64], u: f64) -> (usize, f64) {
    let n = cdf.len() - 1;
    // The last bin whose start is at most u; bins of width 0 start where a later one does.
    let i = (cdf.partition_point(|&c| c <= u).max(1) - 1).min(n - 1);
    let (lo, hi) = (cdf[i], cdf[i + 1]);
    let t = if hi > lo { (u - lo) / (hi - lo) } else { 0.0 };
    (i, t.clamp(0.0, 1.0 - f64::EPSILON))
}

/// (i + t) / n in f32, kept in bin i as `Piecewise2D::pdf` finds it (rounding to f32 may
/// carry a point at either end of its bin into the neighbouring one).
fn inside(i: usize, t: f64, n: usize) -> f32 {
    let mut x = ((i as f64 + t) / n as f64) as f32;
    while x > 0.0 && bin(x, n) > i {
        x = f32::from_bits(x.to_bits() - 1);
    }
    while bin(x, n) < i {
        x = f32::from_bits(x.to_bits() + 1);
    }
    x
}

/// The bin of `x` in [0, 1] among `n`.
#[inline]
pub(crate) fn bin(x: f32, n: usize) -> usize {
    ((x * n as f32) as usize).min(n - 1)
}

/// A running sum normalised to end at 1.
fn cdf_of(values: impl Iterator<Item = f64>, total: f64) -> Vec<f64> {
    let mut out = vec![0.0];
    let mut s = 0.0;
    for v in values {
        s += v;
        out.push(s / total);
    }
    *out.last_mut().expect("at least one bin") = 1.0;
    out
}

impl Piecewise2D {
    /// The density of `values` (`w` x `h`, row-major); an error for an empty table, a
    /// negative or non-finite value, or a total of 0.
    pub fn new(values: &[f64], w: usize, h: usize) -> Result<Self, String> {
        if w == 0 || h == 0 || values.len() != w * h {
            return Err(format!(
                "a table of {} values is not {w} x {h} (both at least 1)",
                values.len()
            ));
        }
        if let Some(i) = values.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(format!(
                "value {} at column {}, row {}: expected a finite value >= 0",
                values[i],
                i % w,
                i / w
            ));
        }
        let rows: Vec<f64> = values.chunks(w).map(|r| r.iter().sum()).collect();
        let total: f64 = rows.iter().sum();
        if !(total > 0.0) {
            return Err("every value is 0: nothing to sample".into());
        }
        let mut conditional = Vec::with_capacity(h * (w + 1));
        for (r, &sum) in values.chunks(w).zip(&rows) {
            if sum > 0.0 {
                conditional.extend(cdf_of(r.iter().copied(), sum));
            } else {
                // Never drawn (the marginal gives it width 0); uniform keeps it well formed.
                conditional.extend((0..=w).map(|j| j as f64 / w as f64));
            }
        }
        let mean = total / (w * h) as f64;
        Ok(Piecewise2D {
            w,
            h,
            conditional,
            marginal: cdf_of(rows.iter().copied(), total),
            density: values.iter().map(|v| (v / mean) as f32).collect(),
        })
    }

    /// Columns and rows.
    pub fn size(&self) -> (usize, usize) {
        (self.w, self.h)
    }

    /// A point of [0, 1)^2 drawn with numbers `u`, and its density.
    pub fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let (row, tv) = invert(&self.marginal, u.y as f64);
        let cdf = &self.conditional[row * (self.w + 1)..(row + 1) * (self.w + 1)];
        let (col, tu) = invert(cdf, u.x as f64);
        let p = Vec2::new(inside(col, tu, self.w), inside(row, tv, self.h));
        (p, self.density[row * self.w + col])
    }

    /// The density at `p` in [0, 1]^2 (0 outside).
    pub fn pdf(&self, p: Vec2) -> f32 {
        if !(p.x >= 0.0 && p.x <= 1.0 && p.y >= 0.0 && p.y <= 1.0) {
            return 0.0;
        }
        self.density[bin(p.y, self.h) * self.w + bin(p.x, self.w)]
    }
}

/// MIS compensation (Karlik et al. 2019): the table less its mean, clamped at 0, so that
/// the light technique leaves the dim part to BSDF sampling; the table itself where that
/// leaves nothing (a constant table).
pub fn compensated(values: &[f64]) -> Vec<f64> {
    let mean = values.iter().sum::<f64>() / values.len().max(1) as f64;
    let out: Vec<f64> = values.iter().map(|v| (v - mean).max(0.0)).collect();
    if out.iter().any(|&v| v > 0.0) {
        out
    } else {
        values.to_vec()
    }
}

/// The direction of latitude-longitude coordinates `uv` in an environment's local frame, as
/// Mitsuba's `envmap` maps them: u = phi / 2 pi (phi from -z towards +x), v = theta / pi
/// (theta from +y, the up axis).
pub fn latlong_direction(uv: Vec2) -> Vec3 {
    let (st, ct) = (PI * uv.y).sin_cos();
    let (sp, cp) = (2.0 * PI * uv.x).sin_cos();
    Vec3::new(st * sp, ct, -st * cp)
}

/// The latitude-longitude coordinates of a unit direction (`latlong_direction`'s inverse).
pub fn latlong_uv(d: Vec3) -> Vec2 {
    let phi = d.x.atan2(-d.z);
    let u = phi / (2.0 * PI);
    Vec2::new(
        if u < 0.0 { u + 1.0 } else { u },
        d.y.clamp(-1.0, 1.0).acos() / PI,
    )
}

/// A density over latitude-longitude coordinates as a density over directions:
/// p(w) = p(u, v) / (2 pi^2 sin theta); 0 at the poles, where the map has no area.
pub fn latlong_pdf_solid_angle(pdf_uv: f32, v: f32) -> f32 {
    let s = (PI * v).sin();
    if s > 0.0 {
        pdf_uv / (2.0 * PI * PI * s)
    } else {
        0.0
    }
}

#[cfg(test)]
#[path = "piecewise_tests.rs"]
mod tests;
