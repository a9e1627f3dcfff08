//! Hashes the renderer's source (everything that decides a pixel's value) into
//! DIRECTLAB_RENDERER_HASH, so the experiment runner's reference cache is invalidated when the
//! renderer changes, not only when the crate version is bumped. Harness code (experiments,
//! plots, reports, statistics, tests) is left out: changing it must not cost a re-render.

use std::path::{Path, PathBuf};

const RENDERER: &[&str] = &[
    "src/render.rs",
    "src/rng.rs",
    "src/math.rs",
    "src/camera.rs",
    "src/integrator",
    "src/bsdf",
    "src/emitter",
    "src/geometry",
    "src/sampling",
    "src/scene",
];

fn files(p: &Path, out: &mut Vec<PathBuf>) {
    if p.is_dir() {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(p)
            .expect("readable source folder")
            .map(|e| e.expect("readable entry").path())
            .collect();
        entries.sort();
        for e in entries {
            files(&e, out);
        }
    } else {
        let name = p.file_name().unwrap_or_default().to_string_lossy();
        let test_only = name.contains("test") || name == "fixtures.rs";
        if name.ends_with(".rs") && !test_only {
            out.push(p.to_path_buf());
        }
    }
}

fn main() {
    let mut all = Vec::new();
    for r in RENDERER {
        println!("cargo:rerun-if-changed={r}");
        files(Path::new(r), &mut all);
    }
    // FNV-1a, 64 bit, over length-prefixed (path, contents) pairs.
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut feed = |b: &[u8]| {
        for &x in (b.len() as u64).to_le_bytes().iter().chain(b) {
            h ^= x as u64;
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    };
    for f in &all {
        feed(f.to_string_lossy().replace('\\', "/").as_bytes());
        feed(&std::fs::read(f).expect("readable source file"));
    }
    println!("cargo:rustc-env=DIRECTLAB_RENDERER_HASH={h:016x}");
}
