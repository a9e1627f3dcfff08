//! The README's and the experiment guide's lists of plug-ins are the registries': every
//! option's list of values in the README's render table, the BSDFs it names and the metrics
//! `experiments/README.md` lists equal what is registered, so a plug-in added or renamed
//! without its documentation fails here.

use crate::common;

use common::repo;
use directlab::emitter::RULES;
use directlab::named::Named;

fn readme() -> String {
    std::fs::read_to_string(repo("README.md")).unwrap()
}

/// The values the README's render-options table gives for `option` (`--x a\|b\|c`).
fn listed(readme: &str, option: &str) -> Vec<String> {
    let at = readme
        .find(&format!("`{option} "))
        .unwrap_or_else(|| panic!("README has no row for {option}"));
    let rest = &readme[at + option.len() + 2..];
    let end = rest.find('`').unwrap();
    rest[..end].split("\\|").map(str::to_string).collect()
}

fn names<T: Named>() -> Vec<String> {
    T::CHOICES.iter().map(|c| c.name.to_string()).collect()
}

#[test]
fn render_options_list_the_registered_values() {
    use directlab::emitter::LightSampling;
    use directlab::sampler::{DimAlloc, SamplerKind};
    use directlab::scene::desc::{Heuristic, StrategyKind};
    let r = readme();
    assert_eq!(listed(&r, "--strategy"), names::<StrategyKind>());
    assert_eq!(listed(&r, "--heuristic"), names::<Heuristic>());
    assert_eq!(listed(&r, "--light-sampling"), names::<LightSampling>());
    assert_eq!(listed(&r, "--sampler"), names::<SamplerKind>());
    assert_eq!(listed(&r, "--dims"), names::<DimAlloc>());
    let mut rules: Vec<String> = RULES.iter().map(|r| r.name.to_string()).collect();
    rules.push("ris:M".into());
    assert_eq!(listed(&r, "--emitter-selection"), rules);
}

#[test]
fn every_registered_bsdf_is_named_in_the_readme() {
    let r = readme();
    let scenes = &r[r.find("- **Scenes**").unwrap()..];
    let scenes = &scenes[..scenes.find("\n- **").unwrap()];
    for name in directlab::bsdf::REGISTERED {
        assert!(
            scenes.contains(&format!("`{name}`")),
            "README does not name BSDF {name}"
        );
    }
}

#[test]
fn the_experiment_guide_lists_every_registered_metric() {
    let guide = std::fs::read_to_string(repo("experiments/README.md")).unwrap();
    let line = guide
        .lines()
        .find(|l| l.starts_with("report = ["))
        .expect("experiments/README.md shows `report = [...]`");
    let want: Vec<String> = directlab::experiment::metric::EXTRA_METRICS
        .iter()
        .map(|d| format!("\"{}\"", d.slug))
        .collect();
    assert_eq!(line, format!("report = [{}]", want.join(", ")));
}

/// `render --help` lists every registered value with its help, and a wrong value is refused
/// with the valid names.
#[test]
fn the_command_line_lists_and_checks_the_registered_values() {
    use directlab::sampler::SamplerKind;
    let help = common::run(common::directlab().args(["render", "--help"]));
    let help = String::from_utf8_lossy(&help.stdout).to_string();
    for r in RULES {
        assert!(
            help.contains(&format!("- {}:", r.name)) && help.contains(r.help),
            "{help}"
        );
    }
    for c in SamplerKind::CHOICES {
        assert!(
            help.contains(&format!("- {}:", c.name)) && help.contains(c.help),
            "{help}"
        );
    }
    for (option, bad, says) in [
        (
            "--emitter-selection",
            "tree",
            "expected uniform, power, exhaustive, bvh or ris:M",
        ),
        (
            "--sampler",
            "halton",
            "possible values: independent, stratified",
        ),
        (
            "--strategy",
            "path",
            "possible values: bsdf, light, mis, mis-onesample",
        ),
    ] {
        let o =
            common::run(common::directlab().args(["render", "scenes/cbox/cbox.xml", option, bad]));
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{option} {bad}: {err}");
        assert!(err.contains(says), "{option} {bad}: {err}");
    }
}

/// The example at the top of experiments/README.md runs as written (its scene path taken
/// from the experiments folder), leaves nothing out and checks both strategies' means.
#[test]
fn the_first_example_of_the_experiment_guide_runs() {
    let guide = std::fs::read_to_string(repo("experiments/README.md")).unwrap();
    let start = guide.find("```toml\n").expect("a TOML example") + 8;
    let toml = &guide[start..start + guide[start..].find("```").unwrap()];
    assert!(toml.lines().count() <= 14, "a short example: {toml}");
    let out = crate::common::scratch("guide-example");
    let exp = out.join("example.toml");
    let scene = repo("scenes/cbox/cbox.xml");
    std::fs::write(
        &exp,
        toml.replace("../scenes/cbox/cbox.xml", scene.to_str().unwrap()),
    )
    .unwrap();
    let o = crate::common::run(
        crate::common::directlab()
            .args(["run", exp.to_str().unwrap(), "--out"])
            .arg(&out),
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(!err.contains("leaving out"), "{err}");
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(stdout.matches("same expectation, ").count(), 2, "{stdout}");
    assert!(out.join("example/index.html").is_file());
    std::fs::remove_dir_all(&out).unwrap();
}
