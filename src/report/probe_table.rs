//! The probe report's table: every (case, strategy) pooled over seeds, with its verdict.

use crate::cost::per_camera_sample;
use crate::counts::Counts;
use crate::experiment::analysis::series;
use crate::experiment::probe::run::{CaseRun, ProbeOutcome};
use crate::experiment::probe::stats::z_score;
use crate::experiment::results::Row;

pub const OK: &str = "ok";
pub const TAIL: &str = "tail unsampled";
pub const BIASED: &str = "BIASED";
pub const NON_FINITE: &str = "NON-FINITE";

/// One (case, strategy) of the table, pooled over seeds.
pub struct TableRow {
    pub case: String,
    pub name: String,
    pub label: String,
    pub blind: Option<String>,
    pub reference: f64,
    pub non_finite: u64,
    pub mean: f64,
    pub z: f64,
    pub relmse: f64,
    pub max_sample: f64,
    pub top_share: f64,
    pub slope: Option<f64>,
    /// Time per sample, mean over seeds (the stream's draw, shading included).
    pub ns_per_sample: f64,
    /// What one sample did, counted over every seed's stream (None for rows without counts).
    pub per_sample: Option<PerSample>,
    pub verdict: &'static str,
}

/// Counted work per camera sample: rays traced (camera, shadow, BSDF), BSDF and light-density
/// evaluations, and emitters the emitter choice weighed (N per choice for the exhaustive one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PerSample {
    pub rays: f64,
    pub evals: f64,
    pub choice_evals: f64,
}

impl PerSample {
    /// Per camera sample of the summed counts `c`; None without a camera ray.
    pub fn of(c: &Counts) -> Option<PerSample> {
        (c.camera_rays > 0).then(|| PerSample {
            rays: per_camera_sample(c, c.rays()),
            evals: per_camera_sample(c, c.bsdf_evals + c.light_pdf_evals),
            choice_evals: per_camera_sample(c, c.choice_evals),
        })
    }
}

/// The spp whose relMSE the table shows.
pub fn table_spp(o: &ProbeOutcome) -> u32 {
    let x = &o.exp.exp;
    x.probe
        .as_ref()
        .and_then(|p| p.table_spp)
        .unwrap_or_else(|| {
            let lo = *x.spp.iter().min().expect("validated non-empty");
            x.spp
                .iter()
                .copied()
                .filter(|&s| s <= 1024)
                .max()
                .unwrap_or(lo)
        })
}

/// What a row shows: finite and unbiased, or why the z-test cannot be read as bias. A mean
/// too low with most squared error in 0.1 % of the samples, or from a technique the case
/// declares blind to part of the integrand, is an unsampled tail: the sample variance
/// underestimates the true one.
fn verdict(r: &TableRow, zc: f64) -> &'static str {
    if r.non_finite > 0 {
        NON_FINITE
    } else if r.z.abs() < zc {
        OK
    } else if r.z < 0.0 && (r.blind.is_some() || r.top_share > crate::stats::TAIL_SHARE) {
        TAIL
    } else {
        BIASED
    }
}

fn pooled(o: &ProbeOutcome, c: &CaseRun, name: &str, label: &str) -> Option<TableRow> {
    let rows: Vec<&Row> = o
        .rows
        .iter()
        .filter(|r| r.case == c.case.name && r.strategy == label)
        .collect();
    // Mean, z, max and share belong to the stream: one row per seed carries them.
    let mut per_seed: Vec<&Row> = Vec::new();
    for r in &rows {
        if !per_seed.iter().any(|q| q.seed == r.seed) {
            per_seed.push(r);
        }
    }
    if per_seed.is_empty() {
        return None;
    }
    let s = per_seed.len() as f64;
    let n = o.exp.exp.probe.as_ref().map_or(1, |p| p.samples) as f64 * s;
    let mean = per_seed.iter().map(|r| r.mean_r).sum::<f64>() / s;
    let var_mean = per_seed.iter().map(|r| r.mean_var_r).sum::<f64>() / (s * s);
    let spp = table_spp(o);
    let at: Vec<f64> = rows
        .iter()
        .filter(|r| r.spp == spp)
        .map(|r| r.relmse)
        .collect();
    let owned: Vec<Row> = rows.iter().map(|r| (*r).clone()).collect();
    let m = o.exp.exp.metrics.primary;
    let slope = series(&owned, &[(label.to_string(), name.to_string())], m)[0].slope;
    // The worst seed; NaN (no squared error at all) only if every seed has none.
    let worst = |f: fn(&Row) -> Option<f64>| {
        per_seed
            .iter()
            .filter_map(|r| f(r).filter(|v| !v.is_nan()))
            .fold(f64::NAN, f64::max)
    };
    let strategy = c
        .kept
        .iter()
        .find(|(_, s)| s.label() == label)
        .map(|(_, s)| *s)?;
    Some(TableRow {
        case: c.case.name.clone(),
        name: name.to_string(),
        label: label.to_string(),
        blind: c.case.blind_for(&strategy).map(str::to_string),
        reference: c.reference(),
        non_finite: per_seed.iter().map(|r| r.non_finite).sum(),
        mean,
        z: z_score(mean, var_mean * n, n as u64, c.reference()),
        relmse: at.iter().sum::<f64>() / at.len().max(1) as f64,
        max_sample: worst(|r| r.max_sample),
        top_share: worst(|r| r.top_share),
        slope,
        ns_per_sample: per_seed.iter().map(|r| 1e9 / r.samples_per_s).sum::<f64>() / s,
        per_sample: per_seed
            .iter()
            .filter_map(|r| r.counts())
            .reduce(|a, b| a + b)
            .as_ref()
            .and_then(PerSample::of),
        verdict: "",
    })
}

/// Every (case, kept strategy) with rows, pooled over seeds, with its verdict.
pub fn table(o: &ProbeOutcome) -> Vec<TableRow> {
    let mut t: Vec<TableRow> = o
        .cases
        .iter()
        .flat_map(|c| {
            c.kept
                .iter()
                .filter_map(move |(name, s)| pooled(o, c, name, &s.label()))
        })
        .collect();
    let zc = critical(o, t.len());
    for r in &mut t {
        r.verdict = verdict(r, zc);
    }
    t
}

fn alpha(o: &ProbeOutcome) -> f64 {
    o.exp.exp.probe.as_ref().map_or(1e-3, |p| p.alpha)
}

/// The table's critical |z|: two-sided at the experiment's alpha, Šidák over `rows` tests.
pub fn critical(o: &ProbeOutcome, rows: usize) -> f64 {
    crate::experiment::probe::stats::z_critical(alpha(o), rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Hand-computed: 10 camera samples that cast 10 camera, 5 shadow and 2 BSDF rays, made
    /// 4 BSDF and 3 light-density evaluations and weighed 100 emitters in their choices (an
    /// exhaustive choice over 10 emitters): 1.7 rays, 0.7 evaluations and 10 choice
    /// evaluations per sample. No camera ray, no figure.
    #[test]
    fn counted_work_per_sample_by_hand() {
        let c = Counts {
            camera_rays: 10,
            shadow_rays: 5,
            bsdf_rays: 2,
            bsdf_evals: 4,
            light_pdf_evals: 3,
            choice_evals: 100,
            ..Counts::default()
        };
        let p = PerSample::of(&c).unwrap();
        assert_eq!(
            p,
            PerSample {
                rays: 1.7,
                evals: 0.7,
                choice_evals: 10.0
            }
        );
        assert_eq!(PerSample::of(&Counts::default()), None);
    }
}
