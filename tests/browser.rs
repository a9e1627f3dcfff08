//! The HTML reports in a real browser: headless Chromium (Debian's `chromium`) loads each
//! page `run --quick` writes with `#selftest`; the page switches images, changes the
//! exposure, holds the reference and shows the error maps, checking its own canvas, and
//! writes a pass/fail line this test reads. Any uncaught script error fails it, and a
//! screenshot must not be blank. Without Chromium the test says why and is skipped, unless
//! DIRECTLAB_REQUIRE_CHROMIUM=1 (set by `.ci/run` once it is installed).

mod common;
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

fn selftest(browser: &str, page: &Path) {
    let url = format!("file://{}#selftest", page.display());
    let o = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--enable-logging=stderr",
            "--virtual-time-budget=10000",
            "--dump-dom",
        ])
        .arg(&url)
        .output()
        .expect("run chromium");
    let dom = String::from_utf8_lossy(&o.stdout);
    let log = String::from_utf8_lossy(&o.stderr);
    let line = dom
        .split("<div id=\"selftest\">")
        .nth(1)
        .and_then(|s| s.split('<').next())
        .unwrap_or("");
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

fn screenshot_not_blank(browser: &str, page: &Path, shot: &Path) {
    let o = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--window-size=1000,800",
            "--virtual-time-budget=10000",
        ])
        .arg(format!("--screenshot={}", shot.display()))
        .arg(format!("file://{}", page.display()))
        .output()
        .expect("run chromium");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
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

#[test]
fn report_pages_test_themselves_in_chromium() {
    let Some(browser) = chromium() else {
        return;
    };
    let out = scratch("browser");
    for exp in ["experiments/fig2.toml", "experiments/fig3.toml"] {
        let o = run(directlab()
            .args(["run", repo(exp).to_str().unwrap(), "--quick", "--out"])
            .arg(&out));
        assert!(o.status.success());
    }
    for name in ["fig2-quick", "fig3-quick"] {
        let page = out.join(name).join("index.html");
        selftest(browser, &page);
        screenshot_not_blank(browser, &page, &out.join(format!("{name}.png")));
    }
}
