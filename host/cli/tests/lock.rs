//! A run directory is held by one process at a time: while a run goes on
//! in it, a second run, a resumption or an experiment into it is refused
//! at once (exit 2), naming the holder; once the holder is killed
//! (SIGKILL), the run resumes.
mod common;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use common::{primo, tmp};

fn throw_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/throw")
        .canonicalize()
        .unwrap()
}

/// The example throw, whose evaluator waits (never answers) while `stop`
/// exists, and measures the throw once it is gone.
fn slow_throw(name: &str, stop: &Path) -> PathBuf {
    let throw = throw_dir();
    let evaluator = format!(
        "if [ -e {} ]; then cat > /dev/null; else exec python3 {}/throw.py; fi",
        stop.display(),
        throw.display()
    );
    let text = std::fs::read_to_string(throw.join("throw.toml"))
        .unwrap()
        .replace("\"demos/", &format!("\"{}/demos/", throw.display()))
        .replace(
            "command = [\"python3\", \"throw.py\"]",
            &format!("command = [\"sh\", \"-c\", \"{evaluator}\"]"),
        );
    let file = tmp(&format!("{name}.toml"));
    std::fs::write(&file, text).unwrap();
    file
}

fn spawn(args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_primo"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap()
}

/// Waits until `dir`'s run log holds its header and `least` records in all.
fn wait_for_log(dir: &Path, least: usize) {
    let deadline = Instant::now() + Duration::from_secs(60);
    let records = || {
        std::fs::read(dir.join("run.log")).map_or(0, |b| b.iter().filter(|c| **c == b'\n').count())
    };
    while records() < least {
        assert!(Instant::now() < deadline, "the run never logged");
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Every way into `dir` is refused at once, naming `holder`.
fn all_refused(dir: &Path, task: &Path, holder: u32) {
    let d = dir.to_str().unwrap();
    let t = task.to_str().unwrap();
    let attempts: [&[&str]; 6] = [
        &["learn", "--task", t, "--out", d],
        &["learn", "--resume", d],
        &["pour", "--method", "power", "--seed", "2", "--out", d],
        &["pour", "--resume", d],
        &["experiment", "golden", "--volumes", "0.5", "--out", d],
        &[
            "experiment",
            "power",
            "--runs",
            "1",
            "--updates",
            "1",
            "--out",
            d,
        ],
    ];
    for args in attempts {
        let started = Instant::now();
        let (code, out, err) = primo(args);
        assert_eq!(code, 2, "{args:?}: {out}{err}");
        let said = format!("{d} is in use by primo pid {holder} (`primo ");
        assert!(err.contains(&said), "{args:?}: {err}");
        assert!(err.contains("wait for it or stop it"), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(started.elapsed() < Duration::from_secs(10), "{args:?}");
    }
}

#[test]
fn a_held_learn_directory_is_refused_and_resumes_once_its_holder_is_killed() {
    let stop = tmp("learn-stop");
    std::fs::write(&stop, "").unwrap();
    let task = slow_throw("slow", &stop);
    let dir = tmp("held-learn");
    let d = dir.to_str().unwrap();
    let mut holder = spawn(&["learn", "--task", task.to_str().unwrap(), "--out", d]);
    wait_for_log(&dir, 1);
    all_refused(&dir, &task, holder.id());
    let log = std::fs::read(dir.join("run.log")).unwrap();
    holder.kill().unwrap(); // SIGKILL: the lock file stays behind
    holder.wait().unwrap();
    assert!(dir.join("primo.lock").exists());
    assert_eq!(std::fs::read(dir.join("run.log")).unwrap(), log);
    std::fs::remove_file(&stop).unwrap();
    let (code, out, err) = primo(&["learn", "--resume", d]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("primo learn: resuming"), "{out}");
    assert!(out.contains("reached the precision"), "{out}");
}

#[test]
fn a_second_pour_into_a_running_pours_directory_is_refused() {
    let dir = tmp("held-pour");
    let d = dir.to_str().unwrap();
    let mut holder = spawn(&[
        "pour",
        "--method",
        "power",
        "--seed",
        "1",
        "--max-rollouts",
        "100000",
        "--out",
        d,
    ]);
    wait_for_log(&dir, 3);
    for args in [
        &["pour", "--method", "power", "--seed", "2", "--out", d][..],
        &["pour", "--resume", d],
    ] {
        let (code, _, err) = primo(args);
        assert_eq!(code, 2, "{args:?}: {err}");
        let said = format!("{d} is in use by primo pid {} (`primo pour ", holder.id());
        assert!(err.contains(&said), "{err}");
    }
    holder.kill().unwrap();
    holder.wait().unwrap();
    // One run's log: one header, its roll-outs in order.
    let text = std::fs::read_to_string(dir.join("run.log")).unwrap();
    let headers = text
        .lines()
        .filter(|l| l.contains("\"kind\":\"run\""))
        .count();
    assert_eq!(headers, 1, "{text}");
}
