//! PNG of a chi-square run: observed | expected | standardised residual, side by side, with
//! titles, axes and colour bars.
//!
//! Observed and expected share one colour scale so a mismatch shows as a visible difference;
//! the residual (obs - exp) / sqrt(exp) is roughly N(0, 1) per cell under the null, so a
//! fixed diverging scale clamped at +-5 makes real structure (a ring, a seam) stand out
//! against noise. The v parameter (cos theta, y, r^2) increases upwards.

use super::chi2::{Chi2Result, Grid};
use image::{Rgb, RgbImage};
use std::path::Path;

/// Pixels between panels.
const GAP: u32 = 4;
const BACKGROUND: Rgb<u8> = Rgb([40, 40, 40]);
/// Cells the pdf gives no mass and no sample reached (outside the support).
const EMPTY: Rgb<u8> = Rgb([128, 128, 128]);
/// Residuals are clamped here.
pub const RESIDUAL_CLAMP: f64 = 5.0;

fn lerp_rgb(stops: &[[f64; 3]], t: f64) -> Rgb<u8> {
    let t = t.clamp(0.0, 1.0) * (stops.len() - 1) as f64;
    let i = (t.floor() as usize).min(stops.len() - 2);
    let f = t - i as f64;
    let c = |k: usize| (255.0 * (stops[i][k] * (1.0 - f) + stops[i + 1][k] * f)).round() as u8;
    Rgb([c(0), c(1), c(2)])
}

/// Perceptually ordered dark-to-bright ramp (a coarse viridis).
fn sequential(t: f64) -> Rgb<u8> {
    const STOPS: [[f64; 3]; 5] = [
        [0.267, 0.005, 0.329],
        [0.230, 0.322, 0.546],
        [0.128, 0.567, 0.551],
        [0.369, 0.789, 0.383],
        [0.993, 0.906, 0.144],
    ];
    lerp_rgb(&STOPS, t)
}

/// Blue (negative) - white (0) - red (positive) for t in [-1, 1].
fn diverging(t: f64) -> Rgb<u8> {
    const STOPS: [[f64; 3]; 3] = [[0.10, 0.25, 0.85], [1.0, 1.0, 1.0], [0.85, 0.10, 0.10]];
    lerp_rgb(&STOPS, 0.5 * (t + 1.0))
}

/// Standardised residual of one cell, clamped; None where the cell is empty and impossible.
fn residual(obs: f64, exp: f64) -> Option<f64> {
    if exp > 0.0 {
        Some(((obs - exp) / exp.sqrt()).clamp(-RESIDUAL_CLAMP, RESIDUAL_CLAMP))
    } else if obs > 0.0 {
        Some(RESIDUAL_CLAMP)
    } else {
        None
    }
}

/// Draws the three panels, each cell `cell_px` pixels square.
pub fn render(observed: &Grid, expected: &Grid, cell_px: u32) -> RgbImage {
    assert_eq!(
        (observed.cols, observed.rows),
        (expected.cols, expected.rows)
    );
    let (cols, rows) = (observed.cols as u32, observed.rows as u32);
    let s = cell_px.max(1);
    let (pw, ph) = (cols * s, rows * s);
    let mut img = RgbImage::from_pixel(3 * pw + 2 * GAP, ph, BACKGROUND);
    let peak = observed
        .data
        .iter()
        .chain(&expected.data)
        .fold(0.0f64, |m, &x| m.max(x));
    let scale = if peak > 0.0 { 1.0 / peak } else { 0.0 };
    for r in 0..rows {
        for c in 0..cols {
            let (obs, exp) = (
                observed.get(c as usize, r as usize),
                expected.get(c as usize, r as usize),
            );
            let colours = [
                sequential(obs * scale),
                sequential(exp * scale),
                residual(obs, exp).map_or(EMPTY, |z| diverging(z / RESIDUAL_CLAMP)),
            ];
            // Row 0 is v = v0, drawn at the bottom.
            let y0 = (rows - 1 - r) * s;
            for (panel, colour) in colours.into_iter().enumerate() {
                let x0 = panel as u32 * (pw + GAP) + c * s;
                for y in y0..y0 + s {
                    for x in x0..x0 + s {
                        img.put_pixel(x, y, colour);
                    }
                }
            }
        }
    }
    img
}

/// The three panels of [`render`] cut apart, each `(w, h, rgb)`.
fn split(img: &RgbImage, cols: u32, cell_px: u32) -> Vec<(u32, u32, Vec<u8>)> {
    let pw = cols * cell_px.max(1);
    (0..3)
        .map(|k| {
            let x0 = k * (pw + GAP);
            let rgb = (0..img.height())
                .flat_map(|y| (x0..x0 + pw).flat_map(move |x| img.get_pixel(x, y).0))
                .collect();
            (pw, img.height(), rgb)
        })
        .collect()
}

/// A horizontal colour bar `w` pixels wide.
fn bar(w: u32, colour: impl Fn(f64) -> Rgb<u8>) -> (u32, u32, Vec<u8>) {
    const H: u32 = 12;
    let row: Vec<u8> = (0..w)
        .flat_map(|x| colour(x as f64 / (w.max(2) - 1) as f64).0)
        .collect();
    (w, H, row.repeat(H as usize))
}

/// Writes a run's heat maps to `path` as a PNG figure: observed, expected and residual
/// panels with titles, their axes in the domain's coordinates ([`Chi2Result::axes`]) and
/// colour bars with their numbers, through [`crate::output::write_atomic`].
pub fn write(path: &Path, result: &Chi2Result, cell_px: u32) -> Result<(), String> {
    use crate::plot::panels::{write_figure, Panel};
    let img = render(&result.observed, &result.expected, cell_px);
    let cols = result.observed.cols as u32;
    let [u, v] = result.axes;
    let axes = if v.is_empty() {
        format!("across {u}")
    } else {
        format!("across {u}, up {v}")
    };
    let titles = [
        "observed samples per cell",
        "expected: N x pdf integral",
        "residual (obs - exp) / sqrt(exp)",
    ];
    let panels: Vec<Panel> = split(&img, cols, cell_px)
        .into_iter()
        .zip(titles)
        .map(|((w, h, rgb), t)| {
            let mut p = Panel::new(t, w, h, rgb);
            p.caption = axes.clone();
            p
        })
        .collect();
    let peak = result
        .observed
        .data
        .iter()
        .chain(&result.expected.data)
        .fold(0.0f64, |m, &x| m.max(x));
    let pw = cols * cell_px.max(1);
    let (w, h, rgb) = bar(pw, sequential);
    let mut counts = Panel::new(format!("0 to {peak:.0} samples per cell"), w, h, rgb);
    counts.caption = "observed and expected share this scale".into();
    let (w, h, rgb) = bar(pw, |t| diverging(2.0 * t - 1.0));
    let mut resid = Panel::new(
        format!("-{RESIDUAL_CLAMP} to +{RESIDUAL_CLAMP} (clamped); grey: impossible and empty"),
        w,
        h,
        rgb,
    );
    resid.caption = "about N(0, 1) per cell when the sampler is right".into();
    let title = format!(
        "{} on the {}: chi2 = {:.2} on {} dof, p = {:.3e}, pdf integral {:.6}",
        if result.passed() { "pass" } else { "FAIL" },
        result.domain,
        result.statistic,
        result.dof,
        result.p_value,
        result.pdf_integral
    );
    write_figure(path, &title, &[panels, vec![counts, resid]])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::chi2::{chi2_test, Chi2Config};
    use crate::stats::domain::Sphere;
    use glam::Vec3;

    #[test]
    fn writes_png_of_expected_size() {
        // Deliberately wrong pair (uniform sphere sampler, cosine pdf) so the residual panel
        // has structure. N = 20k; the verdict is irrelevant here.
        let domain = Sphere {
            n_phi: 11,
            n_cos: 21,
        };
        let cfg = Chi2Config {
            samples: 20_000,
            ..Chi2Config::default()
        };
        let sampler = |g: &mut crate::rng::Rng| {
            let z = 2.0 * g.next_f32() - 1.0;
            let phi = std::f32::consts::TAU * g.next_f32();
            let s = (1.0 - z * z).max(0.0).sqrt();
            Some(Vec3::new(s * phi.cos(), s * phi.sin(), z))
        };
        let r = chi2_test(
            &domain,
            sampler,
            |d| d.z.max(0.0) as f64 / std::f64::consts::PI,
            &cfg,
        );
        let dir = std::env::temp_dir().join(format!("directlab-heatmap-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("chi2.png");
        write(&path, &r, 6).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        // Three panels, their titles and axes above and below, and a row of colour bars.
        assert!(
            img.width() > 3 * 11 * 6 && img.height() > 21 * 6 + 12,
            "{:?}",
            img.dimensions()
        );
        assert_eq!(
            std::fs::read_dir(&dir).unwrap().count(),
            1,
            "a temporary file was left"
        );
        let count = |c: Rgb<u8>| img.pixels().filter(|p| **p == c).count();
        // Lower hemisphere: samples where the pdf is 0 are drawn saturated red, in the residual
        // panel (a cell of 36 pixels at least) and at the bar's end.
        assert!(count(diverging(1.0)) >= 36, "no saturated residual cell");
        assert!(
            count(sequential(1.0)) >= 1 && count(diverging(-1.0)) >= 1,
            "no colour bars"
        );
        // Text: dark pixels in the title line (white background).
        let dark = (0..img.width())
            .flat_map(|x| (0..20).map(move |y| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y).0.iter().all(|&c| c < 100))
            .count();
        assert!(dark > 50, "no title drawn ({dark} dark pixels)");
        // The layout of the panels themselves.
        let panels = render(&r.observed, &r.expected, 6);
        assert_eq!(panels.dimensions(), (3 * 11 * 6 + 2 * GAP, 21 * 6));
        assert_eq!(
            *panels.get_pixel(2 * (66 + GAP) + 3, 21 * 6 - 3),
            diverging(1.0)
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn colour_maps_hit_their_ends() {
        assert_eq!(diverging(0.0), Rgb([255, 255, 255]));
        assert_eq!(diverging(-1.0), Rgb([26, 64, 217]));
        assert_eq!(residual(0.0, 0.0), None);
        assert_eq!(residual(100.0, 4.0), Some(RESIDUAL_CLAMP));
    }

    /// A 3 x 2 grid drawn at 2 pixels a cell, every pixel checked against values worked by
    /// hand: the panels' places and gaps, rows drawn bottom up, one colour scale for observed
    /// and expected (peak 8), residuals (obs - exp) / sqrt(exp) on the diverging map, empty
    /// impossible cells grey, and samples where the pdf is 0 saturated red.
    #[test]
    fn panels_cells_and_colours_by_hand() {
        let grid = |data: [f64; 6]| Grid {
            cols: 3,
            rows: 2,
            data: data.to_vec(),
        };
        // Row 0, then row 1.
        let observed = grid([3.0, 0.0, 8.0, 6.0, 1.0, 0.0]);
        let expected = grid([3.0, 0.0, 0.0, 4.0, 4.0, 0.0]);
        let img = render(&observed, &expected, 2);
        assert_eq!(img.dimensions(), (3 * 6 + 2 * GAP, 4));
        let rgb = |r, g, b| Rgb([r, g, b]);
        let (seq_0, seq_1) = (rgb(68, 1, 84), rgb(253, 231, 37));
        let (seq_375, seq_5) = (rgb(46, 113, 140), rgb(33, 145, 141));
        // (col, row) -> observed, expected and residual colours.
        let want = [
            ((0, 0), [seq_375, seq_375, rgb(255, 255, 255)]),
            ((1, 0), [seq_0, seq_0, EMPTY]),
            ((2, 0), [seq_1, seq_0, diverging(1.0)]),
            // z = (6 - 4) / 2 = 1: 0.2 of the way to red.
            ((0, 1), [sequential(0.75), seq_5, rgb(247, 209, 209)]),
            // z = (1 - 4) / 2 = -1.5: 0.3 of the way to blue.
            ((1, 1), [sequential(0.125), seq_5, rgb(186, 198, 244)]),
            ((2, 1), [seq_0, seq_0, EMPTY]),
        ];
        for ((c, r), colours) in want {
            for (panel, colour) in colours.into_iter().enumerate() {
                let x0 = panel as u32 * (6 + GAP) + 2 * c;
                // Row 1 is drawn above row 0.
                let y0 = 2 * (1 - r);
                for (x, y) in [(x0, y0), (x0 + 1, y0 + 1)] {
                    assert_eq!(
                        *img.get_pixel(x, y),
                        colour,
                        "cell ({c}, {r}) panel {panel}"
                    );
                }
            }
        }
        for x in (6..6 + GAP).chain(16..16 + GAP) {
            assert_eq!(*img.get_pixel(x, 1), BACKGROUND, "gap at x = {x}");
        }
    }
}
