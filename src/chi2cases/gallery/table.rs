//! Runs every check on every gallery row and formats the table.
//!
//! Scenes: (1) the receiver at the origin (normal +z) under three lights — a planar quad
//! split into triangles of areas 1.8, 0.2 and 2.0, a brighter triangle to the side, and a
//! quad facing away — chosen uniformly; Lambert's formula gives the exact answer.
//! (2) the split furnace (six emitting faces, L = 1) with the receiver on its floor, where
//! reflected radiance is exactly the albedo.

use super::estimate::{Setup, Strategy};
use super::lights::Lights;
use super::receiver::{Bsdf, Receiver};
use super::{rows, Bug};
use crate::analytic::{diffuse_radiance, polygon_irradiance};
use crate::chi2cases::checks::WeightCheck;
use crate::geometry::ShapeKind;
use crate::math::Frame;
use crate::rng::Rng;
use crate::scene::desc::{Rgb, ShapeDesc};
use crate::scene::{fixtures, Scene};
use crate::stats::ttest::{one_sample_welford, sidak, welch, Group};
use crate::stats::{chi2_test, Chi2Config, Sphere};
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// Samples per estimator and per chi-square test.
pub const N: u64 = 100_000;
/// Family-wise level of the whole table.
pub const ALPHA: f64 = 0.01;
const SEED: u64 = 2024;

pub struct Column {
    pub key: &'static str,
    pub title: &'static str,
}

pub const COLUMNS: [Column; 11] = [
    Column {
        key: "chi2-light",
        title: "χ² light sampling",
    },
    Column {
        key: "chi2-bsdf",
        title: "χ² BSDF sampling",
    },
    Column {
        key: "weight",
        title: "weight = eval/pdf",
    },
    Column {
        key: "lambert-light",
        title: "Lambert t, light",
    },
    Column {
        key: "lambert-bsdf",
        title: "Lambert t, BSDF",
    },
    Column {
        key: "lambert-mis",
        title: "Lambert t, MIS",
    },
    Column {
        key: "welch-light-bsdf",
        title: "light = BSDF (Welch)",
    },
    Column {
        key: "welch-mis-bsdf",
        title: "MIS = BSDF (Welch)",
    },
    Column {
        key: "furnace-light",
        title: "furnace t, light",
    },
    Column {
        key: "furnace-bsdf",
        title: "furnace t, BSDF",
    },
    Column {
        key: "furnace-mis",
        title: "furnace t, MIS",
    },
];

#[derive(Clone, Debug)]
pub enum Cell {
    /// The check does not apply (no closed form for this receiver).
    NotApplicable,
    /// A statistical test's p-value (0 for the chi-square engine's immediate failures).
    P(f64),
    /// A deterministic check: failures of checked.
    Count(u64, u64),
}

impl Cell {
    pub fn caught(&self, alpha: f64) -> bool {
        match self {
            Cell::NotApplicable => false,
            Cell::P(p) => !(*p >= alpha),
            Cell::Count(f, _) => *f > 0,
        }
    }
}

pub struct Row {
    pub bug: Bug,
    pub receiver: Receiver,
    pub cells: Vec<Cell>,
}

pub struct Table {
    pub rows: Vec<Row>,
    /// Per-cell level: ALPHA Sidak-corrected over every statistical cell.
    pub alpha: f64,
}

fn light(positions: Vec<Vec3>, indices: Vec<[u32; 3]>, radiance: f32, face: Vec3) -> ShapeDesc {
    // Wind every triangle so it emits towards (or, for `face` pointing away, from) `face`.
    let mut idx = indices;
    for t in &mut idx {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        if (b - a).cross(c - a).dot(face) < 0.0 {
            t.swap(1, 2);
        }
    }
    fixtures::mesh(
        positions,
        idx,
        fixtures::diffuse(0.0),
        Some(Rgb::splat(radiance)),
    )
}

pub fn gallery_scene() -> Scene {
    let v = Vec3::new;
    let quad = light(
        vec![
            v(-1., -1., 2.),
            v(1., -1., 2.),
            v(1., 1., 2.),
            v(-1., 1., 2.),
            v(1., 0.8, 2.),
        ],
        vec![[0, 1, 4], [0, 4, 2], [0, 2, 3]],
        1.0,
        -Vec3::Z,
    );
    let side = light(
        vec![v(1.5, -0.5, 1.0), v(2.5, 0.0, 1.5), v(1.5, 0.5, 1.8)],
        vec![[0, 1, 2]],
        4.0,
        -Vec3::X,
    );
    let away = light(
        vec![
            v(-2.5, -0.5, 1.),
            v(-1.5, -0.5, 1.),
            v(-1.5, 0.5, 1.),
            v(-2.5, 0.5, 1.),
        ],
        vec![[0, 1, 2], [0, 2, 3]],
        2.0,
        Vec3::Z,
    );
    Scene::build(fixtures::shapes_only(vec![quad, side, away])).expect("gallery scene")
}

/// Lambert's closed form for a diffuse receiver at the origin (normal +z) in `scene`.
fn lambert(scene: &Scene, albedo: f64) -> f64 {
    let mut e = 0.0;
    for shape in &scene.shapes {
        let (Some(ei), ShapeKind::Mesh(m)) = (shape.emitter, &shape.kind) else {
            continue;
        };
        let crate::emitter::Emitter::Area(a) = &scene.emitters[ei as usize] else {
            continue;
        };
        let l = a.radiance.x as f64;
        for t in 0..m.indices.len() {
            let tri: Vec<DVec3> = m.vertices(t).iter().map(|p| p.as_dvec3()).collect();
            e += polygon_irradiance(DVec3::ZERO, DVec3::Z, &tri, l).expect("above the horizon");
        }
    }
    diffuse_radiance(albedo, e)
}

fn incident(receiver: Receiver) -> Vec3 {
    match receiver {
        Receiver::Diffuse { .. } => Vec3::new(0.3, 0.2, 0.93).normalize(),
        Receiver::Microfacet { .. } => Vec3::new(0.95, 0.0, 0.3).normalize(),
    }
}

fn setup(scene: &Scene, x: Vec3, bug: Bug, receiver: Receiver) -> Setup<'_> {
    Setup {
        scene,
        x,
        frame: Frame::from_normal(Vec3::Z),
        wi: incident(receiver),
        lights: Lights { scene, bug },
        bsdf: Bsdf { receiver, bug },
    }
}

fn chi2_cfg(stream: u64) -> Chi2Config {
    Chi2Config {
        samples: N,
        seed: SEED + stream,
        ..Chi2Config::default()
    }
}

const SPHERE: Sphere = Sphere {
    n_phi: 25,
    n_cos: 49,
};

fn row(bug: Bug, receiver: Receiver, scene: &Scene, furnace: &Scene) -> Vec<Cell> {
    let s = setup(scene, Vec3::ZERO, bug, receiver);
    let chi2_light = chi2_test(
        &SPHERE,
        |r: &mut Rng| s.lights.sample(s.x, r).map(|l| l.wi),
        |d| s.lights.pdf(s.x, d),
        &chi2_cfg(1),
    );
    let mut weights = WeightCheck::default();
    let chi2_bsdf = chi2_test(
        &SPHERE,
        |r: &mut Rng| {
            let b = s.bsdf.sample(s.wi, r.next_f32(), r.next_2d())?;
            let eval = s.bsdf.eval(s.wi, b.wo) as f64;
            weights.record(
                b.weight as f64,
                eval,
                b.pdf as f64,
                s.bsdf.pdf(s.wi, b.wo) as f64,
            );
            Some(b.wo)
        },
        |wo| s.bsdf.pdf(s.wi, wo) as f64,
        &chi2_cfg(2),
    );
    let [l, b, m] =
        [Strategy::Light, Strategy::Bsdf, Strategy::Mis].map(|k| s.run(k, N, SEED, 10 + k as u64));
    let diffuse = match receiver {
        Receiver::Diffuse { albedo } => Some(albedo as f64),
        Receiver::Microfacet { .. } => None,
    };
    let t = |w: &crate::stats::Welford, reference: Option<f64>| {
        reference.map_or(Cell::NotApplicable, |r| {
            Cell::P(one_sample_welford(w, r).p_value)
        })
    };
    let reference = diffuse.map(|a| lambert(scene, a));
    let fx = Vec3::new(0.1, 0.2, -1.0);
    let fs = setup(furnace, fx, bug, receiver);
    let [fl, fb, fm] =
        [Strategy::Light, Strategy::Bsdf, Strategy::Mis].map(|k| fs.run(k, N, SEED, 20 + k as u64));
    vec![
        Cell::P(chi2_light.p_value),
        Cell::P(chi2_bsdf.p_value),
        Cell::Count(weights.failures, weights.checked),
        t(&l, reference),
        t(&b, reference),
        t(&m, reference),
        Cell::P(welch(Group::from(&l), Group::from(&b)).p_value),
        Cell::P(welch(Group::from(&m), Group::from(&b)).p_value),
        t(&fl, diffuse),
        t(&fb, diffuse),
        t(&fm, diffuse),
    ]
}

pub fn run_table() -> Table {
    let scene = gallery_scene();
    let furnace = Scene::build(fixtures::furnace(0.5, true, 1)).expect("furnace");
    let rows: Vec<Row> = rows()
        .into_par_iter()
        .map(|(bug, receiver)| Row {
            bug,
            receiver,
            cells: row(bug, receiver, &scene, &furnace),
        })
        .collect();
    let tests = rows
        .iter()
        .flat_map(|r| &r.cells)
        .filter(|c| matches!(c, Cell::P(_)))
        .count();
    Table {
        rows,
        alpha: sidak(ALPHA, tests),
    }
}

fn fmt_cell(c: &Cell, alpha: f64) -> String {
    let mark = if c.caught(alpha) { " **✗**" } else { "" };
    match c {
        Cell::NotApplicable => "—".into(),
        Cell::P(p) if *p == 0.0 => format!("0{mark}"),
        Cell::P(p) if *p < 1e-3 => format!("{p:.1e}{mark}"),
        Cell::P(p) => format!("{p:.3}{mark}"),
        Cell::Count(0, n) => format!("ok ({n})"),
        Cell::Count(f, n) => format!("{f}/{n}{mark}"),
    }
}

fn receiver_name(r: Receiver) -> String {
    match r {
        Receiver::Diffuse { albedo } => format!("Lambert, albedo {albedo}"),
        Receiver::Microfacet { alpha, kd } => format!("Nori microfacet, alpha {alpha}, kd {kd}"),
    }
}

/// The report: how it was made, then one row per bug with a p-value per check.
pub fn markdown(t: &Table) -> String {
    let mut s = String::new();
    s += "# Bug gallery\n\n";
    s += "Generated by `cargo test --release --lib gallery -- --ignored` \
          (`src/chi2cases/gallery/`); do not edit by hand.\n\n";
    s += "Each row is the study's sampling code with one classic mistake \
          (`shared/REFERENCE.md` §1); the first two rows are the correct code, the controls. \
          Each column is a check of the harness run on that code:\n\n";
    s += &format!(
        "- **χ² light / BSDF sampling**: the chi-square engine (`stats::chi2_test`), {N} samples, \
         sphere of 25 × 49 equal-area cells; light directions from the receiver with the \
         emitter-choice pmf included and rejected samples counted as lost mass; BSDF \
         directions for one incident direction. A p-value of 0 is an immediate failure \
         (samples where the pdf is 0, or lost samples the pdf does not account for).\n\
         - **weight = eval/pdf**: every BSDF sample of the χ² run, its weight against \
         eval/pdf() and its pdf against pdf() (relative 1e-3); failures/checked.\n\
         - **Lambert t**: one-sample Student t-test of {N} estimates of reflected radiance \
         against Lambert's closed form (`analytic::polygon_irradiance`), for light sampling, \
         BSDF sampling and MIS (balance heuristic, one sample of each).\n\
         - **Welch**: unbiasedness across strategies without a closed form: light vs BSDF \
         sampling, MIS vs BSDF sampling ({N} estimates each).\n\
         - **furnace t**: the receiver on the floor of a closed box of six emitting faces \
         (L = 1, chosen uniformly); reflected radiance is exactly the albedo.\n\n"
    );
    s += &format!(
        "Significance: alpha = {ALPHA} for the whole table, Sidak-corrected over its \
         statistical cells to **{:.2e}** per cell; **✗** marks a rejection. \"—\": no closed \
         form for that receiver. Scene 1: a diffuse or microfacet receiver at the origin under \
         a planar quad light split into triangles of areas 1.8, 0.2 and 2.0, a triangle light \
         four times as bright, and a quad light facing away; emitters chosen uniformly.\n\n",
        t.alpha
    );
    s += "| bug | receiver |";
    for c in &COLUMNS {
        s += &format!(" {} |", c.title);
    }
    s += "\n|---|---|";
    s += &"---|".repeat(COLUMNS.len());
    s += "\n";
    for r in &t.rows {
        s += &format!("| {} | {} |", r.bug.describe(), receiver_name(r.receiver));
        for c in &r.cells {
            s += &format!(" {} |", fmt_cell(c, t.alpha));
        }
        s += "\n";
    }
    s += "\nWhat each bug needs to be seen: mistakes in what a sampler claims (pmf, Jacobian, \
          back faces, the pdf a BSDF reports) are caught by chi-square before any image is \
          rendered; mistakes that leave every sampler consistent but combine them wrongly \
          (MIS weights from different directions) only show as bias, against a closed form \
          or between strategies. A back-facing light given a pdf biases no estimate here \
          (its radiance is 0 from behind) and only chi-square sees it.\n\n\
          Bugs seeded into the renderer itself, each wrong in one corner of the configuration \
          space (one side of a surface, one range of angles, one kind of shape, one \
          material), are found by the two-run test against the correct build with no \
          reference: [seeded-bugs/index.md](seeded-bugs/index.md), with their p-value maps.\n";
    s
}
