//! Image figures: rows of labelled image panels (renders, false-colour maps, zoomed crops),
//! composed into one PNG. Text goes through plotters on top of the composed pixels.

use super::colormap::LogScale;
use super::{register_font, FONT};
use plotters::prelude::*;
use std::path::Path;

/// An 8-bit RGB picture with a title above and a caption below.
#[derive(Clone, Debug)]
pub struct Panel {
    pub title: String,
    pub caption: String,
    pub w: u32,
    pub h: u32,
    pub rgb: Vec<u8>,
}

impl Panel {
    pub fn new(title: impl Into<String>, w: u32, h: u32, rgb: Vec<u8>) -> Panel {
        assert_eq!(rgb.len(), (w * h * 3) as usize);
        Panel {
            title: title.into(),
            caption: String::new(),
            w,
            h,
            rgb,
        }
    }

    pub fn caption(mut self, c: impl Into<String>) -> Panel {
        self.caption = c.into();
        self
    }

    /// Nearest-neighbour enlargement by an integer factor (crops stay crisp).
    pub fn enlarge(self, k: u32) -> Panel {
        if k <= 1 {
            return self;
        }
        let (w, h) = (self.w * k, self.h * k);
        let mut rgb = Vec::with_capacity((w * h * 3) as usize);
        for y in 0..h {
            for x in 0..w {
                let i = (((y / k) * self.w + x / k) * 3) as usize;
                rgb.extend_from_slice(&self.rgb[i..i + 3]);
            }
        }
        Panel { w, h, rgb, ..self }
    }

    /// Box-filtered reduction by an integer factor (large renders in a row of panels).
    pub fn shrink(self, k: u32) -> Panel {
        if k <= 1 {
            return self;
        }
        let (w, h) = (self.w / k, self.h / k);
        let mut rgb = Vec::with_capacity((w * h * 3) as usize);
        for y in 0..h {
            for x in 0..w {
                for c in 0..3 {
                    let mut s = 0u32;
                    for dy in 0..k {
                        for dx in 0..k {
                            s += self.rgb[(((y * k + dy) * self.w + x * k + dx) * 3 + c) as usize]
                                as u32;
                        }
                    }
                    rgb.push((s / (k * k)) as u8);
                }
            }
        }
        Panel { w, h, rgb, ..self }
    }

    /// Scales to a width near `target`: integer enlargement or reduction.
    pub fn fit(self, target: u32) -> Panel {
        if self.w * 2 <= target {
            let k = target / self.w;
            self.enlarge(k)
        } else if self.w > target {
            let k = self.w.div_ceil(target);
            self.shrink(k)
        } else {
            self
        }
    }

    pub fn crop(&self, x: u32, y: u32, w: u32, h: u32) -> Panel {
        let mut rgb = Vec::with_capacity((w * h * 3) as usize);
        for yy in y..y + h {
            let i = ((yy * self.w + x) * 3) as usize;
            rgb.extend_from_slice(&self.rgb[i..i + (w * 3) as usize]);
        }
        Panel::new(self.title.clone(), w, h, rgb)
    }

    /// Draws a one-pixel rectangle outline (crop markers).
    pub fn outline(&mut self, x: u32, y: u32, w: u32, h: u32, c: [u8; 3]) {
        let mut put = |px: u32, py: u32| {
            if px < self.w && py < self.h {
                let i = ((py * self.w + px) * 3) as usize;
                self.rgb[i..i + 3].copy_from_slice(&c);
            }
        };
        for px in x..x + w {
            put(px, y);
            put(px, y + h - 1);
        }
        for py in y..y + h {
            put(x, py);
            put(x + w - 1, py);
        }
    }
}

/// A horizontal colour bar for a log scale, as a panel.
pub fn colour_bar(title: &str, s: &LogScale) -> Panel {
    let (w, h) = (200u32, 16u32);
    let mut rgb = Vec::with_capacity((w * h * 3) as usize);
    for _ in 0..h {
        for x in 0..w {
            rgb.extend_from_slice(&super::colormap::viridis(x as f64 / (w - 1) as f64));
        }
    }
    Panel::new(title, w, h, rgb).caption(format!("{:.1e}  to  {:.1e}", s.lo, s.hi))
}

const PAD: u32 = 8;
/// Width of a character at the panels' 13 px text size, generously rounded up.
const CHAR_W: u32 = 7;

/// Shortens `t` to about `width` pixels so it does not run into the next panel's text.
fn fit_text(t: &str, width: u32) -> String {
    let max = (width / CHAR_W) as usize;
    if t.chars().count() <= max || max < 2 {
        return t.to_string();
    }
    let mut s: String = t.chars().take(max - 1).collect();
    s.push('…');
    s
}
const TEXT: u32 = 20;

/// Rows of panels under a title, written as PNG.
pub fn write_figure(path: &Path, title: &str, rows: &[Vec<Panel>]) -> Result<(), String> {
    register_font();
    let row_w = |r: &Vec<Panel>| r.iter().map(|p| p.w + PAD).sum::<u32>() + PAD;
    let row_h = |r: &Vec<Panel>| r.iter().map(|p| p.h).max().unwrap_or(0) + 2 * TEXT + PAD;
    // Titles are wider than small panels; leave room so the last one is not cut.
    let w = rows.iter().map(row_w).max().unwrap_or(0).max(420) + 60;
    let h = TEXT + 2 * PAD + rows.iter().map(row_h).sum::<u32>();
    let mut buf = vec![255u8; (w * h * 3) as usize];
    let mut texts = Vec::new();
    let mut y = TEXT + 2 * PAD;
    for r in rows {
        let mut x = PAD;
        for p in r {
            for py in 0..p.h {
                let dst = (((y + TEXT + py) * w + x) * 3) as usize;
                let src = (py * p.w * 3) as usize;
                buf[dst..dst + (p.w * 3) as usize]
                    .copy_from_slice(&p.rgb[src..src + (p.w * 3) as usize]);
            }
            texts.push((fit_text(&p.title, p.w + PAD), x, y + 3));
            texts.push((fit_text(&p.caption, p.w + PAD), x, y + TEXT + p.h + 3));
            x += p.w + PAD;
        }
        y += row_h(r);
    }
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        let e = |e: DrawingAreaErrorKind<_>| format!("{}: {e}", path.display());
        root.draw(&Text::new(
            title.to_string(),
            (PAD as i32, PAD as i32),
            (FONT, 17).into_font(),
        ))
        .map_err(e)?;
        for (t, x, y) in texts.iter().filter(|t| !t.0.is_empty()) {
            root.draw(&Text::new(
                t.clone(),
                (*x as i32, *y as i32),
                (FONT, 13).into_font(),
            ))
            .map_err(e)?;
        }
        root.present().map_err(e)?;
    }
    crate::film::write_png_rgb8(path, w, h, &buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gradient(w: u32, h: u32) -> Panel {
        let rgb = (0..w * h).flat_map(|i| [(i % 256) as u8, 0, 0]).collect();
        Panel::new("g", w, h, rgb)
    }

    #[test]
    fn enlarge_shrink_crop_round_trip() {
        let p = gradient(4, 2);
        let big = p.clone().enlarge(3);
        assert_eq!((big.w, big.h), (12, 6));
        assert_eq!(big.shrink(3).rgb, p.rgb);
        let c = p.crop(1, 1, 2, 1);
        assert_eq!(c.rgb, vec![5, 0, 0, 6, 0, 0]);
        assert_eq!(gradient(100, 10).fit(400).w, 400);
        assert_eq!(gradient(768, 8).fit(400).w, 384);
    }

    #[test]
    fn long_titles_are_shortened_to_the_panel() {
        assert_eq!(fit_text("short", 100), "short");
        let t = fit_text("a very long title for a small panel", 70);
        assert_eq!(t.chars().count(), 10);
        assert!(t.ends_with('…'));
    }

    #[test]
    fn figure_has_the_panels_pixels() {
        let dir = std::env::temp_dir().join(format!("directlab-fig-{}", std::process::id()));
        let path = dir.join("f.png");
        let mut p = Panel::new("ref", 8, 8, vec![0u8; 8 * 8 * 3]).caption("relMSE 1e-3");
        p.outline(0, 0, 4, 4, [255, 0, 0]);
        write_figure(&path, "figure", &[vec![p.clone(), p], vec![gradient(8, 8)]]).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        // The first panel's top-left corner carries the red outline.
        let (x0, y0) = (PAD, TEXT + 2 * PAD + TEXT);
        assert_eq!(img.get_pixel(x0, y0).0, [255, 0, 0]);
        assert_eq!(img.get_pixel(x0 + 5, y0 + 5).0, [0, 0, 0]);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
