//! Evaluators: who executes a task's checked trajectory and says what it
//! achieved. A program of the lab's (its robot, its simulator, its sensor)
//! talking JSON lines, or the operator at the terminal.
//!
//! The JSON-lines contract, [`PROTOCOL`] 2 (the book's evaluator
//! reference, docs/src/reference/evaluator.md): primo starts the program
//! once, in the task file's directory; for each roll-out it writes one
//! line `{"protocol": 2, "rollout": N, "csv": "PATH"}` to the program's
//! standard input, PATH a CSV file `t,<the demonstrations' columns>` that
//! passed the task's limits; the program answers one line on its standard
//! output that echoes `"rollout": N` and holds `"measured": [..]` (the
//! query achieved), `"reward": R` (R ≥ 0), both, or `"failed": "why"`.
//! Its standard error is the user's (it shows on the terminal). A program
//! that exits, says nothing within the timeout, answers for another
//! roll-out (it fell out of step) or answers anything else ends the run
//! with an error naming the roll-out; the run log keeps every roll-out
//! before it.
//!
//! The program runs in a process group of its own: the terminal's Ctrl-C
//! reaches primo alone, which lets the roll-out in progress finish (or ends
//! the program's whole group at once: [`end_all`]). When a run ends, its
//! program's group is ended too, whatever the program started.

use std::io::{BufRead, BufReader, Write};
use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::Mutex;
use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::time::{Duration, Instant};

use serde::Deserialize;

use crate::Error;

/// The evaluator protocol's version. 2: every answer echoes its
/// request's roll-out number.
pub const PROTOCOL: u32 = 2;

/// What an evaluator said of one roll-out.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Answer {
    /// The query achieved.
    pub measured: Option<Vec<f64>>,
    /// The reward, ≥ 0.
    pub reward: Option<f64>,
    /// The roll-out failed: why.
    pub failed: Option<String>,
}

/// Executes a checked trajectory and measures it.
pub trait Evaluator {
    /// Roll-out `rollout`: its trajectory is the CSV file `csv`.
    fn evaluate(&mut self, rollout: u32, csv: &Path) -> Result<Answer, Error>;
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Line {
    rollout: Option<u32>,
    measured: Option<Vec<f64>>,
    reward: Option<f64>,
    failed: Option<String>,
}

/// Reads one answer to roll-out `rollout`: a JSON object with `rollout`
/// (echoed) and `measured` (`dim` finite numbers), `reward` (a finite
/// number ≥ 0), both, or `failed` (a text) alone.
pub fn parse_answer(line: &str, dim: usize, rollout: u32) -> Result<Answer, String> {
    let l: Line = serde_json::from_str(line.trim()).map_err(|e| {
        format!(
            "{e}; expected {{\"rollout\": {rollout}, \"measured\": [..]}}, \
             {{\"rollout\": {rollout}, \"reward\": R}}, both, or {{\"rollout\": {rollout}, \
             \"failed\": \"why\"}}"
        )
    })?;
    match l.rollout {
        Some(n) if n == rollout => {}
        Some(n) => {
            return Err(format!(
                "the answer is for roll-out {n}, not {rollout}: the evaluator is out of step \
                 (one line per request)"
            ));
        }
        None => {
            return Err(format!(
                "the answer names no roll-out: echo the request's \"rollout\": {rollout} \
                 (evaluator protocol {PROTOCOL})"
            ));
        }
    }
    check(
        Answer {
            measured: l.measured,
            reward: l.reward,
            failed: l.failed,
        },
        dim,
    )
}

/// The rules every answer keeps, however it came.
fn check(a: Answer, dim: usize) -> Result<Answer, String> {
    if a.failed.is_some() {
        if a.measured.is_some() || a.reward.is_some() {
            return Err("a failed roll-out has no `measured` or `reward`".into());
        }
        return Ok(a);
    }
    if a.measured.is_none() && a.reward.is_none() {
        return Err("give `measured`, `reward`, or `failed`".into());
    }
    if let Some(m) = &a.measured {
        if m.len() != dim {
            return Err(format!(
                "`measured` has {} values; the task's query has {dim}",
                m.len()
            ));
        }
        // The learners take them as f32: finite there too, or a measured
        // 1e300 would end the run in the learner instead of being refused.
        if m.iter().any(|v| !(*v as f32).is_finite()) {
            return Err("`measured` holds a value that is not a finite number".into());
        }
    }
    if let Some(r) = a.reward
        && !((r as f32).is_finite() && r >= 0.0)
    {
        return Err(format!("`reward` {r}: must be a finite number >= 0"));
    }
    Ok(a)
}

/// An evaluator program talking JSON lines.
pub struct Program {
    what: String,
    child: Child,
    stdin: Option<ChildStdin>,
    lines: Receiver<std::io::Result<String>>,
    timeout: Duration,
    dim: usize,
}

impl Program {
    /// Starts `argv` in `dir`; answers must come within `timeout` seconds
    /// and carry `dim`-value measurements.
    pub fn start(argv: &[String], dir: &Path, timeout: f64, dim: usize) -> Result<Program, Error> {
        let what = format!("the evaluator `{}`", argv.join(" "));
        let (program, args) = argv
            .split_first()
            .ok_or_else(|| Error::Invalid("the evaluator command is empty".into()))?;
        let mut child = Command::new(program)
            .args(args)
            .current_dir(dir)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .process_group(0)
            .spawn()
            .map_err(|e| {
                Error::Instrument(format!("{what} (in {}) cannot start: {e}", dir.display()))
            })?;
        register(child.id(), true);
        let stdout = child
            .stdout
            .take()
            .ok_or_else(|| Error::Instrument(format!("{what}: no standard output")))?;
        let (tx, lines) = channel();
        // A reader thread: a blocking read cannot time out, a channel can.
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines() {
                let end = line.is_err();
                if tx.send(line).is_err() || end {
                    break;
                }
            }
        });
        Ok(Program {
            what,
            stdin: child.stdin.take(),
            child,
            lines,
            timeout: Duration::from_secs_f64(timeout),
            dim,
        })
    }

    /// How the program ended, if it has.
    fn exit(&mut self) -> String {
        std::thread::sleep(Duration::from_millis(50));
        match self.child.try_wait() {
            Ok(Some(status)) => format!("it exited ({status})"),
            _ => "it closed its standard output".into(),
        }
    }
}

impl Evaluator for Program {
    fn evaluate(&mut self, rollout: u32, csv: &Path) -> Result<Answer, Error> {
        let request = serde_json::json!({"protocol": PROTOCOL, "rollout": rollout, "csv": csv});
        let sent = self
            .stdin
            .as_mut()
            .map(|s| writeln!(s, "{request}").and_then(|()| s.flush()));
        if !matches!(sent, Some(Ok(()))) {
            let how = self.exit();
            return Err(Error::Instrument(format!(
                "{} cannot be sent roll-out {rollout}: {how}",
                self.what
            )));
        }
        let line = match self.lines.recv_timeout(self.timeout) {
            Ok(Ok(line)) => line,
            Ok(Err(e)) => {
                return Err(Error::Instrument(format!(
                    "{}: reading its answer to roll-out {rollout}: {e}",
                    self.what
                )));
            }
            Err(RecvTimeoutError::Disconnected) => {
                let how = self.exit();
                return Err(Error::Instrument(format!(
                    "{} did not answer roll-out {rollout}: {how}",
                    self.what
                )));
            }
            Err(RecvTimeoutError::Timeout) => {
                return Err(Error::Instrument(format!(
                    "{} did not answer roll-out {rollout} within {} s ([evaluate] timeout)",
                    self.what,
                    self.timeout.as_secs_f64()
                )));
            }
        };
        parse_answer(&line, self.dim, rollout).map_err(|why| {
            Error::Instrument(format!(
                "{} answered roll-out {rollout} with `{}`: {why}",
                self.what,
                line.chars().take(200).collect::<String>()
            ))
        })
    }
}

impl Drop for Program {
    fn drop(&mut self) {
        // End of input tells a well-behaved program to finish; one that
        // does not is asked to (SIGTERM), then stopped, with everything it
        // started.
        drop(self.stdin.take());
        let group = self.child.id();
        if !self.exits_within(Duration::from_millis(200)) {
            signal_group(group, libc::SIGTERM);
            if !self.exits_within(Duration::from_millis(500)) {
                signal_group(group, libc::SIGKILL);
                let _ = self.child.wait();
            }
        }
        // What the program left running in its group goes with it.
        signal_group(group, libc::SIGKILL);
        register(group, false);
    }
}

impl Program {
    /// Whether the program exits within `wait`.
    fn exits_within(&mut self, wait: Duration) -> bool {
        let until = Instant::now() + wait;
        loop {
            if matches!(self.child.try_wait(), Ok(Some(_))) {
                return true;
            }
            if Instant::now() >= until {
                return false;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }
}

/// The process groups of the evaluators running now.
static GROUPS: Mutex<Vec<u32>> = Mutex::new(Vec::new());

/// Adds (`running`) or removes an evaluator's process group.
fn register(group: u32, running: bool) {
    let mut groups = GROUPS.lock().unwrap_or_else(|e| e.into_inner());
    groups.retain(|g| *g != group);
    if running {
        groups.push(group);
    }
}

/// Sends `signal` to process group `group` (a group that is gone is no
/// error: there is nothing left to end).
fn signal_group(group: u32, signal: libc::c_int) {
    if let Ok(group) = libc::pid_t::try_from(group) {
        // SAFETY: kill(2) with a negative pid signals a process group; it
        // touches no memory of ours.
        unsafe {
            libc::kill(-group, signal);
        }
    }
}

/// Ends every running evaluator's process group at once (SIGKILL): for a
/// process about to exit without running destructors, as at a second
/// Ctrl-C.
pub fn end_all() {
    let groups = GROUPS.lock().unwrap_or_else(|e| e.into_inner());
    for group in groups.iter() {
        signal_group(*group, libc::SIGKILL);
    }
}

/// The person at the cell, asked at the terminal.
pub trait Prompt {
    /// Shows `question` and returns the line typed (`None` at the end of
    /// input).
    fn ask(&mut self, question: &str) -> Result<Option<String>, Error>;
}

/// The operator as the evaluator: told where each trajectory is, asked
/// what it achieved; a bad answer is asked again with the reason.
pub struct Operator {
    prompt: Box<dyn Prompt>,
    dim: usize,
    /// A reward alone will not do: error learning needs the measurement.
    measured: bool,
}

impl Operator {
    /// Asks through `prompt` for `dim`-value measurements, which error
    /// learning (`measured`) needs; PoWER takes a reward instead.
    pub fn new(prompt: Box<dyn Prompt>, dim: usize, measured: bool) -> Operator {
        Operator {
            prompt,
            dim,
            measured,
        }
    }
}

/// Reads what the operator typed: the measured query's values (separated
/// by spaces or commas), `reward R`, both (`0.41 0.2 reward 0.8`), or
/// `failed WHY`.
pub fn parse_typed(line: &str, dim: usize) -> Result<Answer, String> {
    let line = line.trim();
    if let Some(why) = line.strip_prefix("failed") {
        let why = why.trim();
        return Ok(Answer {
            failed: Some(
                if why.is_empty() {
                    "the operator said so"
                } else {
                    why
                }
                .into(),
            ),
            ..Answer::default()
        });
    }
    let (measured, reward) = match line.split_once("reward") {
        Some((m, r)) => (m, Some(r)),
        None => (line, None),
    };
    let number = |s: &str| {
        s.parse::<f64>()
            .map_err(|_| format!("`{s}` is not a number"))
    };
    let values: Vec<f64> = measured
        .split([' ', ',', '\t'])
        .filter(|s| !s.is_empty())
        .map(number)
        .collect::<Result<_, _>>()?;
    let reward = reward.map(|r| number(r.trim())).transpose()?;
    check(
        Answer {
            measured: (!values.is_empty()).then_some(values),
            reward,
            failed: None,
        },
        dim,
    )
}

impl Evaluator for Operator {
    fn evaluate(&mut self, rollout: u32, csv: &Path) -> Result<Answer, Error> {
        let values = format!(
            "the measured query ({} value{})",
            self.dim,
            if self.dim == 1 { "" } else { "s" }
        );
        let mut question = match self.measured {
            true => format!(
                "roll-out {rollout}: execute {} and enter {values} or `failed WHY`: ",
                csv.display()
            ),
            false => format!(
                "roll-out {rollout}: execute {} and enter {values}, `reward R`, or `failed WHY`: ",
                csv.display()
            ),
        };
        loop {
            let Some(line) = self.prompt.ask(&question)? else {
                return Err(Error::Instrument(format!(
                    "the operator's input ended before roll-out {rollout} was measured"
                )));
            };
            question = match parse_typed(&line, self.dim) {
                Ok(a) if self.measured && a.measured.is_none() && a.failed.is_none() => {
                    format!("error learning needs {values}, not a reward alone; again: ")
                }
                Ok(answer) => return Ok(answer),
                Err(why) => format!("{why}; again: "),
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn answers_are_read_strictly() {
        let a = parse_answer(r#"{"rollout": 4, "measured": [1.5, 0.25]}"#, 2, 4).unwrap();
        assert_eq!(a.measured, Some(vec![1.5, 0.25]));
        let a = parse_answer(r#"{"reward": 0.7, "measured": [2], "rollout": 1}"#, 1, 1).unwrap();
        assert_eq!((a.reward, a.measured), (Some(0.7), Some(vec![2.0])));
        assert!(parse_answer(r#"{"rollout": 1, "failed": "ball hit the wall"}"#, 1, 1).is_ok());
        for (bad, why) in [
            ("", "EOF"),
            ("garbage", "expected"),
            (r#"{"rollout": 3, "measured": [1]}"#, "has 1 values"),
            (r#"{"rollout": 3, "reward": -1}"#, ">= 0"),
            (
                r#"{"rollout": 3, "measured": [1, 2], "extra": 1}"#,
                "unknown field",
            ),
            (r#"{"rollout": 3}"#, "give `measured`"),
            (
                r#"{"rollout": 3, "failed": "x", "reward": 1}"#,
                "no `measured`",
            ),
            (r#"{"measured": [1, 2]}"#, "names no roll-out"),
            (
                r#"{"rollout": 2, "measured": [1, 2]}"#,
                "for roll-out 2, not 3",
            ),
        ] {
            let e = parse_answer(bad, 2, 3).unwrap_err();
            assert!(e.contains(why), "{bad}: {e}");
        }
    }

    #[test]
    fn the_operator_types_numbers() {
        assert_eq!(
            parse_typed(" 1.5, 0.2 ", 2).unwrap().measured,
            Some(vec![1.5, 0.2])
        );
        let a = parse_typed("1.5 reward 0.8", 1).unwrap();
        assert_eq!((a.measured, a.reward), (Some(vec![1.5]), Some(0.8)));
        assert_eq!(parse_typed("reward 0.8", 1).unwrap().reward, Some(0.8));
        assert!(parse_typed("failed spilled", 1).unwrap().failed.is_some());
        assert!(
            parse_typed("1.5 x", 1)
                .unwrap_err()
                .contains("`x` is not a number")
        );
        assert!(parse_typed("1 2", 1).unwrap_err().contains("has 2 values"));
        assert!(parse_typed("", 1).is_err());
        // Beyond f32, as the learners take them: asked again.
        assert!(
            parse_typed("1e300", 1)
                .unwrap_err()
                .contains("not a finite number")
        );
        let e = parse_typed("1 reward 1e300", 1).unwrap_err();
        assert!(e.contains("must be a finite number >= 0"), "{e}");
        let e = parse_answer(r#"{"rollout": 1, "measured": [1e39]}"#, 1, 1).unwrap_err();
        assert!(e.contains("not a finite number"), "{e}");
    }

    struct Script(Vec<&'static str>, Vec<String>);

    impl Prompt for Script {
        fn ask(&mut self, question: &str) -> Result<Option<String>, Error> {
            self.1.push(question.to_string());
            Ok((!self.0.is_empty()).then(|| self.0.remove(0).to_string()))
        }
    }

    #[test]
    fn a_bad_typed_answer_is_asked_again() {
        let mut op = Operator::new(
            Box::new(Script(vec!["two", "reward 0.5", "2.5"], Vec::new())),
            1,
            true,
        );
        let a = op.evaluate(1, Path::new("/tmp/r.csv")).unwrap();
        assert_eq!(a.measured, Some(vec![2.5]));
        // PoWER takes a reward alone.
        let mut op = Operator::new(Box::new(Script(vec!["reward 0.5"], Vec::new())), 1, false);
        assert_eq!(
            op.evaluate(1, Path::new("/tmp/r.csv")).unwrap().reward,
            Some(0.5)
        );
        let mut op = Operator::new(Box::new(Script(vec![], Vec::new())), 1, true);
        assert!(op.evaluate(1, Path::new("/tmp/r.csv")).is_err());
    }
}
