//! `primo robot play --robot franka:…` end to end against `primo robot
//! sim-fci` (both the real binaries, on 127.0.0.1): a roll-out, a reflex
//! (exit status 1), a trajectory beyond the FCI's rates and a bad address
//! (exit status 2).

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};

mod common;
use common::{primo, tmp};

/// A running `primo robot sim-fci`, killed when dropped.
struct SimFci {
    child: Child,
    port: u16,
}

impl SimFci {
    fn start(extra: &[&str]) -> SimFci {
        SimFci::start_at(0, extra)
    }

    /// On `port` (0: any free one).
    fn start_at(port: u16, extra: &[&str]) -> SimFci {
        let mut child = Command::new(env!("CARGO_BIN_EXE_primo"))
            .args([
                "robot",
                "sim-fci",
                "--port",
                &port.to_string(),
                "--no-realtime",
            ])
            .args(extra)
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("sim-fci starts");
        let stdout = child.stdout.take().expect("its stdout");
        let mut line = String::new();
        BufReader::new(stdout)
            .read_line(&mut line)
            .expect("a line from sim-fci");
        let port = line
            .trim()
            .rsplit(':')
            .next()
            .and_then(|p| p.parse().ok())
            .unwrap_or_else(|| panic!("no address in {line:?}"));
        SimFci { child, port }
    }

    fn robot(&self) -> String {
        format!("franka:127.0.0.1:{}", self.port)
    }
}

impl Drop for SimFci {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// `primo robot play CSV` on the simulated controller with `extra` flags:
/// exit status, stdout, stderr.
fn play(sim: &SimFci, csv: &str, extra: &[&str]) -> (i32, String, String) {
    let robot = sim.robot();
    let mut args = vec!["robot", "play", csv, "--robot", &robot, "--no-realtime"];
    args.extend(extra);
    primo(&args)
}

/// A minimum-jerk move of joint 1 by `amplitude` in `seconds` from the
/// FR3's start, every 10 ms.
fn trajectory(name: &str, amplitude: f64, seconds: f64) -> String {
    let home = [0.0, 0.0, 0.0, -1.57, 0.0, 1.57, 0.785];
    let mut csv = String::from("t,joint1,joint2,joint3,joint4,joint5,joint6,joint7\n");
    let n = (seconds / 0.01).round() as usize;
    for k in 0..=n {
        let s = k as f64 / n as f64;
        let mut q = home;
        q[0] += amplitude * s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
        let row: Vec<String> = q.iter().map(|x| format!("{x:.6}")).collect();
        csv.push_str(&format!("{:.3},{}\n", k as f64 * 0.01, row.join(",")));
    }
    let path = tmp(name);
    std::fs::write(&path, csv).expect("the trajectory is written");
    path.display().to_string()
}

#[test]
fn a_rollout_on_the_simulated_fr3_completes() {
    let sim = SimFci::start(&["--once"]);
    let csv = trajectory("move.csv", 0.3, 1.0);
    let (status, out, err) = play(&sim, &csv, &[]);
    assert_eq!(status, 0, "{out}\n{err}");
    assert!(out.contains("primo robot play: motion finished"), "{out}");
    assert!(out.ends_with("primo robot play: completed\n"), "{out}");
}

#[test]
fn a_reflex_ends_the_rollout_with_status_1() {
    let sim = SimFci::start(&[
        "--once",
        "--reflex-after",
        "300",
        "--reflex",
        "cartesian_reflex",
    ]);
    let csv = trajectory("move.csv", 0.3, 1.0);
    let (status, out, err) = play(&sim, &csv, &[]);
    assert_eq!(status, 1, "{out}\n{err}");
    // The reflex shows in the state stream and in the motion's answer on
    // the command channel, whichever comes first: "(a reflex)" or
    // "(aborted by a reflex)".
    assert!(
        err.contains("the robot stopped the motion (") && err.contains("reflex cartesian_reflex"),
        "{err}"
    );
}

#[test]
fn a_trajectory_beyond_the_fcis_rates_is_refused_with_status_2() {
    let sim = SimFci::start(&["--once"]);
    // 0.2 rad in 0.2 s: within the velocity limit, beyond 10 rad/s².
    let csv = trajectory("fast.csv", 0.2, 0.2);
    let (status, out, err) = play(&sim, &csv, &[]);
    assert_eq!(status, 2, "{out}\n{err}");
    assert!(err.contains("joint1 acceleration"), "{err}");
    assert!(err.contains("nothing moved"), "{err}");
    assert!(!out.contains("motion started"), "{out}");
}

#[test]
fn a_bad_address_is_status_2() {
    let csv = trajectory("move.csv", 0.3, 1.0);
    let (status, _, err) = primo(&["robot", "play", &csv, "--robot", "franka:127.0.0.1:http"]);
    assert_eq!(status, 2, "{err}");
    assert!(err.contains("expected franka:ADDR[:PORT]"), "{err}");
}

/// `primo learn --task examples/fr3/reach.toml --robot franka:…`: each
/// learned roll-out of a task over the FR3's joints (its limits from the
/// FR3's URDF) is executed on the simulated controller before the task's
/// evaluator measures it; the executed joint series are kept beside the
/// planned ones.
#[test]
fn a_learning_run_executes_its_rollouts_on_the_simulated_fr3() {
    let task =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/fr3/reach.toml");
    let sim = SimFci::start(&[]);
    let out = tmp("learn-fr3");
    let (code, stdout, err) = primo(&[
        "learn",
        "--task",
        task.to_str().unwrap(),
        "--robot",
        &sim.robot(),
        "--out",
        out.to_str().unwrap(),
        "--force",
    ]);
    assert_eq!(code, 0, "{stdout}{err}");
    assert!(stdout.contains("reached the precision"), "{stdout}");
    let executed = out.join("trajectories/rollout-0001-executed.csv");
    let text = std::fs::read_to_string(&executed).unwrap();
    assert!(text.starts_with("t,joint1,joint2"), "{text}");
    // One row a millisecond of a 2 s movement.
    assert!(text.lines().count() > 1500, "{} rows", text.lines().count());
}

/// A reflex mid-roll-out ends a learning run with exit status 1, what the
/// robot did before it kept, the run log intact; resumed with the robot
/// (its faults cleared), the run makes the roll-out again and ends.
#[test]
fn a_reflex_ends_a_learning_run_with_status_1_and_resume_goes_on() {
    let task =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/fr3/reach.toml");
    let out = tmp("learn-fr3-reflex");
    let out_s = out.to_str().unwrap();
    let faulty = SimFci::start(&["--reflex-after", "500", "--reflex", "joint_reflex"]);
    let (code, _, err) = primo(&[
        "learn",
        "--task",
        task.to_str().unwrap(),
        "--robot",
        &faulty.robot(),
        "--out",
        out_s,
        "--force",
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("roll-out 1") && err.contains("joint_reflex"),
        "{err}"
    );
    let executed =
        std::fs::read_to_string(out.join("trajectories/rollout-0001-executed.csv")).unwrap();
    let rows = executed.lines().count();
    assert!((300..1500).contains(&rows), "{rows} rows before the reflex");
    // The same robot (its address is in the run's log), its fault cleared.
    let port = faulty.port;
    drop(faulty);
    let sim = SimFci::start_at(port, &[]);
    let (code, stdout, err) = primo(&["learn", "--resume", out_s, "--robot", &sim.robot()]);
    assert_eq!(code, 0, "{stdout}{err}");
    assert!(stdout.contains("reached the precision"), "{stdout}");
}

/// The FR3's maximum tracking error of joint 1 in `play`'s report, deg.
fn joint1_error(out: &str) -> f64 {
    out.lines()
        .find_map(|l| l.trim().strip_prefix("j1"))
        .and_then(|l| l.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no j1 row in {out}"))
}

/// An arm held still for 0.6 s mid-move: played as planned, the command
/// runs away from it (the simulated arm then jumps to it); with phase
/// stopping the command waits, every setpoint within the FCI's rates.
#[test]
fn phase_stopping_waits_for_a_held_arm() {
    let held = ["--once", "--hold-after", "300", "--hold-for", "600"];
    let csv = trajectory("held.csv", 0.6, 1.5);
    let sim = SimFci::start(&held);
    let (status, plain, err) = play(&sim, &csv, &[]);
    assert_eq!(status, 0, "{plain}\n{err}");
    let sim = SimFci::start(&held);
    let (status, out, err) = play(&sim, &csv, &["--phase-stop", "10000"]);
    assert_eq!(status, 0, "{out}\n{err}");
    assert!(out.contains("phase stopping: the slowest 0.0"), "{out}");
    let (ran_away, waited) = (joint1_error(&plain), joint1_error(&out));
    assert!(ran_away > 10.0, "{plain}");
    assert!(waited < 0.25 * ran_away, "{waited} deg against {ran_away}");
}

#[test]
fn phase_stopping_needs_a_positive_gain_and_a_franka() {
    let csv = trajectory("move.csv", 0.3, 1.0);
    for (robot, k, why) in [
        (
            "franka:127.0.0.1",
            "0",
            "--phase-stop: 0: must be a positive number",
        ),
        (
            "franka:127.0.0.1",
            "nan",
            "--phase-stop: NaN: must be a positive number",
        ),
        (
            "fri:127.0.0.1",
            "1000",
            "phase stopping streams a Franka's setpoints",
        ),
    ] {
        let (status, _, err) = primo(&["robot", "play", &csv, "--robot", robot, "--phase-stop", k]);
        assert_eq!(status, 2, "{err}");
        assert!(err.contains(why), "{err}");
    }
}

/// `[movement] phase_stop` in a task file: the Franka that executes the
/// roll-outs waits for its held arm; without a robot the key is refused
/// before anything runs or is written.
#[test]
fn a_tasks_phase_stop_waits_for_a_held_arm() {
    let examples = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/fr3");
    let dir = tmp("phase-stop-task");
    std::fs::create_dir_all(&dir).unwrap();
    for f in ["near.csv", "far.csv", "ended.py"] {
        std::fs::copy(examples.join(f), dir.join(f)).unwrap();
    }
    let text = std::fs::read_to_string(examples.join("reach.toml")).unwrap();
    let urdf = examples.join("../../host/franka/src/fr3.urdf");
    let text = text.replace(
        "robot = \"../../host/franka/src/fr3.urdf\"",
        &format!(
            "robot = {:?}\nphase_stop = 10000",
            urdf.display().to_string()
        ),
    );
    let task = dir.join("reach.toml");
    std::fs::write(&task, text).unwrap();
    let out = dir.join("run");
    let learn = |robot: Option<&str>| {
        let mut args = vec!["learn", "--task", task.to_str().unwrap()];
        args.extend(["--out", out.to_str().unwrap(), "--force"]);
        args.extend(robot.iter().flat_map(|r| ["--robot", r]));
        primo(&args)
    };
    let (code, _, err) = learn(None);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("[movement] phase_stop") && err.contains("no robot"),
        "{err}"
    );
    assert!(!out.exists(), "refused before anything was written");
    let sim = SimFci::start(&["--hold-after", "500", "--hold-for", "500"]);
    let (code, stdout, err) = learn(Some(&sim.robot()));
    assert_eq!(code, 0, "{stdout}{err}");
    let executed =
        std::fs::read_to_string(out.join("trajectories/rollout-0001-executed.csv")).unwrap();
    let planned = std::fs::read_to_string(out.join("trajectories/rollout-0001.csv")).unwrap();
    let seconds: f64 = planned
        .lines()
        .last()
        .and_then(|l| l.split(',').next())
        .and_then(|t| t.parse().ok())
        .unwrap();
    // A millisecond a row: the movement ran longer than planned by most
    // of the half second the arm was held.
    let rows = executed.lines().count() as f64;
    assert!(
        rows > seconds * 1000.0 + 250.0,
        "{rows} rows for {seconds} s"
    );
}

/// An arm held for longer than phase stopping waits (three times the
/// planned motion) is stopped with exit status 1, not waited for forever.
#[test]
fn an_arm_held_too_long_stops_the_motion_with_status_1() {
    let sim = SimFci::start(&["--once", "--hold-after", "200", "--hold-for", "60000"]);
    let csv = trajectory("move.csv", 0.3, 0.5);
    let (status, out, err) = play(&sim, &csv, &["--phase-stop", "10000"]);
    assert_eq!(status, 1, "{out}\n{err}");
    assert!(
        err.contains("phase stopping waited for the arm until the motion had taken 3 times"),
        "{err}"
    );
}
