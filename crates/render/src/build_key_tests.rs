//! The cache key follows the renderer and nothing else: every source file and every locked
//! dependency version of this crate change it; a harness crate's files and a harness-only
//! dependency do not; and the key compiled into this build is the key of the files on disk.

use super::*;

fn crate_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn lock_text() -> String {
    std::fs::read_to_string(find_lock(&crate_dir()).expect("workspace Cargo.lock")).unwrap()
}

/// A copy of this crate's key inputs (Cargo.toml, build.rs, src/) in a fresh folder.
fn copy_crate() -> PathBuf {
    static N: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
    let dir = std::env::temp_dir().join(format!(
        "directlab-key-{}-{}",
        std::process::id(),
        N.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
    ));
    let _ = std::fs::remove_dir_all(&dir);
    for rel in source_files(&crate_dir()).unwrap() {
        let to = dir.join(&rel);
        std::fs::create_dir_all(to.parent().unwrap()).unwrap();
        std::fs::copy(crate_dir().join(&rel), &to).unwrap();
    }
    dir
}

/// `text` with the version of package `name` replaced.
fn bump(text: &str, name: &str) -> String {
    let at = text
        .find(&format!("name = \"{name}\"\nversion = \""))
        .unwrap_or_else(|| panic!("{name} in Cargo.lock"));
    let v = at + text[at..].find("version = \"").unwrap() + "version = \"".len();
    format!("{}999.{}", &text[..v], &text[v..])
}

#[test]
fn built_key_is_the_key_of_these_sources() {
    assert_eq!(
        crate::RENDERER_HASH,
        renderer_key(&crate_dir(), &lock_text()).unwrap()
    );
}

#[test]
fn every_source_file_and_renderer_dependency_changes_the_key() {
    let dir = copy_crate();
    let lock = lock_text();
    let base = renderer_key(&dir, &lock).unwrap();
    assert_eq!(base, renderer_key(&crate_dir(), &lock).unwrap());
    let files = source_files(&dir).unwrap();
    // Modules the old hand-kept list had missed, and files deep in the tree.
    for rel in [
        "src/sampler/mod.rs",
        "src/film.rs",
        "src/integrator/lanes/mod.rs",
        "Cargo.toml",
    ] {
        assert!(
            files.iter().any(|f| f == rel),
            "{rel} not hashed: {files:?}"
        );
    }
    for rel in &files {
        let path = dir.join(rel);
        let old = std::fs::read(&path).unwrap();
        let mut new = old.clone();
        new.push(b' ');
        std::fs::write(&path, &new).unwrap();
        assert_ne!(renderer_key(&dir, &lock).unwrap(), base, "{rel}");
        std::fs::write(&path, &old).unwrap();
    }
    // A new file under src/ (a module not yet declared anywhere) counts too.
    std::fs::write(dir.join("src/new_module.rs"), "").unwrap();
    assert_ne!(renderer_key(&dir, &lock).unwrap(), base, "new file");
    std::fs::remove_file(dir.join("src/new_module.rs")).unwrap();
    assert_eq!(renderer_key(&dir, &lock).unwrap(), base);
    // Direct and indirect dependencies (bytemuck comes in through glam).
    for dep in ["glam", "obvhs", "sobol_burley", "exr", "rayon", "bytemuck"] {
        assert_ne!(
            renderer_key(&dir, &bump(&lock, dep)).unwrap(),
            base,
            "{dep}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn harness_files_and_harness_dependencies_do_not_change_the_key() {
    let lock = lock_text();
    let base = renderer_key(&crate_dir(), &lock).unwrap();
    // Crates only the harness uses (plotters and clap are not among them: Cargo.lock lists
    // every optional dependency, and a benchmark crate of obvhs's sorter names both).
    for dep in [
        "csv",
        "toml",
        "indicatif",
        "pulldown-cmark",
        "nv-flip",
        "dejavu",
        "directlab",
    ] {
        assert_eq!(
            renderer_key(&crate_dir(), &bump(&lock, dep)).unwrap(),
            base,
            "{dep}"
        );
    }
    // The harness's own sources are outside this crate's folder: nothing under it names them.
    let files = source_files(&crate_dir()).unwrap();
    assert!(files
        .iter()
        .all(|f| !f.contains("experiment") && !f.contains("report")));
}

#[test]
fn lock_closure_follows_versioned_dependency_names() {
    let lock = r#"
[[package]]
name = "directlab-render"
version = "0.1.0"
dependencies = [
 "a 1.0.0",
 "b",
]

[[package]]
name = "a"
version = "1.0.0"
source = "registry"

[[package]]
name = "a"
version = "2.0.0"
source = "registry"

[[package]]
name = "b"
version = "0.3.0"
dependencies = ["c"]

[[package]]
name = "c"
version = "0.1.0"
"#;
    let got = locked_closure(lock, PACKAGE).unwrap();
    assert_eq!(
        got,
        [
            "a 1.0.0 source = \"registry\"",
            "b 0.3.0 ",
            "c 0.1.0 ",
            "directlab-render 0.1.0 "
        ]
    );
    assert!(locked_closure("", PACKAGE).is_err());
}
