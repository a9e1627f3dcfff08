//! See a wrong pdf fail: a cosine-weighted hemisphere sampler whose pdf forgets the cosine
//! (it returns the uniform hemisphere's 1 / 2 pi). The chi-square rejects it, and the heat
//! map (observed | expected | residual) shows where: too many samples near the pole, too
//! few at the horizon. Exits 0 when the mistake is caught.
//!
//!     cargo run --release --example wrong_pdf -- [heat map path, default wrong_pdf.png]

use directlab::check::{chi2_directions, DirectionSampler, Options};
use glam::{Vec2, Vec3};
use std::f32::consts::{PI, TAU};

struct CosineWithUniformPdf;

impl DirectionSampler for CosineWithUniformPdf {
    fn sample(&self, u: Vec2) -> Option<Vec3> {
        let (r, phi) = (u.x.sqrt(), TAU * u.y);
        Some(Vec3::new(
            r * phi.cos(),
            r * phi.sin(),
            (1.0 - u.x).max(0.0).sqrt(),
        ))
    }
    fn pdf(&self, d: Vec3) -> f64 {
        // The mistake: the cosine sampler's density is z / pi.
        if d.z > 0.0 {
            1.0 / (2.0 * PI as f64)
        } else {
            0.0
        }
    }
}

fn main() {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "wrong_pdf.png".into());
    let o = chi2_directions(
        &CosineWithUniformPdf,
        &Options {
            samples: 200_000,
            ..Options::default()
        },
    );
    println!("{}", o.summary());
    if let Err(e) = o.write_heatmap(std::path::Path::new(&path)) {
        eprintln!("error: {e}");
        std::process::exit(2);
    }
    println!("heat map: {path}");
    if o.passed() {
        eprintln!("the wrong pdf was NOT caught");
        std::process::exit(1);
    }
    println!("caught: the sampler does not match the pdf it claims");
}
