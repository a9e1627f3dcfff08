//! `directlab check-sampler` end to end with a Python sampler (numpy, through
//! helpers/python/directlab_sampler.py): the cosine-hemisphere example passes at 200,000
//! samples (alpha 0.01), its three wrong variants are rejected, and programs that crash, hang,
//! answer the wrong count or a NaN end in an error naming the phase and batch. Without numpy
//! the tests say so and are skipped, unless DIRECTLAB_REQUIRE_NUMPY=1 (set by `.ci/run` once
//! numpy imports).

use crate::common;
use common::{directlab, repo, run, scratch};
use std::process::Command;

fn numpy() -> bool {
    let ok = Command::new("python3")
        .args(["-c", "import numpy"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !ok {
        let required = std::env::var("DIRECTLAB_REQUIRE_NUMPY").is_ok_and(|v| v == "1");
        assert!(
            !required,
            "DIRECTLAB_REQUIRE_NUMPY=1 but python3 cannot import numpy"
        );
        eprintln!("SKIPPED check-sampler: python3 cannot import numpy (pip install numpy)");
    }
    ok
}

fn check(extra: &[&str], program: &[&str]) -> (bool, String) {
    static RUN: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let k = RUN.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
    let out = scratch(&format!("check-sampler-{k}"));
    let o = run(directlab()
        .args(["check-sampler", "--domain", "sphere", "--samples", "200000"])
        .args(extra)
        .arg("--out")
        .arg(&out)
        .arg("--")
        .args(program));
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    (o.status.success(), text)
}

#[test]
fn the_python_example_passes_and_its_wrong_variants_are_rejected() {
    if !numpy() {
        return;
    }
    let example = repo("examples/samplers/cosine_hemisphere.py");
    let ex = example.to_str().unwrap();
    let (ok, text) = check(&[], &["python3", ex]);
    assert!(ok && text.contains("check-sampler/sphere: pass"), "{text}");
    assert!(text.contains("claimed pdf: pass"), "{text}");
    for (wrong, why) in [
        ("cosine", "the histogram's shape failed"),
        ("horizon", "integral: FAIL"),
        ("outside", "its pdf says are impossible"),
    ] {
        let (ok, text) = check(&[], &["python3", ex, "--wrong", wrong]);
        assert!(!ok && text.contains("FAIL"), "{wrong}: {text}");
        assert!(text.contains(why), "{wrong}: {text}");
    }
}

#[test]
fn misbehaving_programs_end_in_errors_naming_the_phase() {
    if !numpy() {
        return;
    }
    let (ok, text) = check(&[], &["python3", "-c", "import sys; sys.exit(3)"]);
    assert!(!ok && text.contains("sample phase, batch 0"), "{text}");
    assert!(text.contains("exited"), "{text}");
    let (ok, text) = check(
        &["--timeout", "1"],
        &["python3", "-c", "import time; time.sleep(30)"],
    );
    assert!(!ok && text.contains("no reply within 1 s"), "{text}");
    // One row instead of 65,536, then a NaN pdf.
    let one_row = "import sys, json; sys.stdin.buffer.readline(); \
        sys.stdout.buffer.write(b'{\"count\": 1, \"cols\": 5}\\n' + bytes(40)); sys.stdout.flush()";
    let (ok, text) = check(&[], &["python3", "-c", one_row]);
    assert!(
        !ok && text.contains("expected a reply of 65536 rows x 5 columns"),
        "{text}"
    );
    let nan = "import sys, os, numpy as np; sys.path.insert(0, os.path.join(sys.argv[1], \
        'helpers', 'python')); from directlab_sampler import serve; \
        serve(lambda u: np.array([0*u[0], 0*u[0], 1+0*u[0]]), lambda d: np.full(d.shape[1], np.nan))";
    let root = repo("");
    let (ok, text) = check(&[], &["python3", "-c", nan, root.to_str().unwrap()]);
    assert!(!ok && text.contains("non-finite value NaN"), "{text}");
    assert!(text.contains("sample phase, batch 0"), "{text}");
}
