//! One run at a time per experiment folder: two runs writing `results.csv`, the cache and the
//! report of one folder would mix their results. A run holds `<folder>/.directlab.lock` (its
//! pid, host and start time) until it ends; a second run is refused naming the holder. A lock
//! left by a killed run (its pid no longer running on this host) is taken over. Shards of a
//! plan take no lock: they write their own unit files, and run side by side by design.

use std::io::Write;
use std::path::{Path, PathBuf};

/// The lock file's name inside an experiment folder.
pub const NAME: &str = ".directlab.lock";

/// A held lock; dropping it releases it.
#[derive(Debug)]
pub struct Lock {
    path: PathBuf,
}

impl Drop for Lock {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

/// Takes the lock of experiment folder `dir` (creating the folder), or says who holds it.
pub fn acquire(dir: &Path) -> Result<Lock, String> {
    if dir.exists() && !dir.is_dir() {
        return Err(format!(
            "{}: is a file; an experiment's output goes to a folder of that name (check --out)",
            dir.display()
        ));
    }
    std::fs::create_dir_all(dir).map_err(|e| {
        format!(
            "{}: cannot create the experiment's folder: {e} (check --out)",
            dir.display()
        )
    })?;
    let path = dir.join(NAME);
    let host = crate::output::host();
    for _ in 0..2 {
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&path)
        {
            Ok(mut f) => {
                let since = std::time::SystemTime::now()
                    .duration_since(std::time::UNIX_EPOCH)
                    .map_or(0, |d| d.as_secs());
                writeln!(f, "{} {host} {since}", std::process::id())
                    .map_err(|e| format!("{}: {e}", path.display()))?;
                return Ok(Lock { path });
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                let text = std::fs::read_to_string(&path).unwrap_or_default();
                let mut parts = text.split_whitespace();
                let pid = parts.next().and_then(|p| p.parse::<u32>().ok());
                let holder_host = parts.next().unwrap_or("").to_string();
                let since = parts.next().unwrap_or("?").to_string();
                let gone = match pid {
                    Some(pid) => holder_host == host && !crate::output::process_running(pid),
                    // Unreadable or half-written: its writer died between create and write.
                    None => true,
                };
                if gone {
                    let _ = std::fs::remove_file(&path);
                    continue;
                }
                return Err(format!(
                    "{}: another directlab run is writing this experiment's folder (pid {} on \
                     host {holder_host}, started at unix time {since}); two runs into one \
                     folder would mix their results. Wait for it, or use another --out (if that \
                     run is gone, remove {})",
                    dir.display(),
                    pid.expect("checked"),
                    path.display()
                ));
            }
            Err(e) => return Err(format!("{}: cannot create the lock: {e}", path.display())),
        }
    }
    Err(format!(
        "{}: could not take the lock (it keeps reappearing)",
        path.display()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_run_is_refused_naming_the_holder_and_a_dead_holder_is_replaced() {
        let d = std::env::temp_dir().join(format!("directlab-lock-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        let held = acquire(&d).unwrap();
        let e = acquire(&d).unwrap_err();
        assert!(
            e.contains(&format!("pid {}", std::process::id())) && e.contains(NAME),
            "{e}"
        );
        drop(held);
        assert!(!d.join(NAME).exists());
        // A lock of a process that is gone (pid beyond pid_max) is taken over.
        std::fs::write(
            d.join(NAME),
            format!("4194305 {} 0\n", crate::output::host()),
        )
        .unwrap();
        let again = acquire(&d).unwrap();
        drop(again);
        // Another host's lock cannot be checked from here: refused.
        std::fs::write(d.join(NAME), "1 some-other-node 0\n").unwrap();
        assert!(acquire(&d).unwrap_err().contains("some-other-node"));
        std::fs::remove_file(d.join(NAME)).unwrap();
        // A file where the folder should be.
        let f = d.join("file");
        std::fs::write(&f, "x").unwrap();
        assert!(acquire(&f).unwrap_err().contains("is a file"));
        std::fs::remove_dir_all(&d).unwrap();
    }
}
