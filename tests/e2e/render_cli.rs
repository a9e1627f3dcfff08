//! End to end through the `directlab render` command, as a user runs it.

use crate::common;
use directlab::film::read_exr;
use directlab::metrics::compare_regions;

use common::{directlab, repo, run, scratch};
use std::path::{Path, PathBuf};

#[test]
fn renders_bundled_cornell_box_with_exr_png_variance_and_stats() {
    let d = scratch("cbox");
    let out = run(directlab()
        .args(["render", repo("scenes/cbox/cbox.xml").to_str().unwrap()])
        .args(["--spp", "4", "-D", "res=32", "--threads", "2"])
        .arg("--out")
        .arg(d.join("img.exr"))
        .arg("--variance")
        .arg(d.join("var.exr"))
        .arg("--stats")
        .arg(d.join("stats.json")));
    assert!(out.status.success());
    let img = read_exr(&d.join("img.exr")).unwrap();
    assert_eq!((img.width, img.height), (32, 32));
    assert!(d.join("img.png").exists() && d.join("var.exr").exists());
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("stats.json")).unwrap()).unwrap();
    for key in [
        "spp",
        "width",
        "height",
        "seconds",
        "samples_per_second",
        "non_finite_samples",
        "mean_rgb",
    ] {
        assert!(stats.get(key).is_some(), "stats lacks {key}: {stats}");
    }
    assert_eq!(stats["spp"], 4);
    assert_eq!(stats["non_finite_samples"], 0);
    let mean = stats["mean_rgb"][0].as_f64().unwrap();
    assert!(mean > 0.01, "the Cornell box is lit: {mean}");
}

/// Same pixels and same bytes: at 160x160 the EXR has nine 64x64 tiles, which must be written
/// in a fixed order (see `film::write_exr`).
#[test]
fn same_seed_gives_identical_files_for_one_and_two_threads() {
    let d = scratch("threads");
    for t in ["1", "2"] {
        let out = run(directlab()
            .args(["render", repo("scenes/cbox/cbox.xml").to_str().unwrap()])
            .args(["--spp", "3", "-D", "res=160", "--seed", "5", "--threads", t])
            .arg("--out")
            .arg(d.join(format!("t{t}.exr"))));
        assert!(out.status.success());
    }
    let a = std::fs::read(d.join("t1.exr")).unwrap();
    let b = std::fs::read(d.join("t2.exr")).unwrap();
    assert_eq!(a, b, "thread count changed the image");
}

/// The Cornell box in Mitsuba 3 XML and in Nori XML: same geometry and materials, different
/// MIS heuristic (power vs balance), so the same expected image. Region z-tests (8x8 pixel
/// regions, 3 channels, 32x32 image at 64 spp) at alpha = 0.01, Sidak-corrected.
#[test]
fn both_dialects_of_the_cornell_box_render_the_same_image() {
    let d = scratch("dialects");
    for (name, scene) in [
        ("mi", "scenes/cbox/cbox.xml"),
        ("nori", "scenes/cbox/cbox-nori.xml"),
    ] {
        let out = run(directlab()
            .args([
                "render",
                repo(scene).to_str().unwrap(),
                "--spp",
                "64",
                "--seed",
                name.len().to_string().as_str(),
            ])
            .args(["--out"])
            .arg(d.join(format!("{name}.exr")))
            .arg("--variance")
            .arg(d.join(format!("{name}-var.exr"))));
        assert!(out.status.success());
    }
    let load = |n: &str| read_exr(&d.join(n)).unwrap();
    let (a, av, b, bv) = (
        load("mi.exr"),
        load("mi-var.exr"),
        load("nori.exr"),
        load("nori-var.exr"),
    );
    let cmp = compare_regions((&a, &av), (&b, &bv), 8, 0.01);
    assert!(cmp.passed(), "{cmp:?}");
}

/// Writes a small Mitsuba 3 scene with the given shape (and emitter) elements.
fn write_scene(dir: &Path, body: &str) -> PathBuf {
    let xml = format!(
        r#"<scene version="3.0.0">
    <sensor type="perspective">
        <float name="fov" value="45"/>
        <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
    </sensor>
{body}
</scene>"#
    );
    let p = dir.join("scene.xml");
    std::fs::write(&p, xml).unwrap();
    p
}

/// A failing render must say what is wrong (file, line, element) and leave no output behind.
fn assert_fails_cleanly(dir: &Path, scene: &Path, expect: &[&str]) {
    let out = directlab()
        .arg("render")
        .arg(scene)
        .arg("--out")
        .arg(dir.join("out.exr"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    for e in expect {
        assert!(err.contains(e), "stderr lacks {e:?}: {err}");
    }
    let left: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n.starts_with("out"))
        .collect();
    assert!(left.is_empty(), "output left behind: {left:?}");
}

#[test]
fn bad_input_gives_clear_errors_and_no_output() {
    let d = scratch("bad");
    let s = write_scene(
        &d,
        r#"<shape type="obj"><string name="filename" value="missing.obj"/></shape>"#,
    );
    assert_fails_cleanly(&d, &s, &["scene.xml:7", "missing.obj"]);
    let s = write_scene(
        &d,
        r#"<shape type="sphere"><float name="radius" value="1.O"/><emitter type="area"/></shape>"#,
    );
    assert_fails_cleanly(&d, &s, &["scene.xml:7", "radius", "1.O"]);
    let s = write_scene(&d, r#"<shape type="teapot"><emitter type="area"/></shape>"#);
    assert_fails_cleanly(&d, &s, &["scene.xml:7", "teapot"]);
    let s = write_scene(
        &d,
        r#"<shape type="sphere"><float name="radius" value="nan"/><emitter type="area"/></shape>"#,
    );
    assert_fails_cleanly(&d, &s, &["scene.xml:7", "radius"]);
    let s = write_scene(&d, r#"<shape type="rectangle"/>"#);
    assert_fails_cleanly(&d, &s, &["no emitters"]);
    std::fs::write(d.join("flat.obj"), "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n").unwrap();
    let s = write_scene(
        &d,
        r#"<shape type="obj"><string name="filename" value="flat.obj"/><emitter type="area"/></shape>"#,
    );
    assert_fails_cleanly(&d, &s, &["scene.xml:7", "zero total area"]);
    let s = write_scene(&d, r#"<shape type="rectangle"><emitter type="area"/>"#);
    assert_fails_cleanly(&d, &s, &["scene.xml"]);
}

#[test]
fn degenerate_triangles_in_an_emitter_are_a_documented_warning() {
    let d = scratch("degenerate");
    std::fs::write(
        d.join("light.obj"),
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv 3 3 0\nf 1 2 3\nf 1 3 4\n",
    )
    .unwrap();
    let s = write_scene(
        &d,
        r#"<shape type="obj"><string name="filename" value="light.obj"/><emitter type="area"/></shape>"#,
    );
    let out = run(directlab()
        .arg("render")
        .arg(&s)
        .arg("--out")
        .arg(d.join("out.exr")));
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("warning:") && err.contains("zero-area"),
        "{err}"
    );
}

#[test]
fn defines_override_defaults() {
    let d = scratch("defines");
    let out = run(directlab()
        .args([
            "render",
            repo("scenes/cbox/cbox.xml").to_str().unwrap(),
            "-D",
            "res=16",
            "--spp",
            "1",
        ])
        .arg("--out")
        .arg(d.join("a.exr")));
    assert!(out.status.success());
    assert_eq!(read_exr(&d.join("a.exr")).unwrap().width, 16);
    let bad = directlab()
        .args([
            "render",
            repo("scenes/cbox/cbox.xml").to_str().unwrap(),
            "-D",
            "oops",
        ])
        .output()
        .unwrap();
    assert!(!bad.status.success());
}

/// `render --aov DIR` on the Cornell box (32x32, 8 spp, power MIS): the six images exist
/// with previews; emitted + light + bsdf is the image (to the EXR's f32 rounding, 1e-5
/// relative); the MIS weights are in [0, 1]; the image itself is bitwise the one rendered
/// without --aov. A file given as the directory is refused by name.
#[test]
fn aov_images_add_up_to_the_image() {
    let d = scratch("aov");
    let render = |out: &Path, aov: Option<&Path>| {
        let mut cmd = directlab();
        cmd.args(["render", repo("scenes/cbox/cbox.xml").to_str().unwrap()])
            .args(["--spp", "8", "-D", "res=32", "--out"])
            .arg(out);
        if let Some(a) = aov {
            cmd.arg("--aov").arg(a);
        }
        run(&mut cmd)
    };
    let aov = d.join("aov");
    let o = render(&d.join("with.exr"), Some(&aov));
    assert!(o.status.success(), "{o:?}");
    assert!(render(&d.join("without.exr"), None).status.success());
    assert_eq!(
        std::fs::read(d.join("with.exr")).unwrap(),
        std::fs::read(d.join("without.exr")).unwrap()
    );
    let img = read_exr(&d.join("with.exr")).unwrap();
    let part = |n: &str| read_exr(&aov.join(format!("{n}.exr"))).unwrap().data;
    let (e, l, b) = (part("emitted"), part("light"), part("bsdf"));
    for (i, m) in img.data.iter().enumerate() {
        for c in 0..3 {
            let sum = e[i][c] + l[i][c] + b[i][c];
            assert!((sum - m[c]).abs() <= 1e-5 * m[c].max(1e-3), "pixel {i}");
        }
    }
    for w in ["weight-light", "weight-bsdf"] {
        assert!(part(w).iter().all(|p| (0.0..=1.0).contains(&p[0])), "{w}");
        assert!(aov.join(format!("{w}.png")).exists());
    }
    assert!(part("second-moment")
        .iter()
        .zip(&img.data)
        .all(|(s, m)| s[0] >= m[0] * m[0] * 0.99999));
    let file = d.join("a-file");
    std::fs::write(&file, "x").unwrap();
    let o = render(&d.join("x.exr"), Some(&file));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("expected a directory"),
        "{err}"
    );
}

/// The bundled environment map is exactly what its generator writes (it is data made by
/// code: a change to either without the other fails here).
#[test]
fn bundled_sky_is_what_its_generator_writes() {
    let out = scratch("sky").join("sky.exr");
    let o = std::process::Command::new("python3")
        .arg(repo("scenes/envmap/make_sky.py"))
        .arg(&out)
        .output()
        .expect("python3");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let made = std::fs::read(&out).unwrap();
    let bundled = std::fs::read(repo("scenes/envmap/sky.exr")).unwrap();
    assert!(
        made == bundled,
        "scenes/envmap/sky.exr differs from make_sky.py's output"
    );
}
