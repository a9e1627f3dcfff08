//! Output files: every file directlab writes goes through [`write_atomic`], which writes a
//! temporary sibling, flushes it to disk and renames it over the target, so a failed or killed
//! run never leaves a half-written file in place of a good one.
//!
//! What the rename must not do to the path it replaces:
//! - a symbolic link is written *through*: the file it points to is replaced, the link stays;
//! - anything that is not a regular file (a directory, a device such as `/dev/full`, a FIFO,
//!   a socket) is refused rather than replaced by a file;
//! - a file with several hard links is refused: a rename would silently detach this name
//!   from the others, which would keep the old contents;
//! - a write-protected file (no write bit for anyone) is refused, even for root, who could
//!   otherwise replace it;
//! - the replaced file's permission bits are kept.
//!
//! [`check_writable`] runs the same checks before a long computation, and also proves that
//! the directory accepts a new file, so an unwritable output fails in a second, not after the
//! render. Temporary files are named `<file>.tmp<pid>`; those left behind by a killed process
//! (its pid no longer running) are removed the next time a file is written in their directory.

use std::cell::RefCell;
use std::fs::{File, Metadata};
use std::path::{Path, PathBuf};

thread_local! {
    /// While [`as_one_set`] runs on this thread: the files written so far, as (temporary,
    /// target), renamed into place together at its end.
    static SET: RefCell<Option<Vec<(PathBuf, PathBuf)>>> = const { RefCell::new(None) };
}

/// Removes the temporary files of a set that did not finish (an error or a panic in it).
struct SetGuard;

impl Drop for SetGuard {
    fn drop(&mut self) {
        if let Some(files) = SET.with(|s| s.borrow_mut().take()) {
            for (tmp, _) in files {
                let _ = std::fs::remove_file(tmp);
            }
        }
    }
}

/// Runs `f` with every [`write_atomic`] on this thread held back: each file is written and
/// flushed under its temporary name, and only when `f` succeeds are they all renamed into
/// place. A failure part-way (a full disk, a bad input found late) leaves every old file as it
/// was, so a report is replaced as one set, never half. Reads of a file written in the set go
/// through [`pending`]. A nested call joins the outer set.
pub fn as_one_set<T>(f: impl FnOnce() -> Result<T, String>) -> Result<T, String> {
    if SET.with(|s| s.borrow().is_some()) {
        return f();
    }
    SET.with(|s| *s.borrow_mut() = Some(Vec::new()));
    let guard = SetGuard;
    let value = f()?;
    let files = SET.with(|s| s.borrow_mut().take()).unwrap_or_default();
    drop(guard);
    let mut dirs = Vec::new();
    for (k, (tmp, target)) in files.iter().enumerate() {
        if let Err(e) = std::fs::rename(tmp, target) {
            for (t, _) in &files[k..] {
                let _ = std::fs::remove_file(t);
            }
            return Err(format!(
                "{}: cannot rename into place: {e}",
                target.display()
            ));
        }
        if let Some(d) = target.parent().filter(|d| !dirs.contains(d)) {
            dirs.push(d);
        }
    }
    for d in dirs {
        if let Ok(d) = File::open(d) {
            let _ = d.sync_all();
        }
    }
    Ok(value)
}

/// The file to read for `path` on this thread: the new version written in the current
/// [`as_one_set`], if any, else `path` itself.
pub fn pending(path: &Path) -> PathBuf {
    let Ok(target) = resolve(path) else {
        return path.to_path_buf();
    };
    SET.with(|s| {
        s.borrow()
            .as_ref()
            .and_then(|files| files.iter().find(|(_, t)| *t == target))
            .map_or_else(|| path.to_path_buf(), |(tmp, _)| tmp.clone())
    })
}

/// Follows symbolic links to the path that is actually written (up to 40 links, as the
/// kernel allows). A dangling link resolves to the missing file it names.
fn resolve(path: &Path) -> Result<PathBuf, String> {
    let mut p = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let link = std::fs::read_link(&p)
                    .map_err(|e| format!("{}: cannot read link: {e}", p.display()))?;
                p = match p.parent() {
                    Some(dir) if link.is_relative() => dir.join(link),
                    _ => link,
                };
            }
            _ => return Ok(p),
        }
    }
    Err(format!(
        "{}: too many levels of symbolic links",
        path.display()
    ))
}

fn kind(m: &Metadata) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    let t = m.file_type();
    if t.is_dir() {
        "a directory"
    } else if t.is_block_device() || t.is_char_device() {
        "a device"
    } else if t.is_fifo() {
        "a FIFO"
    } else if t.is_socket() {
        "a socket"
    } else {
        "not a regular file"
    }
}

/// The existing file at `target` (already resolved), if any, after checking that it may be
/// replaced.
fn existing(shown: &Path, target: &Path) -> Result<Option<Metadata>, String> {
    use std::os::unix::fs::MetadataExt;
    let m = match std::fs::metadata(target) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(format!("{}: cannot inspect: {e}", shown.display())),
    };
    if !m.file_type().is_file() {
        return Err(format!(
            "{}: is {}; expected a regular file or a new path, so it is not replaced",
            shown.display(),
            kind(&m)
        ));
    }
    if m.nlink() > 1 {
        return Err(format!(
            "{}: has {} hard links; replacing it would detach this name from the others, so \
             it is not replaced (remove it or write elsewhere)",
            shown.display(),
            m.nlink()
        ));
    }
    if m.mode() & 0o222 == 0 {
        return Err(format!(
            "{}: is write-protected (mode {:o}); it is not replaced",
            shown.display(),
            m.mode() & 0o7777
        ));
    }
    Ok(Some(m))
}

/// The directory a file at `target` lives in, created if missing.
fn parent_dir(target: &Path) -> Result<PathBuf, String> {
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    std::fs::create_dir_all(&dir)
        .map_err(|e| format!("{}: cannot create directory: {e}", dir.display()))?;
    let m = std::fs::metadata(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    if !m.is_dir() {
        return Err(format!("{}: is not a directory", dir.display()));
    }
    use std::os::unix::fs::PermissionsExt;
    if m.permissions().mode() & 0o222 == 0 {
        return Err(format!(
            "{}: the directory is read-only (mode {:o})",
            dir.display(),
            m.permissions().mode() & 0o7777
        ));
    }
    Ok(dir)
}

/// A sibling path for the temporary file, in the same directory so rename is atomic. Named
/// by pid and host: on a shared file system (cluster shards) a pid alone says nothing about
/// a writer on another node.
fn temp_path(target: &Path) -> PathBuf {
    let mut name = target
        .file_name()
        .map(|n| n.to_os_string())
        .unwrap_or_default();
    name.push(format!(".tmp{}@{}", std::process::id(), host()));
    target.with_file_name(name)
}

/// This machine's host name ("" if it has none), as it appears in temporary file names.
pub fn host() -> String {
    let mut buf = [0u8; 256];
    // SAFETY: the buffer is valid for its length; gethostname NUL-terminates within it or
    // truncates, and the result is read up to the first NUL only.
    let ok = unsafe { libc::gethostname(buf.as_mut_ptr().cast(), buf.len() - 1) } == 0;
    let end = buf.iter().position(|&b| b == 0).unwrap_or(0);
    if ok {
        String::from_utf8_lossy(&buf[..end]).replace(['/', '@'], "_")
    } else {
        String::new()
    }
}

/// The pid in a temporary file's name (`<anything>.tmp<digits>` or
/// `<anything>.tmp<digits>@<host>`), when it was written on this host: another host's
/// writer cannot be checked from here, so its file is left alone.
fn temp_pid(name: &str) -> Option<u32> {
    let (_, tail) = name.rsplit_once(".tmp")?;
    let digits = match tail.split_once('@') {
        Some((d, h)) if h == host() => d,
        Some(_) => return None,
        None => tail,
    };
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    digits.parse().ok()
}

/// Whether process `pid` runs on this machine.
pub fn process_running(pid: u32) -> bool {
    Path::new("/proc").join(pid.to_string()).exists()
}

/// Removes the temporary files in `dir` whose writer is no longer running. Returns how many.
pub fn clean_stale_temps(dir: &Path) -> usize {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return 0;
    };
    let me = std::process::id();
    let mut removed = 0;
    for e in rd.flatten() {
        let name = e.file_name();
        let Some(pid) = name.to_str().and_then(temp_pid) else {
            continue;
        };
        let is_file = e.file_type().map(|t| t.is_file()).unwrap_or(false);
        if is_file && pid != me && !process_running(pid) && std::fs::remove_file(e.path()).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// Checks, before any work, that `path` can be written by [`write_atomic`]: what is there may
/// be replaced, and its directory (or, while it does not exist yet, the nearest existing one
/// above it) accepts a new file. Nothing is created: a run that fails later leaves no empty
/// folders behind.
pub fn check_writable(path: &Path) -> Result<(), String> {
    let target = resolve(path)?;
    existing(path, &target)?;
    let mut dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    while std::fs::symlink_metadata(&dir).is_err() {
        if !dir.pop() || dir.as_os_str().is_empty() {
            dir = PathBuf::from(".");
            break;
        }
    }
    let m = std::fs::metadata(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    if !m.is_dir() {
        return Err(format!(
            "{}: {} is not a directory",
            path.display(),
            dir.display()
        ));
    }
    use std::os::unix::fs::PermissionsExt;
    if m.permissions().mode() & 0o222 == 0 {
        return Err(format!(
            "{}: the directory is read-only (mode {:o})",
            dir.display(),
            m.permissions().mode() & 0o7777
        ));
    }
    let probe = dir.join(
        temp_path(&target)
            .file_name()
            .expect("a temporary file has a name"),
    );
    File::create_new(&probe)
        .map_err(|e| format!("{}: cannot write in {}: {e}", path.display(), dir.display()))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// Refuses two outputs that are the same file (the same path spelled differently, or links to
/// one file): the second write would silently replace the first. `outputs` are (what, path)
/// pairs, e.g. `("--out", ...)`, named in the message.
pub fn check_distinct(outputs: &[(&str, &Path)]) -> Result<(), String> {
    let keys: Vec<PathBuf> = outputs
        .iter()
        .map(|(_, p)| identity(p))
        .collect::<Result<_, _>>()?;
    for i in 0..outputs.len() {
        for j in 0..i {
            if keys[i] == keys[j] {
                return Err(format!(
                    "{} and {} are the same file ({}): one would overwrite the other",
                    outputs[j].0,
                    outputs[i].0,
                    outputs[i].1.display()
                ));
            }
        }
    }
    Ok(())
}

/// An absolute, link-free spelling of the file `path` writes to.
fn identity(path: &Path) -> Result<PathBuf, String> {
    let target = resolve(path)?;
    let name = target
        .file_name()
        .ok_or_else(|| format!("{}: expected a file name", path.display()))?
        .to_os_string();
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    // A directory that does not exist yet cannot hide an alias; spell it absolutely.
    let dir = std::fs::canonicalize(&dir)
        .unwrap_or_else(|_| std::env::current_dir().map(|c| c.join(&dir)).unwrap_or(dir));
    Ok(dir.join(name))
}

/// Writes through `write` into a temporary file, flushes it to disk and renames it over
/// `path` (through symbolic links), keeping the replaced file's permissions.
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<(), String> {
    let target = resolve(path)?;
    let old = existing(path, &target)?;
    let dir = parent_dir(&target)?;
    clean_stale_temps(&dir);
    let tmp = temp_path(&target);
    let result = write(&tmp).and_then(|_| {
        if let Some(old) = &old {
            std::fs::set_permissions(&tmp, old.permissions())
                .map_err(|e| format!("{}: cannot set permissions: {e}", path.display()))?;
        }
        File::open(&tmp)
            .and_then(|f| f.sync_all())
            .map_err(|e| format!("{}: cannot flush to disk: {e}", path.display()))?;
        let held = SET.with(|s| match s.borrow_mut().as_mut() {
            Some(files) => {
                if !files.iter().any(|(_, t)| *t == target) {
                    files.push((tmp.clone(), target.clone()));
                }
                true
            }
            None => false,
        });
        if held {
            return Ok(());
        }
        std::fs::rename(&tmp, &target)
            .map_err(|e| format!("{}: cannot rename into place: {e}", path.display()))
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
        return result;
    }
    // The rename itself is durable once the directory is flushed; not every file system
    // supports that, and the file is in place either way.
    if let Ok(d) = File::open(&dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::{MetadataExt, PermissionsExt};

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("directlab-out-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn put(path: &Path, text: &str) -> Result<(), String> {
        write_atomic(path, |tmp| {
            std::fs::write(tmp, text).map_err(|e| e.to_string())
        })
    }

    #[test]
    fn failed_write_keeps_old_file_and_leaves_no_temp() {
        let dir = scratch("fail");
        let path = dir.join("keep.txt");
        std::fs::write(&path, "good").unwrap();
        let r = write_atomic(&path, |tmp| {
            std::fs::write(tmp, "half").unwrap();
            Err("boom".into())
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "good");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_set_is_replaced_whole_or_not_at_all() {
        let dir = scratch("set");
        let (a, b) = (dir.join("a.txt"), dir.join("b.txt"));
        put(&a, "old a").unwrap();
        put(&b, "old b").unwrap();
        // Fails after the first file: neither is replaced, no temporary is left.
        let r: Result<(), String> = as_one_set(|| {
            put(&a, "new a")?;
            assert_eq!(std::fs::read_to_string(&a).unwrap(), "old a", "held back");
            assert_eq!(std::fs::read_to_string(pending(&a)).unwrap(), "new a");
            Err("disk full".into())
        });
        assert_eq!(r.unwrap_err(), "disk full");
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old a");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 2);
        // A panic in the set leaves the old files too.
        let caught = std::panic::catch_unwind(|| {
            let _ = as_one_set(|| -> Result<(), String> {
                put(&b, "new b")?;
                panic!("bad input found late")
            });
        });
        assert!(caught.is_err());
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "old b");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 2);
        // Success: both are replaced; nested sets join the outer one.
        as_one_set(|| {
            put(&a, "new a")?;
            as_one_set(|| put(&b, "new b"))?;
            assert_eq!(std::fs::read_to_string(&b).unwrap(), "old b");
            Ok(())
        })
        .unwrap();
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "new a");
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "new b");
        assert_eq!(pending(&a), a);
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 2);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn symlinks_are_written_through_and_modes_kept() {
        let dir = scratch("link");
        let real = dir.join("real.txt");
        std::fs::write(&real, "old").unwrap();
        std::fs::set_permissions(&real, std::fs::Permissions::from_mode(0o640)).unwrap();
        let link = dir.join("link.txt");
        std::os::unix::fs::symlink("real.txt", &link).unwrap();
        put(&link, "new").unwrap();
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read_to_string(&real).unwrap(), "new");
        assert_eq!(std::fs::metadata(&real).unwrap().mode() & 0o777, 0o640);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn refuses_non_regular_hard_linked_and_protected_targets() {
        let dir = scratch("refuse");
        let sub = dir.join("sub");
        std::fs::create_dir(&sub).unwrap();
        let e = put(&sub, "x").unwrap_err();
        assert!(e.contains("is a directory"), "{e}");
        assert!(sub.is_dir());

        let a = dir.join("a.txt");
        std::fs::write(&a, "a").unwrap();
        std::fs::hard_link(&a, dir.join("b.txt")).unwrap();
        let e = put(&a, "x").unwrap_err();
        assert!(e.contains("2 hard links"), "{e}");
        assert_eq!(std::fs::read_to_string(dir.join("b.txt")).unwrap(), "a");

        let p = dir.join("p.txt");
        std::fs::write(&p, "p").unwrap();
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o444)).unwrap();
        let e = put(&p, "x").unwrap_err();
        assert!(e.contains("write-protected"), "{e}");
        assert!(check_writable(&p).is_err());
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "p");

        // A character device is never replaced by a file.
        let e = check_writable(Path::new("/dev/null")).unwrap_err();
        assert!(e.contains("a device"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn read_only_directory_is_found_by_the_check() {
        let dir = scratch("rodir");
        let ro = dir.join("ro");
        std::fs::create_dir(&ro).unwrap();
        std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
        let e = check_writable(&ro.join("x.exr")).unwrap_err();
        assert!(e.contains("read-only"), "{e}");
        assert_eq!(std::fs::read_dir(&ro).unwrap().count(), 0);
        assert!(check_writable(&dir.join("new/deeper/x.exr")).is_ok());
        assert!(!dir.join("new").exists(), "the check creates nothing");
        let e = check_writable(&ro.join("new/x.exr")).unwrap_err();
        assert!(e.contains("read-only"), "{e}");
        std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn stale_temps_of_dead_processes_are_removed() {
        let dir = scratch("stale");
        // pid 2^22 + 1 is above Linux's pid limit, so it cannot be running.
        let dead = dir.join("img.exr.tmp4194305");
        std::fs::write(&dead, "half").unwrap();
        let mine = temp_path(&dir.join("other.exr"));
        std::fs::write(&mine, "in flight").unwrap();
        let unrelated = dir.join("notes.tmp");
        std::fs::write(&unrelated, "user's").unwrap();
        let dead_here = dir.join(format!("b.exr.tmp4194305@{}", host()));
        std::fs::write(&dead_here, "half").unwrap();
        // Written by a node sharing the file system: its pid cannot be checked from here.
        let other_host = dir.join("c.exr.tmp4194305@elsewhere-node");
        std::fs::write(&other_host, "in flight there").unwrap();
        put(&dir.join("img.exr"), "new").unwrap();
        assert!(!dead.exists() && !dead_here.exists());
        assert!(mine.exists() && unrelated.exists() && other_host.exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn same_file_under_two_names_is_refused() {
        let dir = scratch("distinct");
        let a = dir.join("a.exr");
        let dotted = dir.join(".").join("a.exr");
        let e = check_distinct(&[("--out", &a), ("--variance", &dotted)]).unwrap_err();
        assert!(e.contains("--out and --variance"), "{e}");
        std::fs::write(&a, "x").unwrap();
        let link = dir.join("l.exr");
        std::os::unix::fs::symlink(&a, &link).unwrap();
        assert!(check_distinct(&[("--out", &a), ("--stats", &link)]).is_err());
        assert!(check_distinct(&[("--out", &a), ("--stats", &dir.join("b.exr"))]).is_ok());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
