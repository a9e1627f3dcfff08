//! The architecture, checked: the renderer crate depends on no harness crate and on no
//! plotting, CSV, TOML, HTML or command-line crate (the compiler keeps it from naming the
//! harness itself); the experiment runner never calls the report writer or the commands above
//! it (reports read results); and every source file reads in one sitting (600 lines at most).

use crate::common;

use common::repo;
use std::path::{Path, PathBuf};

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

#[test]
fn the_renderer_depends_on_no_harness_crate() {
    let toml = std::fs::read_to_string(repo("crates/render/Cargo.toml")).unwrap();
    let deps = &toml[toml.find("[dependencies]").unwrap()..];
    let deps = &deps[..deps.find("[dev-dependencies]").unwrap_or(deps.len())];
    for harness in [
        "directlab ",
        "directlab=",
        "plotters",
        "csv",
        "toml",
        "pulldown-cmark",
        "clap",
        "indicatif",
        "serde_json",
        "nv-flip",
        "statrs",
    ] {
        let named = deps.lines().any(|l| l.trim_start().starts_with(harness));
        assert!(!named, "crates/render depends on {harness}");
    }
}

#[test]
fn the_experiment_runner_never_calls_reports_or_commands() {
    let mut files = Vec::new();
    rust_files(&repo("src/experiment"), &mut files);
    assert!(files.len() > 20);
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        for forbidden in ["crate::report", "crate::pipeline", "crate::cli"] {
            assert!(
                !text.contains(forbidden),
                "{} names {forbidden}",
                f.display()
            );
        }
    }
}

#[test]
fn every_source_file_reads_in_one_sitting() {
    let mut files = Vec::new();
    for d in ["src", "crates/render/src", "tests", "examples"] {
        rust_files(&repo(d), &mut files);
    }
    for f in files {
        let n = std::fs::read_to_string(&f).unwrap().lines().count();
        assert!(n <= 600, "{} has {n} lines", f.display());
    }
}
