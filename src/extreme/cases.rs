//! The extreme cases of issue 6, each a probe of one floor point with a reference value.

use super::reference::{lambert_irradiance, quad_quadrature};
use super::scenes::{probe_scene, Probe, Quad};
use crate::bsdf::fresnel::{fresnel_conductor, fresnel_dielectric};
use crate::emitter::LightSampling;
use crate::integrator::Strategy;
use crate::math::Rgb;
use crate::scene::desc::{BsdfDesc, MicrofacetDistribution, SceneDesc, StrategyKind};
use crate::scene::fixtures::{diffuse, transform};
use crate::scene::{load_scene, Scene};
use glam::{Mat4, Vec3};
use std::f64::consts::PI;
use std::path::Path;

pub const ALBEDO: f32 = 0.5;

/// A pure technique that cannot find a case's light (or lobe) at any affordable sample
/// count: its mean misses a contribution it reaches with probability ~1e-5 or less.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blind {
    /// BSDF sampling alone.
    Bsdf,
    /// Light sampling alone, by area or by solid angle.
    Light,
    /// Light sampling alone, by area.
    LightArea,
}

impl Blind {
    pub fn covers(self, s: &Strategy) -> bool {
        match self {
            Blind::Bsdf => s.kind == StrategyKind::Bsdf,
            Blind::Light => s.kind == StrategyKind::Light,
            Blind::LightArea => {
                s.kind == StrategyKind::Light && s.light_sampling == LightSampling::Area
            }
        }
    }
}

/// One probe: a scene, its reference radiance (channel 0) and where that number comes from.
pub struct Case {
    pub name: String,
    /// The heading the case belongs to.
    pub group: &'static str,
    pub desc: SceneDesc,
    pub reference: f64,
    pub reference_from: &'static str,
    /// A substring the scene build must warn with.
    pub warning: Option<&'static str>,
    /// What the case stresses, for the report.
    pub about: &'static str,
    /// Techniques blind to part of the integrand, and why.
    pub blind: Vec<(Blind, &'static str)>,
}

impl Case {
    fn about(mut self, s: &'static str) -> Case {
        self.about = s;
        self
    }

    fn blind(mut self, b: Blind, why: &'static str) -> Case {
        self.blind.push((b, why));
        self
    }

    /// Why strategy `s` cannot be expected to converge here, if it cannot.
    pub fn blind_for(&self, s: &Strategy) -> Option<&'static str> {
        self.blind
            .iter()
            .find(|(b, _)| b.covers(s))
            .map(|(_, w)| *w)
    }
}

fn case(name: &str, group: &'static str, desc: SceneDesc) -> Case {
    Case {
        name: name.to_string(),
        group,
        desc,
        reference: f64::NAN,
        reference_from: "",
        warning: None,
        about: "",
        blind: Vec::new(),
    }
}

/// Diffuse probe: albedo / pi times Lambert's irradiance of every emitter, at the target.
fn lambert(mut c: Case) -> Case {
    c.reference = ALBEDO as f64 / PI * lambert_irradiance(&c.desc, probe_target(&c.desc), Vec3::Z);
    c.reference_from = "Lambert";
    c
}

/// The floor point the probe camera looks at (its ray meets z = 0).
fn probe_target(desc: &SceneDesc) -> Vec3 {
    let m = desc.camera.to_world;
    let (o, d) = (m.transform_point3(Vec3::ZERO), m.transform_vector3(Vec3::Z));
    o - d * (o.z / d.z)
}

fn floor() -> BsdfDesc {
    diffuse(ALBEDO)
}

/// A square light of `side` centred at `center`, facing the point `toward`.
fn facing(center: Vec3, toward: Vec3, side: f32) -> Quad {
    let n = (toward - center).normalize();
    let u = n.any_orthonormal_vector();
    let h = side * 0.5;
    Quad {
        center,
        u: u * h,
        v: n.cross(u) * h,
    }
}

pub fn light_size() -> Vec<Case> {
    let tiny = Quad::ceiling(Vec3::Z, 1e-4);
    let huge = Quad::ceiling(Vec3::Z, 200.0);
    let above = Probe::above(Vec3::ZERO, 0.5);
    let g = "light size";
    vec![
        lambert(case(
            "tiny-bright",
            g,
            probe_scene(1.0, floor(), vec![tiny.shape(1e8)], above),
        ))
        .about("side 1e-4, radiance 1e8, 1 above the probe")
        .blind(
            Blind::Bsdf,
            "cosine sampling hits the 1e-8 sr light with p ~ 3e-9",
        ),
        lambert(case(
            "huge-dim",
            g,
            probe_scene(100.0, floor(), vec![huge.shape(1e-2)], above),
        ))
        .about("side 200 at height 1 (89.4 deg half-angle), radiance 1e-2"),
        lambert(case(
            "tiny-and-huge",
            g,
            probe_scene(
                100.0,
                floor(),
                vec![tiny.shape(1e8), huge.shape(1e-2)],
                above,
            ),
        ))
        .about("both: emitter choice between powers pi and 400 pi")
        .blind(
            Blind::Bsdf,
            "cosine sampling hits the 1e-8 sr light with p ~ 3e-9",
        ),
    ]
}

/// A unit square light 1e-6 above the floor; the camera sits inside the gap.
fn contact_scene(x: f32) -> SceneDesc {
    let gap = 1e-6;
    let light = Quad::ceiling(Vec3::new(0.0, 0.0, gap), 1.0);
    let probe = Probe {
        eye: Vec3::new(x, 0.0, gap * 0.5),
        target: Vec3::new(x, 0.0, 0.0),
        near: 1e-9,
        pixels: 1,
    };
    probe_scene(1.0, floor(), vec![light.shape(1.0)], probe)
}

/// Why area sampling cannot render contact: the irradiance comes from the light's points
/// within a few gaps (1e-6) of the receiver.
const CONTACT_AREA: &str =
    "area sampling reaches the 1e-6-wide region that carries the irradiance with p ~ 1e-12";

fn contact() -> Vec<Case> {
    let g = "contact";
    vec![
        lambert(case("gap-1e-6-centre", g, contact_scene(0.0)))
            .about("unit light 1e-6 above the receiver (camera in the gap): spawn offsets vs gap")
            .blind(Blind::LightArea, CONTACT_AREA),
        lambert(case("gap-1e-6-edge", g, contact_scene(0.5)))
            .about("as above, receiver under the light's edge")
            .blind(Blind::LightArea, CONTACT_AREA),
        lambert(case("gap-1e-6-outside", g, contact_scene(0.5 + 1e-5)))
            .about("as above, receiver 1e-5 outside the edge")
            .blind(Blind::LightArea, CONTACT_AREA),
    ]
}

/// Unit normal at `deg` degrees from +z, tilted towards -x.
fn tilted(deg: f32) -> Vec3 {
    let t = deg.to_radians();
    Vec3::new(-t.sin(), 0.0, -t.cos())
}

fn grazing() -> Vec<Case> {
    let g = "grazing";
    // Light planes at 89.9 degrees to the floor: normal 0.1 degrees below the horizontal.
    let n = tilted(89.9);
    let quad = |center: Vec3| Quad {
        center,
        u: Vec3::new(0.0, 0.5, 0.0),
        v: n.cross(Vec3::new(0.0, 0.5, 0.0)) * 1.0,
    };
    let front = quad(Vec3::new(1.0, 0.0, 0.6));
    // The plane passes 1e-3 from the receiver, which sees the light almost edge-on.
    let x_c = (1e-3 - 0.6 * -n.z) / -n.x;
    let edge_on = quad(Vec3::new(-x_c, 0.0, 0.6));
    let up = Probe::above(Vec3::ZERO, 1.0);
    let side = Probe {
        eye: Vec3::new(-1.0, 0.0, 1.0),
        ..up
    };
    let t = 0.1f32.to_radians();
    let low = Probe {
        eye: Vec3::new(-10.0 * t.cos(), 0.0, 10.0 * t.sin()),
        ..up
    };
    let big = Quad::ceiling(Vec3::Z, 40.0);
    vec![
        lambert(case(
            "light-at-89.9deg",
            g,
            probe_scene(2.0, floor(), vec![front.shape(1.0)], up),
        ))
        .about("light plane at 89.9 deg to the floor, in front of the receiver"),
        lambert(case(
            "light-edge-on",
            g,
            probe_scene(2.0, floor(), vec![edge_on.shape(1.0)], side),
        ))
        .about("light plane at 89.9 deg passing 1e-3 from the receiver: seen edge-on"),
        lambert(case(
            "camera-at-89.9deg",
            g,
            probe_scene(20.0, floor(), vec![big.shape(1.0)], low),
        ))
        .about("camera 0.1 deg above the floor under a side-40 light"),
    ]
}

const ETA: f32 = 0.2;
const K: f32 = 3.9;

fn rough(alpha: f32) -> BsdfDesc {
    BsdfDesc::RoughConductor {
        distribution: MicrofacetDistribution::Beckmann,
        alpha_u: alpha,
        alpha_v: alpha,
        sample_visible: true,
        eta: Rgb::splat(ETA),
        k: Rgb::splat(K),
        specular_reflectance: Rgb::ONE,
    }
}

/// The camera looks at the origin from 45 degrees; the light is centred on the mirror
/// direction, so a near-specular lobe lies wholly inside it.
fn specular_scene(bsdf: BsdfDesc, side: f32) -> (SceneDesc, Quad) {
    let eye = Vec3::new(-1.0, 0.0, 1.0);
    let light = facing(Vec3::new(1.0, 0.0, 1.0), Vec3::ZERO, side);
    let probe = Probe {
        eye,
        ..Probe::above(Vec3::ZERO, 1.0)
    };
    (probe_scene(2.0, bsdf, vec![light.shape(1.0)], probe), light)
}

fn glossy() -> Vec<Case> {
    let g = "near-specular";
    let cos = std::f32::consts::FRAC_1_SQRT_2;
    let f_conductor = fresnel_conductor(cos, Rgb::splat(ETA), Rgb::splat(K)).x as f64;
    let mut v = Vec::new();
    for (size, side) in [("small", 0.1f32), ("large", 2.0)] {
        for alpha in [1e-4f32, 1e-3] {
            let (desc, _) = specular_scene(rough(alpha), side);
            let mut c = case(&format!("alpha-{alpha:e}-{size}-light"), g, desc);
            // Beckmann mass beyond the light's edge (>= 0.035 rad from the mirror direction)
            // is below exp(-(0.035 / 2e-3)^2), and Smith shadowing at 45 degrees vanishes.
            c.reference = f_conductor;
            c.reference_from = "Fresnel (lobe inside the light)";
            c.about = "Beckmann roughconductor, light centred on the mirror direction";
            // A light sample lands in the lobe (~pi (2 alpha)^2 sr) with p ~ 4 pi alpha^2 / Omega.
            let why = match (alpha < 5e-4, side > 1.0) {
                (true, false) => Some("light samples land in the lobe with p ~ 2e-5"),
                (true, true) => Some("light samples land in the lobe with p ~ 1e-7"),
                (false, true) => Some("light samples land in the lobe with p ~ 1e-5"),
                (false, false) => None,
            };
            if let Some(why) = why {
                c = c.blind(Blind::Light, why);
            }
            v.push(c);
        }
        let (desc, light) = specular_scene(rough(1.0), side);
        let scene = Scene::build(desc.clone()).expect("case scene builds");
        let mut c = case(&format!("alpha-1-{size}-light"), g, desc);
        let eye = Vec3::new(-1.0, 0.0, 1.0);
        c.reference = quad_quadrature(
            &scene.materials[0],
            Vec3::ZERO,
            eye,
            light.corners(),
            1.0,
            1024,
        );
        c.reference_from = "quadrature 1024^2";
        c.about = "Beckmann roughconductor alpha = 1";
        v.push(c);
    }
    let smooth = BsdfDesc::Conductor {
        eta: Rgb::splat(ETA),
        k: Rgb::splat(K),
        specular_reflectance: Rgb::ONE,
    };
    let (desc, _) = specular_scene(smooth, 0.1);
    let mut c = case("smooth-conductor", g, desc);
    c.reference = f_conductor;
    c.reference_from = "Fresnel";
    c.about = "delta lobe: BSDF sampling only, in every strategy";
    v.push(c);
    let glass = BsdfDesc::Dielectric {
        int_ior: 1.5,
        ext_ior: 1.0,
    };
    let (desc, _) = specular_scene(glass, 0.1);
    let mut c = case("smooth-dielectric", g, desc);
    c.reference = fresnel_dielectric(cos, 1.5).0 as f64;
    c.reference_from = "Fresnel (refraction sees nothing)";
    c.about = "delta lobes chosen by Fresnel: reflection R, refraction into the void";
    v.push(c);
    v
}

fn scaled(mut c: Case, s: f32) -> Case {
    transform(&mut c.desc, Mat4::from_scale(Vec3::splat(s)));
    c.name = format!("{}-scale-{s:e}", c.name);
    c.group = "scene scale";
    c.about = "the named base case with the whole scene scaled about the origin";
    lambert(c)
}

fn scales() -> Vec<Case> {
    let mut v = Vec::new();
    for s in [1e-4f32, 1e5] {
        v.push(scaled(light_size().swap_remove(0), s));
        v.push(scaled(contact().swap_remove(0), s));
        v.push(scaled(grazing().swap_remove(1), s));
    }
    v
}

fn degenerate(scenes: &Path) -> Vec<Case> {
    let g = "degenerate input";
    // Below every light of these scenes (the lowest is at z = 0.5).
    let above = Probe::above(Vec3::ZERO, 0.25);
    let mut v = Vec::new();
    let xml = scenes.join("degenerate-emitter.xml");
    let desc = load_scene(&xml, &[]).unwrap_or_else(|e| panic!("{}: {e}", xml.display()));
    let mut c = lambert(case("degenerate-emitter-mesh", g, desc))
        .about("XML + OBJ: duplicate vertices, zero-length normals, 2 zero-area triangles");
    c.warning = Some("zero-area triangle(s)");
    v.push(c);
    let up = |center: Vec3| Quad {
        center,
        u: Vec3::new(0.25, 0.0, 0.0),
        v: Vec3::new(0.0, 0.25, 0.0),
    };
    v.push(
        lambert(case(
            "all-emitters-face-away",
            g,
            probe_scene(
                1.0,
                floor(),
                vec![
                    up(Vec3::new(0.3, 0.0, 0.5)).shape(1.0),
                    up(Vec3::new(-0.3, 0.0, 0.8)).shape(5.0),
                ],
                above,
            ),
        ))
        .about("two lights emitting upwards, away from the receiver: exactly 0"),
    );
    let mut c = lambert(case(
        "zero-radiance-only",
        g,
        probe_scene(
            1.0,
            floor(),
            vec![Quad::ceiling(Vec3::Z * 0.5, 0.5).shape(0.0)],
            above,
        ),
    ))
    .about("the only emitter has L = 0: warning, exactly 0, power choice falls back to uniform");
    c.warning = Some("zero radiance");
    v.push(c);
    let mut c = lambert(case(
        "zero-radiance-beside-lit",
        g,
        probe_scene(
            1.0,
            floor(),
            vec![
                Quad::ceiling(Vec3::new(0.4, 0.0, 0.5), 0.3).shape(0.0),
                Quad::ceiling(Vec3::new(-0.4, 0.0, 0.5), 0.3).shape(2.0),
            ],
            above,
        ),
    ))
    .about("an L = 0 emitter beside a lit one: pmf 0 under power choice");
    c.warning = Some("zero radiance");
    v.push(c);
    v.push(
        lambert(case("4096-emitters", g, many_emitters(64, above)))
            .about("unit light cut into 64 x 64 emitters: pmf 1/4096 (uniform)"),
    );
    v
}

/// A unit square light at height 0.5 cut into n x n tiles, each its own emitter.
fn many_emitters(n: usize, probe: Probe) -> SceneDesc {
    let side = 1.0 / n as f32;
    let mut lights = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            let c = Vec3::new(
                -0.5 + (i as f32 + 0.5) * side,
                -0.5 + (j as f32 + 0.5) * side,
                0.5,
            );
            lights.push(Quad::ceiling(c, side).shape(1.0));
        }
    }
    probe_scene(1.0, floor(), lights, probe)
}

/// Every render case; `scenes` is the `scenes/extreme` folder (for the XML cases).
pub fn all_cases(scenes: &Path) -> Vec<Case> {
    let mut v = light_size();
    v.extend(contact());
    v.extend(grazing());
    v.extend(glossy());
    v.extend(scales());
    v.extend(degenerate(scenes));
    v
}

/// Number of emitters in a scene description (for the report).
pub fn emitter_count(desc: &SceneDesc) -> usize {
    desc.shapes.iter().filter(|s| s.emitter.is_some()).count() + desc.point_lights.len()
}
