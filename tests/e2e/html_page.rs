//! The HTML report's images and size. Figure 1's page shows the progression's spp after the
//! comparison spp, then every seed's image. Figure 3's page at a bundled resolution (Veach's
//! scene at its own 768x512, every strategy's image at the comparison spp and every seed's at
//! equal time, embedded as HDR data) holds every pixel within its page budget, and is
//! box-averaged, saying so, only under a smaller budget; with `--viewer none` it carries no
//! image data at all.

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

/// The page's `DL` data: its film size, factor and image titles.
fn viewer_data(page: &str) -> serde_json::Value {
    let start = page.find("const DL = ").expect("a viewer") + "const DL = ".len();
    let line = &page[start..start + page[start..].find('\n').unwrap()];
    serde_json::from_str(line.trim_end_matches(';')).unwrap()
}

#[test]
fn fig3_page_holds_every_pixel_within_its_budget() {
    let dir = scratch("html-size");
    let file = fig3_full_resolution(&dir);
    let out = dir.join("reports");
    let o = run(directlab()
        .args(["run", file.to_str().unwrap(), "--quick", "--out"])
        .arg(&out));
    assert!(o.status.success());
    let page = out.join("fig3-quick/index.html");
    let full = std::fs::read_to_string(&page).unwrap();
    let dl = viewer_data(&full);
    // Reference + 4 strategies at 4 spp + 4 at equal time for each of its 4 seeds.
    assert_eq!(dl["images"].as_array().unwrap().len(), 1 + 4 + 4 * 4);
    assert_eq!(
        (&dl["width"], &dl["height"], &dl["factor"]),
        (&768.into(), &512.into(), &1.into())
    );
    assert!(full.contains("Every image at full resolution (page budget 32 MB)"));
    let mb = full.len() as f64 / 1e6;
    eprintln!("fig3 page at 768x512, full resolution: {mb:.2} MB");
    assert!(mb < 32.5, "{mb:.2} MB");

    // Under a 4 MB budget the images are box-averaged and the page says so.
    let text = std::fs::read_to_string(&file).unwrap();
    std::fs::write(
        &file,
        text.replace("[figures]\n", "[figures]\npage_mb = 4\n"),
    )
    .unwrap();
    let o = run(directlab()
        .args(["run", file.to_str().unwrap(), "--quick", "--out"])
        .arg(&out));
    assert!(o.status.success());
    let small = std::fs::read_to_string(&page).unwrap();
    let dl = viewer_data(&small);
    let k = dl["factor"].as_u64().unwrap();
    assert!(k >= 2, "factor {k}");
    assert_eq!(dl["width"].as_u64().unwrap(), 768 / k);
    assert!(
        small.contains(&format!("Shown at 1/{k} resolution per axis")),
        "no note"
    );
    assert!(small.contains("page budget of 4 MB"));
    let mb = small.len() as f64 / 1e6;
    eprintln!("fig3 page under a 4 MB budget: 1/{k} per axis, {mb:.2} MB");
    assert!(mb < 4.2, "{mb:.2} MB");

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
    // fig1.toml --quick: equal_spp 4, progression [1, 16], one strategy, no equal time, two
    // seeds with seed_images.
    assert_eq!(
        titles,
        [
            "reference (256 spp)",
            "light sampling, 4 spp",
            "light sampling, 1 spp",
            "light sampling, 16 spp",
            "light sampling, 4 spp, seed 1"
        ]
    );
}
