//! Mitsuba's `envmap` (issue 71, item 4): an infinitely distant environment from a
//! latitude-longitude RGB image (`filename`, `scale`, `to_world`), importance-sampled through
//! a piecewise-constant table of luminance x sin(theta) (`sampling::piecewise`) with its
//! exact density, or through that table less its mean (`mis_compensation`, Karlik et al.
//! 2019), used for sampling and for the MIS density alike.
//!
//! Radiance is the texel's, nearest (piecewise constant like the table; Mitsuba filters the
//! image bilinearly, so renders of coarse maps differ from Mitsuba's by that filter).

use crate::film::Image;
use crate::math::{luminance, Rgb, PI};
use crate::sampling::piecewise::{
    bin, compensated, latlong_direction, latlong_pdf_solid_angle, latlong_uv, Piecewise2D,
};
use glam::{Mat3, Vec2, Vec3};

/// An environment light.
#[derive(Clone, Debug)]
pub struct EnvMap {
    width: usize,
    height: usize,
    /// Texels times `scale`, row-major from theta = 0 (the local +y pole).
    radiance: Vec<Rgb>,
    /// Local (the map's frame) to world: a rotation.
    to_world: Mat3,
    to_local: Mat3,
    table: Piecewise2D,
    /// Whether `table` is the compensated one.
    pub compensated: bool,
}

impl EnvMap {
    /// The environment of `image` (latitude-longitude, `name` for messages) times `scale`,
    /// rotated by `to_world`; sampled through the compensated table if `compensation`. An
    /// error names the file and what is wrong: an empty image, a negative or non-finite
    /// texel, a scale that is not finite and positive, a rotation that is not one, or no
    /// light at all.
    pub fn new(
        image: &Image,
        name: &str,
        scale: f32,
        to_world: Mat3,
        compensation: bool,
    ) -> Result<EnvMap, String> {
        let (w, h) = (image.width as usize, image.height as usize);
        if w == 0 || h == 0 {
            return Err(format!("{name}: an empty image"));
        }
        if !(scale.is_finite() && scale > 0.0) {
            return Err(format!(
                "{name}: scale {scale}: expected a finite value > 0"
            ));
        }
        let ortho = to_world.transpose() * to_world;
        if !ortho.abs_diff_eq(Mat3::IDENTITY, 1e-4) || to_world.determinant() < 0.0 {
            return Err(format!(
                "{name}: to_world must be a rotation (an environment has no position, size \
                 or handedness)"
            ));
        }
        if let Some(i) = image
            .data
            .iter()
            .position(|p| p.iter().any(|c| !(c.is_finite() && *c >= 0.0)))
        {
            return Err(format!(
                "{name}: pixel ({}, {}) is {:?}: expected finite RGB values >= 0",
                i % w,
                i / w,
                image.data[i]
            ));
        }
        let radiance: Vec<Rgb> = image
            .data
            .iter()
            .map(|p| Rgb::new(p[0] as f32, p[1] as f32, p[2] as f32) * scale)
            .collect();
        // Each texel's share of the sphere is proportional to sin(theta) at its row.
        let values: Vec<f64> = radiance
            .iter()
            .enumerate()
            .map(|(i, &l)| {
                let theta = PI as f64 * ((i / w) as f64 + 0.5) / h as f64;
                luminance(l) as f64 * theta.sin()
            })
            .collect();
        if !values.iter().any(|&v| v > 0.0) {
            return Err(format!(
                "{name}: every texel has zero luminance: the environment emits nothing"
            ));
        }
        let values = if compensation {
            compensated(&values)
        } else {
            values
        };
        let table = Piecewise2D::new(&values, w, h).map_err(|e| format!("{name}: {e}"))?;
        Ok(EnvMap {
            width: w,
            height: h,
            radiance,
            to_world,
            to_local: to_world.transpose(),
            table,
            compensated: compensation,
        })
    }

    /// The texel seen along the local direction's coordinates `uv`.
    fn texel(&self, uv: Vec2) -> Rgb {
        self.radiance[bin(uv.y, self.height) * self.width + bin(uv.x, self.width)]
    }

    /// Radiance arriving from the environment along world direction `d` (unit, pointing
    /// away from the scene).
    pub fn eval(&self, d: Vec3) -> Rgb {
        self.texel(latlong_uv(self.to_local * d))
    }

    /// A direction drawn with numbers `u`: the world direction, its radiance and its
    /// solid-angle density; None at a pole, where the map has no area.
    pub fn sample(&self, u: Vec2) -> Option<(Vec3, Rgb, f32)> {
        let (uv, pdf_uv) = self.table.sample(u);
        let pdf = latlong_pdf_solid_angle(pdf_uv, uv.y);
        if !(pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        let d = (self.to_world * latlong_direction(uv)).normalize();
        Some((d, self.texel(uv), pdf))
    }

    /// The solid-angle density with which `sample` draws world direction `d`.
    pub fn pdf(&self, d: Vec3) -> f32 {
        let uv = latlong_uv(self.to_local * d);
        latlong_pdf_solid_angle(self.table.pdf(uv), uv.y)
    }

    /// Mean radiance's luminance over the sphere (for the power of emitter choice: pi R^2
    /// times this for a scene of bounding radius R).
    pub fn mean_luminance(&self) -> f64 {
        let (w, h) = (self.width, self.height);
        let mut sum = 0.0;
        for (i, &l) in self.radiance.iter().enumerate() {
            // Texel solid angle: (2 pi / w) (cos theta0 - cos theta1).
            let (t0, t1) = (
                PI as f64 * (i / w) as f64 / h as f64,
                PI as f64 * ((i / w) + 1) as f64 / h as f64,
            );
            sum += luminance(l) as f64 * (2.0 * PI as f64 / w as f64) * (t0.cos() - t1.cos());
        }
        sum / (4.0 * PI as f64)
    }
}

#[cfg(test)]
#[path = "envmap_tests.rs"]
mod tests;
