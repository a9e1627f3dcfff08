//! `directlab check-sampler`: a sampler written in any language, checked by the engine of
//! directlab's own chi-square cases. The user's program is a pure function of what it is
//! sent ([`program`], over a [`pipe`]): directlab owns the random numbers, the binning, the
//! integration and the statistics ([`engine`]).

pub mod engine;
pub mod files;
pub mod npy;
mod page;
pub mod pipe;
pub mod program;
#[cfg(test)]
mod tests;

use crate::chi2cases::bsdfs::incident;
use crate::chi2cases::protocol::Target;
use crate::chi2cases::{CaseConfig, Check, Outcome};
use crate::limits::Bound;
use crate::sampling::microfacet::MicrofacetDistribution;
use files::Files;
use glam::Vec3;
use pipe::Pipe;
use program::Program;
use serde_json::{Map, Value};
use std::path::PathBuf;
use std::time::Duration;

/// `check-sampler --help`'s closing text: a start and the protocol.
pub const HELP: &str = "\
Quick start (Python with numpy; C++: helpers/cpp/directlab_sampler.hpp):
  # my_sampler.py
  import numpy as np
  from directlab_sampler import serve        # PYTHONPATH=helpers/python
  def sample(u):                             # (2, N) uniforms -> (3, N) directions
      r, phi = np.sqrt(u[0]), 2 * np.pi * u[1]
      return np.array([r * np.cos(phi), r * np.sin(phi), np.sqrt(1 - u[0])])
  def pdf(d):                                # (3, N) -> density per steradian
      return np.maximum(d[2], 0) / np.pi
  serve(sample, pdf)

  directlab check-sampler --domain hemisphere -- python3 my_sampler.py
  directlab check-sampler --case warp/cosine-hemisphere -- python3 my_sampler.py
  helpers/nori/check-warps path/to/nori/src/warp.cpp

Protocol (pipe): each request is a JSON header line
  {\"phase\", \"domain\", \"count\", \"dim\", \"point_dim\", \"params\"}
then count x dim little-endian f64; each reply is a JSON line {\"count\", \"cols\"} then
count x cols f64. Phases: \"sample\" (dim uniforms per row; reply: point (point_dim values),
pdf, valid 1/0, optional weight (1 or 3)), \"pdf\" and \"eval\" (points; reply: one value, or
3 for eval), then {\"phase\": \"end\"}. With --transport files the program is run once per
request with the path of a JSON file (the same header plus \"input\" and \"output\", .npy
files of count x dim and count x cols f64).

Every run draws its numbers from --seed; the same seed gives the same result. A program that
exits, hangs past --timeout, answers the wrong shape or a non-finite value ends the run with
an error naming the phase and batch.";

const RESOLUTION: Bound = Bound {
    max: 1024,
    why: "a 1024-row grid already has a million cells (two million on the sphere)",
};

const BATCH: Bound = Bound {
    max: 1 << 22,
    why: "a message of 4 million rows is 100 MB or more; smaller batches cost nothing",
};

/// What the sampler samples (the header's "domain"); parameters come from `--param`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum DomainKind {
    /// Points (x, y) of the unit square [0, 1)^2, density per unit area.
    Square,
    /// Points (x, y) of the unit disk, density per unit area.
    Disk,
    /// Barycentrics (x, y) on the unit right triangle, density per unit area.
    Triangle,
    /// Unit directions (x, y, z), density per steradian.
    Sphere,
    /// Unit directions with z >= 0, density per steradian.
    Hemisphere,
    /// Directions with z >= cos_theta_max (`--param cos_theta_max=C`).
    Cap,
    /// Directions through a triangle seen from the origin (`--param vertices=[[x,y,z],..]`;
    /// the built-in case's triangle by default).
    SphericalTriangle,
    /// Microfacet normals with density D(m) cos(theta_m) (`--param alpha=A`, optionally
    /// `alpha_v` and `distribution=beckmann|ggx`).
    Microfacet,
    /// A BSDF's outgoing directions for incident directions `--param wi=[x,y,z]` or a list
    /// (by default normal, oblique, grazing and from below); the program also answers eval.
    Bsdf,
}

/// See `--transport`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Transport {
    Pipe,
    Files,
    Stdio,
}

#[derive(clap::Args, Debug)]
pub struct CheckSamplerArgs {
    /// What the program samples.
    #[arg(long, value_enum, required_unless_present = "case")]
    pub domain: Option<DomainKind>,
    /// A built-in case (see `directlab chi2 --list`) whose sampler the program replaces: its
    /// domain, parameters, grid and random numbers, so the same warp gets the same p-value.
    #[arg(long, conflicts_with = "domain")]
    pub case: Option<String>,
    /// A parameter sent to the program with every request, KEY=VALUE (VALUE is JSON, or
    /// else a string); repeatable. The domain's own parameters are read from these too.
    #[arg(long = "param", value_name = "KEY=VALUE")]
    pub params: Vec<String>,
    /// Run every check at this many seeds (--seed, --seed + 1, ...) and test that the
    /// chi-square p-values are uniform (Kolmogorov-Smirnov at --alpha): the calibration of a
    /// correct sampler, which one p-value cannot show.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=1000))]
    pub seeds: u64,
    /// Uniform numbers sent per sample.
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u64).range(1..=16))]
    pub dims: u64,
    /// Samples drawn.
    #[arg(long, default_value_t = 1_000_000, value_parser = crate::limits::parser("--samples", 100, crate::limits::TEST_SAMPLES))]
    pub samples: u64,
    /// Cells along the domain's v axis (the sphere gets 2R-1 rows of cos(theta), R of phi).
    #[arg(long, default_value_t = 51, value_parser = crate::limits::parser("--resolution", 3, RESOLUTION))]
    pub resolution: u64,
    /// Seed of the uniform numbers sent (a run is reproducible from it).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Rows per message to the program.
    /// (Default: 65,536 through a pipe; the largest allowed for files, where every request
    /// starts the program anew.)
    #[arg(long, value_parser = crate::limits::parser("--batch", 1, BATCH))]
    pub batch: Option<u64>,
    /// Integrate each cell's pdf by a fixed N x N trapezoid instead of adaptively, as Mitsuba's
    /// ChiSquareTest does (its `ires`, 4 by default there): to see what a fixed rule does to
    /// a sampler whose density has sharp edges. No boundary pass, no recheck.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=64))]
    pub ires: Option<u64>,
    /// How requests reach the program: `pipe` (one process, requests on its stdin), `files`
    /// (the program is run once per request with the path of a JSON request file whose
    /// "input" and "output" are .npy files; for batch jobs and graders), or `stdio` (the
    /// program is the one that started directlab: requests on directlab's stdout, replies
    /// on its stdin, the report on stderr; the Python helper's ChiSquareTest.run()).
    #[arg(long, value_enum, default_value_t = Transport::Pipe)]
    pub transport: Transport,
    /// Seconds to wait for each reply before the program is killed.
    #[arg(long, default_value_t = 60.0)]
    pub timeout: f64,
    /// Significance level of the test.
    #[arg(long, default_value_t = 0.01)]
    pub alpha: f64,
    /// Where the heat maps, results.csv and index.html go.
    #[arg(long, default_value = "reports/check-sampler")]
    pub out: PathBuf,
    /// The sampler program and its arguments, after `--` (e.g. `-- python3 my_sampler.py`);
    /// none with `--transport stdio`.
    #[arg(last = true)]
    pub command: Vec<String>,
}

/// The command: runs the check and prints its verdict; an error when it fails.
pub fn command(a: &CheckSamplerArgs) -> Result<(), String> {
    let r = run(a)?;
    let verdict = |ok: bool| if ok { "pass" } else { "FAIL" };
    // With --transport stdio, stdout carries the protocol: the report goes to stderr.
    let mut text = String::new();
    for (o, map, _) in &r.outcomes {
        text += &format!(
            "{}: {} ({}); heat map {}\n",
            o.name,
            verdict(o.passed()),
            o.summary(),
            map.display()
        );
        for c in &o.checks {
            text += &format!("  {}: {} ({})\n", c.name, verdict(c.passed), c.detail);
        }
    }
    for (name, c) in &r.calibration {
        text += &format!("{name}: {}: {} ({})\n", c.name, verdict(c.passed), c.detail);
    }
    match a.transport {
        Transport::Stdio => eprint!("{text}"),
        _ => print!("{text}"),
    }
    let failed = r.outcomes.iter().filter(|(o, _, _)| !o.passed()).count()
        + r.calibration.iter().filter(|(_, c)| !c.passed).count();
    let total = r.outcomes.len() + r.calibration.len();
    match failed {
        0 => Ok(()),
        _ => Err(format!(
            "the sampler does not match its pdf ({failed} of {total} checks failed)"
        )),
    }
}

/// What a run found: each check with its heat map, and with `--seeds` above 1, the test
/// of each target's p-values for uniformity.
pub struct Report {
    /// Each check, its heat map and the seconds it took.
    pub outcomes: Vec<(Outcome, PathBuf, f64)>,
    pub calibration: Vec<(String, Check)>,
}

/// One check to run: what is sampled, under which name, from which seeds.
struct Job {
    target: Target,
    name: String,
    seeds: Seeds,
}

/// How a job's random stream follows from `--seed`.
enum Seeds {
    /// The seed itself.
    Plain,
    /// As the built-in case of this name draws it, so the streams are the same.
    Case(String),
    /// Each incident direction of a BSDF its own stream (k-th), so its tests are independent.
    Incident(u64),
}

impl Seeds {
    fn seed(&self, seed: u64) -> u64 {
        match self {
            Seeds::Plain => seed,
            Seeds::Case(name) => crate::chi2cases::case_seed(name, seed),
            Seeds::Incident(k) => crate::rng::mix64(seed ^ crate::rng::mix64(k + 1)),
        }
    }
}

/// Runs the checks; Ok(report) whether they passed or not, Err when the program misbehaved
/// or the arguments are wrong.
pub fn run(a: &CheckSamplerArgs) -> Result<Report, String> {
    if !(a.timeout.is_finite() && a.timeout > 0.0) {
        return Err(format!(
            "--timeout {}: expected a positive number of seconds",
            a.timeout
        ));
    }
    if !(a.alpha > 0.0 && a.alpha < 1.0) {
        return Err(format!("--alpha {}: expected a level in (0, 1)", a.alpha));
    }
    let params = parse_params(&a.params)?;
    let jobs = jobs(a, &params)?;
    let timeout = Duration::from_secs_f64(a.timeout);
    let mut program: Box<dyn Program> = match a.transport {
        Transport::Pipe => Box::new(Pipe::start(&a.command, timeout)?),
        Transport::Files => Box::new(Files::new(&a.command, a.out.join("requests"), timeout)?),
        Transport::Stdio if !a.command.is_empty() => {
            return Err(
                "--transport stdio talks to the process that started directlab: \
                        give no program after --"
                    .into(),
            )
        }
        Transport::Stdio => Box::new(Pipe::stdio(timeout)),
    };
    // The run as a whole is at --alpha: each check at the Sidak level over all of them.
    let runs = jobs.len() * a.seeds as usize;
    let alpha = crate::stats::sidak(a.alpha, runs);
    let mut outcomes = Vec::new();
    let mut calibration = Vec::new();
    for job in &jobs {
        let mut sent = job.target.params();
        if let Value::Object(m) = &mut sent {
            m.extend(params.clone());
        }
        let mut session = engine::Session {
            program: program.as_mut(),
            target: &job.target,
            params: sent,
            dims: a.dims as usize,
            batch: a.batch.unwrap_or(match a.transport {
                Transport::Pipe | Transport::Stdio => 65_536,
                Transport::Files => BATCH.max,
            }) as usize,
            integrals: None,
            ires: a.ires.map(|n| n as usize),
        };
        let mut p_values = Vec::new();
        for s in 0..a.seeds {
            let cfg = job.target.config(&CaseConfig {
                samples: a.samples,
                resolution: a.resolution as usize,
                seed: job.seeds.seed(a.seed + s),
                alpha,
                ..CaseConfig::default()
            });
            let name = match a.seeds {
                1 => job.name.clone(),
                _ => format!("{} seed {}", job.name, a.seed + s),
            };
            let start = std::time::Instant::now();
            let o = engine::check(&mut session, &cfg, &name)?;
            p_values.push(o.chi2.p_value);
            outcomes.push((o, start.elapsed().as_secs_f64()));
        }
        if a.seeds > 1 {
            let level = crate::stats::sidak(a.alpha, jobs.len());
            calibration.push((job.name.clone(), uniformity(p_values, level)));
        }
    }
    program.finish();
    std::fs::create_dir_all(&a.out).map_err(|e| format!("{}: {e}", a.out.display()))?;
    let mut out = Vec::new();
    for (k, (o, seconds)) in outcomes.into_iter().enumerate() {
        let file = match runs {
            1 => "heatmap.png".to_string(),
            _ => format!("heatmap-{k}.png"),
        };
        let path = a.out.join(file);
        o.write_heatmap(&path)?;
        out.push((o, path, seconds));
    }
    let report = Report {
        outcomes: out,
        calibration,
    };
    let program = match a.command.is_empty() {
        true => "the process that started directlab".to_string(),
        false => format!("`{}`", a.command.join(" ")),
    };
    let what = match &a.case {
        Some(case) => format!("{program} in place of {case}"),
        None => program,
    };
    let size = CaseConfig {
        samples: a.samples,
        resolution: a.resolution as usize,
        seed: a.seed,
        alpha,
        ..CaseConfig::default()
    };
    page::write(&a.out, &report, &what, &size)?;
    Ok(report)
}

/// The p-values of one target over seeds against Uniform(0, 1): KS at `alpha`.
fn uniformity(mut p: Vec<f64>, alpha: f64) -> Check {
    p.sort_by(f64::total_cmp);
    let d = crate::stats::ks_uniform(&p);
    let pv = crate::stats::ks_p_value(d, p.len());
    Check {
        name: "uniform p-values",
        passed: pv >= alpha,
        detail: format!(
            "{} seeds: KS distance {d:.3} from uniform, p = {pv:.3} vs {alpha:.2e}; smallest \
             p-value {:.2e}",
            p.len(),
            p[0]
        ),
    }
}

/// `--param KEY=VALUE` as a JSON object (VALUE parsed as JSON, else kept as a string).
fn parse_params(raw: &[String]) -> Result<Map<String, Value>, String> {
    let mut m = Map::new();
    for p in raw {
        let (k, v) = p
            .split_once('=')
            .filter(|(k, _)| !k.is_empty())
            .ok_or_else(|| format!("--param '{p}': expected KEY=VALUE"))?;
        let v = serde_json::from_str(v).unwrap_or_else(|_| Value::String(v.to_string()));
        m.insert(k.to_string(), v);
    }
    Ok(m)
}

fn jobs(a: &CheckSamplerArgs, params: &Map<String, Value>) -> Result<Vec<Job>, String> {
    if let Some(name) = &a.case {
        let cases = crate::chi2cases::all_cases();
        let case = cases.iter().find(|c| &c.name == name).ok_or_else(|| {
            format!("--case {name}: no such case (`directlab chi2 --list` lists them)")
        })?;
        let target = case.external.clone().ok_or_else(|| {
            let with: Vec<&str> = cases
                .iter()
                .filter(|c| c.external.is_some())
                .map(|c| c.name.as_str())
                .collect();
            format!(
                "--case {name}: this case has no protocol form; these do: {}",
                with.join(", ")
            )
        })?;
        return Ok(vec![Job {
            target,
            name: format!("check-sampler/{name}"),
            seeds: Seeds::Case(name.clone()),
        }]);
    }
    let kind = a.domain.expect("clap requires --domain or --case");
    let one = |target: Target| {
        vec![Job {
            name: format!("check-sampler/{}", target.name()),
            target,
            seeds: Seeds::Plain,
        }]
    };
    let num = |key: &str| -> Result<Option<f32>, String> {
        params
            .get(key)
            .map(|v| {
                v.as_f64()
                    .filter(|x| x.is_finite())
                    .map(|x| x as f32)
                    .ok_or_else(|| format!("--param {key}={v}: expected a number"))
            })
            .transpose()
    };
    let need = |key: &str| {
        num(key)?.ok_or_else(|| {
            let d = clap::ValueEnum::to_possible_value(&kind).expect("every kind has a name");
            format!("--domain {} needs --param {key}=VALUE", d.get_name())
        })
    };
    Ok(match kind {
        DomainKind::Square => one(Target::Square),
        DomainKind::Disk => one(Target::Disk),
        DomainKind::Triangle => one(Target::Triangle),
        DomainKind::Sphere => one(Target::Sphere),
        DomainKind::Hemisphere => one(Target::Hemisphere),
        DomainKind::Cap => {
            let c = need("cos_theta_max")?;
            if !(-1.0..1.0).contains(&c) {
                return Err(format!(
                    "--param cos_theta_max={c}: expected a value in [-1, 1)"
                ));
            }
            one(Target::Cap { cos_theta_max: c })
        }
        DomainKind::SphericalTriangle => {
            let vertices = match params.get("vertices") {
                None => crate::chi2cases::warps::spherical_triangle_vertices(),
                Some(v) => vertices(v)?,
            };
            one(Target::SphericalTriangle { vertices })
        }
        DomainKind::Microfacet => {
            let au = need("alpha")?;
            let av = num("alpha_v")?.unwrap_or(au);
            if !(au > 0.0 && av > 0.0) {
                return Err(format!(
                    "--param alpha: expected a positive roughness, got {au}, {av}"
                ));
            }
            let distribution = match params.get("distribution").and_then(Value::as_str) {
                None | Some("beckmann") => MicrofacetDistribution::Beckmann,
                Some("ggx") => MicrofacetDistribution::Ggx,
                Some(d) => {
                    return Err(format!(
                        "--param distribution={d}: expected beckmann or ggx"
                    ))
                }
            };
            one(Target::Normals {
                distribution,
                alpha: (au, av),
            })
        }
        DomainKind::Bsdf => {
            let wis: Vec<(String, Vec3)> = match params.get("wi") {
                None => incident()
                    .into_iter()
                    .map(|(n, w)| (n.to_string(), w))
                    .collect(),
                Some(v) => directions(v, "wi")?
                    .into_iter()
                    .map(|w| (format!("({:.3}, {:.3}, {:.3})", w.x, w.y, w.z), w))
                    .collect(),
            };
            wis.into_iter()
                .zip(0..)
                .map(|((label, wi), k)| Job {
                    name: format!("check-sampler/bsdf/wi={label}"),
                    target: Target::Bsdf { wi },
                    seeds: Seeds::Incident(k),
                })
                .collect()
        }
    })
}

/// A JSON direction [x, y, z] or a list of them, normalised.
fn directions(v: &Value, key: &str) -> Result<Vec<Vec3>, String> {
    let bad = || format!("--param {key}={v}: expected [x, y, z] or a list of them");
    let one = |v: &Value| vec3(v).filter(|d| d.length() > 0.0).map(Vec3::normalize);
    match one(v) {
        Some(d) => Ok(vec![d]),
        None => v
            .as_array()
            .filter(|a| !a.is_empty())
            .ok_or_else(bad)?
            .iter()
            .map(|d| one(d).ok_or_else(bad))
            .collect(),
    }
}

fn vertices(v: &Value) -> Result<[Vec3; 3], String> {
    let bad = || format!("--param vertices={v}: expected three points [[x,y,z],[x,y,z],[x,y,z]]");
    let a = v.as_array().filter(|a| a.len() == 3).ok_or_else(bad)?;
    let [a, b, c] = [vec3(&a[0]), vec3(&a[1]), vec3(&a[2])];
    Ok([a.ok_or_else(bad)?, b.ok_or_else(bad)?, c.ok_or_else(bad)?])
}

/// A finite JSON point [x, y, z].
fn vec3(v: &Value) -> Option<Vec3> {
    let a = v.as_array().filter(|a| a.len() == 3)?;
    let x: Vec<f32> = a
        .iter()
        .map(|x| x.as_f64().map(|x| x as f32))
        .collect::<Option<_>>()?;
    Some(Vec3::new(x[0], x[1], x[2])).filter(|p| p.is_finite())
}
