//! The proofs every registered sampler gets by being registered: each test loops over
//! `SamplerKind::all()` (and both dimension allocations where they differ) on square,
//! landscape and portrait films whose sides are not powers of two (Morton orders, strata and
//! pixel numbering are easiest to get wrong there). A new sampler is checked by these
//! without a line of its own; its own file adds what is particular to it.

use super::*;
use crate::named::Named;
use crate::rng::LANES;

/// Square, landscape and portrait films, no side a power of two.
const FILMS: [(u32, u32); 3] = [(7, 7), (13, 6), (6, 13)];
/// A complete count for every point kind (a power of four).
const SPP: u32 = 16;

/// Every registered sampler with each allocation that changes its points.
fn samplings() -> Vec<Sampling> {
    SamplerKind::all()
        .into_iter()
        .flat_map(|kind| {
            let n = if kind.allocates_dims() { 2 } else { 1 };
            [DimAlloc::Joint, DimAlloc::Padded][..n]
                .iter()
                .map(|&dims| Sampling {
                    kind,
                    dims,
                    run_samples: None,
                })
                .collect::<Vec<_>>()
        })
        .collect()
}

/// The groups of one camera sample of every pixel: (pixel, sample) -> the 9 values of the
/// film, light and BSDF groups, drawn through the lanes (what the renderer draws).
struct Draw;

impl Draw {
    fn run(s: Sampling, seed: u64, (w, h): (u32, u32)) -> Vec<Vec<[f32; 9]>> {
        let cfg = s.config(seed, 0, SPP, (w, h)).unwrap();
        struct V(SamplerConfig);
        impl LanesVisitor for V {
            type Output = Vec<Vec<[f32; 9]>>;
            fn visit<L: SamplerLanes>(self) -> Self::Output {
                let c = self.0;
                let mut out = Vec::new();
                for y in 0..c.height {
                    for x in 0..c.width {
                        let px = L::pixel(&c, x, y);
                        let mut samples = Vec::new();
                        for s0 in (0..SPP as u64).step_by(LANES) {
                            let mut lanes = L::start(px, s0);
                            // Each lane as a scalar sample must draw what the lanes draw.
                            let mut ones: Vec<L::One> = (0..LANES).map(|i| lanes.lane(i)).collect();
                            let (f, l, b) = (lanes.film(), lanes.light(), lanes.bsdf());
                            for (i, one) in ones.iter_mut().enumerate() {
                                let v = [
                                    f[0][i], f[1][i], l[0][i], l[1][i], l[2][i], l[3][i], b[0][i],
                                    b[1][i], b[2][i],
                                ];
                                let (sf, sl) = (one.film(), one.light());
                                let sb = one.bsdf();
                                let scalar = [
                                    sf.x,
                                    sf.y,
                                    sl.select,
                                    sl.primitive,
                                    sl.point.x,
                                    sl.point.y,
                                    sb.lobe,
                                    sb.direction.x,
                                    sb.direction.y,
                                ];
                                assert_eq!(
                                    v.map(f32::to_bits),
                                    scalar.map(f32::to_bits),
                                    "pixel ({x}, {y}) sample {}: lanes and scalar differ",
                                    s0 + i as u64
                                );
                                samples.push(v);
                            }
                        }
                        out.push(samples);
                    }
                }
                out
            }
        }
        s.kind.visit(V(cfg))
    }
}

fn what(s: &Sampling, film: (u32, u32)) -> String {
    format!(
        "{}:{} on {}x{}",
        s.kind.name(),
        s.dims.name(),
        film.0,
        film.1
    )
}

#[test]
fn every_sampler_is_registered_once_with_its_name() {
    let all = SamplerKind::all();
    assert_eq!(
        all[0],
        SamplerKind::default(),
        "the first registered is the default"
    );
    for (i, k) in all.iter().enumerate() {
        assert_eq!(all.iter().filter(|j| *j == k).count(), 1);
        assert_eq!(k.name().parse::<SamplerKind>(), Ok(*k));
        assert!(!k.help().is_empty());
        assert!(all[..i].iter().all(|j| j.name() != k.name()));
    }
}

/// Lanes equal scalar samples bitwise (inside `Draw::run`), every value lies in [0, 1), and
/// the same seed gives the same values while another seed changes every group.
#[test]
fn lanes_are_scalar_samples_in_the_unit_interval_and_follow_the_seed() {
    for s in samplings() {
        for film in FILMS {
            let a = Draw::run(s, 5, film);
            assert_eq!(a.len(), (film.0 * film.1) as usize);
            for v in a.iter().flatten().flatten() {
                assert!((0.0..1.0).contains(v), "{}: value {v}", what(&s, film));
            }
            let again = Draw::run(s, 5, film);
            assert!(a == again, "{}: not deterministic", what(&s, film));
            let other = Draw::run(s, 6, film);
            for d in 0..9 {
                let same = a
                    .iter()
                    .flatten()
                    .zip(other.iter().flatten())
                    .filter(|(p, q)| p[d] == q[d])
                    .count();
                assert!(
                    same * 10 < a.len() * SPP as usize,
                    "{}: dim {d} ignores the seed",
                    what(&s, film)
                );
            }
        }
    }
}

/// Every pixel's film points are its own (no two pixels of a film share their sequence),
/// and where the point kind promises structure at a complete count, each pixel's 16 film
/// points have it: one per cell of a 4x4 grid (jittered) or a (0, 4, 2)-net (nets).
#[test]
fn each_pixel_has_its_own_film_points_with_their_strata() {
    for s in samplings() {
        for film in FILMS {
            let d = Draw::run(s, 11, film);
            let points: Vec<Vec<(f32, f32)>> = d
                .iter()
                .map(|px| px.iter().map(|v| (v[0], v[1])).collect())
                .collect();
            for (i, p) in points.iter().enumerate() {
                for q in &points[i + 1..] {
                    assert!(
                        p != q,
                        "{}: two pixels share their film points",
                        what(&s, film)
                    );
                }
                match s.kind.points() {
                    PointKind::Random => {}
                    PointKind::Jittered => {
                        let mut cells = [0u32; 16];
                        for &(x, y) in p {
                            cells[(y * 4.0) as usize * 4 + (x * 4.0) as usize] += 1;
                        }
                        assert!(
                            cells.iter().all(|&c| c == 1),
                            "{}: pixel {i} {p:?}",
                            what(&s, film)
                        );
                    }
                    PointKind::ScrambledNet | PointKind::ShiftedNet => {
                        assert!(
                            is_02_net(p, 4),
                            "{}: pixel {i} is not a net",
                            what(&s, film)
                        );
                    }
                }
            }
        }
    }
}

/// Pooled over the film, each of the nine dimensions is uniform: Pearson's chi-square of 16
/// equal bins (expected count 49 or more), family-wise alpha 1e-3 (Sidak) over all samplers,
/// films and dimensions. A sampler that maps some pixels' points to a corner fails it.
#[test]
fn every_dimension_is_uniform_over_the_film() {
    let cases = samplings();
    let tests = cases.len() * FILMS.len() * 9;
    let alpha = 1.0 - (1.0f64 - 1e-3).powf(1.0 / tests as f64);
    // The upper 1 - alpha quantile of chi-square with 15 degrees of freedom.
    use statrs::distribution::{ChiSquared, ContinuousCDF};
    let crit = ChiSquared::new(15.0).unwrap().inverse_cdf(1.0 - alpha);
    for s in cases {
        for film in FILMS {
            let d = Draw::run(s, 23, film);
            let n = d.iter().map(Vec::len).sum::<usize>() as f64;
            for dim in 0..9 {
                let mut bins = [0.0f64; 16];
                for v in d.iter().flatten() {
                    bins[(v[dim] * 16.0) as usize] += 1.0;
                }
                let e = n / 16.0;
                let chi2: f64 = bins.iter().map(|&c| (c - e) * (c - e) / e).sum();
                assert!(
                    chi2 < crit,
                    "{} dim {dim}: chi2 {chi2:.1} > {crit:.1} ({bins:?})",
                    what(&s, film)
                );
            }
        }
    }
}
