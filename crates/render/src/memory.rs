//! How much memory this process may still take, from the tightest of what limits it: the
//! machine's free memory, the process's address-space and data limits (`ulimit -v`, `ulimit
//! -d`) and its cgroup's memory limit (a Slurm job's `--mem`, a container's limit). A run that
//! would not fit is refused before it starts, naming the limit that refused it; otherwise it
//! would be killed or abort part-way with nothing written.

use std::path::{Path, PathBuf};

/// One limit on this process's memory: how much it leaves, and what it is.
#[derive(Clone, Debug, PartialEq)]
pub struct Limit {
    /// Bytes the process may still allocate under this limit.
    pub left: u64,
    /// The limit, as a user would name it.
    pub what: String,
}

const GIB: f64 = (1u64 << 30) as f64;

fn gib(b: u64) -> f64 {
    b as f64 / GIB
}

/// The tightest limit on this process's memory now; None where none can be read (the checks
/// are then skipped rather than guessed).
pub fn tightest() -> Option<Limit> {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let mut limits = Vec::new();
    if let Some(avail) = meminfo_available() {
        limits.push(Limit {
            left: avail,
            what: format!(
                "this machine's available memory ({:.1} GiB, MemAvailable)",
                gib(avail)
            ),
        });
    }
    for (resource, name, field) in [
        (
            libc::RLIMIT_AS,
            "the address-space limit (RLIMIT_AS, `ulimit -v`)",
            "VmSize:",
        ),
        (
            libc::RLIMIT_DATA,
            "the data limit (RLIMIT_DATA, `ulimit -d`)",
            "VmData:",
        ),
    ] {
        if let Some(max) = rlimit(resource) {
            let used = status_kib(&status, field).unwrap_or(0) * 1024;
            limits.push(Limit {
                left: max.saturating_sub(used),
                what: format!(
                    "{name} of {:.1} GiB, {:.1} GiB of it in use",
                    gib(max),
                    gib(used)
                ),
            });
        }
    }
    if let Some(l) = cgroup_limit() {
        limits.push(l);
    }
    limits.into_iter().min_by_key(|l| l.left)
}

/// Refuses `need` bytes for `what` (e.g. "rendering the 6500x6500 film") when the tightest
/// limit leaves less, naming that limit.
pub fn check(need: u64, what: &str) -> Result<(), String> {
    check_within(need, what, tightest())
}

fn check_within(need: u64, what: &str, limit: Option<Limit>) -> Result<(), String> {
    match limit {
        Some(l) if need > l.left => Err(format!(
            "{what} needs about {:.1} GiB of memory, and {} leaves {:.1} GiB",
            gib(need),
            l.what,
            gib(l.left)
        )),
        _ => Ok(()),
    }
}

fn meminfo_available() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    status_kib(&text, "MemAvailable:").map(|k| k * 1024)
}

/// A `Name:   1234 kB` field of /proc/meminfo or /proc/self/status, in KiB.
fn status_kib(text: &str, field: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with(field))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// The soft limit of `resource`, None when unlimited or unreadable.
fn rlimit(resource: libc::__rlimit_resource_t) -> Option<u64> {
    let mut r = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: getrlimit writes one rlimit into the valid struct it is given.
    let ok = unsafe { libc::getrlimit(resource, &mut r) } == 0;
    (ok && r.rlim_cur != libc::RLIM_INFINITY).then_some(r.rlim_cur)
}

/// The tightest memory limit of this process's cgroup and its ancestors (v2 `memory.max`
/// less `memory.current`; v1 `memory.limit_in_bytes` less `memory.usage_in_bytes`).
fn cgroup_limit() -> Option<Limit> {
    let text = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    let mut best: Option<Limit> = None;
    for line in text.lines() {
        let mut parts = line.splitn(3, ':');
        let (_, controllers, path) = (parts.next()?, parts.next()?, parts.next()?);
        let (root, max, cur) = if controllers.is_empty() {
            ("/sys/fs/cgroup", "memory.max", "memory.current")
        } else if controllers.split(',').any(|c| c == "memory") {
            (
                "/sys/fs/cgroup/memory",
                "memory.limit_in_bytes",
                "memory.usage_in_bytes",
            )
        } else {
            continue;
        };
        let mut dir = PathBuf::from(root).join(path.trim_start_matches('/'));
        loop {
            if let Some(l) = cgroup_dir_limit(&dir, max, cur) {
                if best.as_ref().is_none_or(|b| l.left < b.left) {
                    best = Some(l);
                }
            }
            if dir == Path::new(root) || !dir.pop() {
                break;
            }
        }
    }
    best
}

fn cgroup_dir_limit(dir: &Path, max: &str, cur: &str) -> Option<Limit> {
    let read = |f: &str| std::fs::read_to_string(dir.join(f)).ok();
    let limit: u64 = read(max)?.trim().parse().ok()?; // "max": no limit
                                                      // v1 reports "no limit" as a huge number near 2^63.
    if limit >= 1 << 62 {
        return None;
    }
    let used: u64 = read(cur).and_then(|t| t.trim().parse().ok()).unwrap_or(0);
    Some(Limit {
        left: limit.saturating_sub(used),
        what: format!(
            "the cgroup memory limit ({} = {:.1} GiB, {:.1} GiB in use; e.g. a Slurm job's --mem)",
            dir.join(max).display(),
            gib(limit),
            gib(used)
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_refusal_names_the_limit_and_what_it_leaves() {
        let l = Limit {
            left: 3 << 30,
            what: "the address-space limit (RLIMIT_AS, `ulimit -v`) of 4.0 GiB".into(),
        };
        assert!(check_within(2 << 30, "rendering", Some(l.clone())).is_ok());
        let e = check_within(5 << 30, "rendering the 6500x6500 film", Some(l)).unwrap_err();
        assert!(
            e.contains("6500x6500") && e.contains("5.0 GiB") && e.contains("RLIMIT_AS"),
            "{e}"
        );
        assert!(e.contains("leaves 3.0 GiB"), "{e}");
        assert!(check_within(u64::MAX, "x", None).is_ok());
    }

    #[test]
    fn a_cgroup_limit_is_what_it_leaves_and_no_limit_is_none() {
        let d = std::env::temp_dir().join(format!("directlab-cgroup-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        std::fs::write(d.join("memory.max"), "4294967296\n").unwrap();
        std::fs::write(d.join("memory.current"), "1073741824\n").unwrap();
        let l = cgroup_dir_limit(&d, "memory.max", "memory.current").unwrap();
        assert_eq!(l.left, 3 << 30);
        assert!(
            l.what.contains("memory.max = 4.0 GiB") && l.what.contains("--mem"),
            "{l:?}"
        );
        std::fs::write(d.join("memory.max"), "max\n").unwrap();
        assert!(cgroup_dir_limit(&d, "memory.max", "memory.current").is_none());
        // cgroup v1 spells "no limit" as a number near 2^63.
        std::fs::write(d.join("memory.max"), "9223372036854771712\n").unwrap();
        assert!(cgroup_dir_limit(&d, "memory.max", "memory.current").is_none());
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn this_process_has_a_limit_that_is_read() {
        let l = tightest().expect("/proc/meminfo is readable here");
        assert!(l.left > 0 && !l.what.is_empty(), "{l:?}");
        assert_eq!(status_kib("VmSize:\t  2048 kB\n", "VmSize:"), Some(2048));
    }
}
