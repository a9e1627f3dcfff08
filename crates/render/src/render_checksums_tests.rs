//! Images are pinned bit for bit: every bundled scene under every strategy of
//! `Strategy::combinations` (and every other sampler and dimension allocation under one
//! strategy), at 1 and 2 threads, hashes to the checksum stored in
//! `tests/data/image_checksums.txt`. A change that moves any image's bits (a refactor of the
//! estimators, the lane kernel or the samplers that was meant to keep them) fails here and
//! names the renders it changed. A change meant to alter images regenerates the file with
//! `DIRECTLAB_UPDATE_CHECKSUMS=1` and says why in its commit.

use crate::integrator::Strategy;
use crate::named::Named;
use crate::render::{render, RenderSettings};
use crate::sampler::{DimAlloc, SamplerKind, Sampling};
use crate::scene::{bundled_tests, Scene};
use std::collections::BTreeMap;
use std::path::PathBuf;

const SCENES: [&str; 7] = [
    "cbox/cbox.xml",
    "cbox/cbox-nori.xml",
    "cbox-materials/cbox-materials.xml",
    "cbox-meshlight/cbox-meshlight.xml",
    "cbox-twolights/cbox-twolights.xml",
    "triangle-light/triangle-light.xml",
    "veach-mis/veach-mis.xml",
];

fn checksum_file() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/image_checksums.txt")
}

/// FNV-1a over the bits of the mean and variance images.
fn hash(out: &crate::render::RenderOutput) -> String {
    let mut h = crate::fnv::Fnv::new();
    for px in out.mean.data.iter().chain(&out.variance.data) {
        for v in px {
            h.bytes(&v.to_bits().to_le_bytes());
        }
    }
    h.hex()
}

#[test]
fn bundled_images_keep_their_bits_for_every_strategy_and_thread_count() {
    let mut got = BTreeMap::new();
    for rel in SCENES {
        let mut desc = bundled_tests::load(rel);
        // Small films, 11 samples per pixel: a whole batch of lanes and a partial one.
        (desc.film.width, desc.film.height) = (20, 14);
        let scene = Scene::build(desc).unwrap_or_else(|e| panic!("{rel}: {e}"));
        let mut all = Strategy::combinations();
        all.push(Strategy {
            hide_emitters: true,
            ..all[1]
        });
        // Every strategy with `independent`, and every other sampler and allocation with
        // one strategy.
        let mut runs: Vec<(Strategy, Sampling)> =
            all.iter().map(|&s| (s, Sampling::default())).collect();
        for kind in &SamplerKind::all()[1..] {
            for dims in [DimAlloc::Joint, DimAlloc::Padded] {
                let sampling = Sampling {
                    kind: *kind,
                    dims,
                    run_samples: None,
                };
                runs.push((all[1], sampling));
            }
        }
        for (s, sampling) in runs {
            let sums = [1, 2].map(|threads| {
                let settings = RenderSettings {
                    spp: 11,
                    seed: 7,
                    first_sample: 0,
                    threads: Some(threads),
                    progress: None,
                    sampling,
                };
                hash(&render(&scene, s, &settings))
            });
            let hidden = if s.hide_emitters { "-hidden" } else { "" };
            let sampler = match sampling.kind {
                SamplerKind::Independent => String::new(),
                k => format!(" {} {}", k.name(), sampling.dims.name()),
            };
            let name = format!("{rel} {}{hidden}{sampler}", s.label());
            assert_eq!(sums[0], sums[1], "{name}: 1 and 2 threads differ");
            let [one, _] = sums;
            got.insert(name, one);
        }
    }
    let text: String = got.iter().map(|(k, v)| format!("{k} {v}\n")).collect();
    if std::env::var_os("DIRECTLAB_UPDATE_CHECKSUMS").is_some() {
        std::fs::write(checksum_file(), &text).unwrap();
        eprintln!("wrote {}", checksum_file().display());
        return;
    }
    let stored = std::fs::read_to_string(checksum_file()).unwrap_or_else(|e| {
        panic!(
            "{}: {e} (write it with DIRECTLAB_UPDATE_CHECKSUMS=1)",
            checksum_file().display()
        )
    });
    let changed: Vec<_> = text
        .lines()
        .zip(stored.lines())
        .filter(|(a, b)| a != b)
        .map(|(a, b)| format!("  now {a}\n  was {b}"))
        .collect();
    assert!(
        changed.is_empty() && text.lines().count() == stored.lines().count(),
        "{} of {} images changed their bits:\n{}",
        changed.len(),
        got.len(),
        changed.join("\n")
    );
}
