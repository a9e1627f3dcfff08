//! Render throughput per sampler: every sampler with the goals' estimator (power-heuristic
//! MIS) at the most threads, timed in turns, and each one's speed against the independent
//! sampler's as the median of its paired repetitions, so a sampler's cost per sample is read
//! against the cheapest one on the same machine at the same moment.

use super::timing::sampler_throughputs;
use super::{paired_ratio, power_mis, BenchArgs, Row};
use crate::named::Named;
use crate::sampler::SamplerKind;
use crate::scene::Scene;

pub(super) fn section(
    scene: &Scene,
    name: &str,
    a: &BenchArgs,
    threads: usize,
    rows: &mut Vec<Row>,
) {
    let kinds = SamplerKind::all();
    let timed = sampler_throughputs(scene, power_mis(), &kinds, a.spp, &[threads], a.repeat);
    let base = &timed[0][0];
    debug_assert_eq!(kinds[0], SamplerKind::Independent);
    for (kind, t) in kinds.iter().zip(&timed) {
        let t = &t[0];
        // Slowdown: the independent sampler's speed over this one's, per repetition.
        let slowdown = paired_ratio(&t.runs, &base.runs);
        println!(
            "  {:<34} {:<26} {:>7} {:>12.2}  {:.2}x the independent sampler's time per sample (paired median)",
            name,
            kind.name(),
            threads,
            t.samples_per_s / 1e6,
            slowdown,
        );
        for (section, value, unit) in [
            ("sampler_throughput", t.samples_per_s, "samples/s"),
            ("sampler_slowdown", slowdown, "ratio"),
        ] {
            rows.push(Row {
                section,
                scene: name.to_string(),
                strategy: format!("{}/{}", power_mis().label(), kind.name()),
                threads,
                n: 0,
                value,
                unit,
            });
        }
    }
}
