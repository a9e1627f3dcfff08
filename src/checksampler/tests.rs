//! The engine against programs run in process (no transport, no Python): directlab's own
//! warps answering the protocol pass and get the built-in case's p-value; a wrong pdf, a
//! lying claim, a wrong weight are each caught. Sizes: 50,000 samples, resolution 21,
//! alpha 0.01 (Sidak-split as in a run).

use super::engine::{check, Session};
use super::program::{validate, Program};
use crate::chi2cases::protocol::Target;
use crate::chi2cases::{case_seed, select, CaseConfig, Outcome};
use crate::sampling::warps::*;
use glam::{Vec2, Vec3};
use serde_json::{json, Value};
use std::cell::Cell;
use std::rc::Rc;

type Rows = Box<dyn FnMut(&str, &[f64]) -> (Vec<f64>, usize)>;

/// A program in process: `answer(phase, row)` gives one reply row.
struct InProcess {
    answer: Rows,
    requests: Rc<Cell<usize>>,
}

impl Program for InProcess {
    fn call(
        &mut self,
        header: Value,
        payload: &[f64],
        rows: usize,
        cols: &[usize],
        _what: &str,
    ) -> Result<(Vec<f64>, usize), String> {
        self.requests.set(self.requests.get() + 1);
        let phase = header["phase"].as_str().unwrap().to_string();
        let dim = header["dim"].as_u64().unwrap() as usize;
        let mut out = Vec::new();
        let mut c = 0;
        for row in payload.chunks_exact(dim) {
            let (v, k) = (self.answer)(&phase, row);
            out.extend(v);
            c = k;
        }
        let c = if rows == 0 { cols[0] } else { c };
        validate(&json!({"count": rows, "cols": c}), &out, rows, cols)?;
        Ok((out, c))
    }
    fn finish(&mut self) {}
}

fn cosine(pdf_scale_near_horizon: f32, claim_lie: f32) -> InProcess {
    let pdf = move |d: Vec3| {
        let p = square_to_cosine_hemisphere_pdf(d);
        p * if d.z < 0.15 {
            pdf_scale_near_horizon
        } else {
            1.0
        }
    };
    InProcess {
        requests: Rc::default(),
        answer: Box::new(move |phase, r| match phase {
            "sample" => {
                let d = square_to_cosine_hemisphere(Vec2::new(r[0] as f32, r[1] as f32));
                let p = pdf(d) * claim_lie;
                (vec![d.x as f64, d.y as f64, d.z as f64, p as f64, 1.0], 5)
            }
            _ => (
                vec![pdf(Vec3::new(r[0] as f32, r[1] as f32, r[2] as f32)) as f64],
                1,
            ),
        }),
    }
}

fn run(program: &mut InProcess, target: &Target, seed: u64) -> Outcome {
    let cfg = CaseConfig {
        samples: 50_000,
        resolution: 21,
        seed,
        alpha: crate::stats::sidak(0.01, 1),
        ..CaseConfig::default()
    };
    let mut s = Session {
        program,
        target,
        params: target.params(),
        dims: 2,
        batch: 8192,
        integrals: None,
        ires: None,
    };
    check(&mut s, &target.config(&cfg), "in-process").unwrap()
}

#[test]
fn a_built_in_warp_through_the_protocol_gets_the_built_in_p_value() {
    let case = &select("warp/cosine-hemisphere")[0];
    let target = case.external.clone().unwrap();
    let o = run(&mut cosine(1.0, 1.0), &target, case_seed(&case.name, 0));
    assert!(o.passed(), "{}", o.summary());
    let builtin = case.run(&CaseConfig {
        samples: 50_000,
        resolution: 21,
        ..CaseConfig::default()
    });
    let (a, b) = (o.chi2.p_value, builtin.chi2.p_value);
    assert!((a - b).abs() < 0.01, "protocol p {a}, built-in p {b}");
    assert_eq!(o.chi2.observed.data, builtin.chi2.observed.data);
}

#[test]
fn a_wrong_pdf_and_a_lying_claim_are_caught() {
    let target = Target::Hemisphere;
    let o = run(&mut cosine(1.3, 1.0), &target, 1);
    assert!(!o.passed(), "pdf 30 % high near the horizon passed");
    let o = run(&mut cosine(1.0, 1.01), &target, 1);
    let claim = o.checks.iter().find(|c| c.name == "claimed pdf").unwrap();
    assert!(!claim.passed && claim.detail.contains("claim a pdf other than pdf(point)"));
    assert!(o.chi2.passed(), "the shape is right; only the claim lies");
}

#[test]
fn the_integration_is_done_once_per_target_not_once_per_seed() {
    let target = Target::Hemisphere;
    let mut p = cosine(1.0, 1.0);
    let requests = p.requests.clone();
    let cfg = CaseConfig {
        samples: 10_000,
        resolution: 11,
        ..CaseConfig::default()
    };
    let mut s = Session {
        program: &mut p,
        target: &target,
        params: json!({}),
        dims: 2,
        batch: 1 << 20,
        integrals: None,
        ires: None,
    };
    check(&mut s, &cfg, "first").unwrap();
    let after_first = requests.get();
    check(&mut s, &CaseConfig { seed: 7, ..cfg }, "second").unwrap();
    // The second seed: one sample and one pdf request, no integration levels.
    assert_eq!(requests.get() - after_first, 2);
}

#[test]
fn validate_names_what_was_expected() {
    let e = validate(&json!({"count": 3, "cols": 2}), &[0.0; 6], 3, &[5, 6]).unwrap_err();
    assert!(e.contains("3 rows x 5 or 6 columns"), "{e}");
    let e = validate(&json!({"count": 1, "cols": 1}), &[f64::INFINITY], 1, &[1]).unwrap_err();
    assert!(e.contains("non-finite value inf in row 0, column 0"), "{e}");
}

/// The pdf at a sample is asked at the point as the program sent it: a point 1e-13 inside a
/// support edge is outside once rounded to f32, and the claimed pdf must still match.
#[test]
fn the_claimed_pdf_is_checked_at_the_exact_point() {
    let third = 1.0 / 3.0;
    assert!(
        (third - 1e-13) as f32 as f64 > third,
        "the f32 rounding crosses the edge"
    );
    let pdf = move |x: f64| if x <= third { 3.0 } else { 0.0 };
    let mut p = InProcess {
        requests: Rc::default(),
        answer: Box::new(move |phase, r| match phase {
            "sample" => (vec![third - 1e-13, r[1], 3.0, 1.0], 4),
            _ => (vec![pdf(r[0])], 1),
        }),
    };
    let o = run(&mut p, &Target::Square, 3);
    let claim = o.checks.iter().find(|c| c.name == "claimed pdf").unwrap();
    assert!(claim.passed, "{}", claim.detail);
}
