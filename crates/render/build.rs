//! Hashes the renderer (every source file of this crate and the resolved versions of the
//! crates it depends on) into DIRECTLAB_RENDERER_HASH, the key of cached reference images.
//! The rules are in src/build_key.rs, which the crate's tests also compile.

#[path = "src/fnv.rs"]
#[allow(dead_code)]
mod fnv;

#[path = "src/build_key.rs"]
#[allow(dead_code)]
mod build_key;

use std::path::PathBuf;

fn main() {
    let dir = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("set by cargo"));
    println!("cargo:rerun-if-changed=src");
    println!("cargo:rerun-if-changed=Cargo.toml");
    println!("cargo:rerun-if-changed=build.rs");
    let lock = match build_key::find_lock(&dir) {
        Some(path) => {
            println!("cargo:rerun-if-changed={}", path.display());
            std::fs::read_to_string(&path)
                .unwrap_or_else(|e| panic!("{}: cannot read: {e}", path.display()))
        }
        None => {
            // Built as a dependency of a project whose lock file is out of reach: the key
            // still covers the sources; dependency upgrades then need --fresh-reference.
            println!(
                "cargo:warning=no Cargo.lock above {}: the renderer hash covers its sources only",
                dir.display()
            );
            format!(
                "[[package]]\nname = \"{}\"\nversion = \"unlocked\"\n",
                build_key::PACKAGE
            )
        }
    };
    let key = build_key::renderer_key(&dir, &lock).unwrap_or_else(|e| panic!("renderer hash: {e}"));
    println!("cargo:rustc-env=DIRECTLAB_RENDERER_HASH={key}");
}
