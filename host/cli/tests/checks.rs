//! The command line checks before it acts: every refused setting is named,
//! exits with status 2, and leaves nothing behind; results are not
//! clobbered; a closed stdout ends a run quietly and `--resume` continues.
mod common;
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};

use common::{primo, tmp};

/// `primo args` running, its stdout and stderr piped.
fn piped(args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_primo"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// `primo args` is refused with status 2, naming `flag`, before `out`
/// exists.
fn refused(args: &[&str], out: &std::path::Path, flag: &str) {
    let (status, stdout, stderr) = primo(args);
    assert_eq!(status, 2, "{args:?}: {stdout}\n{stderr}");
    assert!(stderr.contains(flag), "{args:?}: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "one line: {stderr}");
    assert!(
        !stderr.contains("Configure") && !stderr.contains("{"),
        "{stderr}"
    );
    assert!(!out.exists(), "{args:?} created {}", out.display());
    assert!(stdout.is_empty(), "{args:?} said {stdout}");
}

#[test]
fn bad_pour_settings_are_refused_before_any_output() {
    let out = tmp("refused-pour");
    let o = out.to_str().unwrap();
    refused(&["pour", "--bottle", "5", "--out", o], &out, "--bottle");
    refused(
        &["pour", "--target", "0.8", "--bottle", "0.5", "--out", o],
        &out,
        "--target",
    );
    refused(&["pour", "--target=-0.1", "--out", o], &out, "--target");
    refused(
        &["pour", "--precision", "0", "--out", o],
        &out,
        "--precision",
    );
    refused(
        &["pour", "--max-rollouts", "0", "--out", o],
        &out,
        "--max-rollouts",
    );
    refused(&["pour", "--kernels", "1", "--out", o], &out, "--kernels");
    refused(
        &["pour", "--search", "1.0,0.3", "--out", o],
        &out,
        "--search",
    );
    refused(
        &["pour", "--search", "0.6,1.0", "--out", o],
        &out,
        "--bottle",
    );
    refused(
        &["pour", "--gain", "0", "--method", "fixed-gain", "--out", o],
        &out,
        "--gain",
    );
    refused(
        &["pour", "--sampler", "4", "--method", "power-el", "--out", o],
        &out,
        "--sampler",
    );
    refused(
        &["pour", "--sampler", "2", "--method", "golden", "--out", o],
        &out,
        "--sampler",
    );
    let demo = tmp("refused-demo.csv");
    let (status, _, stderr) = primo(&["demo", "synth", "--out", demo.to_str().unwrap()]);
    assert_eq!(status, 0, "{stderr}");
    let one = format!("{}=0.3", demo.display());
    refused(&["pour", "--demo", &one, "--out", o], &out, "--demo");
    let other = format!("{}=0.3", demo.display());
    refused(
        &["pour", "--demo", &one, "--demo", &other, "--out", o],
        &out,
        "--demo",
    );
    refused(
        &[
            "pour",
            "--robot",
            "udp:1.2.3.4",
            "--scale",
            "/dev/null",
            "--out",
            o,
        ],
        &out,
        "--robot",
    );
}

#[test]
fn an_experiment_checks_its_output_before_computing() {
    let file = tmp("experiment-out-is-a-file");
    std::fs::write(&file, "keep").unwrap();
    let (status, stdout, stderr) = primo(&[
        "experiment",
        "golden",
        "--volumes",
        "0.5",
        "--out",
        file.to_str().unwrap(),
    ]);
    assert_eq!(status, 2, "{stdout}\n{stderr}");
    assert!(
        stderr.contains("--out") && stderr.contains("not a directory"),
        "{stderr}"
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "keep");
    let out = tmp("refused-golden");
    refused(
        &[
            "experiment",
            "golden",
            "--volumes",
            "2",
            "--out",
            out.to_str().unwrap(),
        ],
        &out,
        "--volumes",
    );
}

#[test]
fn a_logged_run_is_replaced_only_with_force_and_then_moved_aside() {
    let out = tmp("force");
    let o = out.to_str().unwrap();
    let (status, _, stderr) = primo(&["pour", "--out", o]);
    assert_eq!(status, 0, "{stderr}");
    let log = std::fs::read(out.join("run.log")).unwrap();
    let (status, _, stderr) = primo(&["pour", "--seed", "2", "--out", o]);
    assert_eq!(status, 2, "{stderr}");
    assert!(stderr.contains("--force"), "{stderr}");
    assert_eq!(std::fs::read(out.join("run.log")).unwrap(), log);
    // Unfinished (its end record gone), and replaced all the same.
    let text = String::from_utf8(log).unwrap();
    let unfinished = text
        .lines()
        .take(text.lines().count() - 1)
        .collect::<Vec<_>>()
        .join("\n")
        + "\n";
    std::fs::write(out.join("run.log"), &unfinished).unwrap();
    let (status, _, stderr) = primo(&["pour", "--seed", "2", "--out", o]);
    assert_eq!(status, 2, "{stderr}");
    assert!(
        stderr.contains("--resume") && stderr.contains("--force"),
        "{stderr}"
    );
    let (status, stdout, stderr) = primo(&["pour", "--seed", "2", "--out", o, "--force"]);
    assert_eq!(status, 0, "{stderr}");
    assert_ne!(
        std::fs::read_to_string(out.join("run.log")).unwrap(),
        unfinished
    );
    let aside: Vec<_> = std::fs::read_dir(out.parent().unwrap())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            name.starts_with("force.replaced-")
        })
        .collect();
    assert_eq!(aside.len(), 1, "{aside:?}");
    assert_eq!(
        std::fs::read_to_string(aside[0].join("run.log")).unwrap(),
        unfinished
    );
    assert!(aside[0].join("summary.json").exists());
    assert!(
        stdout.contains(&format!("moved aside to {}", aside[0].display())),
        "{stdout}"
    );
}

#[test]
fn a_closed_stdout_ends_the_run_quietly_and_resume_continues_it() {
    let out = tmp("broken-pipe");
    let o = out.to_str().unwrap();
    // `primo pour | head -1`: the reader leaves after the first line.
    let mut child = piped(&[
        "pour",
        "--method",
        "power",
        "--max-rollouts",
        "40",
        "--out",
        o,
    ]);
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    // The pipe's reader is gone (dropped above).
    let result = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(first.starts_with("primo pour:"), "{first}");
    assert_eq!(result.status.code(), Some(141), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(stderr.contains("--resume"), "{stderr}");
    let (status, stdout, stderr) = primo(&["pour", "--resume", o]);
    assert_eq!(status, 0, "{stderr}");
    assert!(stdout.contains("resuming"), "{stdout}");
    assert!(stdout.contains("primo pour: learned"), "{stdout}");
    // The same roll-outs as a run never interrupted.
    let whole = tmp("broken-pipe-whole");
    let (status, _, stderr) = primo(&[
        "pour",
        "--method",
        "power",
        "--max-rollouts",
        "40",
        "--out",
        whole.to_str().unwrap(),
    ]);
    assert_eq!(status, 0, "{stderr}");
    assert_eq!(
        std::fs::read(out.join("rollouts.csv")).unwrap(),
        std::fs::read(whole.join("rollouts.csv")).unwrap()
    );
}

#[test]
fn print_start_into_a_closed_pipe_does_not_panic() {
    let mut child = piped(&["rollout", "--print-start"]);
    drop(child.stdout.take());
    let result = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(matches!(result.status.code(), Some(0 | 141)), "{stderr}");
}

#[test]
fn ctrl_c_stops_after_the_rollout_in_progress_and_resume_continues() {
    let out = tmp("ctrl-c");
    let o = out.to_str().unwrap();
    let mut child = piped(&[
        "pour",
        "--method",
        "power",
        "--max-rollouts",
        "200",
        "--out",
        o,
    ]);
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    let mut first = String::new();
    stdout.read_line(&mut first).unwrap();
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let rest: Vec<String> = stdout.lines().map_while(Result::ok).collect();
    let result = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert_eq!(result.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("interrupted"), "{stderr}");
    assert!(
        stderr.contains(&format!("primo pour --resume {o}")),
        "{stderr}"
    );
    let made = rest.iter().filter(|l| l.starts_with("roll-out")).count();
    assert!(made < 200, "the run went on: {made} roll-outs");
    let (status, stdout, stderr) = primo(&["pour", "--resume", o]);
    assert_eq!(status, 0, "{stderr}");
    assert!(stdout.contains("primo pour: learned"), "{stdout}");
}

#[test]
fn the_built_in_pour_task_on_a_real_cell_needs_what_its_glass_holds() {
    let out = tmp("learn-real-glass");
    let o = out.to_str().unwrap();
    let task = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/pour.toml");
    let t = task.to_str().unwrap();
    let real = [
        "learn",
        "--task",
        t,
        "--robot",
        "fri:127.0.0.1",
        "--scale",
        "/dev/null",
        "--out",
        o,
    ];
    let (status, _, stderr) = primo(&real);
    assert_eq!(status, 2, "{stderr}");
    assert!(
        stderr.contains("--robot: give --glass-holds LITRES"),
        "{stderr}"
    );
    assert!(!out.exists());
    let (_, _, stderr) = primo(&[&real[..], &["--glass-holds", "none"]].concat());
    assert!(!stderr.contains("--glass-holds"), "{stderr}");
    // On the simulated cell, a given glass bounds the search and is logged.
    let sim = tmp("learn-sim-glass");
    let s = sim.to_str().unwrap();
    let (status, _, stderr) = primo(&[
        "learn",
        "--task",
        t,
        "--out",
        s,
        "--max-rollouts",
        "2",
        "--glass-holds",
        "0.25",
    ]);
    assert_eq!(status, 0, "{stderr}");
    let log = std::fs::read_to_string(sim.join("run.log")).unwrap();
    assert!(log.contains("\"glass_holds\":0.25"), "{log}");
    // A task with its own evaluator has its own bounds.
    let throw = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/throw/throw.toml");
    let (status, _, stderr) = primo(&[
        "learn",
        "--task",
        throw.to_str().unwrap(),
        "--glass-holds",
        "0.3",
        "--out",
        tmp("throw-glass").to_str().unwrap(),
    ]);
    assert_eq!(status, 2, "{stderr}");
    assert!(stderr.contains("its [goal] low and high"), "{stderr}");
}

#[test]
fn a_real_cell_needs_what_its_glass_holds() {
    let out = tmp("real-glass");
    let o = out.to_str().unwrap();
    let real = [
        "pour",
        "--robot",
        "fri:127.0.0.1",
        "--scale",
        "/dev/null",
        "--out",
        o,
    ];
    let (status, _, stderr) = primo(&real);
    assert_eq!(status, 2, "{stderr}");
    assert!(
        stderr.contains("--robot: give --glass-holds LITRES, what your glass holds"),
        "{stderr}"
    );
    assert!(!out.exists());
    // Saying `none` on purpose passes this check (and fails on the port).
    let (_, _, stderr) = primo(&[&real[..], &["--glass-holds", "none"]].concat());
    assert!(!stderr.contains("--glass-holds"), "{stderr}");
    let (status, _, stderr) = primo(&[&real[..], &["--glass-holds", "lots"]].concat());
    assert_eq!(status, 2);
    assert!(
        stderr.contains("expected what the glass holds in litres, or `none`"),
        "{stderr}"
    );
}
