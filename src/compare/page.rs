//! What `compare` writes beside its page: the p-value maps, A, B and their difference as
//! PNGs, tiles.csv and the histogram of the tile p-values.

use crate::film::{write_png_rgb8, Image};
use crate::stats::welch_map::{Side, WelchMap};
use std::fmt::Write;
use std::path::Path;

/// `tiles.csv`: per tile and channel, the p-value and A - B (empty where excluded).
pub(super) fn write_tiles_csv(path: &Path, m: &WelchMap) -> Result<(), String> {
    let mut text = String::from("tile_x,tile_y,p_r,p_g,p_b,diff_r,diff_g,diff_b\n");
    let cell = |x: f64| {
        if x.is_nan() {
            String::new()
        } else {
            format!("{x:.6e}")
        }
    };
    for (i, (p, d)) in m.p.iter().zip(&m.diff).enumerate() {
        let _ = writeln!(
            text,
            "{},{},{},{},{},{},{},{}",
            i % m.width,
            i / m.width,
            cell(p[0]),
            cell(p[1]),
            cell(p[2]),
            cell(d[0]),
            cell(d[1]),
            cell(d[2])
        );
    }
    crate::output::write_atomic(path, |tmp| {
        std::fs::write(tmp, &text).map_err(|e| format!("{}: {e}", path.display()))
    })
}

/// Counts of `p` in `bins` equal bins of [0, 1].
pub(super) fn histogram(p: &[f64], bins: usize) -> Vec<usize> {
    let mut h = vec![0; bins];
    for x in p {
        h[((x * bins as f64) as usize).min(bins - 1)] += 1;
    }
    h
}

/// The smallest p-value of each unit in grey (log scale: black at 1e-6 or below, white at
/// 1), untested units red.
pub(super) fn p_map_png(path: &Path, m: &WelchMap) -> Result<(), String> {
    let rgb: Vec<u8> = m
        .min_p()
        .iter()
        .flat_map(|p| match p.is_nan() {
            true => [255, 0, 0],
            false => {
                let g = (1.0 + p.max(1e-6).log10() / 6.0).clamp(0.0, 1.0);
                let g = (255.0 * g).round() as u8;
                [g, g, g]
            }
        })
        .collect();
    write_png_rgb8(path, m.width as u32, m.height as u32, &rgb)
}

/// `a.png` and `b.png` (the sides' means at exposure 1) and `diff.png`: A - B per pixel in
/// standard errors of the difference, summed over channels (white at 0, red where A is
/// brighter, blue where B is, full colour at 4; grey where neither side has a variance).
pub(super) fn images(dir: &Path, a: &Side, b: &Side) -> Result<(), String> {
    let (w, h) = (a.width as u32, a.height as u32);
    let image = |s: &Side| Image {
        width: w,
        height: h,
        data: s.mean.clone(),
    };
    crate::film::write_png(&dir.join("a.png"), &image(a))?;
    crate::film::write_png(&dir.join("b.png"), &image(b))?;
    let rgb: Vec<u8> = (0..a.mean.len())
        .flat_map(|i| {
            let d: f64 = (0..3).map(|c| a.mean[i][c] - b.mean[i][c]).sum();
            let v: f64 = (0..3).map(|c| a.var_mean[i][c] + b.var_mean[i][c]).sum();
            let z = d / v.sqrt();
            // 0 / 0 or a non-finite input; a difference with no variance is full colour.
            if z.is_nan() {
                return [128, 128, 128];
            }
            let fade = (255.0 * (1.0 - (z.abs() / 4.0).min(1.0))).round() as u8;
            if z > 0.0 {
                [255, fade, fade]
            } else {
                [fade, fade, 255]
            }
        })
        .collect();
    write_png_rgb8(&dir.join("diff.png"), w, h, &rgb)
}
