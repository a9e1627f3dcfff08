//! The environment emitter on a small procedural sky with a sun: its sampler agrees with its
//! density and radiance, both integrate as they must, rotation moves the map, compensation
//! drops exactly the texels at or below the mean, and bad maps are named.

use super::*;
use crate::rng::Rng;
use crate::sampling::warps::square_to_uniform_sphere;

/// A 64 x 32 sky: blue above, dim ground below, and a bright sun of about 3 x 3 texels.
fn sky() -> Image {
    let (w, h) = (64u32, 32u32);
    let mut data = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let v = (y as f64 + 0.5) / h as f64;
            let base = if v < 0.5 {
                [0.3 + 0.4 * v, 0.5 + 0.4 * v, 1.0]
            } else {
                [0.1, 0.08, 0.05]
            };
            let sun = (x as i32 - 13).abs() <= 1 && (y as i32 - 9).abs() <= 1;
            data.push(if sun { [500.0, 480.0, 400.0] } else { base });
        }
    }
    Image {
        width: w,
        height: h,
        data,
    }
}

fn env(compensation: bool) -> EnvMap {
    EnvMap::new(&sky(), "sky", 1.5, Mat3::IDENTITY, compensation).unwrap()
}

/// 200,000 samples: the density and radiance `sample` returns are `pdf` and `eval` of its
/// direction (relative 1e-3; a direction that rounds onto a texel edge may land in the
/// neighbouring texel: at most 0.1 % of samples); and E[L / pdf] is the integral of L over
/// the sphere (from the texels' solid angles) within 4 standard errors.
#[test]
fn samples_agree_with_pdf_and_eval_and_integrate_the_radiance() {
    let e = env(false);
    let mut rng = Rng::new(4, 4);
    let n = 200_000;
    let (mut sum, mut sq, mut off) = (0.0f64, 0.0f64, 0);
    for _ in 0..n {
        let Some((d, l, pdf)) = e.sample(rng.next_2d()) else {
            continue;
        };
        assert!((d.length() - 1.0).abs() < 1e-5);
        if (e.pdf(d) - pdf).abs() > 1e-3 * pdf || e.eval(d) != l {
            off += 1;
        }
        let v = luminance(l) as f64 / pdf as f64;
        sum += v;
        sq += v * v;
    }
    assert!(
        off <= n / 1000,
        "{off} samples disagree with pdf() or eval()"
    );
    let mean = sum / n as f64;
    let se = ((sq / n as f64 - mean * mean) / n as f64).sqrt();
    let truth = 4.0 * PI as f64 * e.mean_luminance();
    assert!((mean - truth).abs() < 4.0 * se, "{mean} +- {se} vs {truth}");
    // The sun makes the environment far from uniform: importance sampling must show it.
    assert!(se / mean < 0.01, "relative se {}", se / mean);
}

/// The density integrates to 1 over the sphere: the mean of 4 pi pdf(w) over 400,000
/// uniform directions, within 4 standard errors, for the table and the compensated table.
#[test]
fn the_density_integrates_to_one() {
    for comp in [false, true] {
        let e = env(comp);
        let mut rng = Rng::new(8, 1);
        let n = 400_000;
        let (mut sum, mut sq) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let v = 4.0 * PI as f64 * e.pdf(square_to_uniform_sphere(rng.next_2d())) as f64;
            sum += v;
            sq += v * v;
        }
        let mean = sum / n as f64;
        let se = ((sq / n as f64 - mean * mean) / n as f64).sqrt();
        assert!(
            (mean - 1.0).abs() < 4.0 * se,
            "compensation {comp}: {mean} +- {se}"
        );
    }
}

/// Compensation samples only texels whose luminance x sin(theta) is above the table's mean
/// (here the sun and the bright sky), and leaves the radiance as it was.
#[test]
fn compensation_drops_the_texels_at_or_below_the_mean() {
    let (plain, comp) = (env(false), env(true));
    assert!(comp.compensated && !plain.compensated);
    let img = sky();
    let (w, h) = (img.width as usize, img.height as usize);
    let weight = |i: usize| {
        let theta = PI as f64 * ((i / w) as f64 + 0.5) / h as f64;
        let p = img.data[i];
        luminance(Rgb::new(p[0] as f32, p[1] as f32, p[2] as f32)) as f64 * theta.sin()
    };
    let mean = (0..w * h).map(weight).sum::<f64>() / (w * h) as f64;
    for i in 0..w * h {
        let uv = Vec2::new(
            ((i % w) as f32 + 0.5) / w as f32,
            ((i / w) as f32 + 0.5) / h as f32,
        );
        let d = latlong_direction(uv);
        assert_eq!(comp.pdf(d) > 0.0, weight(i) > mean, "texel {i}");
        assert_eq!(comp.eval(d), plain.eval(d));
    }
}

/// A rotation moves the map: the rotated map seen along R d is the map seen along d.
#[test]
fn to_world_rotates_the_map() {
    let r = Mat3::from_rotation_y(0.7) * Mat3::from_rotation_x(-0.3);
    let rotated = EnvMap::new(&sky(), "sky", 1.5, r, false).unwrap();
    let e = env(false);
    let mut rng = Rng::new(3, 3);
    let mut same = 0;
    for _ in 0..1000 {
        let d = square_to_uniform_sphere(rng.next_2d());
        same += (rotated.eval(r * d) == e.eval(d)) as u32;
        assert!((rotated.pdf(r * d) - e.pdf(d)).abs() <= 1e-3 * e.pdf(d).max(1e-3));
    }
    assert!(same >= 995, "{same}/1000");
}

#[test]
fn bad_maps_are_named() {
    let mut black = sky();
    black.data.iter_mut().for_each(|p| *p = [0.0; 3]);
    let err =
        |img: &Image, scale: f32, r: Mat3| EnvMap::new(img, "m.exr", scale, r, false).unwrap_err();
    assert!(err(&black, 1.0, Mat3::IDENTITY).contains("m.exr: every texel has zero luminance"));
    let mut nan = sky();
    nan.data[70][1] = f64::NAN;
    let e = err(&nan, 1.0, Mat3::IDENTITY);
    assert!(
        e.contains("m.exr: pixel (6, 1)") && e.contains("finite"),
        "{e}"
    );
    let mut neg = sky();
    neg.data[0][2] = -1.0;
    assert!(err(&neg, 1.0, Mat3::IDENTITY).contains("pixel (0, 0)"));
    assert!(err(&sky(), 0.0, Mat3::IDENTITY).contains("scale 0"));
    assert!(err(&sky(), 1.0, Mat3::from_diagonal(Vec3::splat(2.0))).contains("rotation"));
    let empty = Image {
        width: 0,
        height: 0,
        data: Vec::new(),
    };
    assert!(err(&empty, 1.0, Mat3::IDENTITY).contains("empty"));
}

/// The table weighs texels by sin(theta): a constant map is sampled (nearly) uniformly over
/// the sphere, its density 1 / 4 pi away from the poles (to 1 % with 512 rows: within a row the
/// density varies as sin(theta at its centre) / sin(theta)),
/// where a table of luminance alone would crowd the poles (1 / 2 pi^2 at the equator).
#[test]
fn a_constant_map_is_sampled_uniformly_over_the_sphere() {
    let flat = Image {
        width: 16,
        height: 512,
        data: vec![[1.0; 3]; 16 * 512],
    };
    let e = EnvMap::new(&flat, "flat", 1.0, Mat3::IDENTITY, false).unwrap();
    for theta in [0.6f32, 0.9, 1.4, 2.2, 2.6] {
        let d = Vec3::new(theta.sin() * 0.6, theta.cos(), -theta.sin() * 0.8);
        let p = e.pdf(d) * 4.0 * PI;
        assert!((p - 1.0).abs() < 0.01, "theta {theta}: 4 pi pdf = {p}");
    }
}

/// The bundled sky (`scenes/envmap/make_sky.py`) loads, and its sun texels draw their share
/// of the table (luminance x sin(theta)) among 100,000 samples, within 4 standard errors;
/// the sun is most of the map's light (71 %).
#[test]
fn the_bundled_sky_loads_and_its_sun_draws_its_share() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/envmap/sky.exr");
    let img = crate::film::read_exr(std::path::Path::new(path)).unwrap();
    assert_eq!((img.width, img.height), (256, 128));
    let e = EnvMap::new(&img, path, 1.0, Mat3::IDENTITY, false).unwrap();
    let (w, h) = (img.width as usize, img.height as usize);
    let (mut sun, mut all) = (0.0f64, 0.0f64);
    for (i, p) in img.data.iter().enumerate() {
        let theta = PI as f64 * ((i / w) as f64 + 0.5) / h as f64;
        let v = luminance(Rgb::new(p[0] as f32, p[1] as f32, p[2] as f32)) as f64 * theta.sin();
        all += v;
        if p[0] >= 1000.0 {
            sun += v;
        }
    }
    let share = sun / all;
    assert!(share > 0.6, "the sun's share of the light: {share}");
    let mut rng = Rng::new(6, 6);
    let n = 100_000;
    let hits = (0..n)
        .filter_map(|_| e.sample(rng.next_2d()))
        .filter(|(_, l, _)| l.x >= 1000.0)
        .count();
    let f = hits as f64 / n as f64;
    let se = (share * (1.0 - share) / n as f64).sqrt();
    assert!(
        (f - share).abs() < 4.0 * se,
        "sun drawn {f}, share {share} +- {se}"
    );
}
