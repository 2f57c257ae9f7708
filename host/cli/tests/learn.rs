//! `primo learn` end to end, through the real binary: the example throw
//! learned by every learner, evaluators that crash, hang or talk garbage,
//! a killed run resumed, the pour task file against `primo pour`, the
//! operator at the terminal, and bad task files refused before anything
//! runs.
mod common;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::{primo, primo_with_input, tmp};

fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples")
}

fn throw_dir() -> PathBuf {
    examples().join("throw").canonicalize().unwrap()
}

/// A task file in its own directory: the example throw's, with `edit`
/// applied, the demonstrations and the evaluator named absolutely.
fn task(name: &str, example: &str, edit: impl Fn(String) -> String) -> PathBuf {
    let dir = tmp(name);
    std::fs::create_dir_all(&dir).unwrap();
    let throw = throw_dir();
    let text = std::fs::read_to_string(throw.join(example))
        .unwrap()
        .replace("\"demos/", &format!("\"{}/demos/", throw.display()))
        .replace("\"throw.py\"", &format!("\"{}/throw.py\"", throw.display()));
    let file = dir.join("task.toml");
    std::fs::write(&file, edit(text)).unwrap();
    file
}

fn learn(task: &Path, out: &Path, extra: &[&str]) -> (i32, String, String) {
    let mut args = vec![
        "learn",
        "--task",
        task.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend(extra);
    primo(&args)
}

fn summary(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
}

fn logged(out: &Path) -> usize {
    std::fs::read_to_string(out.join("run.log")).map_or(0, |t| t.lines().count().saturating_sub(1))
}

#[test]
fn the_throw_reaches_its_precision_with_each_error_learner() {
    for (method, example, most) in [
        ("golden", "throw.toml", 10),
        ("illinois", "throw.toml", 8),
        ("secant", "throw.toml", 8),
        ("fixed-gain", "throw.toml", 10),
        ("weighted-gain", "throw.toml", 10),
        ("secant", "throw-2d.toml", 8),
        ("secant-goals", "throw-short.toml", 6),
    ] {
        let file = task(&format!("{method}-{example}"), example, |t| {
            t.replace("method = \"golden\" ", &format!("method = \"{method}\" "))
        });
        let out = tmp(&format!("out-{method}-{example}"));
        let (code, stdout, err) = learn(&file, &out, &[]);
        assert_eq!(code, 0, "{method} {example}: {err}");
        let s = summary(&out);
        let at = s["converged_at"]
            .as_u64()
            .unwrap_or_else(|| panic!("{stdout}"));
        assert!(at <= most, "{method} {example}: {at} roll-outs\n{stdout}");
        // The last roll-out measured the desired query to the precision.
        let desired = s["desired"].as_array().unwrap();
        let measured = s["last"]["trial"]["measured"].as_array().unwrap();
        for (d, m) in desired.iter().zip(measured) {
            assert!((d.as_f64().unwrap() - m.as_f64().unwrap()).abs() < 0.005);
        }
        // Every roll-out's checked trajectory is kept, with the demos' columns.
        let first = std::fs::read_to_string(out.join("trajectories/rollout-0001.csv")).unwrap();
        assert!(first.starts_with("t,shoulder,elbow\n"), "{first}");
        for f in ["rollouts.csv", "convergence.png", "run.log"] {
            assert!(out.join(f).is_file(), "{f}");
        }
    }
}

#[test]
fn power_improves_the_throws_reward() {
    let file = task("power", "throw-power.toml", |t| t);
    let out = tmp("out-power");
    let (code, stdout, err) = learn(&file, &out, &["--seed", "2"]);
    assert_eq!(code, 0, "{err}");
    let means: Vec<f64> = stdout
        .lines()
        .filter(|l| l.starts_with("roll-out") && l.ends_with("(mean)"))
        .map(|l| {
            let r = l.split("reward ").nth(1).unwrap();
            r.split_whitespace().next().unwrap().parse().unwrap()
        })
        .collect();
    assert_eq!(means.len(), 10, "{stdout}");
    assert!(
        means[9] > means[0] + 0.1 && means[9] > 0.95,
        "the mean's reward went {means:?}"
    );
    // The complete run's log (a task without bounds) reads back.
    let (code, again, err) = primo(&["learn", "--resume", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(again.contains("the run is complete: reporting"), "{again}");
}

#[test]
fn power_with_an_error_learned_query_gets_there_sooner() {
    let means = |toml: &str, name: &str| -> Vec<f64> {
        let file = task(name, toml, |t| t);
        let (code, stdout, err) = learn(&file, &tmp(&format!("out-{name}")), &["--seed", "3"]);
        assert_eq!(code, 0, "{err}");
        stdout
            .lines()
            .filter(|l| l.starts_with("roll-out") && l.ends_with("(mean)"))
            .map(|l| {
                let r = l.split("reward ").nth(1).unwrap();
                r.split_whitespace().next().unwrap().parse().unwrap()
            })
            .collect()
    };
    let plain = means("throw-power.toml", "power-plain");
    let learned = means("throw-power-el.toml", "power-el");
    // The 4th mean is roll-out 13: the error has moved the query twice.
    assert!(
        learned[3] > 0.95 && learned[3] > plain[3],
        "4th mean: {} (power-el) against {} (power)",
        learned[3],
        plain[3]
    );
}

/// The example throw's task with the evaluator `source` (Python, the
/// throw's module importable as `throw`) in place of throw.py, and `edit`.
fn with_evaluator(name: &str, source: &str, edit: impl Fn(String) -> String) -> PathBuf {
    let dir = tmp(name);
    std::fs::create_dir_all(&dir).unwrap();
    let script = dir.join("evaluator.py");
    let path = format!(
        "import sys\nsys.path.insert(0, {:?})\n",
        throw_dir().display().to_string()
    );
    std::fs::write(&script, path + source).unwrap();
    task(name, "throw.toml", |t| {
        edit(t.replace(
            &format!(
                "command = [\"python3\", \"{}/throw.py\"]",
                throw_dir().display()
            ),
            &format!("command = [\"python3\", \"{}\"]", script.display()),
        ))
    })
}

/// An evaluator that fails once, at roll-out 3, as `how` says, then (run
/// again) is the throw's.
fn flaky(name: &str, how: &str) -> PathBuf {
    flaky_with(name, how, |t| t)
}

/// [`flaky`] with `edit` applied to the task.
fn flaky_with(name: &str, how: &str, edit: impl Fn(String) -> String) -> PathBuf {
    let source = format!(
        r#"import json, os, time
import throw
for line in sys.stdin:
    request = json.loads(line)
    if request["rollout"] == 3 and not os.path.exists("failed-once"):
        open("failed-once", "w").close()
        how = {how:?}
        if how == "crash":
            sys.exit(3)
        if how == "hang":
            time.sleep(60)
        if how == "garbage":
            print("the ball went somewhere", flush=True)
            continue
        if how == "twice":
            print(json.dumps({{"rollout": 3, "measured": [1.0]}}), flush=True)
    d, h = throw.throw(*throw.read(request["csv"]))
    print(json.dumps({{"rollout": request["rollout"], "measured": [d]}}), flush=True)
"#
    );
    with_evaluator(name, &source, |t| {
        edit(t.replace("timeout = 30", "timeout = 2"))
    })
}

#[test]
fn an_evaluator_that_fails_ends_the_run_resumably() {
    for (how, says) in [
        (
            "crash",
            "did not answer roll-out 3: it exited (exit status: 3)",
        ),
        (
            "hang",
            "did not answer roll-out 3 within 2 s ([evaluate] timeout)",
        ),
        (
            "garbage",
            "answered roll-out 3 with `the ball went somewhere`",
        ),
    ] {
        let file = flaky(&format!("flaky-{how}"), how);
        let out = tmp(&format!("out-flaky-{how}"));
        let started = Instant::now();
        let (code, _, err) = learn(&file, &out, &[]);
        assert_eq!(code, 1, "{how}: {err}");
        assert!(err.contains(says), "{how}: {err}");
        assert!(err.contains("primo learn --resume"), "{how}: {err}");
        assert!(started.elapsed() < Duration::from_secs(30), "{how}");
        assert_eq!(logged(&out), 2, "{how}");
        let (code, stdout, err) = primo(&["learn", "--resume", out.to_str().unwrap()]);
        assert_eq!(code, 0, "{how}: {err}");
        assert!(stdout.contains("resuming"), "{stdout}");
        assert_eq!(
            stdout.lines().filter(|l| l.ends_with("(logged)")).count(),
            2,
            "{stdout}"
        );
        assert!(summary(&out)["converged_at"].as_u64().is_some(), "{stdout}");
    }
}

#[test]
fn an_evaluator_out_of_step_is_refused() {
    // Two lines for roll-out 3: the second is refused as roll-out 4's.
    let file = flaky("flaky-twice", "twice");
    let out = tmp("out-flaky-twice");
    let (code, _, err) = learn(&file, &out, &[]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("the answer is for roll-out 3, not 4: the evaluator is out of step"),
        "{err}"
    );
    assert_eq!(logged(&out), 3);
}

/// The example throw with an evaluator that says a throw failed when
/// `fails` (a Python expression of `q`, the roll-out's distance) holds.
fn failing(name: &str, fails: &str) -> PathBuf {
    let source = format!(
        r#"import json
import throw
for line in sys.stdin:
    request = json.loads(line)
    q, _ = throw.throw(*throw.read(request["csv"]))
    answer = {{"failed": "the ball flew over the net"}} if {fails} else {{"measured": [q]}}
    answer["rollout"] = request["rollout"]
    print(json.dumps(answer), flush=True)
"#
    );
    with_evaluator(name, &source, |t| t)
}

#[test]
fn rejected_and_failed_probes_narrow_the_search() {
    // Bounds the demonstrations do not support: the probes beyond them
    // are rejected by the limits (too short a movement, too fast).
    let wide = task("wide", "throw.toml", |t| {
        t.replace("low = [1.0]", "low = [0.1]")
            .replace("high = [1.9]", "high = [5.0]")
    });
    // Throws past 1.6 m "fail" at the evaluator.
    let net = failing("net", "q > 1.6");
    for (file, marker) in [(wide, "REJECTED"), (net, "FAILED")] {
        for method in ["golden", "illinois", "secant"] {
            let text = std::fs::read_to_string(&file).unwrap();
            let with = file.with_file_name(format!("{method}.toml"));
            let set = format!("method = \"{method}\"");
            std::fs::write(&with, text.replace("method = \"golden\"", &set)).unwrap();
            let out = tmp(&format!("out-narrow-{marker}-{method}"));
            let (code, stdout, err) = learn(&with, &out, &[]);
            assert_eq!(code, 0, "{marker} {method}: {err}");
            let narrowed: Vec<_> = stdout
                .lines()
                .filter(|l| l.starts_with("roll-out") && l.contains(marker))
                .collect();
            // The secant learner's steps stay among the feasible queries.
            let bracketed = method != "secant";
            assert!(
                !narrowed.is_empty() || !bracketed,
                "{marker} {method}: {stdout}"
            );
            for l in narrowed {
                assert!(
                    l.contains("error learning now searches away from q ="),
                    "{l}"
                );
            }
            let s = summary(&out);
            assert_eq!(s["converged"], true, "{marker} {method}: {stdout}");
            assert_eq!(s["stopped"], "converged");
        }
    }
}

#[test]
fn a_run_that_misses_its_precision_says_why() {
    let file = task("missed", "throw.toml", |t| t);
    let out = tmp("out-missed");
    let (code, stdout, err) = learn(&file, &out, &["--max-rollouts", "3"]);
    assert_eq!(code, 0, "{err}");
    let last = stdout.lines().last().unwrap();
    assert!(
        last.contains("did not reach the precision: the budget of 3 roll-outs ran out"),
        "{last}"
    );
    let s = summary(&out);
    assert_eq!(
        (&s["converged"], &s["stopped"]),
        (&false.into(), &"budget".into())
    );
    // The desired query itself fails: nothing to narrow toward.
    let file = failing("infeasible", "True");
    let out = tmp("out-infeasible");
    let (code, stdout, err) = learn(&file, &out, &[]);
    assert_eq!(code, 0, "{err}");
    assert!(
        stdout.contains(
            "did not reach the precision: the desired query q = 1.5 could not be rolled out \
             (the ball flew over the net)"
        ),
        "{stdout}"
    );
    let s = summary(&out);
    assert_eq!(
        (&s["converged"], &s["stopped"]),
        (&false.into(), &"infeasible".into())
    );
    assert_eq!(s["rollouts"], 1);
    // PoWER has no precision to reach.
    let file = task("missed-power", "throw-power.toml", |t| t);
    let out = tmp("out-missed-power");
    let (code, _, err) = learn(&file, &out, &["--max-rollouts", "4"]);
    assert_eq!(code, 0, "{err}");
    let s = summary(&out);
    assert_eq!(
        (&s["converged"], &s["stopped"]),
        (&serde_json::Value::Null, &"learned".into())
    );
}

/// Whether process `pid` is gone (or a zombie: nothing runs).
fn gone(pid: i32) -> bool {
    match std::fs::read_to_string(format!("/proc/{pid}/stat")) {
        Err(_) => true,
        Ok(stat) => stat
            .rsplit_once(')')
            .is_some_and(|(_, rest)| rest.trim_start().starts_with('Z')),
    }
}

#[test]
fn an_interrupt_ends_the_evaluator_and_everything_it_started() {
    // Roll-out 2 hangs in an evaluator that started a child of its own.
    let source = r#"import json, os, subprocess, time
import throw
for line in sys.stdin:
    request = json.loads(line)
    if request["rollout"] == 2:
        child = subprocess.Popen(["sleep", "1000"])
        with open("pids.tmp", "w") as f:
            f.write(f"{os.getpid()} {child.pid}")
        os.rename("pids.tmp", "pids")
        time.sleep(1000)
    d, h = throw.throw(*throw.read(request["csv"]))
    print(json.dumps({"rollout": request["rollout"], "measured": [d]}), flush=True)
"#;
    for presses in [1, 2] {
        let name = format!("interrupted-{presses}");
        let file = with_evaluator(&name, source, |t| t.replace("timeout = 30", "timeout = 3"));
        let pids = file.with_file_name("pids");
        let out = tmp(&format!("out-{name}"));
        let child = Command::new(env!("CARGO_BIN_EXE_primo"))
            .args(["learn", "--task", file.to_str().unwrap(), "--out"])
            .arg(&out)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let deadline = Instant::now() + Duration::from_secs(30);
        while !pids.exists() {
            assert!(Instant::now() < deadline, "roll-out 2 never started");
            std::thread::sleep(Duration::from_millis(10));
        }
        let pids: Vec<i32> = std::fs::read_to_string(&pids)
            .unwrap()
            .split(' ')
            .map(|p| p.parse().unwrap())
            .collect();
        let pressed = Instant::now();
        for _ in 0..presses {
            // SAFETY: signals the child by its pid.
            assert_eq!(unsafe { libc::kill(child.id() as i32, libc::SIGINT) }, 0);
            std::thread::sleep(Duration::from_millis(200));
        }
        let result = child.wait_with_output().unwrap();
        let took = pressed.elapsed();
        let stderr = String::from_utf8_lossy(&result.stderr);
        assert_eq!(result.status.code(), Some(130), "{presses}: {stderr}");
        assert!(stderr.contains("primo learn --resume"), "{stderr}");
        match presses {
            // The roll-out in progress is waited for, to its timeout.
            1 => assert!(stderr.contains("within 3 s"), "{stderr}"),
            _ => assert!(took < Duration::from_secs(2), "{took:?}"),
        }
        let deadline = Instant::now() + Duration::from_secs(5);
        while !pids.iter().all(|p| gone(*p)) {
            assert!(Instant::now() < deadline, "{presses}: {pids:?} still run");
            std::thread::sleep(Duration::from_millis(20));
        }
        assert_eq!(logged(&out), 1);
    }
}

#[test]
fn a_resumed_run_takes_changed_bounds_budget_and_evaluator_that_keep_its_roll_outs() {
    // Roll-out 3 crashes the evaluator: two roll-outs are logged.
    let file = flaky("changed", "crash");
    let out = tmp("out-changed");
    let o = out.to_str().unwrap();
    let (code, _, err) = learn(&file, &out, &[]);
    assert_eq!(code, 1, "{err}");
    let log = std::fs::read(out.join("run.log")).unwrap();
    let text = std::fs::read_to_string(&file).unwrap();
    let edited = |name: &str, edit: &dyn Fn(&str) -> String| {
        let f = file.with_file_name(name);
        std::fs::write(&f, edit(&text)).unwrap();
        f
    };
    let resume = |with: &[&str]| primo(&[&["learn", "--resume", o][..], with].concat());
    // What would make the logged roll-outs another run's is refused, the
    // log left as it is.
    let desired = edited("desired.toml", &|t| {
        t.replace("desired = [1.5]", "desired = [1.4]")
    });
    let high = edited("high.toml", &|t| t.replace("high = [1.9]", "high = [1.8]"));
    for (with, says) in [
        (
            vec!["--task", desired.to_str().unwrap()],
            "[goal] desired differs from the logged run's",
        ),
        (
            vec!["--task", high.to_str().unwrap()],
            "[goal] high [1.9] -> [1.8]: the changed settings do not keep the logged roll-outs",
        ),
        (
            vec!["--max-rollouts", "1"],
            "a budget of 1 roll-outs: the run has made 2 already",
        ),
    ] {
        let (code, _, err) = resume(&with);
        assert_eq!(code, 2, "{with:?}: {err}");
        assert!(err.contains(says), "{with:?}: {err}");
        assert_eq!(std::fs::read(out.join("run.log")).unwrap(), log, "{with:?}");
    }
    // Another evaluator (the throw's own) and a larger budget are taken.
    let throw = throw_dir().join("throw.py");
    let evaluator = edited("evaluator.toml", &|t| {
        t.lines()
            .map(|l| match l.starts_with("command = ") {
                true => format!("command = [\"python3\", \"{}\"]", throw.display()),
                false => l.replace("max_rollouts = 20", "max_rollouts = 25"),
            })
            .collect::<Vec<_>>()
            .join("\n")
    });
    let (code, stdout, err) = resume(&["--task", evaluator.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("resuming with [learner] max_rollouts 20 -> 25"),
        "{err}"
    );
    assert!(
        err.contains("resuming with [evaluate] command `python3 "),
        "{err}"
    );
    assert!(stdout.contains("reached the precision"), "{stdout}");
    // The log keeps the change, and the log as it was beside it.
    let header = std::fs::read_to_string(out.join("run.log")).unwrap();
    assert!(
        header
            .lines()
            .next()
            .unwrap()
            .contains("\"max_rollouts\":25"),
        "{header}"
    );
    let before: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with("run.log.before-")
        })
        .collect();
    assert_eq!(before.len(), 1);
    assert_eq!(std::fs::read(&before[0]).unwrap(), log);
    // Told again, the complete run is the changed one.
    let (code, again, err) = resume(&[]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(again.lines().last(), stdout.lines().last());
}

#[test]
fn each_command_names_the_command_that_continues_the_others_log() {
    // A task run that stopped: its advice is `primo learn --resume`, and
    // `primo pour --resume` sends the user there, calling nothing corrupt.
    let file = flaky("advice", "crash");
    let out = tmp("out-advice");
    let o = out.to_str().unwrap();
    let (code, _, err) = learn(&file, &out, &[]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(&format!("continue with `primo learn --resume {o}`")),
        "{err}"
    );
    let log = std::fs::read(out.join("run.log")).unwrap();
    let (code, _, err) = primo(&["pour", "--resume", o]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains(&format!(
            "is a task run, written by `primo learn`: continue it with `primo learn --resume {o}`"
        )),
        "{err}"
    );
    assert!(!err.contains("corrupt"), "{err}");
    assert_eq!(std::fs::read(out.join("run.log")).unwrap(), log);
    // A pour's log is continued (here: reported again) by `primo learn`.
    let pour = tmp("out-advice-pour");
    let p = pour.to_str().unwrap();
    let (code, _, err) = primo(&["pour", "--max-rollouts", "3", "--out", p]);
    assert_eq!(code, 0, "{err}");
    let (code, stdout, err) = primo(&["learn", "--resume", p]);
    assert_eq!(code, 0, "{err}");
    assert!(
        stdout.contains("the run is complete: reporting"),
        "{stdout}"
    );
}

#[test]
fn a_killed_run_resumes_with_nothing_lost() {
    // A slow evaluator, so the kill lands mid-run.
    let slow = tmp("slow.py");
    std::fs::write(
        &slow,
        format!(
            "import sys, time\nsys.path.insert(0, {:?})\nimport throw\n\
             sys.stdin = (time.sleep(0.2) or l for l in sys.stdin)\nthrow.serve(True)\n",
            throw_dir().display().to_string()
        ),
    )
    .unwrap();
    let file = task("killed-task", "throw-2d.toml", |t| {
        t.replace(
            &format!(
                "[\"python3\", \"{}/throw.py\", \"--height\"]",
                throw_dir().display()
            ),
            &format!("[\"python3\", \"{}\"]", slow.display()),
        )
        .replace("precision = 0.005", "precision = 0.0000001")
    });
    let whole = tmp("killed-whole");
    let (code, stdout, err) = learn(&file, &whole, &[]);
    assert_eq!(code, 0, "{err}");
    let made = stdout.lines().filter(|l| l.starts_with("roll-out")).count();
    assert!(made >= 5, "{stdout}");

    let killed = tmp("killed-run");
    let mut child = Command::new(env!("CARGO_BIN_EXE_primo"))
        .args(["learn", "--task", file.to_str().unwrap(), "--out"])
        .arg(&killed)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let deadline = Instant::now() + Duration::from_secs(60);
    while logged(&killed) < 3 {
        assert!(
            Instant::now() < deadline,
            "the run never logged 3 roll-outs"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    assert!(!killed.join("summary.json").exists());
    let (code, stdout, err) = primo(&["learn", "--resume", killed.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        stdout.lines().filter(|l| l.starts_with("roll-out")).count(),
        made,
        "{stdout}"
    );
    for f in ["run.log", "rollouts.csv"] {
        assert_eq!(
            std::fs::read_to_string(killed.join(f)).unwrap(),
            std::fs::read_to_string(whole.join(f)).unwrap(),
            "{f}"
        );
    }
}

#[test]
fn the_pour_task_file_is_primo_pour() {
    let (a, b) = (tmp("pour-task"), tmp("pour-cli"));
    let pour = examples().join("pour.toml");
    let (code, _, err) = learn(&pour, &a, &["--seed", "4", "--max-rollouts", "6"]);
    assert_eq!(code, 0, "{err}");
    let b_out = b.to_str().unwrap();
    let (code, _, err) = primo(&["pour", "--seed", "4", "--max-rollouts", "6", "--out", b_out]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        std::fs::read_to_string(a.join("rollouts.csv")).unwrap(),
        std::fs::read_to_string(b.join("rollouts.csv")).unwrap()
    );
    // Its PoWER's importance sampler too: power-el's 2 by default, the
    // paper's 3 when told; they part at the second update.
    let rows = |sampler: Option<&str>, name: &str| {
        let (a, b) = (
            tmp(&format!("pour-task-{name}")),
            tmp(&format!("pour-cli-{name}")),
        );
        let dir = tmp(&format!("pour-{name}"));
        std::fs::create_dir_all(&dir).unwrap();
        let key = sampler.map_or(String::new(), |n| format!("\nsampler = {n}"));
        let text = std::fs::read_to_string(&pour).unwrap().replace(
            "method = \"golden\"",
            &format!("method = \"power-el\"{key}"),
        );
        std::fs::write(dir.join("task.toml"), text).unwrap();
        let (code, _, err) = learn(&dir.join("task.toml"), &a, &["--max-rollouts", "9"]);
        assert_eq!(code, 0, "{err}");
        let mut args = vec!["pour", "--method", "power-el", "--space", "cartesian"];
        args.extend(["--max-rollouts", "9", "--out", b.to_str().unwrap()]);
        args.extend(sampler.map(|n| ["--sampler", n]).into_iter().flatten());
        let (code, _, err) = primo(&args);
        assert_eq!(code, 0, "{err}");
        let read = |d: &PathBuf| std::fs::read_to_string(d.join("rollouts.csv")).unwrap();
        assert_eq!(read(&a), read(&b), "{name}");
        read(&a)
    };
    assert_ne!(rows(None, "el"), rows(Some("3"), "el-3"));
}

#[test]
fn the_operator_is_asked_again_after_a_bad_answer() {
    let file = task("operator", "throw.toml", |t| {
        let at = t.find("[evaluate]").unwrap();
        format!("{}[evaluate]\noperator = true\n", &t[..at])
            .replace("max_rollouts = 20", "max_rollouts = 2")
    });
    let out = tmp("out-operator");
    let (code, stdout, err) = primo_with_input(
        &[
            "learn",
            "--task",
            file.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        b"far\nreward 0.5\n1.2 1.3\n1.25\n1.6\n",
    );
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("`far` is not a number; again:"), "{stdout}");
    assert!(
        stdout.contains(
            "error learning needs the measured query (1 value), not a reward alone; again:"
        ),
        "{stdout}"
    );
    assert!(
        stdout.contains("has 2 values; the task's query has 1; again:"),
        "{stdout}"
    );
    assert!(stdout.contains("trajectories/rollout-0001.csv"), "{stdout}");
    assert!(stdout.contains("measured 1.25"), "{stdout}");
    assert!(stdout.contains("measured 1.6"), "{stdout}");
}

/// A change to a task file's text.
type Edit = Box<dyn Fn(String) -> String>;

#[test]
fn bad_task_files_are_refused_before_anything_runs() {
    let throw = throw_dir();
    let slow_dir = throw.display().to_string();
    let cases: Vec<(&str, Edit, &str)> = vec![
        (
            "unknown key",
            Box::new(|t| t.replace("kernels = 20", "kernels = 20\nkernals = 3")),
            ":18: unknown field `kernals`",
        ),
        (
            "wrong type",
            Box::new(|t| t.replace("kernels = 20", "kernels = \"many\"")),
            ":17: invalid type: string \"many\"",
        ),
        (
            "missing goal",
            Box::new(|t| t.replace("[goal]", "[goal_]")),
            "unknown field `goal_`",
        ),
        (
            "one demo",
            Box::new(move |t| {
                t.replace(
                    &format!(
                        "[[demo]]\nfile = \"{}/demos/slow.csv\"\nquery = [1.0639]",
                        slow_dir
                    ),
                    "",
                )
            }),
            "1 [[demo]]: a skill generalizes over at least two demonstrations",
        ),
        (
            "same query",
            Box::new(|t| t.replace("query = [1.0639]", "query = [1.8079]")),
            ":14: [[demo]] query: [1.8079] is also the query of",
        ),
        (
            "desired outside",
            Box::new(|t| t.replace("desired = [1.5]", "desired = [2.5]")),
            ":26: [goal] desired: value 1 is 2.5, outside the bounds",
        ),
        (
            "no precision",
            Box::new(|t| t.replace("precision = 0.005         # 5 mm", "")),
            "[goal]: error learning needs `precision`",
        ),
        (
            "demo beyond the limits",
            Box::new(|t| t.replace("max_speed = 10.0", "max_speed = 2.0")),
            "fast.csv: the demonstration itself is beyond the task's limits: column `shoulder` at sample",
        ),
        (
            "limit of no column",
            Box::new(|t| {
                t.replace(
                    "elbow = {",
                    "wrist = { min = 0.0, max = 1.0, max_speed = 1.0 }\nelbow = {",
                )
            }),
            "[movement.limits] wrist: not a column of the demonstrations (shoulder,elbow)",
        ),
        (
            "no limits",
            Box::new(|t| {
                t.lines()
                    .filter(|l| {
                        !l.starts_with("shoulder")
                            && !l.starts_with("elbow")
                            && *l != "[movement.limits]"
                    })
                    .collect::<Vec<_>>()
                    .join("\n")
            }),
            "[movement]: no limits",
        ),
        (
            "golden on two values",
            Box::new(|t| {
                t.replace("query = [1.8079]", "query = [1.8079, 1.0]")
                    .replace("query = [1.0639]", "query = [1.0639, 1.0]")
            }),
            ":32: [learner] method: golden searches a one-value query; the demonstrations' \
             queries have 2: use \"secant\"",
        ),
        (
            "desired of another dimension",
            Box::new(|t| t.replace("desired = [1.5]", "desired = [1.5, 0.5]")),
            ":26: [goal] desired: 2 values; the demonstrations' queries have 1",
        ),
        (
            "power key for golden",
            Box::new(|t| t.replace("max_rollouts = 20", "max_rollouts = 20\ns1 = 0.3")),
            "[learner] s1: a PoWER setting",
        ),
        (
            "a timeout for the operator",
            Box::new(|t| {
                t.lines()
                    .map(|l| match l.starts_with("command = ") {
                        true => "operator = true",
                        false => l,
                    })
                    .collect::<Vec<_>>()
                    .join("\n")
            }),
            "[evaluate] timeout: for `command` evaluators",
        ),
        (
            "two evaluators",
            Box::new(|t| t.replace("timeout = 30", "timeout = 30\noperator = true")),
            "[evaluate]: give exactly one of",
        ),
        (
            "version",
            Box::new(|t| t.replace("version = 1", "version = 7")),
            ":6: version: 7: this primo reads task files of version 1",
        ),
        (
            "missing demo file",
            Box::new(|t| t.replace("demos/slow.csv", "demos/none.csv")),
            ":13: [[demo]] file:",
        ),
    ];
    for (what, edit, says) in cases {
        let file = task(
            &format!("bad-{}", what.replace(' ', "-")),
            "throw.toml",
            edit,
        );
        let out = tmp(&format!("out-bad-{}", what.replace(' ', "-")));
        let (code, _, err) = learn(&file, &out, &[]);
        assert_eq!(code, 2, "{what}: {err}");
        assert!(err.contains(says), "{what}: {err}");
        assert!(
            err.contains(&file.display().to_string()) || err.contains(".csv"),
            "{what}: {err}"
        );
        assert!(!out.exists(), "{what}: output made");
    }
    // Demonstrations with other columns: named by file and column.
    let dir = tmp("bad-columns");
    std::fs::create_dir_all(&dir).unwrap();
    let swapped = std::fs::read_to_string(throw.join("demos/slow.csv"))
        .unwrap()
        .replacen("t,shoulder,elbow", "t,elbow,shoulder", 1);
    std::fs::write(dir.join("swapped.csv"), swapped).unwrap();
    let file = task("bad-columns", "throw.toml", |t| {
        t.replace(
            &format!("{}/demos/slow.csv", throw.display()),
            &dir.join("swapped.csv").display().to_string(),
        )
    });
    let (code, _, err) = learn(&file, &tmp("out-bad-columns"), &[]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("swapped.csv: column 2 is `elbow`, expected `shoulder` (the columns are in another order)"),
        "{err}"
    );
    // The built-in pour is primo pour: its PoWER's roll-outs per update,
    // decay and reward are the paper's.
    let pour = tmp("bad-pour");
    std::fs::create_dir_all(&pour).unwrap();
    let text = std::fs::read_to_string(examples().join("pour.toml"))
        .unwrap()
        .replace(
            "method = \"golden\"",
            "method = \"power\"\nrollouts_per_update = 2",
        );
    std::fs::write(pour.join("task.toml"), text).unwrap();
    let (code, _, err) = learn(&pour.join("task.toml"), &tmp("out-bad-pour"), &[]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("[learner] rollouts_per_update: the built-in pour runs as `primo pour`"),
        "{err}"
    );
    // A flag that makes no sense for a task with its own evaluator.
    let (code, _, err) = learn(
        &task("bad-robot", "throw.toml", |t| t),
        &tmp("out-bad-robot"),
        &["--robot", "fri:127.0.0.1", "--scale", "/dev/null"],
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--robot/--scale"), "{err}");
}

/// `file` learned with the learner on the firmware in QEMU, then in this
/// process (outputs `out-NAME-mcu`, `out-NAME-host`): each run's
/// directory and what it printed.
fn on_the_mcu_and_here(name: &str, file: &Path) -> [(PathBuf, String); 2] {
    let (mcu, host) = (
        tmp(&format!("out-{name}-mcu")),
        tmp(&format!("out-{name}-host")),
    );
    let (code, on_mcu, err) = learn(file, &mcu, &["--coprocessor", "qemu"]);
    assert_eq!(code, 0, "{err}");
    assert!(on_mcu.contains("learner: firmware"), "{on_mcu}");
    let (code, in_process, err) = learn(file, &host, &[]);
    assert_eq!(code, 0, "{err}");
    [(mcu, on_mcu), (host, in_process)]
}

/// The roll-outs' lines of what a run printed.
fn rollout_lines(printed: &str) -> Vec<&str> {
    (printed.lines())
        .filter(|l| l.starts_with("roll-out"))
        .collect()
}

/// The run logs in `a` and `b` hold the same roll-outs, byte for byte.
fn same_logged_rollouts(a: &Path, b: &Path) {
    let log = |d: &Path| std::fs::read_to_string(d.join("run.log")).unwrap();
    assert_eq!(
        log(a).lines().skip(1).collect::<Vec<_>>(),
        log(b).lines().skip(1).collect::<Vec<_>>()
    );
}

#[test]
fn the_secant_learner_runs_on_the_emulated_mcu() {
    let file = task("copro", "throw-2d.toml", |t| t);
    let [(mcu, on_mcu), (host, in_process)] = on_the_mcu_and_here("copro", &file);
    // The same roll-outs, bit for bit: the M4F's secant is the host's.
    assert!(rollout_lines(&in_process).len() >= 2, "{in_process}");
    assert_eq!(rollout_lines(&on_mcu), rollout_lines(&in_process));
    assert_eq!(
        std::fs::read_to_string(mcu.join("rollouts.csv")).unwrap(),
        std::fs::read_to_string(host.join("rollouts.csv")).unwrap()
    );
}

#[test]
fn power_with_an_error_learned_query_runs_on_the_emulated_mcu() {
    let file = task("copro-el", "throw-power-el.toml", |t| {
        t.replace("max_rollouts = 40", "max_rollouts = 9")
    });
    let [(mcu, _), (host, _)] = on_the_mcu_and_here("copro-el", &file);
    // Every roll-out's query (error-learned) and Δθ, bit for bit.
    let csv = std::fs::read_to_string(host.join("rollouts.csv")).unwrap();
    assert_eq!(csv.lines().count(), 10, "{csv}");
    assert_eq!(
        std::fs::read_to_string(mcu.join("rollouts.csv")).unwrap(),
        csv
    );
    same_logged_rollouts(&mcu, &host);
}

/// The example throw toward 0.8 m, shorter than both demonstrations (1.06
/// and 1.81 m), learned by `method`: the query's search bounded below by
/// 0 m (a distance), secant-goals' goal by the shoulder's limits.
fn short_throw(t: String, method: &str) -> String {
    let goals = method == "secant-goals";
    (t.lines())
        .filter_map(|l| match l.split(" = ").next() {
            Some("desired") => Some("desired = [0.8]".into()),
            Some("low") if goals => None,
            Some("high") if goals => None,
            Some("low") => Some("low = [0.0]".into()),
            Some("method") => Some(format!("method = \"{method}\"")),
            _ => Some(l.to_string()),
        })
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn secant_goals_throws_shorter_than_the_demonstrations_where_the_query_cannot() {
    let run = |method: &str| {
        let file = task(&format!("short-{method}"), "throw.toml", |t| {
            short_throw(t, method)
        });
        let out = tmp(&format!("out-short-{method}"));
        let (code, stdout, err) = learn(&file, &out, &[]);
        assert_eq!(code, 0, "{method}: {err}");
        (out, stdout)
    };
    // The movement generalized to 0 m lands at 0.86 m: the query stalls
    // on its bound (it would reach 0.8 m at q = -0.76 m, τ ≈ 2 s).
    let (out, stdout) = run("secant");
    let s = summary(&out);
    assert_eq!(s["stopped"], "stalled", "{stdout}");
    let best = s["best"]["trial"]["measured"][0].as_f64().unwrap();
    assert!(best > 0.85, "{stdout}");
    // A smaller swing (the shoulder's goal) does it.
    let (out, stdout) = run("secant-goals");
    assert!(
        stdout.contains("toward q = 0.8, the goal of shoulder,"),
        "{stdout}"
    );
    let s = summary(&out);
    assert!(s["converged_at"].as_u64().unwrap() <= 6, "{stdout}");
    assert_eq!(s["goals"], serde_json::json!(["shoulder"]));
    assert_eq!(s["desired"], serde_json::json!([0.8]));
    let last = &s["last"];
    let measured = last["trial"]["measured"][0].as_f64().unwrap();
    assert!((measured - 0.8).abs() < 0.005, "{stdout}");
    // Every roll-out is generalized at the desired query; the learned
    // goal is where the trajectory ends.
    assert_eq!(last["query"], serde_json::json!([0.8]));
    let goal = last["trial"]["goals"][0][1].as_f64().unwrap();
    let n = last["rollout"].as_u64().unwrap();
    let trajectory =
        std::fs::read_to_string(out.join(format!("trajectories/rollout-{n:04}.csv"))).unwrap();
    let end: Vec<f64> = (trajectory.lines().last().unwrap().split(','))
        .map(|v| v.parse().unwrap())
        .collect();
    assert!((end[1] - goal).abs() < 1e-3, "{end:?} against {goal}");
    let csv = std::fs::read_to_string(out.join("rollouts.csv")).unwrap();
    assert!(
        csv.starts_with("rollout,update,mean,query,goal_shoulder,measured,error,"),
        "{csv}"
    );
    let line = stdout
        .lines()
        .find(|l| l.starts_with("roll-out   1:"))
        .unwrap();
    assert!(
        line.starts_with("roll-out   1: goals shoulder = -0.4"),
        "{line}"
    );
}

#[test]
fn a_secant_goals_run_resumes_as_if_never_stopped() {
    let edit = |t: String| short_throw(t, "secant-goals");
    let file = flaky_with("goals-resumed", "crash", edit);
    let out = tmp("out-goals-resumed");
    let (code, _, err) = learn(&file, &out, &[]);
    assert_eq!(code, 1, "{err}");
    assert_eq!(logged(&out), 2);
    let (code, stdout, err) = primo(&["learn", "--resume", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        stdout.lines().filter(|l| l.ends_with("(logged)")).count(),
        2,
        "{stdout}"
    );
    // The evaluator no longer fails: the same task run whole.
    let whole = tmp("out-goals-whole");
    let (code, _, err) = learn(&file, &whole, &[]);
    assert_eq!(code, 0, "{err}");
    for f in ["run.log", "rollouts.csv"] {
        assert_eq!(
            std::fs::read_to_string(out.join(f)).unwrap(),
            std::fs::read_to_string(whole.join(f)).unwrap(),
            "{f}"
        );
    }
    // The run resumed with `keys` added to its `[learner]`.
    let text = std::fs::read_to_string(&file).unwrap();
    let resume_with = |name: &str, keys: &str| {
        let edited = file.with_file_name(name);
        let method = "method = \"secant-goals\"";
        std::fs::write(&edited, text.replace(method, &format!("{method}\n{keys}"))).unwrap();
        let (code, _, err) = primo(&[
            "learn",
            "--resume",
            out.to_str().unwrap(),
            "--task",
            edited.to_str().unwrap(),
        ]);
        (code, err)
    };
    // Wider bounds for the goal are a change the logged roll-outs keep.
    let (code, err) = resume_with("wider.toml", "goals_min = [-2.6]");
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("resuming with [learner] goals_min [] -> [-2.6]"),
        "{err}"
    );
    // Bounds that change what the learner asks are refused, the goals
    // asked and logged named by column.
    let (code, err) = resume_with("narrow.toml", "goals_min = [-0.41]\ngoals_max = [-0.39]");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("(goals shoulder = "), "{err}");
    assert!(err.contains(", logged goals shoulder = "), "{err}");
}

#[test]
fn secant_goals_runs_on_the_emulated_mcu() {
    let file = task("copro-goals", "throw.toml", |t| {
        short_throw(t, "secant-goals")
    });
    let [(mcu, on_mcu), (host, in_process)] = on_the_mcu_and_here("copro-goals", &file);
    // The same goals asked, bit for bit, and the same learner states.
    assert!(rollout_lines(&in_process).len() >= 3, "{in_process}");
    assert_eq!(rollout_lines(&on_mcu), rollout_lines(&in_process));
    same_logged_rollouts(&mcu, &host);
}

#[test]
fn bad_goal_settings_are_refused_before_anything_runs() {
    let goals = |keys: &'static str| {
        move |t: String| {
            short_throw(t, "secant-goals").replace(
                "method = \"secant-goals\"",
                &format!("method = \"secant-goals\"\n{keys}"),
            )
        }
    };
    for (what, keys, says) in [
        (
            "no such column",
            "goals = [\"wrist\"]",
            "[learner] goals: `wrist` is no position column of the demonstrations (shoulder, \
             elbow)",
        ),
        (
            "too many",
            "goals = [\"shoulder\", \"elbow\"]",
            "[learner] goals: 2 column(s); the demonstrations' queries, and so the error, have \
             1 value(s)",
        ),
        (
            "start outside",
            "goals_min = [0.0]",
            "[learner] goals_min, goals_max: the movement generalized to the desired query \
             ends `shoulder` at -0.4",
        ),
        (
            "min above max",
            "goals_min = [0.5]\ngoals_max = [0.2]",
            "[learner] goals_max: value 1 is 0.2, not above goals_min's 0.5",
        ),
    ] {
        let name = format!("bad-goals-{}", what.replace(' ', "-"));
        let file = task(&name, "throw.toml", goals(keys));
        let out = tmp(&format!("out-{name}"));
        let (code, _, err) = learn(&file, &out, &[]);
        assert_eq!(code, 2, "{what}: {err}");
        assert!(err.contains(says), "{what}: {err}");
        assert!(err.contains(&file.display().to_string()), "{what}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{what}: {err}");
        assert!(!out.exists(), "{what}: output made");
    }
    // Two goals, as the demonstrations' order has them.
    let file = task("bad-goals-order", "throw-2d.toml", |t| {
        t.replace("low = [1.05, 0.6]\n", "")
            .replace("high = [1.75, 1.3]\n", "")
            .replace(
                "method = \"secant\"",
                "method = \"secant-goals\"\ngoals = [\"elbow\", \"shoulder\"]",
            )
    });
    let (code, _, err) = learn(&file, &tmp("out-bad-goals-order"), &[]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains(
            "[learner] goals: elbow, shoulder: the learner changes consecutive columns' goals, \
             in the demonstrations' order (shoulder, elbow)"
        ),
        "{err}"
    );
    // The built-in pour learns the bottle's volume, not goals; neither
    // does `primo pour`, whose --method does not offer it.
    let pour = tmp("bad-goals-pour");
    std::fs::create_dir_all(&pour).unwrap();
    let text = std::fs::read_to_string(examples().join("pour.toml"))
        .unwrap()
        .replace("method = \"golden\"", "method = \"secant-goals\"");
    std::fs::write(pour.join("task.toml"), text).unwrap();
    let (code, _, err) = learn(&pour.join("task.toml"), &tmp("out-bad-goals-pour"), &[]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("[learner] method: secant-goals learns the goals of the task's own"),
        "{err}"
    );
    let (code, _, err) = primo(&["pour", "--method", "secant-goals"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("secant-goals"), "{err}");
}

/// A task whose tool turns about z to a yaw on either side of 180°:
/// columns `x, qw, qx, qy, qz` (the quaternion's sign flipped on every
/// third row, as some recorders write it), the query the final yaw in
/// degrees within [0, 360), measured by a standard-library evaluator.
fn turn_task(name: &str, limits: &str) -> PathBuf {
    let dir = tmp(name);
    std::fs::create_dir_all(&dir).unwrap();
    for (file, from, to) in [("low.csv", 140.0f64, 170.0f64), ("high.csv", 220.0, 190.0)] {
        let mut csv = String::from("t,x,qw,qx,qy,qz\n");
        for i in 0..=50 {
            let t = i as f64 / 50.0;
            let s = t * t * (3.0 - 2.0 * t);
            let half = (from + (to - from) * s).to_radians() / 2.0;
            let sign = if i % 3 == 1 { -1.0 } else { 1.0 };
            csv += &format!(
                "{t},{},{},0,0,{}\n",
                0.1 * s,
                sign * half.cos(),
                sign * half.sin()
            );
        }
        std::fs::write(dir.join(file), csv).unwrap();
    }
    std::fs::write(
        dir.join("yaw.py"),
        r#"import csv, json, math, sys
for line in sys.stdin:
    request = json.loads(line)
    with open(request["csv"], newline="") as f:
        rows = list(csv.reader(f))
    assert rows[0] == ["t", "x", "qw", "qx", "qy", "qz"], rows[0]
    for r in rows[1:]:
        norm = math.sqrt(sum(float(v) ** 2 for v in r[2:]))
        assert abs(norm - 1) < 1e-5, r
    w, z = float(rows[-1][2]), float(rows[-1][5])
    yaw = math.degrees(2 * math.atan2(z, w)) % 360
    print(json.dumps({"rollout": request["rollout"], "measured": [yaw]}), flush=True)
"#,
    )
    .unwrap();
    let file = dir.join("task.toml");
    std::fs::write(
        &file,
        format!(
            r#"version = 1
[[demo]]
file = "low.csv"
query = [170.0]
[[demo]]
file = "high.csv"
query = [190.0]
[movement]
kernels = 10
[movement.limits]
x = {{ min = -1.0, max = 1.0, max_speed = 5.0 }}
{limits}
[goal]
desired = [184.0]
low = [165.0]
high = [195.0]
precision = 0.01
[learner]
method = "secant"
max_rollouts = 5
[evaluate]
command = ["python3", "yaw.py"]
"#
        ),
    )
    .unwrap();
    file
}

#[test]
fn an_orientation_group_is_learned_through_180_degrees() {
    let file = turn_task("turn", "");
    let out = tmp("out-turn");
    let (code, stdout, err) = learn(&file, &out, &[]);
    assert_eq!(code, 0, "{stdout}\n{err}");
    let s = summary(&out);
    // G(184°) lands there at once: the goals blend through 180°, not 0°.
    assert_eq!(s["converged_at"].as_u64(), Some(1), "{stdout}");
    let yaw = s["last"]["trial"]["measured"][0].as_f64().unwrap();
    assert!((yaw - 184.0).abs() < 0.01, "{yaw}");
    // A per-column limit on a quaternion's component is refused.
    let file = turn_task(
        "turn-limit",
        "qw = { min = -1.0, max = 1.0, max_speed = 5.0 }",
    );
    let (code, _, err) = learn(&file, &tmp("out-turn-limit"), &[]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("[movement.limits] qw: a component of the orientation qw,qx,qy,qz"),
        "{err}"
    );
}

/// A relative `--out` from another directory than the task file's: the
/// evaluator (started in the task file's directory) still finds each
/// roll-out's trajectory.
#[test]
fn a_relative_out_reaches_the_evaluator_in_the_task_files_directory() {
    let file = task("relative-out", "throw.toml", |t| t);
    let here = tmp("relative-out-cwd");
    std::fs::create_dir_all(&here).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_primo"))
        .args(["learn", "--task", file.to_str().unwrap(), "--out", "out"])
        .args(["--max-rollouts", "2"])
        .current_dir(&here)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert_eq!(logged(&here.join("out")), 3, "two roll-outs and the end");
}
