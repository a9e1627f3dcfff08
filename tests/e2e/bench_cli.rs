//! End to end through `directlab bench` at toy sizes: every section the speed goals are read
//! from is printed and written to the CSV, with finite, positive numbers. (The numbers
//! themselves are the benchmark's business, not a test's.)

use crate::common;

use common::{directlab, repo, run, scratch};
use std::collections::HashMap;

#[test]
fn bench_writes_every_section() {
    let dir = scratch("bench");
    let out = dir.join("bench.csv");
    let cbox = repo("scenes/cbox/cbox.xml");
    let o = run(directlab()
        .args(["bench", "--scene", cbox.to_str().unwrap()])
        .args([
            "--spp",
            "1",
            "--res",
            "16",
            "--repeat",
            "2",
            "--threads",
            "1,2",
        ])
        .args([
            "--max-triangles",
            "10000",
            "--max-emitters",
            "10",
            "--sweep-spp",
            "4",
            "--max-load-emitters",
            "1000",
            "--max-choice-emitters",
            "100",
        ])
        .arg("--out")
        .arg(&out));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for printed in [
        "M samples/s",
        "1->2",
        "workers busy",
        "paired median",
        "slowest run",
        "ray-tracing limit",
        "of render time outside traversal",
        "ns per sample",
        "at 2 threads: ",
        "ns of thread time per sample",
        "band by band (8 rows each) on 1 thread(s)",
        "band by band (8 rows each) on 2 thread(s)",
        "raw obvhs",
        "growth over",
        "machine limit: 2 independent 1-thread renders",
        "machine: ",
        "cbox.xml: 16x16",
        "scene loading as the emitter count grows",
        "x the independent sampler's time per sample",
        "emitter choice alone",
        "tree: depth",
        "cost model (",
        "held out",
        "worst held-out prediction error",
        "light sampling alone: ",
        "(paired median; goal 1.2x",
    ] {
        assert!(
            stdout.contains(printed),
            "{printed} missing from:\n{stdout}"
        );
    }

    check_rows(&out);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every row of the bench's CSV is a number of its kind, and each section has its rows.
fn check_rows(out: &std::path::Path) {
    let mut r = csv::Reader::from_path(out).unwrap();
    let mut sections: HashMap<String, usize> = HashMap::new();
    let mut speeds: HashMap<(String, String, String), f64> = HashMap::new();
    for row in r.records() {
        let row = row.unwrap();
        let value: f64 = row[5].parse().unwrap();
        let what = format!("{} {} {}", &row[0], &row[2], &row[4]);
        if &row[0] == "machine" {
            assert!(!row[2].is_empty(), "machine row names no CPU");
        }
        // The share outside traversal is a difference of two timings: at toy sizes it may be
        // anything, but it is a number.
        if row[2].contains("share_outside_traversal") || row[2].contains("outside_traversal_per") {
            assert!(value.is_finite(), "{what}: {value}");
        } else if row[0].starts_with("cost_prediction_error") {
            // Modelled / measured - 1: above -1 (the model predicts no negative time).
            assert!(value.is_finite() && value >= -1.0, "{what}: {value}");
        } else if &row[0] == "cost_model" {
            // A cost per unit is never negative; a term the runs do not need costs 0.
            assert!(value.is_finite() && value >= 0.0, "{what}: {value}");
        } else {
            assert!(value.is_finite() && value > 0.0, "{what}: {value}");
        }
        *sections.entry(row[0].to_string()).or_default() += 1;
        if row[0].starts_with("throughput") {
            speeds.insert(
                (row[0].to_string(), row[2].to_string(), row[3].to_string()),
                value,
            );
        }
    }
    // The slowest of the repetitions is never faster than the reported (fastest) one.
    for ((section, strategy, threads), slowest) in &speeds {
        if section == "throughput_slowest" {
            let best = speeds[&("throughput".into(), strategy.clone(), threads.clone())];
            assert!(*slowest <= best, "{strategy} {threads}: {slowest} > {best}");
        }
    }
    let strategies = 7;
    assert_eq!(sections["throughput"], strategies * 2, "{sections:?}");
    assert_eq!(
        sections["throughput_slowest"],
        strategies * 2,
        "{sections:?}"
    );
    assert_eq!(sections["thread_scaling"], strategies, "{sections:?}");
    assert_eq!(
        sections["thread_scaling_paired"], strategies,
        "{sections:?}"
    );
    assert_eq!(sections["thread_busy"], strategies, "{sections:?}");
    // Two independent 1-thread renders against one, once per scene.
    assert_eq!(sections["machine_scaling"], 1, "{sections:?}");
    assert_eq!(
        sections["thread_work_per_sample"], strategies,
        "{sections:?}"
    );
    // directlab: closest-hit, occlusion and emitter-query rates, traversal-only samples/s in
    // the renderer's order and by ray type, the render, the two shares, the time per sample
    // outside traversal, the share and that time traced and rendered band by band, and the
    // share and time both ways again at 2 threads; obvhs: two rates.
    assert_eq!(sections["ray_limit"], 17, "{sections:?}");
    assert_eq!(sections["scaling_triangles"], 2, "{sections:?}");
    // Growth over the sweep: best against best, and the median of paired ratios.
    assert_eq!(sections["scaling_triangles_growth"], 2, "{sections:?}");
    // Four emitter choices (uniform, power, bvh, ris:8) rendered at 1 and 10 emitters.
    assert_eq!(sections["scaling_emitters"], 8, "{sections:?}");
    // The choice alone: four rules x (choice, pmf) at 1, 10 and 100 emitters; the tree's
    // build time, memory and depth at each.
    assert_eq!(sections["emitter_choice"], 4 * 2 * 3, "{sections:?}");
    assert_eq!(sections["light_tree"], 3 * 3, "{sections:?}");
    assert_eq!(sections["peak_memory"], 1, "{sections:?}");
    // Reading and building the scene of 1,000 emitters.
    assert_eq!(sections["load_xml"], 1, "{sections:?}");
    assert_eq!(sections["load_build"], 1, "{sections:?}");
    // Each goal of light, BSDF, one-sample and solid-angle against power MIS, per thread count.
    assert_eq!(sections["throughput_ratio"], 4 * 2, "{sections:?}");
    // The cost model: one coefficient per term, its error on the 20 runs it was fitted on
    // (7 strategies at two spp, six other mixes of techniques) and the 6 it never saw.
    assert_eq!(
        sections["cost_model"],
        directlab::cost::TERMS.len(),
        "{sections:?}"
    );
    assert_eq!(sections["cost_prediction_error_fitted"], 20, "{sections:?}");
    assert_eq!(
        sections["cost_prediction_error_held_out"], 6,
        "{sections:?}"
    );
    // The CPU the numbers were measured on, named.
    assert_eq!(sections["machine"], 1, "{sections:?}");
    // Every sampler's speed and its slowdown against the independent one (whose own is 1).
    let samplers = <directlab::sampler::SamplerKind as directlab::named::Named>::CHOICES.len();
    assert_eq!(sections["sampler_throughput"], samplers, "{sections:?}");
    assert_eq!(sections["sampler_slowdown"], samplers, "{sections:?}");
}
