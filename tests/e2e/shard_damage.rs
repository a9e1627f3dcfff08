//! Unit files altered on disk (a damaged disk, a careless edit): `merge` checks every unit's
//! checksum, its film and counts against the plan and its values before writing anything, and
//! a good merged report stays byte for byte as it was; `status` lists the unit as bad with
//! its shard.

use crate::common::{directlab, plan_of, run, scratch, tiny_experiment};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn cli(args: &[&str], exp: &Path, out: &Path) -> std::process::Output {
    run(directlab().args(args).arg(exp).arg("--out").arg(out))
}

/// Every file of the experiment's folder but its units and reference cache, with its bytes.
fn report_files(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut m = BTreeMap::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            let name = p.file_name().unwrap().to_str().unwrap().to_string();
            if p.is_dir() {
                if name != "units" && name != "cache" {
                    todo.push(p);
                }
            } else {
                m.insert(p.clone(), std::fs::read(&p).unwrap());
            }
        }
    }
    m
}

/// Where a unit file's parts are: (row start, row length, statistics start or None).
fn layout(b: &[u8]) -> (usize, usize, Option<usize>) {
    let u32_at = |at: usize| u32::from_le_bytes(b[at..at + 4].try_into().unwrap()) as usize;
    let mut at = 8;
    at += 4 + u32_at(at); // plan id
    at += 8; // unit index
    at += 4 + u32_at(at); // unit name
    let row_len = u32_at(at);
    let row = at + 4;
    at = row + row_len;
    let stats = (b[at] == 1).then_some(at + 1);
    (row, row_len, stats)
}

/// The unit file's checksum made right again after an edit (FNV-1a 64 of everything before
/// it), so the checks behind the checksum are reached.
fn reseal(b: &mut [u8]) {
    let n = b.len();
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &x in &b[..n - 16] {
        h ^= x as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    b[n - 16..n - 8].copy_from_slice(&h.to_le_bytes());
}

fn put_u64(b: &mut [u8], at: usize, v: u64) {
    b[at..at + 8].copy_from_slice(&v.to_le_bytes());
}

#[test]
fn edited_units_are_refused_and_the_merged_report_is_left_whole() {
    let d = scratch("shards-damage");
    let exp = tiny_experiment(&d, 1);
    let out = d.join("out");
    assert!(cli(&["run", "--shard", "0/1"], &exp, &out).status.success());
    let o = cli(&["merge"], &exp, &out);
    assert!(o.status.success(), "{}", stderr(&o));
    let dir = out.join("tiny");
    let good = report_files(&dir);
    assert!(good.keys().any(|p| p.ends_with("index.md")));
    assert!(good.keys().any(|p| p.ends_with("results.csv")));

    let (units, plan) = plan_of(&dir);
    let list = plan["units"].as_array().unwrap();
    let find = |pred: &dyn Fn(&serde_json::Value) -> bool| {
        let i = list.iter().position(pred).unwrap();
        units.join(format!("{i:05}.unit"))
    };
    let image_unit = find(&|u| u["stage"] == "sweep" && u["image"] == true);
    let row_unit = find(&|u| u["stage"] == "sweep");
    let chunk = find(&|u| u["stage"] == "reference");

    // Each case: the edit, whether it is resealed, what the error must say. Then the merge
    // fails naming the file and its shard, status lists it as bad, and the report is as it was.
    type Edit = fn(&mut Vec<u8>);
    let dims: Edit = |b| {
        let s = layout(b).2.unwrap();
        put_u64(b, s, 32); // 16x16 relabelled 32x8: the same byte count
        put_u64(b, s + 8, 8);
    };
    let row: Edit = |b| {
        let (at, len, _) = layout(b);
        let text = std::str::from_utf8(&b[at..at + len]).unwrap();
        let values = text.find('\n').unwrap() + 1;
        let digit = text[values..]
            .find(|c: char| c.is_ascii_digit() && c != '9')
            .unwrap();
        b[at + values + digit] += 1;
    };
    let pixel: Edit = |b| {
        let s = layout(b).2.unwrap();
        put_u64(b, s + 40 + 8 * 7, 1e6f64.to_bits()); // pixel 2, green: mean 1e6
    };
    let nan_pixel: Edit = |b| {
        let s = layout(b).2.unwrap();
        put_u64(b, s + 40, f64::NAN.to_bits());
    };
    let cases: [(&Path, Edit, bool, &str); 6] = [
        (&image_unit, dims, false, "checksum"),
        (&image_unit, dims, true, "32x8 film; the plan says"),
        (&row_unit, row, false, "checksum"),
        (&chunk, pixel, false, "checksum"),
        (&chunk, nan_pixel, true, "pixel (0, 0)"),
        (&image_unit, nan_pixel, true, "pixel (0, 0)"),
    ];
    for (unit, edit, seal, want) in cases {
        let original = std::fs::read(unit).unwrap();
        let mut b = original.clone();
        edit(&mut b);
        if seal {
            reseal(&mut b);
        }
        std::fs::write(unit, &b).unwrap();
        // The reference merged already: its chunks are read again only without the cache.
        let cache = dir.join("cache");
        let moved = d.join("cache-aside");
        if *unit == chunk {
            std::fs::rename(&cache, &moved).unwrap();
        }
        let o = cli(&["merge"], &exp, &out);
        let e = stderr(&o);
        assert!(!o.status.success(), "{want}: merged");
        assert!(
            e.contains(&unit.display().to_string()) && e.contains(want) && e.contains("shard 0/1"),
            "{want}: {e}"
        );
        assert!(
            report_files(&dir) == good,
            "{want}: the merged report changed"
        );
        let s = cli(&["status"], &exp, &out);
        let s = String::from_utf8_lossy(&s.stdout);
        assert!(s.contains("bad:") && s.contains(want), "{want}: {s}");
        std::fs::write(unit, &original).unwrap();
        if *unit == chunk {
            std::fs::rename(&moved, &cache).unwrap();
        }
    }
    // Restored, the units merge again into the same report (timing columns aside, the rows
    // are the units', so results.csv is byte-identical).
    assert!(cli(&["merge"], &exp, &out).status.success());
    assert_eq!(
        std::fs::read(dir.join("results.csv")).unwrap(),
        good[&dir.join("results.csv")]
    );
    std::fs::remove_dir_all(&d).unwrap();
}
