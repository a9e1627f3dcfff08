//! The renderer's cache key, [`crate::RENDERER_HASH`]: computed by `build.rs` (which includes
//! this file) from every file of this crate's sources and the resolved versions of every crate
//! it depends on, read from `Cargo.lock`. No list is kept by hand, so nothing that decides a
//! pixel's value can be left out of it: a new module, a new dependency or an upgrade of one
//! changes the key, and every cached reference rendered by the old code is re-rendered.
//!
//! What the key covers: `Cargo.toml`, `build.rs` and every file under `src/` (tests included:
//! telling test code from renderer code by file name is the kind of rule that drifts), and,
//! for this package and every package reachable from it through `Cargo.lock`'s dependency
//! lists, the name, version, source and checksum. Those lists include build, dev and optional
//! dependencies, so the key errs on the side of re-rendering: an upgrade of a crate that is
//! listed but never built for the renderer also changes it.
//! Files of the harness crate are outside this crate's folder and never seen.

use crate::fnv::Fnv;
use std::path::{Path, PathBuf};

/// The package whose dependencies the key follows in `Cargo.lock`.
pub const PACKAGE: &str = "directlab-render";

/// The files the key reads, relative to the crate folder `dir` with `/` separators, sorted:
/// `Cargo.toml`, `build.rs` and everything under `src/`.
pub fn source_files(dir: &Path) -> Result<Vec<String>, String> {
    fn walk(dir: &Path, rel: &str, out: &mut Vec<String>) -> Result<(), String> {
        let rd = std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        for entry in rd {
            let entry = entry.map_err(|e| format!("{}: {e}", dir.display()))?;
            let name = entry.file_name().to_string_lossy().into_owned();
            let rel = format!("{rel}/{name}");
            let path = entry.path();
            if path.is_dir() {
                walk(&path, &rel, out)?;
            } else {
                out.push(rel);
            }
        }
        Ok(())
    }
    let mut out = vec!["Cargo.toml".to_string(), "build.rs".to_string()];
    walk(&dir.join("src"), "src", &mut out)?;
    out.sort();
    Ok(out)
}

/// One `[[package]]` of a `Cargo.lock`.
#[derive(Debug, Default, Clone)]
struct Locked {
    name: String,
    version: String,
    /// Every other line of the entry (source, checksum), as written.
    rest: Vec<String>,
    /// Entries of `dependencies`: `name`, or `name version` where the name is ambiguous.
    deps: Vec<String>,
}

fn parse_lock(text: &str) -> Vec<Locked> {
    let mut out: Vec<Locked> = Vec::new();
    let mut in_deps = false;
    for line in text.lines() {
        let line = line.trim();
        if line == "[[package]]" {
            out.push(Locked::default());
            in_deps = false;
            continue;
        }
        let Some(p) = out.last_mut() else { continue };
        if in_deps {
            if line == "]" {
                in_deps = false;
            } else {
                p.deps
                    .push(line.trim_end_matches(',').trim_matches('"').to_string());
            }
        } else if let Some(list) = line.strip_prefix("dependencies = [") {
            match list.strip_suffix(']') {
                // Written on one line (Cargo writes one entry per line; hand edits may not).
                Some(inline) => p.deps.extend(
                    inline
                        .split(',')
                        .map(|d| d.trim().trim_matches('"').to_string())
                        .filter(|d| !d.is_empty()),
                ),
                None => in_deps = true,
            }
        } else if let Some(v) = line.strip_prefix("name = ") {
            p.name = v.trim_matches('"').to_string();
        } else if let Some(v) = line.strip_prefix("version = ") {
            p.version = v.trim_matches('"').to_string();
        } else if !line.is_empty() && !line.starts_with('[') {
            p.rest.push(line.to_string());
        }
    }
    out
}

/// `package` and every package reachable from it in the lock file `text`, each as one line
/// (`name version` and its source and checksum), sorted.
pub fn locked_closure(text: &str, package: &str) -> Result<Vec<String>, String> {
    let all = parse_lock(text);
    let find = |spec: &str| -> Option<&Locked> {
        let mut words = spec.split(' ');
        let name = words.next()?;
        let version = words.next();
        all.iter()
            .find(|p| p.name == name && version.is_none_or(|v| p.version == v))
    };
    let root = find(package).ok_or_else(|| format!("Cargo.lock has no package {package}"))?;
    let mut seen: Vec<&Locked> = vec![root];
    let mut stack = vec![root];
    while let Some(p) = stack.pop() {
        for d in &p.deps {
            let q =
                find(d).ok_or_else(|| format!("Cargo.lock: {} needs {d}, not listed", p.name))?;
            if !seen.iter().any(|s| std::ptr::eq(*s, q)) {
                seen.push(q);
                stack.push(q);
            }
        }
    }
    let mut lines: Vec<String> = seen
        .iter()
        .map(|p| format!("{} {} {}", p.name, p.version, p.rest.join(" ")))
        .collect();
    lines.sort();
    Ok(lines)
}

/// The `Cargo.lock` that resolves the crate in `dir`: the nearest one in `dir` or above it.
pub fn find_lock(dir: &Path) -> Option<PathBuf> {
    dir.ancestors()
        .map(|d| d.join("Cargo.lock"))
        .find(|p| p.is_file())
}

/// The key of the crate in `dir` resolved by the lock file `lock` (its text).
pub fn renderer_key(dir: &Path, lock: &str) -> Result<String, String> {
    let mut h = Fnv::new();
    for rel in source_files(dir)? {
        let path = dir.join(&rel);
        let bytes = std::fs::read(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        h.field(rel.as_bytes());
        h.field(&bytes);
    }
    for line in locked_closure(lock, PACKAGE)? {
        h.field(line.as_bytes());
    }
    Ok(h.hex())
}

#[cfg(test)]
#[path = "build_key_tests.rs"]
mod tests;
