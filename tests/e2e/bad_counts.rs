//! Counts near 2^32 and 2^64, the process's memory limit, and the cases that used to pass
//! silently: each is a clear error naming the option, file or line and the limit, within a
//! few seconds, with no output left behind (exit 2 for a command-line usage error, 1 else).

use crate::common::{directlab, fails, repo, scratch, tiny_experiment, within};
use std::path::Path;
use std::process::Command;

fn cmd(args: &[&str]) -> Command {
    let mut c = directlab();
    c.args(args);
    c
}

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

#[test]
fn counts_beyond_their_bounds_are_refused_naming_where_they_came_from() {
    let d = scratch("bad-counts");
    let cbox = repo("scenes/cbox/cbox.xml");
    let exp = tiny_experiment(&d, 1);
    let out = d.join("out");
    let (e, o) = (p(&exp), p(&out));
    // Shards: on the command line and in an edited plan.json.
    fails(
        &mut cmd(&["plan", e, "--out", o, "--shards", "4294967295"]),
        2,
        &["shard count is 4294967295", "at most 100000"],
    );
    fails(
        &mut cmd(&["run", e, "--out", o, "--shard", "0/4294967295"]),
        2,
        &["at most 100000"],
    );
    fails(
        &mut cmd(&["status", e, "--out", o, "--shards", "18446744073709551615"]),
        2,
        &["at most 100000"],
    );
    assert!(!out.exists(), "a refused command wrote something");
    assert!(
        within(&mut cmd(&["plan", e, "--out", o, "--shards", "4"]), 60)
            .status
            .success()
    );
    let plan = out.join("tiny/plan.json");
    let text = std::fs::read_to_string(&plan).unwrap();
    std::fs::write(
        &plan,
        text.replace("\"shards\": 4,", "\"shards\": 4294967295,"),
    )
    .unwrap();
    fails(
        &mut cmd(&["status", e, "--out", o]),
        1,
        &["plan.json", "\"shards\"", "at most 100000"],
    );
    std::fs::write(&plan, text.replace("\"shards\": 4,", "\"shards\": 5,")).unwrap();
    fails(
        &mut cmd(&["status", e, "--out", o]),
        1,
        &["plan.json", "was edited", "plan --shards"],
    );

    // Samples per pixel and per camera sample.
    let c = p(&cbox);
    fails(
        &mut cmd(&["render", c, "--spp", "4294967295"]),
        2,
        &["--spp is 4294967295", "at most 16777216"],
    );
    fails(
        &mut cmd(&["render", c, "-D", "spp=4294967295"]),
        1,
        &[
            "cbox.xml:27",
            "'sample_count' is 4294967295",
            "at most 16777216",
        ],
    );
    fails(
        &mut cmd(&["render", c, "--emitter-samples", "1000000000"]),
        1,
        &["emitter_samples is 1000000000", "at most 1024"],
    );
    let sweep = d.join("sweep.toml");
    std::fs::write(
        &sweep,
        std::fs::read_to_string(&exp)
            .unwrap()
            .replace("spp = [1, 4, 16]", "spp = [1, 4294967295]"),
    )
    .unwrap();
    fails(
        &mut cmd(&["run", p(&sweep), "--out", o]),
        1,
        &["sweep.toml", "spp is 4294967295", "at most 16777216"],
    );

    let strategy = d.join("strategy.toml");
    std::fs::write(
        &strategy,
        std::fs::read_to_string(&exp).unwrap().replace(
            "strategy = \"light\"\nemitter_selection = \"power\"",
            "strategy = \"light\"\nemitter_selection = \"power\"\nemitter_samples = 1000000000",
        ),
    )
    .unwrap();
    fails(
        &mut cmd(&["run", p(&strategy), "--out", o]),
        1,
        &[
            "strategy.toml",
            "emitter_samples is 1000000000",
            "at most 1024",
        ],
    );
    // The many-light grid: one BSDF tested once, not once per material (9,220 cases).
    let grid = repo("scenes/many-lights/grid.xml");
    let o2 = within(&mut cmd(&["chi2", "--scene", p(&grid), "--list"]), 30);
    let listed =
        String::from_utf8_lossy(&o2.stdout).to_string() + &String::from_utf8_lossy(&o2.stderr);
    assert!(o2.status.success(), "{listed}");
    let cases = listed.lines().filter(|l| l.starts_with("scene/")).count();
    assert!(cases <= 16, "{cases} cases: {listed}");
    assert!(listed.contains("same BSDF and parameters"), "{listed}");

    // The integrands' seeds and largest N; --quick no longer overrides what is given.
    let i = d.join("i");
    for (args, words) in [
        (
            vec!["--seeds", "18446744073709551615"],
            vec!["--seeds is 18446744073709551615", "at most 100000"],
        ),
        (
            vec!["--max-n", "4294967295"],
            vec!["--max-n is 4294967295", "at most 1048576"],
        ),
        (
            vec!["--quick", "--seeds", "0"],
            vec!["--seeds 0", "at least 2"],
        ),
        (
            vec!["--quick", "--samplers", "sobol,sobol"],
            vec!["--samplers lists sobol twice"],
        ),
    ] {
        let mut c = cmd(&["integrands", "--out", p(&i)]);
        c.args(&args);
        fails(&mut c, 1, &words);
    }
    assert!(!i.exists());

    // Nori test files: testCount and sampleCount name their line.
    let nori = d.join("t.xml");
    std::fs::write(
        &nori,
        "<test type=\"chi2test\">\n  <integer name=\"testCount\" value=\"1000000000\"/>\n  \
         <bsdf type=\"diffuse\"/>\n</test>\n",
    )
    .unwrap();
    fails(
        &mut cmd(&["test", p(&nori), "--out", p(&d.join("t"))]),
        1,
        &["t.xml:2", "'testCount' is 1000000000", "at most 10000"],
    );
    std::fs::write(
        &nori,
        "<test type=\"ttest\">\n  <integer name=\"sampleCount\" value=\"4294967295\"/>\n</test>\n",
    )
    .unwrap();
    fails(
        &mut cmd(&["test", p(&nori)]),
        1,
        &[
            "t.xml:2",
            "'sampleCount' is 4294967295",
            "at most 1073741824",
        ],
    );
    // A chi2test of a mirror alone would "pass" with 0 degrees of freedom.
    std::fs::write(
        &nori,
        "<test type=\"chi2test\">\n  <bsdf type=\"mirror\"/>\n</test>\n",
    )
    .unwrap();
    fails(
        &mut cmd(&["test", p(&nori), "--out", p(&d.join("t"))]),
        1,
        &["t.xml", "0 degrees of freedom", "delta"],
    );
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn metrics_that_would_switch_off_are_refused() {
    let d = scratch("bad-metrics");
    let exp = tiny_experiment(&d, 1);
    let text = std::fs::read_to_string(&exp).unwrap();
    let out = d.join("out");
    for (from, to, words) in [
        (
            "relmse_epsilon = 0.01",
            "relmse_epsilon = inf",
            vec!["relmse_epsilon = inf", "finite positive"],
        ),
        (
            "relmse_epsilon = 0.01",
            "relmse_epsilon = 0.01\nreport = [\"ssim\", \"ssim\"]",
            vec!["metrics.report lists \"ssim\" twice"],
        ),
    ] {
        std::fs::write(&exp, text.replace(from, to)).unwrap();
        let mut words = words;
        words.push("tiny.toml");
        let err = fails(&mut cmd(&["run", p(&exp), "--out", p(&out)]), 1, &words);
        assert!(!out.join("tiny/results.csv").exists());
        // A run that wrote nothing ends with its failure, not with a reports line, and
        // leaves no empty index.
        assert!(!err.contains("reports in"), "{err}");
        assert!(
            err.trim_end().lines().last().unwrap().starts_with("error:"),
            "{err}"
        );
        assert!(!out.join("index.md").exists());
    }
    std::fs::remove_dir_all(&d).unwrap();
}

/// A run into a folder another run holds, and `--out` naming a file: refused at once.
#[test]
fn a_second_run_into_one_folder_and_an_out_that_is_a_file_are_refused_at_once() {
    let d = scratch("bad-lock");
    let exp = tiny_experiment(&d, 1);
    let out = d.join("out");
    std::fs::create_dir_all(out.join("tiny")).unwrap();
    // This test's own process stands for a run in progress.
    let lock = out.join("tiny/.directlab.lock");
    let host = std::fs::read_to_string("/proc/sys/kernel/hostname").unwrap();
    std::fs::write(&lock, format!("{} {} 0\n", std::process::id(), host.trim())).unwrap();
    for args in [vec!["run"], vec!["merge"]] {
        let mut c = cmd(&args);
        c.arg(&exp).arg("--out").arg(&out);
        let err = fails(
            &mut c,
            1,
            &[
                "another directlab run",
                &format!("pid {}", std::process::id()),
            ],
        );
        assert!(err.contains(".directlab.lock"), "{err}");
    }
    assert_eq!(std::fs::read_dir(out.join("tiny")).unwrap().count(), 1);
    std::fs::remove_file(&lock).unwrap();

    let file = d.join("a-file");
    std::fs::write(&file, "keep me").unwrap();
    let start = std::time::Instant::now();
    fails(
        &mut cmd(&["run", p(&exp), "--out", p(&file)]),
        1,
        &["a-file", "check --out"],
    );
    assert!(
        start.elapsed().as_secs_f64() < 5.0,
        "refused only after rendering"
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "keep me");
    std::fs::remove_dir_all(&d).unwrap();
}

/// `--json` on `plan` and `status`: stdout is JSON lines only.
#[test]
fn plan_and_status_speak_json_when_asked() {
    let d = scratch("json-plan");
    let exp = tiny_experiment(&d, 1);
    let out = d.join("out");
    for (args, event) in [
        (["plan", "--json"], "plan"),
        (["status", "--json"], "status"),
    ] {
        let o = within(cmd(&args).arg(&exp).arg("--out").arg(&out), 60);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let text = String::from_utf8(o.stdout).unwrap();
        assert!(!text.trim().is_empty());
        for line in text.lines() {
            let v: serde_json::Value =
                serde_json::from_str(line).unwrap_or_else(|e| panic!("{e}: {line}"));
            assert_eq!(v["event"], event, "{line}");
        }
    }
    std::fs::remove_dir_all(&d).unwrap();
}

/// A film too large for the process's address-space limit (`ulimit -v`, as a Slurm job's
/// cgroup limit is for a cluster) is refused before rendering, naming the limit; a render
/// that fails leaves no folders behind. (1 GiB: below any machine's free memory that runs
/// these tests, so the address-space limit is the one that refuses.)
#[test]
fn the_process_memory_limit_refuses_a_film_before_rendering() {
    let d = scratch("bad-memory");
    let out = d.join("new/deeper/x.exr");
    let script = format!(
        "ulimit -v 1048576 && exec {} render {} -D res=4000 --spp 1 --out {}",
        env!("CARGO_BIN_EXE_directlab"),
        p(&repo("scenes/cbox/cbox.xml")),
        p(&out)
    );
    let start = std::time::Instant::now();
    let err = fails(
        Command::new("bash").args(["-c", &script]),
        1,
        &["4000x4000", "RLIMIT_AS", "ulimit -v"],
    );
    assert!(
        start.elapsed().as_secs_f64() < 10.0,
        "refused only after rendering: {err}"
    );
    assert!(
        !d.join("new").exists(),
        "a failed render created its --out folders"
    );
    std::fs::remove_dir_all(&d).unwrap();
}

/// 100,000 parameters nobody reads: refused in seconds, naming the first.
#[test]
fn a_plugin_with_a_hundred_thousand_unknown_parameters_is_refused_quickly() {
    let d = scratch("bad-params");
    let mut xml = String::from("<scene version=\"3.0.0\">\n<bsdf type=\"diffuse\" id=\"b\">\n");
    for k in 0..100_000 {
        xml.push_str(&format!("<float name=\"p{k}\" value=\"1\"/>\n"));
    }
    xml.push_str("</bsdf>\n</scene>\n");
    let scene = d.join("many.xml");
    std::fs::write(&scene, xml).unwrap();
    let start = std::time::Instant::now();
    fails(&mut cmd(&["render", p(&scene)]), 1, &["many.xml", "p0"]);
    assert!(start.elapsed().as_secs_f64() < 10.0);
    std::fs::remove_dir_all(&d).unwrap();
}

/// A scene of one rectangle light, its film filter and its translation given.
fn light_scene(dir: &Path, filter: &str, x: &str) -> std::path::PathBuf {
    let xml = format!(
        r#"<scene version="3.0.0">
    <integrator type="direct"/>
    <sensor type="perspective">
        <float name="fov" value="45"/>
        <transform name="to_world"><lookat origin="0, 0, -3" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="1"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="8"/>
            <integer name="height" value="8"/>
            {filter}
        </film>
    </sensor>
    <shape type="rectangle">
        <transform name="to_world"><translate x="{x}"/></transform>
        <emitter type="area"><rgb name="radiance" value="1"/></emitter>
    </shape>
</scene>
"#
    );
    let path = dir.join("light.xml");
    std::fs::write(&path, xml).unwrap();
    path
}

/// A filter wider than any film (the image came out black with exit 0) and a light moved so
/// far that f32 cannot resolve it (reported as "zero total area" with no cause).
#[test]
fn a_huge_filter_and_a_light_beyond_f32_resolution_are_explained() {
    let d = scratch("bad-far");
    let out = d.join("x.exr");
    let tent = r#"<rfilter type="tent"><float name="radius" value="1e30"/></rfilter>"#;
    let scene = light_scene(&d, tent, "0");
    fails(
        &mut cmd(&["render", p(&scene), "--out", p(&out)]),
        1,
        &[
            "light.xml:10",
            "filter radius 1000000000000000000000000000000 pixels",
            "at most 64",
        ],
    );
    let scene = light_scene(&d, r#"<rfilter type="box"/>"#, "1e30");
    fails(
        &mut cmd(&["render", p(&scene), "--out", p(&out)]),
        1,
        &["zero total area", "from the origin", "to_world"],
    );
    // Both fine where they are sane.
    let scene = light_scene(&d, r#"<rfilter type="tent"/>"#, "0.1");
    let o = within(&mut cmd(&["render", p(&scene), "--out", p(&out)]), 60);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::remove_dir_all(&d).unwrap();
}
