//! The files transport of `check-sampler`, for batch jobs, clusters and graders: each request
//! is a JSON file (the pipe's header plus "input" and "output") and a `.npy` of its rows;
//! the program is run once per request with the JSON file's path as its last argument and
//! writes its reply rows to "output" (a `.npy`). Nothing else changes: the same messages,
//! the same checks of each reply.

use super::npy;
use super::program::{validate, Program};
use serde_json::{json, Value};
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

pub struct Files {
    command: Vec<String>,
    dir: PathBuf,
    timeout: Duration,
    next: usize,
}

impl Files {
    /// Requests go into `dir` (created); `command` is run once per request.
    pub fn new(command: &[String], dir: PathBuf, timeout: Duration) -> Result<Files, String> {
        if command.is_empty() {
            return Err("check-sampler: no program to run (give it after --)".into());
        }
        std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        let dir = dir
            .canonicalize()
            .map_err(|e| format!("{}: {e}", dir.display()))?;
        Ok(Files {
            command: command.to_vec(),
            dir,
            timeout,
            next: 0,
        })
    }

    /// Runs the program on `request` within the timeout.
    fn run(&self, request: &std::path::Path) -> Result<(), String> {
        let program = self.command.join(" ");
        let mut child = Command::new(&self.command[0])
            .args(&self.command[1..])
            .arg(request)
            .stdin(Stdio::null())
            .spawn()
            .map_err(|e| format!("cannot start '{}': {e}", self.command[0]))?;
        let since = Instant::now();
        loop {
            match child.try_wait() {
                Ok(Some(s)) if s.success() => return Ok(()),
                Ok(Some(s)) => return Err(format!("'{program}' exited: {s}")),
                Ok(None) if since.elapsed() > self.timeout => {
                    let _ = child.kill();
                    let _ = child.wait();
                    return Err(format!(
                        "'{program}' did not finish within {} s (killed)",
                        self.timeout.as_secs_f64()
                    ));
                }
                Ok(None) => std::thread::sleep(Duration::from_millis(2)),
                Err(e) => return Err(format!("waiting for '{program}': {e}")),
            }
        }
    }
}

impl Program for Files {
    fn call(
        &mut self,
        header: Value,
        payload: &[f64],
        rows: usize,
        cols: &[usize],
        what: &str,
    ) -> Result<(Vec<f64>, usize), String> {
        let fail = |why: String| format!("check-sampler: {what}: {why}");
        let k = self.next;
        self.next += 1;
        let input = self.dir.join(format!("request-{k}.npy"));
        let output = self.dir.join(format!("reply-{k}.npy"));
        let request = self.dir.join(format!("request-{k}.json"));
        let _ = std::fs::remove_file(&output);
        let dim = header["dim"].as_u64().unwrap_or(1) as usize;
        npy::write(&input, payload, rows, dim).map_err(fail)?;
        let mut head = header;
        head["input"] = json!(input.to_string_lossy());
        head["output"] = json!(output.to_string_lossy());
        let text = serde_json::to_string_pretty(&head).expect("json");
        std::fs::write(&request, text).map_err(|e| fail(format!("{}: {e}", request.display())))?;
        self.run(&request).map_err(fail)?;
        if !output.exists() {
            return Err(fail(format!(
                "the program finished without writing {}",
                output.display()
            )));
        }
        let (values, n, c) = npy::read(&output).map_err(fail)?;
        let c = validate(&json!({"count": n, "cols": c}), &values, rows, cols).map_err(fail)?;
        for f in [&input, &output, &request] {
            let _ = std::fs::remove_file(f);
        }
        Ok((values, c))
    }

    fn finish(&mut self) {}
}
