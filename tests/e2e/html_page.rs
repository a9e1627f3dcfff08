//! The HTML report's images and size. Figure 1's page shows the progression's spp after the
//! comparison spp. Figure 3's page at a bundled resolution (Veach's scene at its own 768x512,
//! every strategy's image at the comparison spp and at equal time, embedded as HDR data)
//! stays a few MB; with `--viewer none` it carries no image data at all.

use crate::common;
use common::{directlab, repo, run, scratch};

/// fig3.toml with its [quick] sizes but the scene's own resolution.
fn fig3_full_resolution(dir: &std::path::Path) -> std::path::PathBuf {
    let text = std::fs::read_to_string(repo("experiments/fig3.toml")).unwrap();
    let scene = repo("scenes/veach-mis/veach-mis.xml");
    let text = text
        .replace(
            "scene = \"../scenes/veach-mis/veach-mis.xml\"",
            &format!("scene = {:?}", scene.to_str().unwrap()),
        )
        .replace("defines = { width = \"48\", height = \"32\" }\n", "")
        .replace("reference_spp = 64", "reference_spp = 16");
    assert!(
        !text.contains("width = \"48\""),
        "fig3.toml changed: {text}"
    );
    let path = dir.join("fig3.toml");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn fig3_page_at_its_bundled_resolution_stays_a_few_mb() {
    let dir = scratch("html-size");
    let file = fig3_full_resolution(&dir);
    let out = dir.join("reports");
    let o = run(directlab()
        .args(["run", file.to_str().unwrap(), "--quick", "--out"])
        .arg(&out));
    assert!(o.status.success());
    let page = out.join("fig3-quick/index.html");
    let full = std::fs::read_to_string(&page).unwrap();
    // Reference + 4 strategies at 4 spp + 4 at equal time.
    assert_eq!(full.matches("\"title\":").count(), 9);
    for field in ["\"factor\":2,", "\"width\":384}", "\"height\":256,"] {
        assert!(full.contains(field), "768x512 at half size: no {field}");
    }
    let mb = full.len() as f64 / 1e6;
    eprintln!("fig3 page at 768x512: {mb:.2} MB");
    assert!(mb < 4.0, "{mb:.2} MB");

    let o = run(directlab()
        .args([
            "run",
            file.to_str().unwrap(),
            "--quick",
            "--viewer",
            "none",
            "--out",
        ])
        .arg(&out));
    assert!(o.status.success());
    let bare = std::fs::read_to_string(&page).unwrap();
    assert!(!bare.contains("const DL ="), "no image viewer");
    assert!(!bare.contains("data:image"), "no embedded figure");
    assert!(
        bare.contains("<img src=\"convergence.png\""),
        "figures linked"
    );
    eprintln!("with --viewer none: {} KB", bare.len() / 1000);
    assert!(bare.len() < 200_000, "{} bytes", bare.len());
}

#[test]
fn fig1_page_shows_the_comparison_spp_then_the_progression() {
    let out = scratch("html-fig1");
    let o = run(directlab()
        .args([
            "run",
            repo("experiments/fig1.toml").to_str().unwrap(),
            "--quick",
            "--out",
        ])
        .arg(&out));
    assert!(o.status.success());
    let page = std::fs::read_to_string(out.join("fig1-quick/index.html")).unwrap();
    let titles: Vec<&str> = page
        .split("\"title\":\"")
        .skip(1)
        .map(|t| t.split('"').next().unwrap())
        .collect();
    // fig1.toml --quick: equal_spp 4, progression [1, 16], one strategy, no equal time.
    assert_eq!(
        titles,
        [
            "reference (256 spp)",
            "light sampling, 4 spp",
            "light sampling, 1 spp",
            "light sampling, 16 spp"
        ]
    );
}
