//! Emitter choice: pmfs reported by every rule agree with their sampling, by counting (the
//! harness's chi-square) and at many shading points.

use crate::emitter::*;
use crate::math::Rgb;
use crate::rng::Rng;
use crate::stats::chi2::{chi2_sf, pearson};
use glam::Vec3;

fn emitters() -> Vec<Emitter> {
    let area = |area: f32, l: f32| {
        Emitter::Area(AreaLight {
            shape: 0,
            radiance: Rgb::splat(l),
            area,
            triangles: None,
        })
    };
    vec![
        area(0.01, 100.0),
        area(4.0, 0.5),
        area(1.0, 0.0),
        Emitter::Point(PointLight {
            position: Vec3::ZERO,
            intensity: Rgb::new(1.0, 2.0, 0.5),
        }),
        area(0.2, 3.0),
    ]
}

/// The count the lane tables check against their own, for both rules; none chooses
/// nothing.
#[test]
fn len_counts_the_emitters() {
    // Without shapes: the rules that need no bounds.
    for mode in point_independent() {
        let s = EmitterSelector::new(&emitters(), &[], mode);
        assert_eq!((s.len(), s.is_empty()), (5, false));
        let one = EmitterSelector::new(&emitters()[..1], &[], mode);
        assert_eq!((one.len(), one.is_empty()), (1, false));
        let none = EmitterSelector::new(&[], &[], mode);
        assert_eq!((none.len(), none.is_empty()), (0, true));
        assert!(none.sample(Vec3::ZERO, Vec3::ZERO, 0.5).is_none());
    }
}

#[test]
fn power_pmf_is_proportional_to_power() {
    let e = emitters();
    let sel = EmitterSelector::new(&e, &[], EmitterSelection::Power);
    let total: f64 = e.iter().map(Emitter::power).sum();
    for (i, em) in e.iter().enumerate() {
        assert!((sel.pmf(Vec3::ZERO, Vec3::ZERO, i) as f64 - em.power() / total).abs() < 1e-6);
    }
    // pi * A * L for area lights, 4 pi * luminance(I) for point lights.
    assert!((e[0].power() - std::f64::consts::PI * 0.01 * 100.0).abs() < 1e-4);
    assert_eq!(sel.pmf(Vec3::ZERO, Vec3::ZERO, 2), 0.0);
}

/// `single` is `sample`'s answer for every u of one emitter, whatever its power, and
/// None for more (or none).
#[test]
fn single_is_what_sample_returns_for_one_emitter() {
    let mut rng = Rng::new(8, 3);
    let below_one = f32::from_bits(1.0f32.to_bits() - 1);
    for (k, e) in emitters().into_iter().enumerate() {
        for mode in point_independent() {
            let sel = EmitterSelector::new(std::slice::from_ref(&e), &[], mode);
            let single = sel.single().unwrap();
            for u in [0.0, 0.5, below_one]
                .into_iter()
                .chain((0..1000).map(|_| rng.next_f32()))
            {
                assert_eq!(
                    sel.sample(Vec3::ZERO, Vec3::ZERO, u),
                    Some((0, single)),
                    "emitter {k}, {mode:?}, u {u}"
                );
            }
        }
    }
    for mode in point_independent() {
        assert_eq!(EmitterSelector::new(&emitters(), &[], mode).single(), None);
        assert_eq!(EmitterSelector::new(&[], &[], mode).single(), None);
    }
}

/// Chi-square of 1M choices against the pmf, alpha = 0.01, for both selection modes; and
/// the sampled pmf equals pmf(i).
#[test]
fn choice_frequencies_match_pmf() {
    let e = emitters();
    for mode in point_independent() {
        let sel = EmitterSelector::new(&e, &[], mode);
        let n = 1_000_000;
        let mut counts = vec![0.0f64; e.len()];
        let mut rng = Rng::new(31, 7);
        for _ in 0..n {
            let (i, pmf) = sel.sample(Vec3::ZERO, Vec3::ZERO, rng.next_f32()).unwrap();
            assert_eq!(pmf, sel.pmf(Vec3::ZERO, Vec3::ZERO, i));
            counts[i] += 1.0;
        }
        let mut cells: Vec<(f64, f64)> = Vec::new();
        for (i, &c) in counts.iter().enumerate() {
            let expected = sel.pmf(Vec3::ZERO, Vec3::ZERO, i) as f64 * n as f64;
            if expected == 0.0 {
                assert_eq!(c, 0.0, "emitter {i} has pmf 0 but was chosen");
            } else {
                cells.push((c, expected));
            }
        }
        let p = pearson(&mut cells, 5.0).unwrap();
        let pv = chi2_sf(p.statistic, p.dof);
        assert!(
            pv > 0.01,
            "{mode:?}: chi2 {} dof {} p {pv}",
            p.statistic,
            p.dof
        );
    }
}

// ---- The shading-point-dependent choices (exhaustive, bvh) ----

use crate::geometry::{Mesh, Shape, ShapeKind, Sphere};
use crate::sampling::warps::square_to_uniform_sphere;

/// Every registered rule (and RIS): each gets the pmf checks below by being registered.
fn rules() -> Vec<EmitterSelection> {
    EmitterSelection::every()
}

/// The rules whose choice is the same at every shading point.
fn point_independent() -> Vec<EmitterSelection> {
    rules().into_iter().filter(|m| !m.at_point()).collect()
}

/// A mesh emitter of these triangles (and vertex normals), as the scene builder makes one.
fn mesh_light(
    shapes: &mut Vec<Shape>,
    emitters: &mut Vec<Emitter>,
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    indices: Vec<[u32; 3]>,
    radiance: f32,
) {
    let mesh = Mesh::new(positions, normals, indices);
    let area = (0..mesh.indices.len()).map(|t| mesh.triangle_area(t)).sum();
    emitters.push(Emitter::Area(AreaLight {
        shape: shapes.len() as u32,
        radiance: Rgb::splat(radiance),
        area,
        triangles: None,
    }));
    shapes.push(Shape {
        kind: ShapeKind::Mesh(mesh),
        material: 0,
        emitter: Some(emitters.len() as u32 - 1),
    });
}

/// `n` lights of every kind at random places, sizes and orientations, in a box of half-size
/// `extent`: one-sided triangles and quads, smooth-shaded meshes, spheres, point lights, and
/// lights that emit nothing (zero radiance, a degenerate triangle).
fn random_lights(seed: u64, n: usize, extent: f32) -> (Vec<Emitter>, Vec<Shape>) {
    let mut rng = Rng::new(seed, 5);
    let (mut shapes, mut emitters) = (Vec::new(), Vec::new());
    for k in 0..n {
        let c = (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0) * extent;
        let size = extent * 0.2 * (0.05 + rng.next_f32());
        let radiance = 0.1 + 10.0 * rng.next_f32();
        let d = |rng: &mut Rng| square_to_uniform_sphere(rng.next_2d());
        match k % 7 {
            0 | 1 => {
                let v = vec![c, c + d(&mut rng) * size, c + d(&mut rng) * size];
                mesh_light(
                    &mut shapes,
                    &mut emitters,
                    v,
                    None,
                    vec![[0, 1, 2]],
                    radiance,
                );
            }
            2 => {
                let (a, b) = (d(&mut rng) * size, d(&mut rng) * size);
                let v = vec![c - a - b, c + a - b, c + a + b, c - a + b];
                let idx = vec![[0, 1, 2], [0, 2, 3]];
                mesh_light(&mut shapes, &mut emitters, v, None, idx, radiance);
            }
            3 => {
                // A bent strip with vertex normals spread up to ~60 degrees.
                let axis = d(&mut rng);
                let v: Vec<Vec3> = (0..6)
                    .map(|j| c + d(&mut rng) * size * (0.5 + j as f32 * 0.1))
                    .collect();
                let normals = (0..6)
                    .map(|_| (axis + d(&mut rng) * 0.6).normalize())
                    .collect();
                let idx = vec![[0, 1, 2], [1, 3, 2], [2, 3, 4], [3, 5, 4]];
                mesh_light(&mut shapes, &mut emitters, v, Some(normals), idx, radiance);
            }
            4 => {
                emitters.push(Emitter::Area(AreaLight {
                    shape: shapes.len() as u32,
                    radiance: Rgb::splat(radiance),
                    area: 4.0 * std::f32::consts::PI * size * size,
                    triangles: None,
                }));
                shapes.push(Shape {
                    kind: ShapeKind::Sphere(Sphere {
                        center: c,
                        radius: size,
                        flip_normals: false,
                    }),
                    material: 0,
                    emitter: Some(emitters.len() as u32 - 1),
                });
            }
            5 => emitters.push(Emitter::Point(PointLight {
                position: c,
                intensity: Rgb::splat(radiance * size * size),
            })),
            _ => {
                // Emits nothing: no radiance, or a triangle without area.
                let (v, l) = if rng.next_f32() < 0.5 {
                    (vec![c, c + Vec3::X * size, c + Vec3::Y * size], 0.0)
                } else {
                    (
                        vec![c, c + Vec3::X * size, c + Vec3::X * 2.0 * size],
                        radiance,
                    )
                };
                mesh_light(&mut shapes, &mut emitters, v, None, vec![[0, 1, 2]], l);
            }
        }
    }
    (emitters, shapes)
}

/// Shading points in and around the lights' box, with random normals (and none).
fn shading_points(seed: u64, n: usize, extent: f32) -> Vec<(Vec3, Vec3)> {
    let mut rng = Rng::new(seed, 77);
    (0..n)
        .map(|k| {
            let p =
                (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 3.0 - 1.5) * extent;
            let n = match k % 4 {
                0 => Vec3::ZERO,
                _ => square_to_uniform_sphere(rng.next_2d()),
            };
            (p, n)
        })
        .collect()
}

/// Points on light e that send light towards p, sampled (64 per light): if any does, the
/// light can contribute at p (a receiver of any orientation: the choice's receiver term is
/// two-sided).
fn can_contribute(e: &Emitter, shapes: &[Shape], p: Vec3, rng: &mut Rng) -> bool {
    if e.power() <= 0.0 {
        return false;
    }
    match e {
        Emitter::Point(l) => l.position != p,
        Emitter::Area(a) => (0..64).any(|_| match &shapes[a.shape as usize].kind {
            ShapeKind::Mesh(m) => {
                let t = (rng.next_f32() * m.indices.len() as f32) as usize;
                let b = crate::sampling::warps::square_to_uniform_triangle(rng.next_2d());
                let sp = m.surface_point(t.min(m.indices.len() - 1), b, 0);
                m.triangle_area(t.min(m.indices.len() - 1)) > 0.0 && sp.ns.dot(p - sp.p) > 0.0
            }
            ShapeKind::Sphere(s) => {
                let sp = s.surface_point_along(square_to_uniform_sphere(rng.next_2d()), 0);
                sp.ns.dot(p - sp.p) > 0.0
            }
        }),
    }
}

/// For both point-dependent rules, random light sets of 1 to 300 lights and 40 shading points
/// each: the pmf a choice reports is `pmf` at that point (1e-6 relative; it is bitwise), the
/// pmfs plus the probability of choosing nothing sum to 1 (1e-6), no light that can send
/// light to the point has pmf 0, and a light that emits nothing is never chosen.
#[test]
fn point_choices_report_their_pmf_and_miss_no_light() {
    let mut rng = Rng::new(12, 3);
    for (seed, n) in [(1u64, 1usize), (2, 2), (3, 7), (4, 50), (5, 300)] {
        let (emitters, shapes) = random_lights(seed, n, 2.0);
        let never = EmitterSelector::never_chosen(&emitters, &shapes);
        for mode in rules() {
            let sel = EmitterSelector::new(&emitters, &shapes, mode);
            for (p, nrm) in shading_points(seed, 40, 2.0) {
                let pmfs: Vec<f32> = (0..n).map(|i| sel.pmf(p, nrm, i)).collect();
                let sum: f64 = pmfs.iter().map(|&x| x as f64).sum();
                let none = sel.none_probability(p, nrm);
                assert!(
                    (sum + none - 1.0).abs() < 1e-6,
                    "{mode} n {n} at {p}: sum {sum} + none {none}"
                );
                for (i, e) in emitters.iter().enumerate() {
                    // Rules blind to the point (uniform) may choose a light that emits
                    // nothing; the others must not.
                    if never.contains(&i) && mode.at_point() {
                        assert_eq!(pmfs[i], 0.0, "{mode}: light {i} emits nothing");
                    } else if can_contribute(e, &shapes, p, &mut rng) {
                        assert!(
                            pmfs[i] > 0.0,
                            "{mode} n {n}: light {i} can light {p} but has pmf 0"
                        );
                    }
                }
                for _ in 0..200 {
                    if let Some((i, pmf)) = sel.sample(p, nrm, rng.next_f32()) {
                        let want = pmfs[i];
                        assert!(
                            (pmf - want).abs() <= 1e-6 * want,
                            "{mode}: sampled pmf {pmf} vs pmf {want}"
                        );
                        assert!(pmf > 0.0);
                    }
                }
            }
        }
    }
}

/// Pearson's chi-square of 200k choices against the pmfs, with a bin for choosing nothing
/// where that has probability, at 6 shading points per rule over 300 random lights; each
/// test at alpha = 0.01 Sidak-corrected over the 6 points of every rule.
#[test]
fn point_choice_counts_match_their_pmf() {
    let (emitters, shapes) = random_lights(9, 300, 2.0);
    let n = emitters.len();
    let draws = 200_000;
    let alpha = 1.0 - (1.0f64 - 0.01).powf(1.0 / (6 * rules().len()) as f64);
    for mode in rules() {
        let sel = EmitterSelector::new(&emitters, &shapes, mode);
        for (k, (p, nrm)) in shading_points(21, 6, 2.0).into_iter().enumerate() {
            let mut counts = vec![0.0f64; n + 1];
            let mut rng = Rng::new(40 + k as u64, 1);
            for _ in 0..draws {
                match sel.sample(p, nrm, rng.next_f32()) {
                    Some((i, _)) => counts[i] += 1.0,
                    None => counts[n] += 1.0,
                }
            }
            let mut cells = Vec::new();
            for (i, &c) in counts.iter().enumerate() {
                let prob = if i < n {
                    sel.pmf(p, nrm, i) as f64
                } else {
                    sel.none_probability(p, nrm)
                };
                if prob == 0.0 {
                    assert_eq!(c, 0.0, "{mode}: bin {i} has probability 0 but was drawn");
                } else {
                    cells.push((c, prob * draws as f64));
                }
            }
            let t = pearson(&mut cells, 5.0).unwrap();
            let pv = chi2_sf(t.statistic, t.dof);
            assert!(
                pv > alpha,
                "{mode} point {k}: chi2 {} dof {} p {pv}",
                t.statistic,
                t.dof
            );
        }
    }
}

/// The pmfs at a point do not change when the scene (lights and point) is scaled by 1e-3 or
/// 1e3 (area lights only: a point light's share changes with the unit, as its irradiance
/// does), to within the rounding of the scaled vertices: 1e-4 relative plus 1e-7. (A light
/// seen just inside its cutoff has an importance proportional to a small cosine, which the
/// vertices' rounding moves by ~1e-4 of itself; pbrt-v4's clamp changes pmfs by factors.)
#[test]
fn point_choices_do_not_depend_on_the_unit() {
    let (emitters, shapes) = random_lights(17, 120, 2.0);
    // Lights that emit at this scale (a degenerate triangle can gain an area from the
    // rounding of scaled vertices).
    let keep: Vec<usize> = (0..emitters.len())
        .filter(|&i| !emitters[i].is_delta() && LightBounds::of(&emitters[i], &shapes).is_some())
        .collect();
    let scaled = |s: f32| -> (Vec<Emitter>, Vec<Shape>) {
        let mut out_e = Vec::new();
        let mut out_s = Vec::new();
        for &i in &keep {
            let Emitter::Area(a) = &emitters[i] else {
                unreachable!()
            };
            let kind = match &shapes[a.shape as usize].kind {
                ShapeKind::Mesh(m) => ShapeKind::Mesh(Mesh::new(
                    m.positions.iter().map(|p| *p * s).collect(),
                    m.normals.clone(),
                    m.indices.clone(),
                )),
                ShapeKind::Sphere(sp) => ShapeKind::Sphere(Sphere {
                    center: sp.center * s,
                    radius: sp.radius * s,
                    ..*sp
                }),
            };
            out_e.push(Emitter::Area(AreaLight {
                shape: out_s.len() as u32,
                area: a.area * s * s,
                ..a.clone()
            }));
            out_s.push(Shape {
                kind,
                material: 0,
                emitter: Some(out_e.len() as u32 - 1),
            });
        }
        (out_e, out_s)
    };
    let (e1, s1) = scaled(1.0);
    for mode in rules() {
        let base = EmitterSelector::new(&e1, &s1, mode);
        for s in [1e-3f32, 1e3] {
            let (es, ss) = scaled(s);
            let other = EmitterSelector::new(&es, &ss, mode);
            for (p, nrm) in shading_points(3, 30, 2.0) {
                for i in 0..e1.len() {
                    let (a, b) = (base.pmf(p, nrm, i), other.pmf(p * s, nrm, i));
                    assert!(
                        (a - b).abs() <= 1e-4 * a.max(b) + 1e-7,
                        "{mode} scale {s}, light {i} at {p}: {a} vs {b}"
                    );
                }
            }
        }
    }
}

/// Lights spread over 32 octaves (quads of size 0.1 * 2^(k/2) at distance 2^(k/2), all facing the
/// origin) make a tree deeper than 32 levels (pbrt-v4's bit trail stops there): it builds,
/// its pmfs sum to 1 and match the choices' (chi-square, 400k draws, alpha = 0.01), and the
/// choices report them.
#[test]
fn a_deep_tree_builds_and_samples() {
    let (mut shapes, mut emitters) = (Vec::new(), Vec::new());
    for k in 0..64 {
        let s = 2f32.powf(k as f32 / 2.0);
        let c = Vec3::new(s, 0.0, 0.0);
        let h = 0.05 * s;
        // Facing -x, towards the origin.
        let v = vec![
            c + Vec3::new(0.0, -h, -h),
            c + Vec3::new(0.0, -h, h),
            c + Vec3::new(0.0, h, h),
            c + Vec3::new(0.0, h, -h),
        ];
        mesh_light(
            &mut shapes,
            &mut emitters,
            v,
            None,
            vec![[0, 1, 2], [0, 2, 3]],
            1.0,
        );
    }
    let sel = EmitterSelector::new(&emitters, &shapes, EmitterSelection::Bvh);
    let (depth, _) = sel.tree_stats().unwrap();
    assert!(depth > 32, "depth {depth}");
    let (p, nrm) = (Vec3::new(-0.5, 0.1, 0.0), Vec3::X);
    let pmfs: Vec<f64> = (0..64).map(|i| sel.pmf(p, nrm, i) as f64).collect();
    assert!((pmfs.iter().sum::<f64>() - 1.0).abs() < 1e-6);
    let zero: Vec<usize> = (0..64).filter(|&i| pmfs[i] == 0.0).collect();
    assert!(zero.is_empty(), "pmf 0 for {zero:?}: {pmfs:?}");
    let draws = 400_000;
    let mut counts = vec![0.0f64; 64];
    let mut rng = Rng::new(5, 5);
    for _ in 0..draws {
        let (i, pmf) = sel.sample(p, nrm, rng.next_f32()).unwrap();
        assert_eq!(pmf as f64, pmfs[i]);
        counts[i] += 1.0;
    }
    let mut cells: Vec<(f64, f64)> = counts
        .iter()
        .zip(&pmfs)
        .map(|(&c, &q)| (c, q * draws as f64))
        .collect();
    let t = pearson(&mut cells, 5.0).unwrap();
    let pv = chi2_sf(t.statistic, t.dof);
    assert!(pv > 0.01, "chi2 {} dof {} p {pv}", t.statistic, t.dof);
}

#[test]
fn selections_parse_and_name_themselves() {
    for s in [
        "uniform",
        "power",
        "exhaustive",
        "bvh",
        "ris:1",
        "ris:32",
        "ris:256",
    ] {
        let sel: EmitterSelection = s.parse().unwrap();
        assert_eq!(sel.name(), s);
    }
    assert_eq!(
        "ris:8".parse::<EmitterSelection>(),
        Ok(EmitterSelection::Ris(8))
    );
    for bad in ["ris", "ris:0", "ris:257", "ris:x", "tree", ""] {
        let e = bad.parse::<EmitterSelection>().unwrap_err();
        assert!(
            e.contains("expected uniform, power, exhaustive, bvh or ris:M"),
            "{e}"
        );
    }
    assert!(EmitterSelection::Bvh.at_point() && !EmitterSelection::Ris(4).at_point());
    // Every registered rule: a unique name and short form that parse back, and help.
    for (i, r) in RULES.iter().enumerate() {
        assert_eq!(r.name.parse::<EmitterSelection>(), Ok(r.value));
        assert_eq!(
            (r.value.name(), r.value.short()),
            (r.name.to_string(), r.short.to_string())
        );
        assert!(!r.help.is_empty());
        assert!(RULES[..i]
            .iter()
            .all(|o| o.name != r.name && o.short != r.short && o.value != r.value));
    }
    assert!(rules().len() > RULES.len(), "RIS is checked too");
}
