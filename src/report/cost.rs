//! The report's counted-cost section: what each strategy did per camera sample (rays and
//! evaluations, the same on every machine) and how well the cost model fitted on the
//! experiment's runs (`experiment::costs`) predicts each run's time.

use super::e;
use crate::cost::{per_camera_sample, TERMS};
use crate::counts::Counts;
use crate::experiment::costs::Costs;
use crate::experiment::results::Row;
use std::fmt::Write;

/// The section for `rows` (strategies `labels` as (label, name), equal-spp point `spp`).
pub(super) fn cost_section(
    md: &mut String,
    rows: &[Row],
    labels: &[(String, String)],
    costs: &Costs,
    spp: u32,
) {
    let m = &costs.model;
    let terms: Vec<String> = TERMS
        .iter()
        .zip(&m.seconds_per)
        .filter(|(_, c)| **c > 0.0)
        .map(|(t, c)| format!("{} {}", t.replace('_', " "), per_unit(*c)))
        .collect();
    let _ = writeln!(
        md,
        "## Counted cost\n\nWhat each strategy did per camera sample, counted (the same on \
         every machine and thread count, so shards from different nodes compare), and the \
         linear cost model fitted on this experiment's {} timed runs: seconds = a \
         non-negative cost per unit of each count, {}; every other term costs nothing here. \
         A run far from its modelled time ran slower or faster than its work says (a slower \
         sampler, a cold start, a busy machine).\n",
        m.runs,
        terms.join(", ")
    );
    let _ = writeln!(
        md,
        "| strategy | rays | shadow rays | BSDF rays | BSDF rays ended by the bounds test | \
         BSDF evals | light-pdf evals | choice evals | seconds at {spp} spp | modelled | \
         largest model error |\n|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for (label, name) in labels {
        let mine = |r: &Row| &r.strategy == label;
        let Some(c) = total(rows, mine) else { continue };
        let per = |v: u64| format!("{:.3}", per_camera_sample(&c, v));
        let at = |r: &Row| mine(r) && r.is_sweep() && r.spp == spp;
        let measured: Vec<f64> = rows.iter().filter(|r| at(r)).map(|r| r.seconds).collect();
        let seconds = if measured.is_empty() {
            "-".into()
        } else {
            e(measured.iter().sum::<f64>() / measured.len() as f64)
        };
        let modelled = costs.mean(rows, at).map_or("-".into(), e);
        let worst = costs
            .worst_error(rows, mine)
            .map_or("-".into(), |w| format!("{:.1} %", w * 100.0));
        let _ = writeln!(
            md,
            "| {name} | {} | {} | {} | {} | {} | {} | {} | {seconds} | {modelled} | {worst} |",
            per(c.rays()),
            per(c.shadow_rays),
            per(c.bsdf_rays),
            per(c.bsdf_rejected),
            per(c.bsdf_evals),
            per(c.light_pdf_evals),
            per(c.choice_evals),
        );
    }
    md.push('\n');
}

/// The summed counts of the rows `pick` accepts that have counts.
fn total(rows: &[Row], pick: impl Fn(&Row) -> bool) -> Option<Counts> {
    rows.iter()
        .filter(|r| pick(r))
        .filter_map(Row::counts)
        .reduce(|a, b| a + b)
}

/// A cost per unit, in ns below 10 us and in ms above (a per-render constant).
fn per_unit(s: f64) -> String {
    if s >= 1e-5 {
        format!("{:.3} ms", s * 1e3)
    } else {
        format!("{:.2} ns", s * 1e9)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::method::{Method, SamplerSpec};
    use crate::experiment::results::test_row;
    use crate::integrator::Strategy;

    /// Hand-computed: strategy A casts 3 rays per camera sample (1 camera, 1 shadow, 1 BSDF),
    /// B only camera rays. Times are exactly 1 us per camera ray and 2 us per other ray, so the
    /// model is exact: A at 4 spp on 16 pixels = 64 camera + 128 other rays = 320 us.
    #[test]
    fn counted_cost_by_hand() {
        let strategies = Strategy::combinations();
        let methods: Vec<Method> = strategies[..2]
            .iter()
            .map(|&strategy| Method {
                strategy,
                sampler: SamplerSpec::default(),
            })
            .collect();
        let labels = vec![
            ("A".to_string(), "a".to_string()),
            ("B".to_string(), "b".to_string()),
        ];
        let mut rows = Vec::new();
        for (label, others) in [("A", 1u64), ("B", 0)] {
            for spp in [1u32, 4, 16] {
                for seed in 0..2 {
                    let mut r = test_row(label, spp, seed);
                    let n = 16 * u64::from(spp);
                    r.set_counts(&Counts {
                        camera_rays: n,
                        shadow_rays: others * n,
                        bsdf_rays: others * n,
                        ..Counts::default()
                    });
                    r.seconds = 1e-6 * n as f64 + 2e-6 * (2 * others * n) as f64;
                    rows.push(r);
                }
            }
        }
        let costs = Costs::fit(&rows, &labels, &methods).unwrap();
        assert_eq!(costs.model.runs, 12);
        let a4 = costs
            .mean(&rows, |r| r.strategy == "A" && r.spp == 4)
            .unwrap();
        assert!((a4 - 320e-6).abs() < 1e-12, "{a4}");
        let mut md = String::new();
        cost_section(&mut md, &rows, &labels, &costs, 4);
        assert!(
            md.contains("fitted on this experiment's 12 timed runs"),
            "{md}"
        );
        // Per camera sample: A 3 rays (1 shadow, 1 BSDF), B 1; measured = modelled.
        assert!(md.contains("| a | 3.000 | 1.000 | 1.000 | 0.000 | 0.000 | 0.000 | 0.000 | 3.200e-4 | 3.200e-4 | 0.0 % |"), "{md}");
        assert!(md.contains("| b | 1.000 | 0.000 | 0.000 | 0.000 | 0.000 | 0.000 | 0.000 | 6.400e-5 | 6.400e-5 | 0.0 % |"), "{md}");
        // A run twice as slow as its work: the fit absorbs part of it, the rest shows.
        rows[0].seconds *= 2.0;
        let costs = Costs::fit(&rows, &labels, &methods).unwrap();
        let worst = costs.worst_error(&rows, |r| r.strategy == "A").unwrap();
        assert!(worst > 0.3, "{worst}");
    }
}
