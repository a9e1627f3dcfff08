//! The lane kernel against the per-sample definition, bitwise: fixed scenes that name each
//! path the lanes take, and random scenes (`scene::random`) for what no one thought to fix.

use super::*;
use crate::counts::Counts;
use crate::emitter::EmitterSelection;
use crate::named::Named;
use crate::rng::Rng;
use crate::scene::desc::{Heuristic, StrategyKind};
use glam::Vec3;

/// The values of samples `0 .. spp` of pixel (x, y) by their definition, one sample at a
/// time: the sampler's sample s (lane 0 of a batch that starts at s), `generate_ray`, `li`.
struct PerSample<'a> {
    scene: &'a Scene,
    direct: &'a crate::integrator::Direct<'a>,
    cfg: SamplerConfig,
    x: u32,
    y: u32,
    spp: u32,
}

impl LanesVisitor for PerSample<'_> {
    type Output = (Vec<Vec3>, Counts);
    fn visit<L: SamplerLanes>(self) -> (Vec<Vec3>, Counts) {
        let pixel = L::pixel(&self.cfg, self.x, self.y);
        let mut c = Counts::default();
        let li = (0..self.spp)
            .map(|s| {
                let mut one = L::start(pixel, s as u64).lane(0);
                let ray = self.scene.camera.generate_ray(self.x, self.y, &mut one);
                self.direct.li_counted(&ray, &mut one, &mut c)
            })
            .collect();
        (li, c)
    }
}

/// Renders with `kernel` and recomputes every pixel from its definition: the sampler's
/// sample (for `independent`, generator `for_sample(seed, pixel, s)`), `generate_ray`, `li`,
/// one sample at a time. The first pixel whose mean or variance differs in any bit is the
/// error, or counts (`Counts`) that differ from the per-sample ones; otherwise the count of
/// lit pixels.
fn per_sample_mismatch(kernel: &LaneKernel, settings: &RenderSettings) -> Result<u32, String> {
    let out = render_with(kernel, settings);
    let (scene, strategy) = (kernel.direct.scene, kernel.direct.strategy);
    let direct = crate::integrator::Direct::new(scene, strategy);
    let cam = &scene.camera;
    let cfg = settings.sampler_config((cam.width, cam.height))?;
    let mut lit = 0;
    let mut counts = Counts::default();
    for y in 0..cam.height {
        for x in 0..cam.width {
            let mut st = PixelStats::default();
            let (li, c) = settings.sampling.kind.visit(PerSample {
                scene,
                direct: &direct,
                cfg,
                x,
                y,
                spp: settings.spp,
            });
            counts += c;
            for batch in li.chunks(LANES) {
                let v = std::array::from_fn(|i| batch.get(i).copied().unwrap_or_default());
                st.push_batch(&v, batch.len());
            }
            let (mean, var) = st.finish();
            lit += (mean[0] > 0.0) as u32;
            let (got_mean, got_var) = (out.mean.get(x, y), out.variance.get(x, y));
            if got_mean.map(f64::to_bits) != mean.map(f64::to_bits)
                || got_var.map(f64::to_bits) != var.map(f64::to_bits)
            {
                return Err(format!(
                    "pixel ({x}, {y}): render mean {got_mean:?} variance {got_var:?}, per \
                     sample mean {mean:?} variance {var:?}"
                ));
            }
        }
    }
    if out.counts != counts {
        return Err(format!(
            "render counts {:?}, per sample {counts:?}",
            out.counts
        ));
    }
    Ok(lit)
}

/// The render loop starts samples eight at a time and `LaneKernel::li_lanes` shades them
/// eight at a time; every pixel must still be exactly the per-sample definition: generator
/// `for_sample(seed, pixel, s)`, `generate_ray`, `li`. spp 11 leaves a partial batch of
/// three. Every case must shade batches in lanes, and most of its hits there, so a change
/// that quietly sends a case to the scalar path fails here too.
#[test]
fn lane_samples_are_bitwise_the_per_sample_definition() {
    use crate::scene::desc::{FilterDesc, SceneDesc};
    let mis = crate::integrator::Strategy::combinations()
        .into_iter()
        .find(|s| s.kind == StrategyKind::Mis && s.emitter_samples == 1)
        .unwrap();
    let power = crate::integrator::Strategy {
        heuristic: Heuristic::Power,
        selection: EmitterSelection::Power,
        ..mis
    };
    let no_point_lights = |d: &mut SceneDesc| d.point_lights.clear();
    let tent = |d: &mut SceneDesc| d.film.filter = FilterDesc::Tent { radius: 1.0 };
    let keep = |_: &mut SceneDesc| {};
    // Vertex normals on the light mesh, tilted away from its face normal by up to 0.2
    // towards each vertex's offset from the centroid: light points with shading normals.
    let smooth_light = |d: &mut SceneDesc| {
        use crate::scene::desc::ShapeGeometry;
        for shape in d.shapes.iter_mut().filter(|s| s.emitter.is_some()) {
            if let ShapeGeometry::Mesh {
                positions,
                normals,
                indices,
            } = &mut shape.geometry
            {
                let [a, b, c] = indices[0].map(|i| positions[i as usize]);
                let ng = (b - a).cross(c - a).normalize();
                let centre = positions.iter().sum::<Vec3>() / positions.len() as f32;
                let size = positions
                    .iter()
                    .map(|p| p.distance(centre))
                    .fold(0.0, f32::max);
                let tilt = |p: Vec3| (ng + 0.2 * (p - centre) / size).normalize();
                *normals = Some(positions.iter().map(|&p| tilt(p)).collect());
            }
        }
    };
    // Rougher plates, seen at grazing angles: their slope inversions need the
    // lanes' extra vector step after the fixed ones.
    let rough_plates = |d: &mut SceneDesc| {
        use crate::bsdf::BsdfKind;
        use crate::sampling::microfacet::Microfacet;
        for shape in &mut d.shapes {
            if let BsdfKind::RoughConductor(rc) = &mut shape.bsdf.kind {
                rc.mf = Microfacet::new(rc.mf.distribution, 0.4, 0.4);
            }
        }
    };
    // Plates of a grey index other than the scene's eta 0, k 1, whose conductor term is
    // exactly 1 at every angle: the lanes' Fresnel with a value to get wrong.
    let grey_plates = |d: &mut SceneDesc| {
        use crate::bsdf::BsdfKind;
        for shape in &mut d.shapes {
            if let BsdfKind::RoughConductor(rc) = &mut shape.bsdf.kind {
                (rc.eta, rc.k) = (Vec3::splat(0.2), Vec3::splat(3.0));
            }
        }
    };
    let with = |kind, e, b, light_sampling| Strategy {
        kind,
        emitter_samples: e,
        bsdf_samples: b,
        light_sampling,
        ..power
    };
    use crate::emitter::LightSampling::{Area, SolidAngle};
    type Edit = dyn Fn(&mut SceneDesc);
    let cases: [(&str, &Edit, crate::integrator::Strategy); 16] = [
        ("cbox/cbox.xml", &keep, mis),
        // A light mesh of many triangles: the lanes' per-triangle records.
        ("cbox-meshlight/cbox-meshlight.xml", &keep, power),
        // The same with vertex normals: the lanes' smooth light points.
        ("cbox-meshlight/cbox-meshlight.xml", &smooth_light, power),
        (
            "cbox/cbox.xml",
            &keep,
            crate::integrator::Strategy {
                hide_emitters: true,
                ..power
            },
        ),
        ("cbox-twolights/cbox-twolights.xml", &keep, power),
        // Rough, smooth and two-sided materials: delta hits take the scalar path.
        ("cbox-materials/cbox-materials.xml", &no_point_lights, power),
        // With its point lights, drawn lane by lane.
        ("cbox-materials/cbox-materials.xml", &keep, power),
        ("veach-mis/veach-mis.xml", &tent, mis),
        ("veach-mis/veach-mis.xml", &rough_plates, power),
        ("veach-mis/veach-mis.xml", &grey_plates, power),
        // The other estimators and solid-angle sampling.
        (
            "cbox/cbox.xml",
            &keep,
            with(StrategyKind::Light, 1, 1, Area),
        ),
        (
            "cbox-materials/cbox-materials.xml",
            &keep,
            with(StrategyKind::Bsdf, 1, 2, Area),
        ),
        (
            "cbox-materials/cbox-materials.xml",
            &keep,
            with(StrategyKind::Light, 2, 1, SolidAngle),
        ),
        (
            "cbox-twolights/cbox-twolights.xml",
            &keep,
            with(StrategyKind::Mis, 2, 3, SolidAngle),
        ),
        (
            "veach-mis/veach-mis.xml",
            &keep,
            with(StrategyKind::MisOneSample, 1, 1, Area),
        ),
        (
            "veach-mis/veach-mis.xml",
            &keep,
            with(StrategyKind::MisOneSample, 2, 1, SolidAngle),
        ),
    ];
    for (rel, edit, strategy) in cases {
        let mut desc = crate::scene::bundled_tests::load(rel);
        (desc.film.width, desc.film.height) = (12, 9);
        edit(&mut desc);
        let scene = Scene::build(desc).unwrap();
        let settings = RenderSettings {
            spp: 11,
            seed: 5,
            first_sample: 0,
            threads: Some(1),
            progress: None,
            sampling: Default::default(),
        };
        let kernel = LaneKernel::new(&scene, strategy);
        let lit = per_sample_mismatch(&kernel, &settings)
            .unwrap_or_else(|e| panic!("{rel} {strategy:?}: {e}"));
        let cam = &scene.camera;
        assert!(lit > cam.width * cam.height / 2, "{rel}: {lit} lit pixels");
        let paths: std::collections::BTreeMap<_, _> = kernel.paths.counts().into_iter().collect();
        let batches = paths["uniform batch"] + paths["mixed batch"];
        assert!(
            batches * 8 > 4 * paths["scalar lane"],
            "{rel} {strategy:?}: most hits in lanes, {paths:?}"
        );
    }
}

/// Every estimator configuration: each registered strategy with either heuristic, one or
/// several samples per technique, every emitter choice (RIS over one and eight candidates),
/// every light sampling mode, emitters shown or hidden.
fn configurations() -> Vec<Strategy> {
    let mut v = Vec::new();
    for kind in StrategyKind::all() {
        for heuristic in Heuristic::all() {
            for (emitter_samples, bsdf_samples) in [(1, 1), (2, 1), (1, 2), (2, 3)] {
                for selection in EmitterSelection::every() {
                    for light_sampling in crate::emitter::LightSampling::all() {
                        for hide_emitters in [false, true] {
                            v.push(Strategy {
                                kind,
                                heuristic,
                                emitter_samples,
                                bsdf_samples,
                                selection,
                                light_sampling,
                                hide_emitters,
                            });
                        }
                    }
                }
            }
        }
    }
    v
}

/// Property test: random scenes (every material, mesh and sphere lights on both sides of the
/// lanes' eight-entry tables, smooth-shaded OBJ receivers and lights, point lights now and
/// then, any camera and filter) under a covered strategy, or now and then any other, render
/// bitwise as their per-sample definition. The lanes must cover exactly the scenes without
/// point lights under a covered strategy. `DIRECTLAB_PROPTEST_CASES` runs more seeds; a
/// failure names its seed, which alone reproduces the scene.
#[test]
fn random_scenes_render_bitwise_as_their_per_sample_definition() {
    use crate::scene::random::random_scene;
    use std::collections::BTreeMap;
    let cases: u64 = std::env::var("DIRECTLAB_PROPTEST_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(48);
    let dir = std::env::temp_dir().join(format!("directlab-random-{}", std::process::id()));
    let all = configurations();
    let mut seen: BTreeMap<String, u32> = BTreeMap::new();
    let mut tally = |what: String| *seen.entry(what).or_default() += 1;
    for seed in 0..cases {
        let r = random_scene(seed, &dir);
        let mut pick = Rng::new(seed, 77);
        let strategy = all[(pick.next_u32() as usize) % all.len()];
        let scene = Scene::build(r.desc).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        let kernel = LaneKernel::new(&scene, strategy);
        // Every sampler and allocation: the lanes draw each sample's numbers as the scalar
        // path does.
        let sampling = crate::sampler::Sampling {
            kind: crate::sampler::SamplerKind::all()
                [seed as usize % crate::sampler::SamplerKind::CHOICES.len()],
            dims: [
                crate::sampler::DimAlloc::Joint,
                crate::sampler::DimAlloc::Padded,
            ][(seed / 4 % 2) as usize],
            run_samples: None,
        };
        tally(format!(
            "sampler {} {}",
            sampling.kind.name(),
            sampling.dims.name()
        ));
        let settings = RenderSettings {
            spp: 11,
            seed: seed ^ 0xabc,
            first_sample: 0,
            threads: Some(1),
            progress: None,
            sampling,
        };
        let lit = per_sample_mismatch(&kernel, &settings)
            .unwrap_or_else(|e| panic!("seed {seed} ({strategy:?}): {e}"));
        tally("lanes".into());
        for (path, n) in kernel.paths.counts() {
            if n > 0 {
                tally(format!("path {path}"));
            }
        }
        tally(format!("strategy {}", strategy.kind.name()));
        tally(format!("heuristic {:?}", strategy.heuristic));
        let several = (strategy.emitter_samples, strategy.bsdf_samples) != (1, 1);
        tally(format!("several samples {several}"));
        tally(format!("light sampling {}", strategy.light_sampling.name()));
        if r.features.point_lights > 0 {
            tally("point lights".into());
        }
        tally(format!("selection {:?}", strategy.selection));
        tally(format!("hide_emitters {}", strategy.hide_emitters));
        if lit > 0 {
            tally("lit".into());
        }
        for m in &r.features.materials {
            tally(format!("material {m}"));
        }
        for l in &r.features.lights {
            tally(format!("light {l}"));
        }
        let n = r
            .features
            .lights
            .iter()
            .filter(|l| **l != "mesh-smooth")
            .count();
        tally(format!(
            "lights {}",
            if n > 8 { "over 8" } else { "up to 8" }
        ));
        if r.features.smooth_receivers > 0 {
            tally("smooth receiver".into());
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    // What the seeds must have sent through the lanes, for the test to be about them.
    let mut want = vec![
        "heuristic Balance".to_string(),
        "heuristic Power".into(),
        "several samples true".into(),
        "several samples false".into(),
        "point lights".into(),
        "hide_emitters true".into(),
        "hide_emitters false".into(),
        "smooth receiver".into(),
        "lights over 8".into(),
        "lights up to 8".into(),
    ];
    for path in crate::integrator::Paths::NAMES {
        want.push(format!("path {path}"));
    }
    for kind in StrategyKind::all() {
        want.push(format!("strategy {}", kind.name()));
    }
    for ls in crate::emitter::LightSampling::all() {
        want.push(format!("light sampling {}", ls.name()));
    }
    for s in EmitterSelection::every() {
        want.push(format!("selection {s:?}"));
    }
    for kind in crate::sampler::SamplerKind::all() {
        for dims in ["joint", "padded"] {
            want.push(format!("sampler {} {dims}", kind.name()));
        }
    }
    for m in [
        "diffuse",
        "rough-beckmann-grey",
        "rough-ggx",
        "rough-coloured",
        "twosided",
        "twosided-rough",
        "dielectric",
        "plastic",
        "roughplastic",
        "nori-microfacet",
    ] {
        want.push(format!("material {m}"));
    }
    for l in ["mesh", "mesh-big", "mesh-smooth", "sphere"] {
        want.push(format!("light {l}"));
    }
    let missing: Vec<_> = want.iter().filter(|w| !seen.contains_key(*w)).collect();
    assert!(
        missing.is_empty(),
        "not covered: {missing:?} (seen {seen:?})"
    );
    assert!(seen["lit"] >= seen["lanes"] * 3 / 4, "{seen:?}");
}
