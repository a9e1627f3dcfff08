//! `directlab compare` end to end on the Cornell box at 64x64 (alpha 0.01, 8x8 tiles):
//! two sets of six seeds at 16 spp agree; the same with B's light 3 % brighter (B's images
//! scaled) is detected, exits non-zero and names the region; a single render with its
//! variance against another agrees; bad input is named.

use crate::common::{directlab, repo, run, run_text, scratch};
use directlab::film::{read_exr, write_exr};
use std::path::{Path, PathBuf};

fn render(out: &Path, seed: u32, spp: u32, variance: Option<&Path>) {
    let mut cmd = directlab();
    cmd.arg("render")
        .arg(repo("scenes/cbox/cbox.xml"))
        .args([
            "--spp",
            &spp.to_string(),
            "--seed",
            &seed.to_string(),
            "-D",
            "res=64",
        ])
        .arg("--out")
        .arg(out);
    if let Some(v) = variance {
        cmd.arg("--variance").arg(v);
    }
    let o = run(&mut cmd);
    assert!(o.status.success(), "{o:?}");
}

fn seeds(dir: &Path, first: u32, scale: f64) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    for s in 0..6 {
        let f = dir.join(format!("seed{s}.exr"));
        render(&f, first + s, 16, None);
        if scale != 1.0 {
            let mut img = read_exr(&f).unwrap();
            img.data
                .iter_mut()
                .for_each(|p| p.iter_mut().for_each(|c| *c *= scale));
            write_exr(&f, &img).unwrap();
        }
    }
    dir.to_path_buf()
}

fn compare(args: &[&std::ffi::OsStr]) -> (bool, String) {
    run_text(directlab().arg("compare").args(args))
}

#[test]
fn seeds_agree_and_a_three_percent_light_is_detected() {
    let dir = scratch("compare-seeds");
    let a = seeds(&dir.join("a"), 1, 1.0);
    let b = seeds(&dir.join("b"), 101, 1.0);
    let b3 = seeds(&dir.join("b3"), 201, 1.03);
    let out = dir.join("out");
    let (ok, text) = compare(&[
        a.as_os_str(),
        b.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert!(
        ok && text.contains("no bias detected at alpha 0.01"),
        "{text}"
    );
    assert!(out.join("index.html").exists() && out.join("p-tiles.png").exists());
    // A NaN pixel in one seed is excluded, said so, and mapped; the rest still agrees.
    let nan = dir.join("nan");
    std::fs::create_dir_all(&nan).unwrap();
    for f in std::fs::read_dir(&a).unwrap() {
        let f = f.unwrap().path();
        std::fs::copy(&f, nan.join(f.file_name().unwrap())).unwrap();
    }
    let one = nan.join("seed0.exr");
    let mut img = read_exr(&one).unwrap();
    img.data[64 * 5 + 3][1] = f64::NAN;
    write_exr(&one, &img).unwrap();
    let (ok, text) = compare(&[
        nan.as_os_str(),
        b.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert!(
        ok && text.contains("excluded: 1 pixel(s) with non-finite input (1 tile(s) not tested"),
        "{text}"
    );
    let (ok, text) = compare(&[
        a.as_os_str(),
        b3.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert!(!ok && text.contains("bias detected"), "{text}");
    let md = std::fs::read_to_string(out.join("index.md")).unwrap();
    assert!(
        md.contains("region 1:") && md.contains("A/B - 1 = -"),
        "{md}"
    );
}

#[test]
fn single_renders_with_variances_agree_and_bad_input_is_named() {
    let dir = scratch("compare-single");
    let (a, av) = (dir.join("a.exr"), dir.join("a-var.exr"));
    let (b, bv) = (dir.join("b.exr"), dir.join("b-var.exr"));
    render(&a, 1, 64, Some(&av));
    render(&b, 2, 64, Some(&bv));
    let out = dir.join("out");
    let mut args: Vec<&std::ffi::OsStr> = vec![a.as_os_str(), b.as_os_str()];
    args.extend([
        "--variance-a".as_ref(),
        av.as_os_str(),
        "--variance-b".as_ref(),
    ]);
    args.extend([
        bv.as_os_str(),
        "--spp-a".as_ref(),
        "64".as_ref(),
        "--spp-b".as_ref(),
    ]);
    args.extend(["64".as_ref(), "--out".as_ref(), out.as_os_str()]);
    let (ok, text) = compare(&args);
    assert!(ok && text.contains("no bias detected"), "{text}");
    // No variance for a single render; one seed in a directory; different sizes.
    let (ok, text) = compare(&[a.as_os_str(), b.as_os_str()]);
    assert!(
        !ok && text.contains("needs --variance-a and --stats-a (or --spp-a)"),
        "{text}"
    );
    // `render --stats` gives a single render's spp and sampler: an independent one is
    // taken, a correlated one (sobol) refused by name.
    for (sampler, name) in [("independent", "i"), ("sobol", "s")] {
        let (img, var, st) = (
            dir.join(format!("{name}.exr")),
            dir.join(format!("{name}-var.exr")),
            dir.join(format!("{name}.json")),
        );
        let o = run(directlab()
            .arg("render")
            .arg(repo("scenes/cbox/cbox.xml"))
            .args([
                "-D",
                "res=64",
                "--spp",
                "64",
                "--seed",
                "5",
                "--sampler",
                sampler,
            ])
            .arg("--out")
            .arg(&img)
            .arg("--variance")
            .arg(&var)
            .arg("--stats")
            .arg(&st));
        assert!(o.status.success());
        let mut args: Vec<&std::ffi::OsStr> = vec![img.as_os_str(), b.as_os_str()];
        args.extend([
            "--variance-a".as_ref(),
            var.as_os_str(),
            "--stats-a".as_ref(),
        ]);
        args.extend([st.as_os_str(), "--variance-b".as_ref(), bv.as_os_str()]);
        args.extend([
            "--spp-b".as_ref(),
            "64".as_ref(),
            "--out".as_ref(),
            out.as_os_str(),
        ]);
        let (ok, text) = compare(&args);
        match sampler {
            "independent" => assert!(ok && text.contains("no bias detected"), "{text}"),
            _ => assert!(
                !ok && text.contains("sobol sampler") && text.contains("correlated"),
                "{text}"
            ),
        }
    }
    let one = dir.join("one");
    std::fs::create_dir_all(&one).unwrap();
    std::fs::copy(&a, one.join("s.exr")).unwrap();
    let (ok, text) = compare(&[one.as_os_str(), one.as_os_str()]);
    assert!(
        !ok && text.contains("needs at least two seeds' EXRs"),
        "{text}"
    );
    let small = dir.join("small.exr");
    let mut img = read_exr(&a).unwrap();
    img.width = 32;
    img.height = 128;
    write_exr(&small, &img).unwrap();
    let mut args: Vec<&std::ffi::OsStr> = vec![small.as_os_str(), b.as_os_str()];
    args.extend([
        "--variance-a".as_ref(),
        av.as_os_str(),
        "--spp-a".as_ref(),
        "64".as_ref(),
    ]);
    let (ok, text) = compare(&args);
    assert!(
        !ok && text.contains("64x64, but its image") && text.contains("is 32x128"),
        "{text}"
    );
}

/// Calibration on real renders: 20 pairs of correct runs (Cornell box 32x32, four seeds of
/// 4 spp per side, 4x4 tiles) give tile p-values uniform by KS (pooled over the pairs, about
/// 3400 tests, at 0.01), and no pair reports a bias at alpha 0.01 over the 20 (Sidak: 5.0e-4
/// each).
#[test]
fn twenty_correct_pairs_give_uniform_p_values_and_no_detection() {
    let dir = scratch("compare-calibration");
    let mut pooled = Vec::new();
    let alpha = (1.0 - 0.99f64.powf(1.0 / 20.0)).to_string();
    for pair in 0..20u32 {
        let mut sides = Vec::new();
        for side in 0..2u32 {
            let d = dir.join(format!("pair{pair}-{side}"));
            std::fs::create_dir_all(&d).unwrap();
            for s in 0..4 {
                let seed = 1000 * pair + 100 * side + s;
                let o = run(directlab()
                    .arg("render")
                    .arg(repo("scenes/cbox/cbox.xml"))
                    .args(["--spp", "4", "--seed", &seed.to_string(), "-D", "res=32"])
                    .arg("--out")
                    .arg(d.join(format!("s{s}.exr"))));
                assert!(o.status.success());
            }
            sides.push(d);
        }
        let out = dir.join(format!("out{pair}"));
        let (ok, text) = compare(&[
            sides[0].as_os_str(),
            sides[1].as_os_str(),
            "--tile".as_ref(),
            "4".as_ref(),
            "--alpha".as_ref(),
            alpha.as_ref(),
            "--out".as_ref(),
            out.as_os_str(),
        ]);
        assert!(
            ok && text.contains("no bias detected"),
            "pair {pair}: {text}"
        );
        let csv = std::fs::read_to_string(out.join("tiles.csv")).unwrap();
        for line in csv.lines().skip(1) {
            let f: Vec<&str> = line.split(',').collect();
            pooled.extend(f[2..5].iter().filter_map(|p| p.parse::<f64>().ok()));
        }
    }
    // Channels constant on both sides (the light seen directly) are not tested.
    assert!(
        pooled.len() > 3000 && pooled.len() < 20 * 64 * 3,
        "{}",
        pooled.len()
    );
    pooled.sort_by(f64::total_cmp);
    let d = directlab::stats::ks_uniform(&pooled);
    let p = directlab::stats::ks_p_value(d, pooled.len());
    assert!(p > 0.01, "KS distance {d}, p {p}");
}

/// Two configurations rendered by compare itself (`--render-a`, `--render-b`), four seeds
/// of 4 spp each at 32x32, zsobol (correlated: the seeds are the samples): light sampling
/// against MIS agree at alpha 0.01; light against BSDF sampling is inconclusive, not biased
/// (BSDF sampling sees the light from the ceiling in none of its 16 samples, so its variance
/// there is unknown); the Cornell box against its disc-light variant (another light at the
/// same place, as bright within a few per cent) is detected at 64 spp; the page shows A, B and their difference; options compare owns
/// are refused by name.
#[test]
fn configurations_rendered_here() {
    let dir = scratch("compare-render");
    let out = dir.join("out");
    let cbox = repo("scenes/cbox/cbox.xml");
    let line = |scene: &Path, rest: &str| format!("{} -D res=32 {rest}", scene.display());
    let args = |a: &str, b: &str| {
        vec![
            "--render-a".to_string(),
            a.to_string(),
            "--render-b".to_string(),
            b.to_string(),
            "--seeds".to_string(),
            "4".to_string(),
            "--tile".to_string(),
            "4".to_string(),
            "--out".to_string(),
            out.display().to_string(),
        ]
    };
    let (ok, text) = compare_strings(&args(
        &line(&cbox, "--spp 4 --sampler zsobol --strategy light"),
        &line(&cbox, "--spp 4 --sampler zsobol --strategy mis"),
    ));
    assert!(ok && text.contains("no bias detected"), "{text}");
    let seeds = std::fs::read_dir(out.join("a")).unwrap().count();
    assert_eq!(seeds, 4);
    let md = std::fs::read_to_string(out.join("index.md")).unwrap();
    assert!(
        md.contains("light-e1-uni-area, 4 spp, sampler zsobol; seeds 0..3")
            && md.contains("seeds 4..7"),
        "{md}"
    );
    for f in ["a.png", "b.png", "diff.png", "index.html"] {
        assert!(out.join(f).exists(), "{f}");
    }
    let (ok, text) = compare_strings(&args(
        &line(&cbox, "--spp 4 --sampler zsobol --strategy light"),
        &line(&cbox, "--spp 4 --sampler zsobol --strategy bsdf"),
    ));
    assert!(
        !ok && text.contains("inconclusive: ") && text.contains("too few samples"),
        "{text}"
    );
    let disc = repo("scenes/cbox-meshlight/cbox-meshlight.xml");
    let (ok, text) = compare_strings(&args(&line(&cbox, "--spp 64"), &line(&disc, "--spp 64")));
    assert!(!ok && text.contains("bias detected"), "{text}");
    let (ok, text) = compare_strings(&args(&line(&cbox, "--seed 3"), &line(&cbox, "--spp 4")));
    assert!(
        !ok && text.contains("--seed is compare's to choose"),
        "{text}"
    );
}

fn compare_strings(args: &[String]) -> (bool, String) {
    run_text(directlab().arg("compare").args(args))
}

/// `compare-power` on the Cornell box at 32x32, 3 trials at 16 spp: a 20 % bias in the
/// centre is found in every trial and no bias in none, in both modes (two sides of eight
/// seeds; one render of 8 x 16 samples with its variance per side); the table and power.csv say so; a
/// correlated sampler is refused in the variance mode, and --spp in the configuration is
/// refused.
#[test]
fn compare_power_tables_detection_rates() {
    let dir = scratch("compare-power");
    let line = format!("{} -D res=32", repo("scenes/cbox/cbox.xml").display());
    for mode in [None, Some("--per-pixel-variance")] {
        let out = dir.join(format!("out-{}", mode.is_some()));
        let mut cmd = directlab();
        cmd.args([
            "compare-power",
            &line,
            "--spp",
            "16",
            "--bias",
            "0.2",
            "--trials",
            "3",
        ])
        .args(["--seeds", "8", "--tile", "4", "--out"])
        .arg(&out)
        .args(mode);
        let (ok, text) = run_text(&mut cmd);
        assert!(ok, "{text}");
        assert!(
            text.contains("| 16 | 0/3 [0.00, 0.56] | 3/3 [0.44, 1.00] |"),
            "{mode:?}: {text}"
        );
        let csv = std::fs::read_to_string(out.join("power.csv")).unwrap();
        assert!(csv.contains("\n16,0.2,3,3,0,1.0000,"), "{csv}");
        assert!(out.join("index.html").exists());
    }
    let (ok, text) = run_text(directlab().args([
        "compare-power",
        &format!("{line} --sampler zsobol"),
        "--per-pixel-variance",
        "--trials",
        "1",
        "--spp",
        "4",
    ]));
    assert!(
        !ok && text.contains("zsobol sampler's samples in a pixel are correlated"),
        "{text}"
    );
    let (ok, text) = run_text(directlab().args(["compare-power", &format!("{line} --spp 4")]));
    assert!(
        !ok && text.contains("--spp is compare's to choose"),
        "{text}"
    );
}

/// `directlab guard`: every bundled scene agrees with the stored tiles (this build renders
/// what main rendered, within noise); stored tiles moved by 5 % in one scene make it fail
/// and name that scene; a missing file is named with the command that writes it.
#[test]
fn guard_holds_the_bundled_scenes_and_names_a_moved_one() {
    let dir = scratch("guard");
    let tiles = repo("tests/regression/tiles.json");
    let guard = |t: &Path| {
        run_text(
            directlab()
                .arg("guard")
                .arg("--tiles")
                .arg(t)
                .arg("--scenes")
                .arg(repo("scenes")),
        )
    };
    let (ok, text) = guard(&tiles);
    assert!(ok && text.matches(": agrees (").count() == 8, "{text}");
    let mut stored: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&tiles).unwrap()).unwrap();
    for p in stored["cbox-plastic/cbox-plastic.xml"]["mean"]
        .as_array_mut()
        .unwrap()
    {
        for c in p.as_array_mut().unwrap() {
            *c = serde_json::json!(c.as_f64().unwrap() * 1.05);
        }
    }
    let moved = dir.join("moved.json");
    std::fs::write(&moved, stored.to_string()).unwrap();
    let (ok, text) = guard(&moved);
    assert!(
        !ok && text.contains("cbox-plastic/cbox-plastic.xml: MOVED")
            && text.contains("1 of 8 bundled scenes differ"),
        "{text}"
    );
    let (ok, text) = guard(&dir.join("none.json"));
    assert!(
        !ok && text.contains("directlab guard --store writes it"),
        "{text}"
    );
}
