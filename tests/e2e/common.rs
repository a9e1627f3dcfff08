//! Helpers shared by the end-to-end tests: paths into the repository, scratch directories,
//! and running the `directlab` binary.
// Every test file uses part of it.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// A path inside the repository.
pub fn repo(p: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(p)
}

/// A fresh, empty directory for one test (`name` must be unique among the tests).
pub fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("directlab-e2e-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Writes a generated report's `index.md` into `dir` (a temporary file, renamed).
pub fn write_index(dir: &Path, md: &str) {
    std::fs::create_dir_all(dir).unwrap();
    let tmp = dir.join("index.md.tmp");
    std::fs::write(&tmp, md).unwrap();
    std::fs::rename(&tmp, dir.join("index.md")).unwrap();
}

/// The `directlab` command built for these tests.
pub fn directlab() -> Command {
    Command::new(env!("CARGO_BIN_EXE_directlab"))
}

/// Runs `cmd`, showing its stderr if it fails (the caller decides whether it should).
pub fn run(cmd: &mut Command) -> Output {
    let out = cmd.output().expect("run directlab");
    if !out.status.success() {
        eprintln!("stderr: {}", String::from_utf8_lossy(&out.stderr));
    }
    out
}

/// Runs `cmd`: whether it succeeded, and its stdout followed by its stderr.
pub fn run_text(cmd: &mut Command) -> (bool, String) {
    let o = cmd.output().expect("run the command");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    (o.status.success(), text)
}

/// A small sweep for the sharding tests (16x16 two-light box, a reference of three chunks,
/// two strategies x three spp x two seeds, one equal-time budget), written into `dir`.
pub fn tiny_experiment(dir: &Path, seeds: u32) -> PathBuf {
    let scene = repo("scenes/cbox-twolights/cbox-twolights.xml");
    let text = format!(
        r#"title = "sharding test"
scene = "{}"
defines = {{ res = "16" }}
spp = [1, 4, 16]
seeds = {seeds}

[reference]
spp = 2600
strategy = {{ strategy = "mis", heuristic = "power", emitter_selection = "power" }}

[metrics]
relmse_epsilon = 0.01

[[strategy]]
name = "uniform choice"
strategy = "light"
emitter_selection = "uniform"

[[strategy]]
name = "power choice"
strategy = "light"
emitter_selection = "power"

[equal_time]
seconds = [0.02]

[figures]
equal_spp = 4
"#,
        scene.display()
    );
    let p = dir.join("tiny.toml");
    std::fs::write(&p, text).unwrap();
    p
}

/// The sweep rows of a results.csv without the columns that measure time (seconds,
/// samples/s): what must be equal however the sweep was split.
pub fn sweep_rows(csv: &Path) -> Vec<Vec<(String, String)>> {
    let text = std::fs::read_to_string(csv).unwrap_or_else(|e| panic!("{}: {e}", csv.display()));
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    lines
        .map(|l| {
            header
                .iter()
                .cloned()
                .zip(l.split(',').map(String::from))
                .collect::<Vec<_>>()
        })
        .filter(|r| r.iter().any(|(k, v)| k == "kind" && v == "spp"))
        .map(|r| {
            r.into_iter()
                .filter(|(k, _)| k != "seconds" && k != "samples_per_s")
                .collect()
        })
        .collect()
}

/// The reference cached under `<out>/<name>/cache`: its mean image (f32 EXR) and its
/// per-pixel statistics in f64, as bytes.
pub fn reference_bytes(exp_dir: &Path) -> (Vec<u8>, Vec<u8>) {
    let find = |suffix: &str| {
        std::fs::read_dir(exp_dir.join("cache"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .find(|p| {
                let n = p.file_name().unwrap().to_string_lossy().to_string();
                n.starts_with("reference-") && n.ends_with(suffix) && !n.ends_with("-var.exr")
            })
            .unwrap_or_else(|| panic!("no reference*{suffix} in {}", exp_dir.display()))
    };
    (
        std::fs::read(find(".exr")).unwrap(),
        std::fs::read(find(".f64")).unwrap(),
    )
}

/// The units folder of the plan in `exp_dir` and the plan's JSON.
pub fn plan_of(exp_dir: &Path) -> (PathBuf, serde_json::Value) {
    let plan: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(exp_dir.join("plan.json")).unwrap()).unwrap();
    let id = plan["id"].as_str().unwrap().to_string();
    (exp_dir.join("units").join(id), plan)
}

/// Every unit file in `units` with its modification time and inode (a rewritten file
/// changes both).
pub fn unit_files(units: &Path) -> Vec<(PathBuf, i64, u64)> {
    use std::os::unix::fs::MetadataExt;
    let mut v: Vec<_> = std::fs::read_dir(units)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "unit") && p.is_file())
        .map(|p| {
            let m = std::fs::metadata(&p).unwrap();
            (p, m.mtime() * 1_000_000_000 + m.mtime_nsec(), m.ino())
        })
        .collect();
    v.sort();
    v
}

/// Runs `cmd`, killing it and failing the test if it is still running after `secs`.
pub fn within(cmd: &mut Command, secs: u64) -> Output {
    let mut child = cmd
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run directlab");
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(secs) {
            let _ = child.kill();
            panic!("still running after {secs} s: {cmd:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// Runs `cmd` (60 s at most) and checks that it failed with `code` and a message containing
/// every one of `words`.
pub fn fails(cmd: &mut Command, code: i32, words: &[&str]) -> String {
    let o = within(cmd, 60);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(o.status.code(), Some(code), "{cmd:?}\n{err}");
    for w in words {
        assert!(err.contains(w), "{cmd:?}: expected '{w}' in:\n{err}");
    }
    assert!(!err.contains("panicked"), "{err}");
    err
}
