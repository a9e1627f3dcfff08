//! The HTML reports in a real browser: headless Chromium (Debian's `chromium`) loads every
//! page `reproduce --quick`, `extreme --quick` and `chi2` write, with `#selftest`. A sweep's
//! page switches images (keys, arrows, the picker past the ninth), changes the exposure (its
//! number shown), holds the reference, shows the error maps with numbered colour bars, reads
//! the pixel under a moved mouse, keeps side by side in one row, writes the view into the
//! address and restores it from one, checking its own canvas; every page sorts its tables and checks that its figures are all
//! there and load. The page writes a pass/fail line this test reads; any uncaught script error
//! fails it, and a screenshot must not be blank. Without Chromium the test says why and is
//! skipped, unless DIRECTLAB_REQUIRE_CHROMIUM=1 (set by `.ci/run` once it is installed).

use crate::common;
use common::{directlab, repo, run, scratch};
use std::path::Path;
use std::process::Command;

fn chromium() -> Option<&'static str> {
    let found = ["chromium", "chromium-browser", "google-chrome"]
        .into_iter()
        .find(|c| {
            Command::new(c)
                .arg("--version")
                .output()
                .is_ok_and(|o| o.status.success())
        });
    if found.is_none() {
        let required = std::env::var("DIRECTLAB_REQUIRE_CHROMIUM").is_ok_and(|v| v == "1");
        assert!(
            !required,
            "DIRECTLAB_REQUIRE_CHROMIUM=1 but no chromium on PATH"
        );
        eprintln!("SKIPPED browser: no chromium on PATH (Debian: apt-get install chromium)");
    }
    found
}

/// The page's own pass/fail line, and chromium's log.
fn selftest_line(browser: &str, page: &Path) -> (String, String) {
    let url = format!("file://{}#selftest", page.display());
    let o = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--enable-logging=stderr",
            "--virtual-time-budget=10000",
            // The window of the issue where side by side used to stack.
            "--window-size=1400,900",
            "--dump-dom",
        ])
        .arg(&url)
        .output()
        .expect("run chromium");
    let dom = String::from_utf8_lossy(&o.stdout);
    let line = dom
        .split("<div id=\"selftest\">")
        .nth(1)
        .and_then(|s| s.split('<').next())
        .unwrap_or("")
        .to_string();
    (line, String::from_utf8_lossy(&o.stderr).into_owned())
}

fn selftest(browser: &str, page: &Path) {
    let (line, log) = selftest_line(browser, page);
    assert!(
        line.starts_with("SELFTEST PASS"),
        "{}: '{line}'\n{log}",
        page.display()
    );
    assert!(
        !log.contains("Uncaught"),
        "{}: script error:\n{log}",
        page.display()
    );
}

/// Chromium's screenshot of `url` in a window of `size` ("W,H") into `shot`.
fn screenshot(browser: &str, url: &str, size: &str, shot: &Path) {
    let o = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--hide-scrollbars",
            "--virtual-time-budget=10000",
        ])
        .arg(format!("--window-size={size}"))
        .arg(format!("--screenshot={}", shot.display()))
        .arg(url)
        .output()
        .expect("run chromium");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn screenshot_not_blank(browser: &str, page: &Path, shot: &Path) {
    let url = format!("file://{}", page.display());
    screenshot(browser, &url, "1000,800", shot);
    let img = image::open(shot).unwrap().into_rgb8();
    let mut colours: Vec<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    colours.sort();
    colours.dedup();
    assert!(
        colours.len() > 50,
        "{}: a blank page ({} colours)",
        page.display(),
        colours.len()
    );
}

/// Every `index.html` one folder below `root`.
fn pages(root: &Path) -> Vec<std::path::PathBuf> {
    let mut v: Vec<_> = std::fs::read_dir(root)
        .unwrap()
        .flatten()
        .map(|d| d.path().join("index.html"))
        .filter(|p| p.exists())
        .collect();
    v.sort();
    v
}

#[test]
fn report_pages_test_themselves_in_chromium() {
    let Some(browser) = chromium() else {
        return;
    };
    let out = scratch("browser");
    let cli = |args: &[&str]| {
        let o = run(directlab().args(args).arg("--out").arg(&out));
        assert!(o.status.success(), "{args:?}");
    };
    cli(&["reproduce", "--quick"]);
    cli(&["extreme", "--quick"]);
    let chi2 = out.join("chi2");
    let o = run(directlab()
        .args([
            "chi2",
            "warp/uniform",
            "--samples",
            "20000",
            "--resolution",
            "11",
        ])
        .arg("--out")
        .arg(&chi2));
    assert!(o.status.success());
    let found = pages(&out);
    let names: Vec<String> = found
        .iter()
        .map(|p| {
            p.parent()
                .unwrap()
                .file_name()
                .unwrap()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    for want in [
        "fig1-quick",
        "fig2-quick",
        "fig3-quick",
        "fig4-quick",
        "fig5-tiles-quick",
        "integrands-quick",
        "extreme-quick",
        "chi2",
    ] {
        assert!(
            names.iter().any(|n| n == want),
            "no {want} page in {names:?}"
        );
    }
    for page in &found {
        selftest(browser, page);
    }
    let root = out.join("index.html");
    let index = std::fs::read_to_string(&root).unwrap();
    assert!(index.contains("href=\"fig3-quick/index.html\""), "{index}");
    assert!(
        index.contains("href=\"chi2/index.html\""),
        "chi2 joins the index: {index}"
    );
    let fig3 = out.join("fig3-quick/index.html");
    screenshot_not_blank(browser, &fig3, &out.join("fig3-quick.png"));
}

/// The checks can fail: a page whose linked figure is gone says so.
#[test]
fn a_page_with_a_missing_figure_fails_its_selftest() {
    let Some(browser) = chromium() else {
        return;
    };
    let out = scratch("browser-missing");
    let o = run(directlab()
        .args([
            "run",
            repo("experiments/fig3.toml").to_str().unwrap(),
            "--quick",
        ])
        .args(["--viewer", "none", "--out"])
        .arg(&out));
    assert!(o.status.success());
    let page = out.join("fig3-quick/index.html");
    selftest(browser, &page);
    std::fs::remove_file(out.join("fig3-quick/convergence.png")).unwrap();
    let (line, _) = selftest_line(browser, &page);
    assert!(
        line.starts_with("SELFTEST FAIL") && line.contains("every figure loads"),
        "'{line}'"
    );
}

/// Writes `reports/readme/fig3-page.png`, the README's picture: the committed Figure 3 page
/// with light sampling beside the reference, scaled down, in grey. Run after `reproduce` with
/// `cargo test --release --test browser -- --ignored`.
#[test]
#[ignore]
fn regenerate_readme_screenshot() {
    let browser = chromium().expect("chromium");
    let page = repo("reports/fig3/index.html");
    let shot = scratch("readme").join("shot.png");
    let url = format!("file://{}#image=2&layout=side", page.display());
    screenshot(browser, &url, "1600,740", &shot);
    let img = image::open(&shot).unwrap();
    let small = img.resize(960, 960, image::imageops::FilterType::Lanczos3);
    // The scene is grey: one channel keeps the picture and a third of the bytes.
    small
        .to_luma8()
        .save(repo("reports/readme/fig3-page.png"))
        .unwrap();
}
