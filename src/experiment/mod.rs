//! The experiment runner: sweeps of (strategy, spp, seed) against a cached reference, with
//! resumable results, left-out analysis and figures. It produces results (rows, images,
//! figures, metadata in an [`Outcome`]) and never calls the report writer: `report/` reads
//! what it produced, and `pipeline/` runs one after the other.

pub mod analysis;
pub mod args;
pub mod budget;
pub mod cache;
pub mod cases;
pub mod chunks;
pub mod costs;
pub mod events;
pub mod figures;
pub mod leftout;
pub mod lock;
mod measure;
pub mod method;
pub mod metric;
pub mod plan;
pub mod probe;
pub mod resolve;
pub mod results;
pub mod runner;
pub mod schema;
pub mod shard;
mod validate;

pub use resolve::load;
pub use runner::{run_experiment, Outcome, RunOptions};
pub use schema::Resolved;
use std::path::{Path, PathBuf};

/// The `experiments/` folder: in the working directory, else in the source tree this binary
/// was built from (so `cargo run -- reproduce` works from anywhere in a clone).
pub fn experiments_dir() -> Result<PathBuf, String> {
    let local = PathBuf::from("experiments");
    if local.is_dir() {
        return Ok(local);
    }
    let built = Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments");
    if built.is_dir() {
        return Ok(built);
    }
    Err("no experiments/ folder in the working directory; run from the repository root".into())
}

/// Every `*.toml` in the experiments folder, sorted.
pub fn all_experiments() -> Result<Vec<PathBuf>, String> {
    let dir = experiments_dir()?;
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    v.sort();
    Ok(v)
}
