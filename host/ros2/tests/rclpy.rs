//! primo's ROS 2 executor against an independent peer: an rclpy
//! FollowJointTrajectory server with /joint_states
//! (tests/peers/fake_jtc.py), over DDS on loopback. See [`peer`] for how
//! the peers are run and why these tests skip without `PRIMO_PEERS_VENV`.

mod peer;

use std::time::{Duration, Instant};

use peer::Peer;
use primo_robot::{JointPath, Robot, safety::check_joints};
use primo_ros2::dds::{Event, Ros2Config, Run, execute};
use primo_ros2::{Controller, ErrorCode, Ros2Error};

/// From 0.1 rad on every joint to 0.3 rad in `seconds`, 21 samples.
fn path(seconds: f64) -> JointPath {
    let times = (0..=20).map(|k| f64::from(k) * seconds / 20.0).collect();
    let rows = (0..=20).map(|k| [0.1 + 0.01 * f64::from(k); 7]).collect();
    check_joints(&Robot::lwr4(), times, rows).unwrap()
}

/// The controller's joints in reverse (primo maps them by name) and at
/// the path's start.
const JOINTS: &str = "a7,a6,a5,a4,a3,a2,a1";
const AT_START: &str = "0.1,0.1,0.1,0.1,0.1,0.1,0.1";

fn config(domain: u16) -> Ros2Config {
    Ros2Config {
        domain,
        discovery: Duration::from_secs(20),
        ..Ros2Config::default()
    }
}

/// Starts the fake controller in `mode` and runs a 1 s path against it.
fn run(domain: u16, mode: &str, joints: &str, start: &str) -> Option<(Run, Peer, Vec<Event>)> {
    run_path(domain, mode, joints, start, &path(1.0))
}

/// Starts the fake controller in `mode` and runs `path` against it.
fn run_path(
    domain: u16,
    mode: &str,
    joints: &str,
    start: &str,
    path: &JointPath,
) -> Option<(Run, Peer, Vec<Event>)> {
    let venv = peer::venv(&format!("ros2 {mode}"))?;
    let args = ["--mode", mode, "--joints", joints, "--start", start];
    let mut jtc = Peer::start(&venv, domain, "fake_jtc.py", &args);
    let controller = Controller::parse("ros2:/arm_controller").unwrap();
    let mut events = Vec::new();
    let started = Instant::now();
    let run = execute(&controller, path, &config(domain), &mut |e| events.push(e));
    let run = match run {
        Ok(run) => run,
        Err(e) => panic!("{e}\n{}", jtc.stderr()),
    };
    eprintln!(
        "ros2 {mode}: {:.2} s, events {events:?}, {} states, {} feedback, {:?}",
        started.elapsed().as_secs_f64(),
        run.executed.times.len(),
        run.feedback,
        run.outcome
    );
    jtc.drain(Duration::from_millis(300));
    Some((run, jtc, events))
}

#[test]
fn a_goal_runs_to_success_and_its_joint_series_is_recorded() {
    let Some((run, jtc, events)) = run(11, "ok", JOINTS, AT_START) else {
        return;
    };
    assert_eq!(run.outcome, Ok(()), "{}", jtc.stderr());
    assert!(events.contains(&Event::Accepted), "{events:?}");
    // The goal names the description's joints in its order.
    let goal = jtc.said.iter().find(|l| l.contains("\"goal\"")).unwrap();
    assert!(
        goal.contains(r#""joints": ["a1", "a2", "a3", "a4", "a5", "a6", "a7"], "points": 21"#),
        "{goal}"
    );
    assert!(jtc.said.iter().any(|l| l.contains("\"succeed\"")));
    // Up to 100 Hz for about a second (fewer on a busy machine), in the
    // chain's order, from the start to the end.
    let e = &run.executed;
    assert!(e.times.len() > 5, "{} joint states", e.times.len());
    let last = e.rows(7).last().unwrap();
    for q in last {
        assert!((q - 0.3).abs() < 0.05, "ended at {last:?}");
    }
    let a1: Vec<f64> = e.rows(7).map(|q| q[0]).collect();
    assert!(a1.windows(2).all(|w| w[0] <= w[1] + 1e-9), "{a1:?}");
    assert!(run.feedback > 0, "{} feedback messages", run.feedback);
    assert!(e.times.windows(2).all(|w| w[0] <= w[1]));
}

#[test]
fn a_rejected_goal_is_a_typed_error() {
    let Some((run, _, _)) = run(12, "reject", JOINTS, AT_START) else {
        return;
    };
    assert_eq!(run.outcome, Err(Ros2Error::Rejected));
    assert!(run.executed.times.is_empty());
}

#[test]
fn an_abort_mid_way_is_the_controllers_error_code() {
    let Some((run, _, _)) = run(13, "abort", JOINTS, AT_START) else {
        return;
    };
    assert_eq!(
        run.outcome,
        Err(Ros2Error::Failed {
            code: ErrorCode::PathToleranceViolated,
            message: "fake_jtc: half-way".into()
        })
    );
    // It stopped on the way (about half-way; the last state seen may lag
    // on a busy machine).
    let last = run.executed.rows(7).last().map(|r| r[0]);
    assert!(last.is_some_and(|a1| a1 < 0.29), "last a1 {last:?}");
}

#[test]
fn joints_that_are_not_the_controllers_are_invalid_joints() {
    // The controller has an eighth joint the description lacks.
    let Some((run, _, _)) = run(
        14,
        "ok",
        "a1,a2,a3,a4,a5,a6,a7,rail",
        "0.1,0.1,0.1,0.1,0.1,0.1,0.1,0",
    ) else {
        return;
    };
    assert!(
        matches!(
            run.outcome,
            Err(Ros2Error::Failed {
                code: ErrorCode::InvalidJoints,
                ..
            })
        ),
        "{:?}",
        run.outcome
    );
}

#[test]
fn joint_states_falling_silent_cancel_the_goal() {
    // The goal lasts 4 s; 1 s of silence ends it.
    let Some((run, mut jtc, _)) = run_path(15, "silent", JOINTS, AT_START, &path(4.0)) else {
        return;
    };
    assert!(
        matches!(run.outcome, Err(Ros2Error::StatesLost { .. })),
        "{:?}",
        run.outcome
    );
    jtc.wait_for("\"canceled\"", Duration::from_secs(5));
}

#[test]
fn stale_joint_states_cancel_the_goal() {
    // The goal lasts 4 s; the stamp freezes at its start, 1 s is stale.
    let Some((run, mut jtc, _)) = run_path(16, "stale", JOINTS, AT_START, &path(4.0)) else {
        return;
    };
    assert!(
        matches!(run.outcome, Err(Ros2Error::Stale { .. })),
        "{:?}",
        run.outcome
    );
    jtc.wait_for("\"canceled\"", Duration::from_secs(5));
}

#[test]
fn without_joint_states_nothing_is_sent() {
    let Some((run, jtc, events)) = run(17, "mute", JOINTS, AT_START) else {
        return;
    };
    assert!(
        matches!(run.outcome, Err(Ros2Error::NoJointStates { .. })),
        "{:?}",
        run.outcome
    );
    assert!(!events.contains(&Event::GoalSent));
    assert!(!jtc.said.iter().any(|l| l.contains("\"goal\"")));
}

#[test]
fn a_robot_away_from_the_start_gets_no_goal() {
    let Some((run, jtc, _)) = run(18, "ok", JOINTS, "0,0,0,0,0,0,0") else {
        return;
    };
    let Err(e) = &run.outcome else {
        panic!("succeeded away from the start")
    };
    assert!(
        e.to_string()
            .starts_with("the robot is not at the trajectory's start: joint `a1` is at 0.0000"),
        "{e}"
    );
    assert!(!jtc.said.iter().any(|l| l.contains("\"goal\"")));
}

#[test]
fn a_robot_away_from_the_start_is_brought_there_with_an_approach() {
    let Some(venv) = peer::venv("ros2 approach") else {
        return;
    };
    let jtc = Peer::start(&venv, 20, "fake_jtc.py", &["--joints", JOINTS]);
    let controller = Controller::parse("ros2:/arm_controller").unwrap();
    let mut cfg = config(20);
    cfg.execution.approach_speed = Some(0.5);
    let run = execute(&controller, &path(1.0), &cfg, &mut |_| {})
        .unwrap_or_else(|e| panic!("{e}\n{}", jtc.stderr()));
    assert_eq!(run.outcome, Ok(()), "{}", jtc.stderr());
    // From 0 (0.1 rad at half of a2's 1.92 rad/s: about 0.2 s), then the
    // path to 0.3.
    let rows: Vec<&[f64]> = run.executed.rows(7).collect();
    assert!(rows[0].iter().all(|q| q.abs() < 0.05), "{:?}", rows[0]);
    let last = rows[rows.len() - 1];
    assert!(last.iter().all(|q| (q - 0.3).abs() < 0.05), "{last:?}");
}

#[test]
fn no_controller_is_a_typed_error() {
    if peer::venv("ros2 no controller").is_none() {
        return;
    }
    let controller = Controller::parse("ros2:/nobody").unwrap();
    let cfg = Ros2Config {
        discovery: Duration::from_millis(500),
        ..config(19)
    };
    let e = execute(&controller, &path(1.0), &cfg, &mut |_| {}).unwrap_err();
    assert!(
        e.to_string().starts_with(
            "no FollowJointTrajectory server at /nobody/follow_joint_trajectory within"
        ),
        "{e}"
    );
}
