//! Helpers shared by the end-to-end tests: paths into the repository, scratch directories,
//! and running the `directlab` binary.
// Each test binary compiles this module and uses only part of it.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

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
