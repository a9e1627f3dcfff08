//! `directlab test`: Nori's test files through the CLI (the committed ones pass, a wrong
//! reference fails, bad files give clear errors), and scenes whose integrator is a path
//! tracer (refused by `render`, rendered as their direct part with `--integrator direct`).

use crate::common;
use common::{directlab, repo, run, scratch};
use glam::DVec3;
use std::path::Path;

fn stdout(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Every committed test file passes (t-tests at 20,000 samples, chi-square at 100,000, each
/// file at Nori's family-wise alpha 0.01) and prints its table.
#[test]
fn committed_test_files_pass() {
    let out = scratch("noritest-pass");
    for (file, samples, rows) in [
        ("ttest-lambert.xml", "20000", "125 of 125 t-tests passed"),
        ("ttest-furnace.xml", "20000", "3 of 3 t-tests passed"),
        ("ttest-albedo.xml", "20000", "12 of 12 t-tests passed"),
        ("chi2test-bsdfs.xml", "100000", "FAIL"),
    ] {
        let o = run(directlab()
            .arg("test")
            .arg(repo(&format!("scenes/tests/{file}")))
            .args(["--samples", samples, "--out"])
            .arg(&out));
        assert!(o.status.success(), "{file}: {}", stderr(&o));
        let text = stdout(&o);
        if rows == "FAIL" {
            assert!(
                !text.contains("FAIL") && text.contains("microfacet"),
                "{text}"
            );
            assert!(out.join("chi2test-bsdfs/results.csv").exists());
        } else {
            assert!(text.contains(rows), "{file}: {text}");
        }
        assert!(text.contains(&format!("{file}: passed")), "{text}");
    }
}

/// A scene test whose reference is off by 3 % fails (exit 1, its row marked FAIL), with the
/// rest of the file passing: the t-test has the power to see it at 20,000 samples.
#[test]
fn a_wrong_reference_fails() {
    let d = scratch("noritest-wrong");
    let text = std::fs::read_to_string(repo("scenes/tests/ttest-lambert.xml")).unwrap();
    let line = text.lines().find(|l| l.contains("references")).unwrap();
    let value = line.split('"').nth(3).unwrap();
    let mut refs: Vec<f64> = value.split(' ').map(|v| v.parse().unwrap()).collect();
    refs[2] *= 1.03;
    let new: Vec<String> = refs.iter().map(|r| format!("{r:.9}")).collect();
    let text = text.replace(value, &new.join(" ")).replace(
        "meshes/",
        &format!("{}/", repo("scenes/tests/meshes").display()),
    );
    let file = d.join("wrong.xml");
    std::fs::write(&file, text).unwrap();
    let o = run(directlab()
        .arg("test")
        .arg(&file)
        .args(["--samples", "20000"]));
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    let table = stdout(&o);
    let failed: Vec<&str> = table.lines().filter(|l| l.ends_with("FAIL")).collect();
    assert!(
        !failed.is_empty() && failed.iter().all(|l| l.starts_with("scene 3 ")),
        "{table}"
    );
    assert!(stderr(&o).contains("some tests failed"), "{}", stderr(&o));
}

/// The Lambert references of the committed file are Lambert's formula as directlab's
/// analytic module computes it, summed over each light mesh's triangles (irradiance is
/// additive over a partition of the polygon): a wrong number in the file fails here.
#[test]
fn lambert_references_are_the_closed_form() {
    let text = std::fs::read_to_string(repo("scenes/tests/ttest-lambert.xml")).unwrap();
    let line = text.lines().find(|l| l.contains("references")).unwrap();
    let refs: Vec<f64> = line
        .split('"')
        .nth(3)
        .unwrap()
        .split(' ')
        .map(|v| v.parse().unwrap())
        .collect();
    let lights: Vec<&str> = text
        .lines()
        .filter_map(|l| l.split("meshes/light-").nth(1))
        .map(|l| l.split('"').next().unwrap())
        .collect();
    assert_eq!((refs.len(), lights.len()), (5, 5));
    for (r, obj) in refs.iter().zip(&lights) {
        let (v, f) = read_obj(&repo(&format!("scenes/tests/meshes/light-{obj}")));
        let e: f64 = f
            .iter()
            .map(|t| {
                let tri = t.map(|i| v[i]);
                directlab::analytic::polygon_irradiance(DVec3::ZERO, DVec3::Y, &tri, 3.0).unwrap()
            })
            .sum();
        let want = directlab::analytic::diffuse_radiance(0.5, e);
        assert!(
            (r - want).abs() < 1e-8 * want,
            "{obj}: file {r}, formula {want}"
        );
    }
}

fn read_obj(path: &Path) -> (Vec<DVec3>, Vec<[usize; 3]>) {
    let (mut v, mut f) = (Vec::new(), Vec::new());
    for l in std::fs::read_to_string(path).unwrap().lines() {
        let w: Vec<&str> = l.split_whitespace().collect();
        match w.first() {
            Some(&"v") => v.push(DVec3::new(
                w[1].parse().unwrap(),
                w[2].parse().unwrap(),
                w[3].parse().unwrap(),
            )),
            Some(&"f") => f.push([1, 2, 3].map(|k| w[k].parse::<usize>().unwrap() - 1)),
            _ => {}
        }
    }
    (v, f)
}

/// Bad test files: a clear error naming the file, the line and what was expected, before
/// any test runs.
#[test]
fn bad_test_files_give_clear_errors() {
    let d = scratch("noritest-bad");
    let bsdf = r#"<bsdf type="diffuse"/>"#;
    let cases = [
        (
            r#"<test type="ztest"></test>"#.to_string(),
            vec![
                "bad.xml:1",
                "unknown test type 'ztest'; expected ttest or chi2test",
            ],
        ),
        (
            format!(
                "<test type=\"ttest\">\n<string name=\"angles\" value=\"0 30\"/>\n\
                 <string name=\"references\" value=\"1 1 1\"/>\n{bsdf}{bsdf}</test>"
            ),
            vec![
                "bad.xml:1",
                "3 reference values for 2 BSDFs at 2 angles; expected 2",
            ],
        ),
        (
            "<test type=\"chi2test\">\n<bsdf type=\"velvet\"/>\n</test>".to_string(),
            vec!["bad.xml:2", "unknown bsdf type 'velvet'"],
        ),
        (
            "<scene>\n</scene>".to_string(),
            vec![
                "bad.xml:1",
                "expected <test type=\"ttest\">",
                "directlab render",
            ],
        ),
        (
            "<test type=\"ttest\">\n<string name=\"references\" value=\"1 x\"/>\n</test>"
                .to_string(),
            vec!["bad.xml:2", "entry 2 is \"x\""],
        ),
        (
            "<test type=\"ttest\">\n<integer name=\"sampleCont\" value=\"5\"/>\n</test>"
                .to_string(),
            vec!["bad.xml:2", "unknown parameter 'sample_cont'"],
        ),
    ];
    for (xml, expect) in cases {
        let file = d.join("bad.xml");
        std::fs::write(&file, &xml).unwrap();
        let o = run(directlab().arg("test").arg(&file));
        assert_eq!(o.status.code(), Some(1), "{xml}");
        let e = stderr(&o);
        for x in expect {
            assert!(e.contains(x), "{xml}: expected '{x}' in: {e}");
        }
        assert!(!e.contains("panicked"), "{e}");
    }
}

/// A Nori scene naming path_mis: `render` refuses it and says how to render its direct part;
/// with `--integrator direct` it renders, says the image is the direct part, and records
/// the integrator in the statistics. An experiment file takes `integrator = "direct"`.
#[test]
fn path_tracer_scenes_render_their_direct_part_when_asked() {
    let d = scratch("noritest-direct");
    let text = std::fs::read_to_string(repo("scenes/tests/ttest-lambert.xml")).unwrap();
    let start = text.find("<scene>").unwrap();
    let end = text.find("</scene>").unwrap() + "</scene>".len();
    let scene = text[start..end].replace(
        "meshes/",
        &format!("{}/", repo("scenes/tests/meshes").display()),
    );
    let file = d.join("path.xml");
    std::fs::write(&file, &scene).unwrap();
    let exr = d.join("out.exr");
    let o = run(directlab()
        .arg("render")
        .arg(&file)
        .args(["--spp", "4", "--out"])
        .arg(&exr));
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(
        e.contains("path.xml:2")
            && e.contains("integrator 'path_mis' renders global illumination")
            && e.contains("--integrator direct"),
        "{e}"
    );
    assert!(!exr.exists());
    let stats = d.join("stats.json");
    let o = run(directlab()
        .arg("render")
        .arg(&file)
        .args(["--spp", "4", "--integrator", "direct", "--out"])
        .arg(&exr)
        .arg("--stats")
        .arg(&stats));
    assert!(o.status.success());
    assert!(stderr(&o).contains("the image is the direct part only"));
    let s = std::fs::read_to_string(&stats).unwrap();
    assert!(s.contains("\"direct_part_of\": \"path_mis\""), "{s}");
    // The same through an experiment file.
    let exp = d.join("exp.toml");
    std::fs::write(
        &exp,
        format!(
            "scene = \"{}\"\nintegrator = \"direct\"\nspp = [2, 4]\nseeds = 1\n\
             [[strategy]]\nname = \"mis\"\nstrategy = \"mis\"\n[reference]\nspp = 16\n",
            file.display()
        ),
    )
    .unwrap();
    let o = run(directlab()
        .arg("run")
        .arg(&exp)
        .arg("--out")
        .arg(d.join("reports")));
    assert!(o.status.success(), "{}", stderr(&o));
    let md = std::fs::read_to_string(d.join("reports/exp/index.md")).unwrap();
    assert!(
        md.contains("Direct illumination only") && md.contains("`path_mis`"),
        "{md}"
    );
    let bad = std::fs::read_to_string(&exp)
        .unwrap()
        .replace("integrator = \"direct\"\n", "");
    std::fs::write(&exp, bad).unwrap();
    let o = run(directlab()
        .arg("run")
        .arg(&exp)
        .arg("--out")
        .arg(d.join("reports2")));
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("integrator = \"direct\""));
}

/// `chi2 --scene`: a scene's own BSDFs (at the registry's incident directions, grazing
/// included) and its light sampling from receiver points, with its emitter choice; results
/// and heat maps under `<out>/scenes/<name>/`; what cannot be tested is said with the reason.
#[test]
fn chi2_of_a_scene_tests_its_bsdfs_and_lights() {
    let out = scratch("chi2-scene");
    let o = run(directlab()
        .arg("chi2")
        .arg("--scene")
        .arg(repo("scenes/veach-mis/veach-mis.xml"))
        .args(["--samples", "50000", "--emitter-selection", "bvh", "--out"])
        .arg(&out));
    assert!(o.status.success(), "{}", stderr(&o));
    let csv = std::fs::read_to_string(out.join("scenes/veach-mis/results.csv")).unwrap();
    for want in [
        "scene/bsdf2-roughconductor-grazing",
        "scene/lights-bvh-receiver0",
        "scene/bsdf0-diffuse-normal",
    ] {
        assert!(csv.contains(want), "{want} missing from {csv}");
    }
    assert!(out
        .join("scenes/veach-mis/scene/lights-bvh-receiver0.png")
        .exists());
    assert!(
        stderr(&o).contains("left out: receiver 2"),
        "{}",
        stderr(&o)
    );
    // The ceiling light seen edge-on from just under the ceiling (receiver 1): a sliver the
    // whole sphere's grid could not resolve (chi2 1242 on 52 dof for a correct sampler); the
    // window fitted to the lights does, under every emitter choice and light-sampling mode.
    for sel in ["uniform", "power", "bvh"] {
        for mode in ["area", "solid-angle"] {
            let o = run(directlab()
                .arg("chi2")
                .arg("--scene")
                .arg(repo("scenes/cbox-twolights/cbox-twolights.xml"))
                .args(["lights", "--samples", "300000", "--emitter-selection", sel])
                .args(["--light-sampling", mode, "--out"])
                .arg(&out));
            assert!(o.status.success(), "{sel} {mode}: {}", stderr(&o));
        }
    }
    // Each receiver is named by its position and normal.
    let o = run(directlab()
        .arg("chi2")
        .arg("--scene")
        .arg(repo("scenes/cbox-twolights/cbox-twolights.xml"))
        .args(["lights", "--list"]));
    let listed = String::from_utf8_lossy(&o.stdout);
    assert!(
        listed.contains("receiver1") && listed.contains("(normal ["),
        "{listed}"
    );
    let o = run(directlab()
        .arg("chi2")
        .arg("--scene")
        .arg(repo("scenes/cbox/no-such.xml")));
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("no-such.xml"), "{}", stderr(&o));
}
