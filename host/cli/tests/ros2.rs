//! `primo robot play --robot ros2:/CONTROLLER` end to end against an
//! rclpy joint trajectory controller (tests/peers/fake_jtc.py), run as
//! primo-ros2's own tests run their peers (its tests/peer/mod.rs: skipped
//! without `PRIMO_PEERS_VENV`, only in a loopback-only network namespace,
//! a ROS_DOMAIN_ID of each test's own).

mod common;
#[path = "../../ros2/tests/peer/mod.rs"]
mod peer;

use common::{primo_env, tmp};
use peer::Peer;

/// 1 s from 0.1 rad on every joint to 0.3 rad, as `primo dmp run` writes.
fn trajectory() -> std::path::PathBuf {
    let mut text = String::from("t,a1,a2,a3,a4,a5,a6,a7\n");
    for k in 0..=20 {
        let q = 0.1 + 0.01 * f64::from(k);
        text.push_str(&format!(
            "{},{}\n",
            f64::from(k) * 0.05,
            vec![q.to_string(); 7].join(",")
        ));
    }
    let file = tmp("play.csv");
    std::fs::write(&file, text).unwrap();
    file
}

/// Plays the trajectory through the fake controller in `mode`, recording
/// the joint states: exit status, stdout, stderr, the record.
fn play(domain: u16, mode: &str) -> Option<(i32, String, String, String)> {
    let venv = peer::venv(&format!("primo robot play ros2 {mode}"))?;
    let args = [
        "--mode",
        mode,
        "--joints",
        "a7,a6,a5,a4,a3,a2,a1",
        "--start",
        "0.1,0.1,0.1,0.1,0.1,0.1,0.1",
    ];
    let jtc = Peer::start(&venv, domain, "fake_jtc.py", &args);
    let csv = trajectory();
    let record = tmp("executed.csv");
    let domain = domain.to_string();
    let (status, out, err) = primo_env(
        &[
            "robot",
            "play",
            csv.to_str().unwrap(),
            "--robot",
            "ros2:/arm_controller",
            "--start-timeout",
            "20",
            "--record",
            record.to_str().unwrap(),
        ],
        &[
            ("ROS_DOMAIN_ID", &domain),
            ("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST"),
            ("ROS_DISTRO", "jazzy"),
        ],
    );
    let recorded = std::fs::read_to_string(&record)
        .unwrap_or_else(|e| panic!("no record ({e}); primo said {out}{err}\n{}", jtc.stderr()));
    drop(jtc);
    Some((status, out, err, recorded))
}

#[test]
fn play_through_ros2_completes_and_records_the_joint_states() {
    let Some((status, out, err, recorded)) = play(31, "ok") else {
        return;
    };
    assert_eq!(status, 0, "{out}{err}");
    assert!(out.contains("the controller accepted the goal"), "{out}");
    assert!(out.ends_with("primo robot play: completed\n"), "{out}");
    let mut lines = recorded.lines();
    assert_eq!(lines.next(), Some("t,a1,a2,a3,a4,a5,a6,a7"));
    let rows: Vec<&str> = lines.collect();
    // Up to 100 Hz (fewer on a busy machine), ending at the end.
    assert!(rows.len() > 5, "{} rows", rows.len());
    let last: Vec<f64> = rows[rows.len() - 1]
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    assert!(last[1..].iter().all(|q| (q - 0.3).abs() < 0.05), "{last:?}");
}

#[test]
fn an_abort_mid_way_exits_1_with_the_controllers_error_and_keeps_the_record() {
    let Some((status, out, err, recorded)) = play(32, "abort") else {
        return;
    };
    assert_eq!(status, 1, "{out}{err}");
    assert_eq!(
        err,
        "primo: robot play: the controller stopped the trajectory: a joint left the path \
         tolerance (PATH_TOLERANCE_VIOLATED): \"fake_jtc: half-way\"\n"
    );
    assert!(recorded.lines().count() > 2, "{recorded}");
}

#[test]
fn a_rejected_goal_exits_1() {
    let Some((status, _, err, recorded)) = play(33, "reject") else {
        return;
    };
    assert_eq!(status, 1, "{err}");
    assert!(
        err.contains("the controller rejected the goal: the robot did not move"),
        "{err}"
    );
    assert_eq!(recorded, "t,a1,a2,a3,a4,a5,a6,a7\n");
}

#[test]
fn no_controller_exits_1_after_the_start_timeout() {
    if peer::venv("primo robot play ros2, no controller").is_none() {
        return;
    }
    let csv = trajectory();
    let (status, _, err) = primo_env(
        &[
            "robot",
            "play",
            csv.to_str().unwrap(),
            "--robot",
            "ros2:/nobody",
            "--start-timeout",
            "0.5",
        ],
        &[("ROS_DOMAIN_ID", "34")],
    );
    assert_eq!(status, 1, "{err}");
    assert!(
        err.contains("no FollowJointTrajectory server at /nobody/follow_joint_trajectory within"),
        "{err}"
    );
}

/// `primo learn` of the example throw (two joints, its arm's URDF), its
/// roll-outs executed by the fake controller in `mode` before throw.py
/// measures them: exit status, stdout, stderr.
fn learn(peer: &Peer, domain: &str, args: &[&str]) -> (i32, String, String) {
    let (status, out, err) = primo_env(
        &[&["learn", "--robot", "ros2:/arm_controller"], args].concat(),
        &[
            ("ROS_DOMAIN_ID", domain),
            ("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST"),
            ("ROS_DISTRO", "jazzy"),
        ],
    );
    if status > 1 {
        panic!(
            "primo learn {args:?}: {status}\n{out}{err}\n{}",
            peer.stderr()
        );
    }
    (status, out, err)
}

#[test]
fn a_learning_run_through_ros2_ends_on_an_abort_and_resumes() {
    let Some(venv) = peer::venv("primo learn ros2") else {
        return;
    };
    let task = peer::root().join("examples/throw/throw-arm.toml");
    let out = tmp("learn-ros2");
    let (task, out_s) = (task.to_str().unwrap(), out.to_str().unwrap());
    let arm = ["--joints", "elbow,shoulder", "--start", "0.6,-2.0"];
    let jtc = Peer::start(
        &venv,
        35,
        "fake_jtc.py",
        &[&["--mode", "abort"], &arm[..]].concat(),
    );
    let (status, _, err) = learn(
        &jtc,
        "35",
        &["--task", task, "--out", out_s, "--max-rollouts", "2"],
    );
    assert_eq!(status, 1, "{err}");
    assert!(
        err.contains(
            "roll-out 1: the robot did not complete it: the controller stopped the trajectory: \
             a joint left the path tolerance (PATH_TOLERANCE_VIOLATED)"
        ),
        "{err}"
    );
    let executed = out.join("trajectories/rollout-0001-executed.csv");
    let text = std::fs::read_to_string(&executed).unwrap();
    assert!(text.starts_with("t,shoulder,elbow\n"), "{text}");
    drop(jtc);
    // Resuming needs the robot again; with it, the run goes on.
    let (status, _, err) = primo_env(&["learn", "--resume", out_s], &[("ROS_DOMAIN_ID", "35")]);
    assert_eq!(status, 2, "{err}");
    assert!(
        err.contains("executed by the robot ros2:/arm_controller: give it again"),
        "{err}"
    );
    let jtc = Peer::start(
        &venv,
        35,
        "fake_jtc.py",
        &[&["--mode", "ok"], &arm[..]].concat(),
    );
    let (status, stdout, err) = learn(&jtc, "35", &["--resume", out_s]);
    assert_eq!(status, 0, "{stdout}{err}\n{}", jtc.stderr());
    for n in 1..=2 {
        let executed = out.join(format!("trajectories/rollout-{n:04}-executed.csv"));
        let rows = std::fs::read_to_string(&executed).unwrap().lines().count();
        assert!(rows > 3, "roll-out {n}: {rows} rows");
    }
}
