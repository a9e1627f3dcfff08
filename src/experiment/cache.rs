//! Reference images: rendered once at high spp and cached under a key that changes whenever
//! anything that could change the image changes: the scene file and every file it references
//! (meshes), the `-D` overrides, the reference's spp, seed and estimator, the crate version and
//! the renderer crate's hash ([`RENDERER_HASH`]: every source file of `crates/render` and the
//! locked versions of the crates it depends on). A reference cached under another key is
//! re-rendered, and the run and its report say why ([`why_not_cached`]).

use crate::film::{self, Image};
use crate::integrator::Strategy;
use crate::scene::Scene;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

pub use crate::RENDERER_HASH;

pub use crate::fnv::Fnv;

/// The scene file and the files it names through `filename` parameters (after `$name`
/// substitution with the defines), in document order.
pub fn scene_files(scene: &Path, defines: &[(String, String)]) -> Result<Vec<PathBuf>, String> {
    let xml = std::fs::read_to_string(scene)
        .map_err(|e| format!("{}: cannot read scene: {e}", scene.display()))?;
    let root =
        crate::scene::xml::parse_document(&xml, scene, defines).map_err(|e| e.to_string())?;
    let dir = scene.parent().unwrap_or(Path::new("."));
    let mut files = vec![scene.to_path_buf()];
    let mut stack = vec![&root];
    while let Some(e) = stack.pop() {
        if e.attr("name") == Some("filename") {
            if let Some(v) = e.attr("value") {
                files.push(dir.join(v));
            }
        }
        stack.extend(e.children.iter().rev());
    }
    Ok(files)
}

/// Everything the reference image depends on.
pub struct KeyInputs<'a> {
    pub scene: &'a Path,
    pub defines: &'a [(String, String)],
    pub spp: u32,
    pub seed: u64,
    pub strategy: &'a Strategy,
}

pub fn reference_key(k: &KeyInputs) -> Result<String, String> {
    let mut h = Fnv::new();
    h.field(env!("CARGO_PKG_VERSION").as_bytes());
    h.field(RENDERER_HASH.as_bytes());
    // A test build's seeded bug renders other pixels from the same sources (no field
    // without one, so that the keys of correct builds stay as they were).
    let bug = directlab_render::seeded::tag();
    if !bug.is_empty() {
        h.field(bug.as_bytes());
    }
    for f in scene_files(k.scene, k.defines)? {
        let bytes = std::fs::read(&f).map_err(|e| format!("{}: cannot read: {e}", f.display()))?;
        // File names relative to the scene folder would be nicer, but the contents are what
        // matter; the name only guards against two files swapping places.
        h.field(f.file_name().unwrap_or_default().as_encoded_bytes());
        h.field(&bytes);
    }
    let mut defines = k.defines.to_vec();
    defines.sort();
    for (n, v) in &defines {
        h.field(n.as_bytes()).field(v.as_bytes());
    }
    h.field(&k.spp.to_le_bytes()).field(&k.seed.to_le_bytes());
    h.field(format!("{:?}", k.strategy).as_bytes());
    Ok(h.hex())
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ReferenceInfo {
    pub key: String,
    /// `RENDERER_HASH` of the binary that rendered it.
    #[serde(default)]
    pub renderer: String,
    pub strategy: String,
    pub spp: u32,
    pub seed: u64,
    pub seconds: f64,
    pub non_finite_samples: u64,
    /// mean over pixels and channels of the reference's variance image: the expected MSE
    /// between the reference and the true image, added to every measured MSE.
    pub mse_floor: f64,
    /// The same for relMSE (each pixel's variance divided by r^2 + epsilon).
    pub relmse_floor: f64,
    pub relmse_epsilon: f64,
}

pub struct Reference {
    pub mean: Image,
    pub variance: Image,
    pub info: ReferenceInfo,
    /// True if it came from the cache.
    pub cached: bool,
    /// Why it was rendered rather than read from the cache (None when cached).
    pub why_rendered: Option<String>,
}

/// Why the cache in `dir` has no reference under `key`: the references it holds under other
/// keys were made by another renderer build ("renderer changed", with both hashes), or by this
/// one for other inputs (scene, meshes, defines or reference settings), or there are none.
pub fn why_not_cached(dir: &Path, key: &str) -> String {
    let mut others: Vec<ReferenceInfo> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .filter_map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            let k = name.strip_prefix("reference-")?.strip_suffix(".json")?;
            if k == key {
                return None;
            }
            serde_json::from_str(&std::fs::read_to_string(e.path()).ok()?).ok()
        })
        .collect();
    others.sort_by(|a, b| a.key.cmp(&b.key));
    match others.iter().find(|i| i.renderer != RENDERER_HASH) {
        Some(old) => format!(
            "renderer changed: the cached reference {} was rendered by renderer {}, this \
             build is renderer {RENDERER_HASH}",
            old.key,
            if old.renderer.is_empty() {
                "(unknown)"
            } else {
                &old.renderer
            }
        ),
        None if !others.is_empty() => format!(
            "the scene, its meshes, the defines or the reference settings changed (cached \
             reference {} has another key, same renderer)",
            others[0].key
        ),
        None => "no reference in the cache yet".into(),
    }
}

/// Noise floors of a reference with per-pixel variance-of-mean `var`.
pub fn noise_floor(mean: &Image, var: &Image, eps: f64) -> (f64, f64) {
    let (mut m, mut r) = (0.0f64, 0.0f64);
    for (p, v) in mean.data.iter().zip(&var.data) {
        for c in 0..3 {
            m += v[c];
            r += v[c] / (p[c] * p[c] + eps);
        }
    }
    let n = 3.0 * mean.data.len().max(1) as f64;
    (m / n, r / n)
}

fn paths(dir: &Path, key: &str) -> (PathBuf, PathBuf, PathBuf) {
    (
        dir.join(format!("reference-{key}.exr")),
        dir.join(format!("reference-{key}-var.exr")),
        dir.join(format!("reference-{key}.json")),
    )
}

fn load(dir: &Path, key: &str) -> Option<(Image, Image, ReferenceInfo)> {
    let (m, v, j) = paths(dir, key);
    let info: ReferenceInfo = serde_json::from_str(&std::fs::read_to_string(j).ok()?).ok()?;
    Some((film::read_exr(&m).ok()?, film::read_exr(&v).ok()?, info))
}

pub struct ReferenceRequest<'a> {
    pub scene: &'a Scene,
    pub key: String,
    pub strategy: Strategy,
    pub spp: u32,
    pub seed: u64,
    pub threads: Option<usize>,
    pub relmse_epsilon: f64,
    pub fresh: bool,
    pub progress: bool,
}

/// The reference cached in `dir` under `key`, with its floors for `eps`.
pub fn cached(dir: &Path, key: &str, eps: f64) -> Option<Reference> {
    let (mean, variance, mut info) = load(dir, key)?;
    // The floor depends on epsilon, which is not part of the key.
    let (m, r) = noise_floor(&mean, &variance, eps);
    info.mse_floor = m;
    info.relmse_floor = r;
    info.relmse_epsilon = eps;
    Some(Reference {
        mean,
        variance,
        info,
        cached: true,
        why_rendered: None,
    })
}

/// What a reference is, apart from its pixels.
pub struct Identity<'a> {
    pub key: &'a str,
    pub strategy: &'a Strategy,
    pub spp: u32,
    pub seed: u64,
    pub relmse_epsilon: f64,
}

/// The cached reference for `req.key`, or a new render stored under it.
pub fn get_or_render(dir: &Path, req: &ReferenceRequest) -> Result<Reference, String> {
    if !req.fresh {
        if let Some(r) = cached(dir, &req.key, req.relmse_epsilon) {
            return Ok(r);
        }
    }
    let why = if req.fresh {
        "--fresh-reference".to_string()
    } else {
        why_not_cached(dir, &req.key)
    };
    eprintln!(
        "rendering the reference ({} at {} spp; {why}); it is cached in {} for later runs",
        req.strategy.label(),
        req.spp,
        dir.display()
    );
    let acc = super::chunks::render_chunked(
        dir,
        &super::chunks::ChunkedRender {
            scene: req.scene,
            strategy: req.strategy,
            spp: req.spp,
            seed: req.seed,
            threads: req.threads,
            progress: req.progress,
            key: &req.key,
        },
    )?;
    let mut r = store(
        dir,
        &Identity {
            key: &req.key,
            strategy: &req.strategy,
            spp: req.spp,
            seed: req.seed,
            relmse_epsilon: req.relmse_epsilon,
        },
        &acc,
    )?;
    r.why_rendered = Some(why);
    Ok(r)
}

/// Stores the merged statistics `acc` of reference `id` in the cache (the JSON last: its
/// presence marks a complete entry) and removes references of other keys.
pub fn store(dir: &Path, id: &Identity, acc: &super::chunks::Accum) -> Result<Reference, String> {
    let why = why_not_cached(dir, id.key);
    let (mut mean, mut variance) = acc.images();
    // The EXR holds f32: measure against what is stored, so a run that renders the
    // reference and one that reads it from the cache (or from merged shards) agree exactly.
    for p in mean.data.iter_mut().chain(variance.data.iter_mut()) {
        *p = p.map(|v| v as f32 as f64);
    }
    let (mse_floor, relmse_floor) = noise_floor(&mean, &variance, id.relmse_epsilon);
    let info = ReferenceInfo {
        key: id.key.to_string(),
        renderer: RENDERER_HASH.to_string(),
        strategy: id.strategy.label(),
        spp: id.spp,
        seed: id.seed,
        seconds: acc.seconds,
        non_finite_samples: acc.non_finite_samples,
        mse_floor,
        relmse_floor,
        relmse_epsilon: id.relmse_epsilon,
    };
    let (m, v, j) = paths(dir, id.key);
    film::write_exr(&m, &mean)?;
    film::write_exr(&v, &variance)?;
    let chunks = super::chunks::chunk_ranges(id.spp).len() as u32;
    // Without its render time (the JSON has it), so equal statistics are equal bytes.
    let timeless = super::chunks::Accum {
        seconds: 0.0,
        ..acc.clone()
    };
    super::chunks::save(&stats_path(dir, id.key), id.key, chunks, &timeless)?;
    let json = serde_json::to_string_pretty(&info).map_err(|e| e.to_string())?;
    crate::output::write_atomic(&j, |tmp| {
        std::fs::write(tmp, json).map_err(|e| format!("{}: {e}", j.display()))
    })?;
    prune(dir, id.key);
    Ok(Reference {
        mean,
        variance,
        info,
        cached: false,
        why_rendered: Some(why),
    })
}

/// The per-pixel count, mean and M2 in f64 of the reference cached under `key` (EXR holds
/// f32): what a longer reference could be merged onto, and what shows that two ways of
/// rendering it agree bit for bit.
pub fn stats_path(dir: &Path, key: &str) -> PathBuf {
    dir.join(format!("reference-{key}.f64"))
}

/// A closed-form reference: `value` in every pixel and channel, with no noise (floors 0).
/// `key` should cover the scene, the value and the renderer, as a rendered reference's does,
/// so that results measured with an older renderer are redone.
pub fn constant(width: u32, height: u32, value: f64, key: String) -> Reference {
    let mut mean = Image::new(width, height);
    mean.data.fill([value; 3]);
    Reference {
        mean,
        variance: Image::new(width, height),
        info: ReferenceInfo {
            key,
            renderer: RENDERER_HASH.to_string(),
            strategy: "closed form".into(),
            spp: 0,
            seed: 0,
            seconds: 0.0,
            non_finite_samples: 0,
            mse_floor: 0.0,
            relmse_floor: 0.0,
            relmse_epsilon: 0.0,
        },
        cached: true,
        why_rendered: None,
    }
}

/// Key of a closed-form reference: the scene's key inputs (no render settings) and the value.
pub fn constant_key(
    scene: &Path,
    defines: &[(String, String)],
    value: f64,
    base: &Strategy,
) -> Result<String, String> {
    let k = reference_key(&KeyInputs {
        scene,
        defines,
        spp: 0,
        seed: 0,
        strategy: base,
    })?;
    let mut h = Fnv::new();
    h.field(k.as_bytes()).field(&value.to_le_bytes());
    Ok(h.hex())
}

/// Removes references of other keys (an older scene, renderer or setting): one experiment
/// folder keeps one reference, instead of a growing pile of 5 MB EXRs.
fn prune(dir: &Path, key: &str) {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return;
    };
    for e in rd.flatten() {
        let name = e.file_name().to_string_lossy().to_string();
        if name.starts_with("reference-") && !name.starts_with(&format!("reference-{key}")) {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::desc::{Heuristic, StrategyKind};

    fn strategy() -> Strategy {
        Strategy {
            kind: StrategyKind::Mis,
            heuristic: Heuristic::Balance,
            emitter_samples: 1,
            bsdf_samples: 1,
            selection: crate::emitter::EmitterSelection::Uniform,
            light_sampling: crate::emitter::LightSampling::Area,
            hide_emitters: false,
        }
    }

    #[test]
    fn key_follows_scene_files_defines_and_settings() {
        let dir = std::env::temp_dir().join(format!("directlab-key-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/triangle-light");
        for f in ["triangle-light.xml", "triangle.obj"] {
            std::fs::copy(src.join(f), dir.join(f)).unwrap();
        }
        let scene = dir.join("triangle-light.xml");
        let s = strategy();
        let defines = vec![("res".to_string(), "16".to_string())];
        let k = |defines: &[(String, String)], spp: u32, st: &Strategy| {
            reference_key(&KeyInputs {
                scene: &scene,
                defines,
                spp,
                seed: 99,
                strategy: st,
            })
            .unwrap()
        };
        let base = k(&defines, 64, &s);
        assert_eq!(base, k(&defines, 64, &s), "deterministic");
        assert_eq!(
            scene_files(&scene, &defines).unwrap(),
            vec![scene.clone(), dir.join("triangle.obj")]
        );
        assert_ne!(base, k(&[], 64, &s));
        assert_ne!(base, k(&defines, 128, &s));
        let power = Strategy {
            heuristic: Heuristic::Power,
            ..s
        };
        assert_ne!(base, k(&defines, 64, &power));
        // A change to a referenced mesh, not to the XML, must change the key too.
        let obj = dir.join("triangle.obj");
        let text = std::fs::read_to_string(&obj).unwrap();
        std::fs::write(&obj, text.replace("v 0.5 1 -0.5", "v 0.5 1.01 -0.5")).unwrap();
        assert_ne!(
            std::fs::read_to_string(&obj).unwrap(),
            text,
            "the edit must apply"
        );
        assert_ne!(base, k(&defines, 64, &s));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_new_reference_replaces_older_keys_only() {
        let dir = std::env::temp_dir().join(format!("directlab-prune-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("images")).unwrap();
        for f in [
            "reference-old.exr",
            "reference-old.json",
            "reference-new.exr",
            "other.txt",
        ] {
            std::fs::write(dir.join(f), "").unwrap();
        }
        prune(&dir, "new");
        let mut left: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .collect();
        left.sort();
        assert_eq!(left, ["images", "other.txt", "reference-new.exr"]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn noise_floor_is_mean_variance_and_relative_variance() {
        let mut mean = Image::new(2, 1);
        let mut var = Image::new(2, 1);
        mean.set(0, 0, [1.0; 3]);
        var.set(0, 0, [0.3; 3]);
        var.set(1, 0, [0.1; 3]);
        let (m, r) = noise_floor(&mean, &var, 1.0);
        assert!((m - 0.2).abs() < 1e-12);
        assert!((r - (0.3 / 2.0 + 0.1 / 1.0) / 2.0).abs() < 1e-12);
    }
}
