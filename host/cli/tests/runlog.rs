//! `primo pour`'s run log end to end: a run killed with SIGKILL and
//! resumed reaches exactly the uninterrupted run's result; torn and
//! corrupt logs are recovered or refused, never silently used.
mod common;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::{primo, tmp};

/// A PoWER run on the simulated cell, small enough to be quick.
fn power_args(out: &Path, rollouts: u32) -> Vec<String> {
    [
        "pour",
        "--method",
        "power",
        "--glass",
        "small",
        "--kernels",
        "10",
        "--seed",
        "3",
        "--max-rollouts",
        &rollouts.to_string(),
        "--out",
        out.to_str().unwrap(),
    ]
    .map(String::from)
    .to_vec()
}

fn run_to_end(out: &Path, rollouts: u32) {
    let args = power_args(out, rollouts);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let (code, _, err) = primo(&args);
    assert_eq!(code, 0, "{err}");
}

fn read(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap()
}

fn lines(path: &Path) -> usize {
    std::fs::read(path).map_or(0, |b| b.iter().filter(|c| **c == b'\n').count())
}

fn resume(dir: &Path) -> (i32, String, String) {
    primo(&["pour", "--resume", dir.to_str().unwrap()])
}

#[test]
fn a_killed_run_resumes_to_exactly_the_uninterrupted_result() {
    const ROLLOUTS: u32 = 80;
    let whole = tmp("whole");
    run_to_end(&whole, ROLLOUTS);

    let killed = tmp("killed");
    let mut child = Command::new(env!("CARGO_BIN_EXE_primo"))
        .args(power_args(&killed, ROLLOUTS))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let log = killed.join("run.log");
    let deadline = Instant::now() + Duration::from_secs(120);
    while lines(&log) < 12 {
        assert!(
            Instant::now() < deadline,
            "the run never logged 11 roll-outs"
        );
        std::thread::sleep(Duration::from_micros(200));
    }
    child.kill().unwrap(); // SIGKILL: no chance to tidy up
    child.wait().unwrap();
    let at_kill = lines(&log) - 1;
    assert!(at_kill < ROLLOUTS as usize, "the run ended before the kill");
    assert!(!killed.join("rollouts.csv").exists());

    let (code, out, err) = resume(&killed);
    assert_eq!(code, 0, "{err}");
    let resumed_after: usize = out
        .lines()
        .find_map(|l| {
            l.strip_prefix(&format!(
                "primo pour: resuming {} after roll-out ",
                killed.display()
            ))
        })
        .unwrap_or_else(|| panic!("{out}"))
        .parse()
        .unwrap();
    assert!(
        (at_kill..=at_kill + 1).contains(&resumed_after),
        "{at_kill} {resumed_after}"
    );
    // The logged roll-outs are told again, not made again; the rest are new.
    assert_eq!(
        out.lines().filter(|l| l.ends_with("(logged)")).count(),
        resumed_after
    );
    let made = out.lines().filter(|l| l.starts_with("roll-out")).count();
    assert_eq!(made, ROLLOUTS as usize, "{out}");
    // Bit for bit the uninterrupted run: every roll-out, the learner's
    // state after each, the reports.
    assert_eq!(read(&killed.join("run.log")), read(&whole.join("run.log")));
    assert_eq!(
        read(&killed.join("rollouts.csv")),
        read(&whole.join("rollouts.csv"))
    );
    assert_eq!(
        read(&killed.join("series.csv")),
        read(&whole.join("series.csv"))
    );
}

/// An unfinished run of 6 roll-outs (the end record cut off), and the
/// log of the same run finished.
fn unfinished(name: &str) -> (std::path::PathBuf, Vec<u8>) {
    let dir = tmp(name);
    run_to_end(&dir, 6);
    let finished = read(&dir.join("run.log"));
    let mut bytes = finished.clone();
    bytes.pop();
    let end = bytes.iter().rposition(|b| *b == b'\n').unwrap() + 1;
    std::fs::write(dir.join("run.log"), &bytes[..end]).unwrap();
    std::fs::remove_file(dir.join("rollouts.csv")).unwrap();
    (dir, finished)
}

#[test]
fn a_torn_tail_is_set_aside_and_the_run_completes() {
    let (dir, finished) = unfinished("torn");
    let log = dir.join("run.log");
    let mut bytes = read(&log);
    let last = bytes[..bytes.len() - 1]
        .iter()
        .rposition(|b| *b == b'\n')
        .unwrap()
        + 1;
    // The write of roll-out 6 torn half way.
    let torn = bytes[last..].to_vec();
    bytes.truncate(last + torn.len() / 2);
    std::fs::write(&log, &bytes).unwrap();
    let (code, out, err) = resume(&dir);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("the last record, line 7 (torn:") && err.contains("were moved to"),
        "{err}"
    );
    assert!(out.contains("after roll-out 5"), "{out}");
    assert_eq!(read(&log), finished);
    let aside = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(Result::ok)
        .find(|e| {
            e.file_name()
                .to_string_lossy()
                .starts_with("run.log.damaged-")
        })
        .unwrap();
    assert_eq!(read(&aside.path()), torn[..torn.len() / 2]);
}

#[test]
fn a_corrupt_log_is_refused_and_left_as_it_is() {
    let (dir, _) = unfinished("corrupt");
    let log = dir.join("run.log");
    let mut bytes = read(&log);
    // A digit of roll-out 2's poured volume changed.
    let second = bytes
        .iter()
        .enumerate()
        .filter(|(_, b)| **b == b'\n')
        .nth(1)
        .unwrap()
        .0;
    let at = second
        + 1
        + bytes[second + 1..]
            .windows(8)
            .position(|w| w == b"\"poured\"")
            .unwrap()
        + 10;
    bytes[at] = if bytes[at] == b'1' { b'2' } else { b'1' };
    std::fs::write(&log, &bytes).unwrap();
    let (code, _, err) = resume(&dir);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("run.log:3: CRC") && err.contains("corrupt, not torn"),
        "{err}"
    );
    assert_eq!(read(&log), bytes);
    assert!(!dir.join("rollouts.csv").exists());
}

#[test]
fn an_unfinished_run_is_never_overwritten_and_settings_come_from_its_log() {
    let (dir, _) = unfinished("keep");
    let before = read(&dir.join("run.log"));
    let args = power_args(&dir, 6);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let (code, _, err) = primo(&args);
    assert_eq!(code, 2);
    assert!(
        err.contains("an unfinished run (6 roll-outs)") && err.contains("--resume"),
        "{err}"
    );
    assert_eq!(read(&dir.join("run.log")), before);
    // Settings cannot change on resuming.
    let (code, _, err) = primo(&["pour", "--resume", dir.to_str().unwrap(), "--seed", "4"]);
    assert_eq!(code, 2);
    assert!(err.contains("cannot be used with"), "{err}");
    // A complete run resumed only reports.
    let (code, out, err) = resume(&dir);
    assert_eq!(code, 0, "{err}");
    let (code, again, err) = resume(&dir);
    assert_eq!(code, 0, "{err}");
    assert!(again.contains("the run is complete: reporting"), "{again}");
    assert_eq!(
        again.lines().filter(|l| l.ends_with("(logged)")).count(),
        6,
        "{out}"
    );
}

#[test]
fn a_run_resumes_on_the_coprocessor_where_the_host_left_it() {
    // The learner on the emulated Cortex-M4F is told the logged outcomes
    // and must reach the logged states bit for bit, then goes on.
    let (dir, finished) = unfinished("coprocessor");
    let mut bytes = read(&dir.join("run.log"));
    for _ in 0..3 {
        bytes.pop();
        let end = bytes.iter().rposition(|b| *b == b'\n').unwrap() + 1;
        bytes.truncate(end);
    }
    std::fs::write(dir.join("run.log"), &bytes).unwrap();
    let (code, out, err) = primo(&[
        "pour",
        "--resume",
        dir.to_str().unwrap(),
        "--coprocessor",
        "qemu",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("after roll-out 3") && out.contains("QEMU"),
        "{out}"
    );
    assert_eq!(read(&dir.join("run.log")), finished);
}

#[test]
fn a_log_that_cannot_be_read_or_appended_to_is_refused_before_anything_runs() {
    // A directory where the log should be.
    let dir = tmp("log-is-a-directory");
    std::fs::create_dir_all(dir.join("run.log")).unwrap();
    for command in ["pour", "learn"] {
        let (code, _, err) = primo(&[command, "--resume", dir.to_str().unwrap()]);
        assert_eq!((code, err.lines().count()), (2, 1), "{command}: {err}");
        assert!(
            err.contains(&format!(
                "--resume {}: not a file: it is a directory",
                dir.join("run.log").display()
            )),
            "{command}: {err}"
        );
    }
    // Bytes that are no text at all are no run.
    let dir = tmp("log-of-binary");
    std::fs::create_dir_all(&dir).unwrap();
    let garbage: Vec<u8> = (0..=255u8).rev().cycle().take(600).collect();
    std::fs::write(dir.join("run.log"), &garbage).unwrap();
    for command in ["pour", "learn"] {
        let (code, _, err) = primo(&[command, "--resume", dir.to_str().unwrap()]);
        assert_eq!((code, err.lines().count()), (2, 1), "{command}: {err}");
        assert!(err.contains("run.log:1: "), "{command}: {err}");
        assert_eq!(read(&dir.join("run.log")), garbage);
    }
}

#[test]
fn a_run_that_used_up_its_budget_goes_on_with_a_larger_one() {
    // Error learning stopped by its budget, then given more: the same
    // roll-outs as a run given the larger budget from the start.
    let golden = |out: &Path, rollouts: &str| {
        let (code, _, err) = primo(&[
            "pour",
            "--max-rollouts",
            rollouts,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{err}");
    };
    let (short, whole) = (tmp("budget-short"), tmp("budget-whole"));
    golden(&short, "3");
    golden(&whole, "20");
    let summary = std::fs::read_to_string(short.join("summary.json")).unwrap();
    assert!(summary.contains("\"converged\": false"), "{summary}");
    let (code, out, err) = primo(&[
        "pour",
        "--resume",
        short.to_str().unwrap(),
        "--max-rollouts",
        "20",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("roll-out budget 3 -> 20"), "{err}");
    assert!(out.contains("converged"), "{out}");
    let rows = |dir: &Path| std::fs::read_to_string(dir.join("rollouts.csv")).unwrap();
    assert_eq!(rows(&short), rows(&whole));
    // The log as it was is kept beside the continued one.
    let kept = std::fs::read_dir(&short)
        .unwrap()
        .filter(|e| {
            let name = e.as_ref().unwrap().file_name();
            name.to_string_lossy().starts_with("run.log.before-")
        })
        .count();
    assert_eq!(kept, 1);
    // PoWER's run, given more roll-outs on resume, makes the longer run's.
    let (short, whole) = (tmp("budget-power-short"), tmp("budget-power-whole"));
    run_to_end(&short, 4);
    run_to_end(&whole, 8);
    let (code, _, err) = primo(&[
        "pour",
        "--resume",
        short.to_str().unwrap(),
        "--max-rollouts",
        "8",
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(rows(&short), rows(&whole));
    // A budget below what is logged would drop roll-outs: refused.
    let (code, _, err) = primo(&[
        "pour",
        "--resume",
        short.to_str().unwrap(),
        "--max-rollouts",
        "2",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("the run has made 8 already"), "{err}");
}
