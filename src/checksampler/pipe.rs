//! The pipe transport of `check-sampler`: the user's program runs as a subprocess; every
//! request is one JSON header line on its stdin followed by `count x dim` little-endian f64,
//! every reply one JSON header line (`{"count": n, "cols": c}`) on its stdout followed by
//! `count x cols` f64. A reply that does not come within the timeout, a program that exits,
//! a wrong count or a non-finite value is an error naming the phase and the batch.
//!
//! [`Pipe::stdio`] turns it around for a program that runs directlab itself (the Python
//! helper's `ChiSquareTest.run()`): requests go out on directlab's stdout, replies come in
//! on its stdin.

use super::program::{validate, Program};
use serde_json::{json, Value};
use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{channel, Receiver, RecvTimeoutError};
use std::time::Duration;

/// A running sampler program.
pub struct Pipe {
    /// None when the program is the process that started directlab.
    child: Option<Child>,
    stdin: Option<Box<dyn Write + Send>>,
    replies: Receiver<Result<(Value, Vec<f64>), String>>,
    timeout: Duration,
    program: String,
}

impl Pipe {
    /// Starts `command` (program and arguments); its stderr passes through to ours.
    pub fn start(command: &[String], timeout: Duration) -> Result<Pipe, String> {
        let (prog, args) = command
            .split_first()
            .ok_or("check-sampler: no program to run (give it after --)")?;
        // A program that exits early closes its input: writing to it must be an error we
        // report, not the SIGPIPE that main() restores for `| head`.
        // SAFETY: setting a signal's disposition to ignore has no preconditions.
        unsafe {
            libc::signal(libc::SIGPIPE, libc::SIG_IGN);
        }
        let mut child = Command::new(prog)
            .args(args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .map_err(|e| format!("check-sampler: cannot start '{prog}': {e}"))?;
        let stdout = child.stdout.take().expect("piped");
        let stdin = child.stdin.take().expect("piped");
        Ok(Pipe {
            stdin: Some(Box::new(stdin)),
            child: Some(child),
            replies: listen(stdout),
            timeout,
            program: command.join(" "),
        })
    }

    /// The program that started directlab, over directlab's own stdin and stdout.
    pub fn stdio(timeout: Duration) -> Pipe {
        Pipe {
            stdin: Some(Box::new(std::io::stdout())),
            child: None,
            replies: listen(std::io::stdin()),
            timeout,
            program: "the parent process (--transport stdio)".into(),
        }
    }
}

/// Reads replies from `from` on a thread of their own, so a silent program can time out.
fn listen(from: impl Read + Send + 'static) -> Receiver<Result<(Value, Vec<f64>), String>> {
    let (tx, replies) = channel();
    std::thread::spawn(move || {
        let mut r = BufReader::new(from);
        loop {
            let msg = read_message(&mut r);
            let stop = msg.is_err();
            if tx.send(msg).is_err() || stop {
                break;
            }
        }
    });
    replies
}

impl Program for Pipe {
    fn call(
        &mut self,
        header: Value,
        payload: &[f64],
        rows: usize,
        cols: &[usize],
        what: &str,
    ) -> Result<(Vec<f64>, usize), String> {
        let fail = |why: String| format!("check-sampler: {what}: {why}");
        let mut bytes = serde_json::to_vec(&header).expect("json");
        bytes.push(b'\n');
        for x in payload {
            bytes.extend_from_slice(&x.to_le_bytes());
        }
        // Written from another thread: a program that stops reading must not hang us.
        let mut stdin = self
            .stdin
            .take()
            .ok_or_else(|| fail("the program's input is closed".into()))?;
        let writer = std::thread::spawn(move || {
            let r = stdin.write_all(&bytes).and_then(|_| stdin.flush());
            (stdin, r)
        });
        let reply = match self.replies.recv_timeout(self.timeout) {
            Ok(r) => r,
            Err(RecvTimeoutError::Timeout) => {
                if let Some(c) = &mut self.child {
                    let _ = c.kill();
                }
                return Err(fail(format!(
                    "no reply within {} s from '{}' (killed)",
                    self.timeout.as_secs_f64(),
                    self.program
                )));
            }
            Err(RecvTimeoutError::Disconnected) => Err("the program's output ended".into()),
        };
        // A reply means the request was read; the writer returns a moment later (unless the
        // program answered without reading, which the next request will find closed).
        let since = std::time::Instant::now();
        while !writer.is_finished() && since.elapsed() < Duration::from_secs(1) {
            std::thread::sleep(Duration::from_millis(1));
        }
        if writer.is_finished() {
            if let Ok((stdin, Ok(()))) = writer.join() {
                self.stdin = Some(stdin);
            }
        }
        let (head, values) = reply.map_err(|e| {
            // The program's exit status, once it has one (its output ends just before).
            let mut status = None;
            for _ in 0..200 {
                status = self
                    .child
                    .as_mut()
                    .and_then(|c| c.try_wait().ok().flatten());
                if status.is_some() {
                    break;
                }
                std::thread::sleep(Duration::from_millis(5));
            }
            fail(match status {
                Some(s) => format!("{e} ('{}' exited: {s})", self.program),
                None => e,
            })
        })?;
        let c = validate(&head, &values, rows, cols).map_err(fail)?;
        Ok((values, c))
    }

    fn finish(&mut self) {
        if let Some(mut s) = self.stdin.take() {
            let _ = s.write_all(format!("{}\n", json!({"phase": "end"})).as_bytes());
            let _ = s.flush();
        }
        if let Some(c) = &mut self.child {
            let _ = c.wait();
        }
    }
}

impl Drop for Pipe {
    fn drop(&mut self) {
        let Some(c) = &mut self.child else { return };
        if c.try_wait().ok().flatten().is_none() && self.stdin.is_none() {
            let _ = c.kill();
        }
    }
}

/// One reply: its header line, then `count x cols` little-endian f64.
fn read_message(r: &mut impl BufRead) -> Result<(Value, Vec<f64>), String> {
    let mut line = String::new();
    match r.read_line(&mut line) {
        Ok(0) => return Err("the program's output ended".into()),
        Err(e) => return Err(format!("reading the program's output: {e}")),
        Ok(_) => {}
    }
    let head: Value = serde_json::from_str(line.trim()).map_err(|e| {
        let shown: String = line.chars().take(120).collect();
        format!("expected a JSON header line, got '{}' ({e})", shown.trim())
    })?;
    let n = head["count"].as_u64().unwrap_or(0) as usize;
    let cols = head["cols"].as_u64().unwrap_or(0) as usize;
    let len = n
        .checked_mul(cols)
        .filter(|&l| l <= 1 << 28)
        .ok_or_else(|| format!("reply header {head} announces too many values"))?;
    let mut bytes = vec![0u8; len * 8];
    r.read_exact(&mut bytes)
        .map_err(|e| format!("reply header {head}, but its {len} values did not follow: {e}"))?;
    let values = bytes
        .chunks_exact(8)
        .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
        .collect();
    Ok((head, values))
}
