//! Bad input through the command line, as a user meets it: each case ends with a clear error
//! naming what is wrong (exit 1, or 2 for a usage error), before any rendering, and leaves
//! what was at the output path as it was. Cases that used to hang or run for minutes run
//! under a watchdog (`within`): the test fails if they outlast it.

use crate::common;

use common::{directlab, fails, repo, scratch, within};
use std::os::unix::fs::{FileTypeExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn cbox() -> String {
    repo("scenes/cbox/cbox.xml").to_str().unwrap().to_string()
}

fn render(out: &Path) -> Command {
    let mut c = directlab();
    c.args(["render", &cbox(), "-D", "res=8", "--spp", "2"])
        .arg("--out")
        .arg(out);
    c
}

/// A file with known contents that the failed commands must leave alone.
fn sentinel(path: &Path) {
    std::fs::write(path, "keep me").unwrap();
}

fn unchanged(path: &Path) {
    assert_eq!(
        std::fs::read_to_string(path).unwrap(),
        "keep me",
        "{path:?}"
    );
}

#[test]
fn films_too_large_for_memory_are_refused_before_rendering() {
    let d = scratch("bad-memory");
    let out = d.join("img.exr");
    sentinel(&out);
    // 30000^2 pixels need about 107 GiB; this machine has 24 GiB in all.
    fails(
        directlab()
            .args(["render", &cbox(), "-D", "res=30000", "--out"])
            .arg(&out),
        1,
        &["30000x30000", "GiB", "available"],
    );
    // Used to grow a tile list until allocation failed.
    fails(
        directlab()
            .args(["render", &cbox(), "-D", "res=1000000000", "--out"])
            .arg(&out),
        1,
        &["1000000000x1000000000", "pixels"],
    );
    unchanged(&out);
    // chi2's tables are bounded too (100000 used to try to allocate 80 GB), and 0 is refused
    // rather than silently raised.
    for r in ["100000", "0"] {
        fails(
            directlab()
                .args(["chi2", "--resolution", r, "--out"])
                .arg(&d),
            2,
            &["--resolution", "from 3 to 2048"],
        );
    }
}

#[test]
fn output_paths_that_are_not_plain_files_are_refused() {
    let d = scratch("bad-outputs");
    // A symbolic link to a device (as root, `--out /dev/full` used to replace the device node).
    let dev = d.join("dev.exr");
    std::os::unix::fs::symlink("/dev/null", &dev).unwrap();
    fails(&mut render(&dev), 1, &["dev.exr", "is a device"]);
    assert!(std::fs::symlink_metadata(&dev)
        .unwrap()
        .file_type()
        .is_symlink());
    assert!(std::fs::metadata("/dev/null")
        .unwrap()
        .file_type()
        .is_char_device());
    fails(
        render(&d.join("ok.exr")).args(["--variance", "/dev/null"]),
        1,
        &["/dev/null", "is a device"],
    );
    assert!(!d.join("ok.exr").exists(), "refused before rendering");

    // A directory.
    let dir = d.join("dir.exr");
    std::fs::create_dir(&dir).unwrap();
    fails(&mut render(&dir), 1, &["dir.exr", "is a directory"]);

    // Hard links and write-protected files.
    let a = d.join("a.exr");
    sentinel(&a);
    std::fs::hard_link(&a, d.join("b.exr")).unwrap();
    fails(&mut render(&a), 1, &["a.exr", "hard links"]);
    unchanged(&a);
    let p = d.join("p.exr");
    sentinel(&p);
    std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o444)).unwrap();
    fails(&mut render(&p), 1, &["p.exr", "write-protected"]);
    unchanged(&p);

    // A read-only directory, found before the render.
    let ro = d.join("ro");
    std::fs::create_dir(&ro).unwrap();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    fails(&mut render(&ro.join("x.exr")), 1, &["read-only"]);
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
    assert_eq!(std::fs::read_dir(&ro).unwrap().count(), 0);
}

#[test]
fn colliding_outputs_are_refused() {
    let d = scratch("bad-collide");
    // The PNG preview would take the EXR's path.
    let png = d.join("x.png");
    sentinel(&png);
    fails(&mut render(&png), 1, &["x.png", ".exr"]);
    unchanged(&png);
    let out = d.join("img.exr");
    sentinel(&out);
    fails(
        render(&out)
            .arg("--variance")
            .arg(d.join(".").join("img.exr")),
        1,
        &["--out and --variance are the same file"],
    );
    fails(
        render(&out).arg("--stats").arg(d.join("img.png")),
        1,
        &["the PNG preview and --stats are the same file"],
    );
    unchanged(&out);
    assert!(!d.join("img.png").exists());
}

#[test]
fn writes_keep_modes_follow_links_and_clear_stale_temporaries() {
    let d = scratch("bad-writes");
    let real = d.join("real.exr");
    sentinel(&real);
    std::fs::set_permissions(&real, std::fs::Permissions::from_mode(0o640)).unwrap();
    let link = d.join("link.exr");
    std::os::unix::fs::symlink("real.exr", &link).unwrap();
    // Left by a killed run (pid above Linux's limit, so not running).
    let stale = d.join("link.png.tmp4194305");
    std::fs::write(&stale, "half").unwrap();
    let o = within(&mut render(&link), 60);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    let m = std::fs::metadata(&real).unwrap();
    assert_eq!(m.permissions().mode() & 0o777, 0o640);
    assert!(directlab::film::read_exr(&real).is_ok());
    assert!(!stale.exists(), "stale temporary file left");
}

#[test]
fn silently_accepted_values_are_now_errors() {
    let d = scratch("bad-values");
    let out = d.join("img.exr");
    fails(render(&out).args(["--spp", "0"]), 2, &["--spp"]);
    fails(
        render(&out).args(["--threads", "0"]),
        2,
        &["from 1 to 1024"],
    );
    // Used to spend 70 s creating threads, then panic.
    fails(
        render(&out).args(["--threads", "100000"]),
        2,
        &["from 1 to 1024"],
    );
    fails(directlab().args(["bench", "--spp", "0"]), 2, &["--spp"]);
    // A typo in -D used to be ignored.
    fails(
        render(&out).args(["-D", "rse=16"]),
        1,
        &["cbox.xml", "'rse'", "declares res, spp"],
    );
    // Zero emitter samples: light sampling draws nothing, an error; MIS becomes BSDF
    // sampling, as in Mitsuba.
    fails(
        render(&out).args(["--strategy", "light", "--emitter-samples", "0"]),
        1,
        &["emitter_samples = 0"],
    );
    let stats = d.join("s.json");
    let o = within(
        render(&out)
            .args(["--strategy", "mis", "--emitter-samples", "0", "--stats"])
            .arg(&stats),
        60,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    assert_eq!(s["strategy"], "bsdf-b1");
    // And in XML.
    let xml = d.join("zero.xml");
    std::fs::write(
        &xml,
        "<scene version=\"3.0.0\">\n<integrator type=\"direct\">\n\
         <integer name=\"emitter_samples\" value=\"0\"/>\n<integer name=\"bsdf_samples\" value=\"0\"/>\n\
         </integrator>\n</scene>\n",
    )
    .unwrap();
    fails(
        directlab().arg("render").arg(&xml).arg("--out").arg(&out),
        1,
        &["zero.xml:2", "both 0"],
    );
}

/// A scene file with `body` inside `<scene>`, a small film and a floor.
fn scene_file(d: &Path, name: &str, body: &str) -> PathBuf {
    let p = d.join(name);
    std::fs::write(
        &p,
        format!(
            "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"><film type=\"hdrfilm\">\
             <integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/>{}\
             </film></sensor>\n{body}\n</scene>\n",
            if name.contains("gauss") {
                "<rfilter type=\"gaussian\"><float name=\"stddev\" value=\"50\"/>\
                 <float name=\"radius\" value=\"0.01\"/></rfilter>"
            } else {
                ""
            }
        ),
    )
    .unwrap();
    p
}

#[test]
fn inputs_that_crashed_or_hung_end_with_an_error_or_finish() {
    let d = scratch("bad-hang");
    let out = d.join("img.exr");
    // 20,000 nested elements used to overflow the stack.
    let nest = d.join("nest.xml");
    std::fs::write(
        &nest,
        format!(
            "<scene version=\"3.0.0\">{}{}</scene>",
            "<a>".repeat(20000),
            "</a>".repeat(20000)
        ),
    )
    .unwrap();
    fails(
        directlab().arg("render").arg(&nest).arg("--out").arg(&out),
        1,
        &["nest.xml:1", "deeper than 256"],
    );
    // Used to be read until memory ran out.
    fails(
        directlab().args(["render", "/dev/zero", "--out"]).arg(&out),
        1,
        &["/dev/zero", "regular file"],
    );
    // A Gaussian filter far narrower than its stddev: rejection sampling took minutes.
    let gauss = scene_file(
        &d,
        "gauss.xml",
        "<shape type=\"rectangle\"><emitter type=\"area\"><rgb name=\"radiance\" value=\"1\"/></emitter></shape>",
    );
    let o = within(
        directlab()
            .arg("render")
            .arg(&gauss)
            .args(["--spp", "256", "--out"])
            .arg(&out),
        60,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn many_emitters_load_in_linear_time() {
    // 65,536 emitters took 115 s to load when each element's line was found by scanning the
    // document from its start; linear loading takes a few seconds.
    let d = scratch("bad-many");
    let body: String = (0..65536)
        .map(|i| {
            format!(
                "<shape type=\"rectangle\"><transform name=\"to_world\"><scale value=\"0.001\"/>\
                 <translate x=\"{}\" y=\"{}\" z=\"1\"/></transform><emitter type=\"area\">\
                 <rgb name=\"radiance\" value=\"1\"/></emitter></shape>\n",
                (i % 256) as f32 * 0.003,
                (i / 256) as f32 * 0.003
            )
        })
        .collect();
    let scene = scene_file(&d, "many.xml", &body);
    let o = within(
        directlab()
            .arg("render")
            .arg(&scene)
            .args(["--spp", "1", "--out"])
            .arg(d.join("m.exr")),
        60,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn messages_name_the_file_and_line_and_do_not_echo_huge_values() {
    let d = scratch("bad-messages");
    let out = d.join("img.exr");
    std::fs::write(d.join("bad.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n").unwrap();
    let s = scene_file(
        &d,
        "obj.xml",
        "<shape type=\"obj\"><string name=\"filename\" value=\"bad.obj\"/></shape>",
    );
    fails(
        directlab().arg("render").arg(&s).arg("--out").arg(&out),
        1,
        &["bad.obj:4", "face vertex '7'"],
    );
    let s = scene_file(
        &d,
        "huge.xml",
        "<shape type=\"rectangle\"><transform name=\"to_world\"><scale value=\"1e20\"/></transform>\
         <emitter type=\"area\"><rgb name=\"radiance\" value=\"1\"/></emitter></shape>",
    );
    let e = fails(
        directlab().arg("render").arg(&s).arg("--out").arg(&out),
        1,
        &["huge.xml:3", "overflows single precision"],
    );
    assert!(!e.contains("zero total area"), "{e}");
    let long = "9".repeat(100_000);
    let s = scene_file(
        &d,
        "long.xml",
        &format!("<shape type=\"sphere\"><float name=\"radius\" value=\"x{long}\"/></shape>"),
    );
    let e = fails(
        directlab().arg("render").arg(&s).arg("--out").arg(&out),
        1,
        &["long.xml:3", "100001 characters"],
    );
    assert!(e.len() < 2000, "{} bytes of message", e.len());
}

fn experiment(d: &Path, name: &str, extra: &str) -> PathBuf {
    let p = d.join(name);
    std::fs::write(
        &p,
        format!(
            "scene = \"{}\"\nspp = [1, 2]\n[defines]\nres = \"8\"\n[[strategy]]\nname = \"mis\"\n\
             [reference]\nspp = 8\nseed = 100\n{extra}",
            cbox()
        ),
    )
    .unwrap();
    p
}

#[test]
fn experiment_values_that_were_silently_accepted_are_errors() {
    let d = scratch("bad-exp");
    let reports = d.join("reports");
    for (name, extra, words) in [
        (
            "nan.toml",
            "[figures]\nexposure = nan\n",
            &["figures.exposure"][..],
        ),
        (
            "inf.toml",
            "[equal_time]\nseconds = [inf]\n",
            &["equal_time.seconds = inf"][..],
        ),
        (
            "prog.toml",
            "[figures]\nprogression = [1, 3]\n",
            &["figures.progression: 3"][..],
        ),
    ] {
        let f = experiment(&d, name, extra);
        let e = fails(
            directlab().arg("run").arg(&f).arg("--out").arg(&reports),
            1,
            words,
        );
        assert!(e.contains(name), "{e}");
        assert!(!reports.join(name.trim_end_matches(".toml")).exists());
    }
    // A TOML syntax error names the file once.
    let f = d.join("syntax.toml");
    std::fs::write(&f, "spp = [1, 2\n").unwrap();
    let e = fails(
        directlab().arg("run").arg(&f).arg("--out").arg(&reports),
        1,
        &["line 1"],
    );
    assert_eq!(e.matches("syntax.toml").count(), 2, "{e}"); // the error and the summary
}

/// A reference render killed with SIGKILL resumes from its last checkpoint, and ends with
/// the bytes of an uninterrupted run.
#[test]
fn killed_reference_render_resumes_from_its_checkpoint() {
    let d = scratch("bad-kill");
    let exp = |dir: &Path| {
        let p = dir.join("k.toml");
        std::fs::write(
            &p,
            format!(
                "scene = \"{}\"\nspp = [1]\n[defines]\nres = \"48\"\n[[strategy]]\nname = \"mis\"\n\
                 [reference]\nspp = 6144\nseed = 100\n",
                cbox()
            ),
        )
        .unwrap();
        p
    };
    let (a, b) = (d.join("a"), d.join("b"));
    std::fs::create_dir_all(&a).unwrap();
    std::fs::create_dir_all(&b).unwrap();
    let run = |dir: &Path| {
        let mut c = directlab();
        c.arg("run")
            .arg(exp(dir))
            .args(["--threads", "2", "--out"])
            .arg(dir.join("reports"));
        c
    };
    let o = within(&mut run(&a), 300);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    let cache = b.join("reports/k/cache");
    let mut child = run(&b)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let partial = loop {
        let found = std::fs::read_dir(&cache).ok().and_then(|rd| {
            rd.flatten()
                .map(|e| e.path())
                .find(|p| p.extension().is_some_and(|x| x == "partial"))
        });
        if let Some(p) = found {
            break p;
        }
        assert!(
            child.try_wait().unwrap().is_none(),
            "finished before a checkpoint was seen"
        );
        assert!(start.elapsed() < Duration::from_secs(300));
        std::thread::sleep(Duration::from_millis(5));
    };
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    assert!(partial.exists());
    let o = within(&mut run(&b), 300);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("resuming the reference from its checkpoint"),
        "{err}"
    );
    assert!(!partial.exists());
    let exr = |dir: &Path| {
        let cache = dir.join("reports/k/cache");
        let mut v: Vec<PathBuf> = std::fs::read_dir(&cache)
            .unwrap()
            .flatten()
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|x| x == "exr"))
            .collect();
        v.sort();
        v.iter()
            .map(|p| std::fs::read(p).unwrap())
            .collect::<Vec<_>>()
    };
    let (ea, eb) = (exr(&a), exr(&b));
    assert_eq!(ea.len(), 2);
    assert!(
        ea == eb,
        "the resumed reference differs from the uninterrupted one"
    );
}

#[test]
fn reflectance_above_one_is_warned_about() {
    let d = scratch("bad-albedo");
    let s = scene_file(
        &d,
        "bright.xml",
        "<shape type=\"rectangle\"><bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.5, 1.5, 0.5\"/></bsdf></shape>\n\
         <shape type=\"rectangle\"><bsdf type=\"conductor\"><rgb name=\"specular_reflectance\" value=\"0.9\"/></bsdf>\
         <emitter type=\"area\"><rgb name=\"radiance\" value=\"1\"/></emitter></shape>",
    );
    let o = within(
        directlab()
            .arg("render")
            .arg(&s)
            .args(["--spp", "1", "--out"])
            .arg(d.join("b.exr")),
        60,
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("bright.xml:3") && err.contains("reflectance") && err.contains("exceeds 1"),
        "{err}"
    );
    assert_eq!(
        err.matches("exceeds 1").count(),
        1,
        "only the diffuse one: {err}"
    );
}

/// Output into a pipe nobody reads any more (`directlab chi2 --list | head -1` once head has
/// exited): the process ends by SIGPIPE, as Unix tools do, without a panic message.
#[test]
fn a_closed_stdout_pipe_ends_quietly() {
    use std::os::unix::process::ExitStatusExt;
    let (reader, writer) = std::io::pipe().unwrap();
    // Closed before the process starts, so its first write meets a closed pipe.
    drop(reader);
    let out = directlab()
        .args(["chi2", "--list"])
        .stdout(writer)
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(out.status.signal(), Some(SIGPIPE), "{:?}", out.status);
}

/// SIGPIPE's number on Linux and the BSDs.
const SIGPIPE: i32 = 13;
