//! The reference cache through `directlab run`: a reference made by another renderer build is
//! rendered again, and the run, its `--json` events and its report say why.

use crate::common;

use common::{directlab, run, scratch};
use std::path::Path;

/// `directlab run EXP --out OUT`, which must succeed.
fn run_ok(exp: &Path, out: &Path) {
    let o = run(directlab().args(["run", exp.to_str().unwrap(), "--out", out.to_str().unwrap()]));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// A reference cached by another renderer build is not trusted: the run renders it again and
/// the report and the `reference` event say "renderer changed". An older reference of the same
/// renderer under another key (the scene was edited) is named as such.
#[test]
fn reference_of_another_renderer_is_rendered_again_and_the_report_says_why() {
    let out = scratch("renderer-changed");
    let exp = common::tiny_experiment(&out, 1);
    run_ok(&exp, &out);
    let dir = out.join("tiny");
    let cache = dir.join("cache");
    let json = std::fs::read_dir(&cache)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "json"))
        .expect("a cached reference");
    let index = std::fs::read_to_string(dir.join("index.md")).unwrap();
    assert!(index.contains("no reference in the cache yet"), "{index}");

    // What an older build left: its key and its renderer hash differ from this build's.
    let info: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let key = info["key"].as_str().unwrap().to_string();
    let mut old = info.clone();
    old["key"] = "0123456789abcdef".into();
    old["renderer"] = "fedcba9876543210".into();
    for f in std::fs::read_dir(&cache).unwrap() {
        let p = f.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().to_string();
        if name.contains(&key) {
            std::fs::rename(&p, cache.join(name.replace(&key, "0123456789abcdef"))).unwrap();
        }
    }
    std::fs::write(
        cache.join("reference-0123456789abcdef.json"),
        serde_json::to_string(&old).unwrap(),
    )
    .unwrap();
    std::fs::remove_file(dir.join("results.csv")).unwrap();
    let o = run(directlab().args([
        "run",
        exp.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]));
    assert!(o.status.success());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains("renderer changed"), "{stderr}");
    let event = String::from_utf8_lossy(&o.stdout)
        .lines()
        .find(|l| l.contains("\"event\":\"reference\""))
        .expect("a reference event")
        .to_string();
    assert!(event.contains("renderer changed"), "{event}");
    let index = std::fs::read_to_string(dir.join("index.md")).unwrap();
    assert!(
        index.contains("rendered in this run: renderer changed")
            && index.contains("fedcba9876543210"),
        "{index}"
    );
    // The old build's reference is gone, the new one is back under this build's key.
    assert!(cache.join(format!("reference-{key}.json")).exists());
    assert!(!cache.join("reference-0123456789abcdef.json").exists());

    // Same renderer, other key: the scene or settings changed.
    let mut same = old.clone();
    same["renderer"] = info["renderer"].clone();
    std::fs::write(
        cache.join("reference-0123456789abcdef.json"),
        serde_json::to_string(&same).unwrap(),
    )
    .unwrap();
    std::fs::remove_file(cache.join(format!("reference-{key}.json"))).unwrap();
    std::fs::remove_file(dir.join("results.csv")).unwrap();
    let o = run(directlab().args(["run", exp.to_str().unwrap(), "--out", out.to_str().unwrap()]));
    assert!(o.status.success());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("the scene, its meshes, the defines or the reference settings changed"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&out).unwrap();
}
