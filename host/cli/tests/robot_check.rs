//! `primo robot check`: trajectories against the limits of a robot from
//! its URDF, or of the built-in LWR 4. Exit 0 passes, 1 fails the check
//! (the violation on stdout), 2 is input that cannot be checked.

mod common;

use common::{primo, seven, tmp};

/// A planar arm: two revolute joints about z (links 0.4 and 0.3 m, ±2 rad
/// at 1 rad/s), then a prismatic slide along x (0 to 0.2 m at 0.1 m/s).
const PLANAR: &str = r#"<?xml version="1.0"?>
<robot name="planar">
  <link name="base"/> <link name="upper"/> <link name="fore"/> <link name="hand"/>
  <joint name="shoulder" type="revolute">
    <parent link="base"/> <child link="upper"/> <axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" velocity="1" effort="10"/>
  </joint>
  <joint name="elbow" type="revolute">
    <parent link="upper"/> <child link="fore"/>
    <origin xyz="0.4 0 0"/> <axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" velocity="1" effort="10"/>
  </joint>
  <joint name="slide" type="prismatic">
    <parent link="fore"/> <child link="hand"/>
    <origin xyz="0.3 0 0"/> <axis xyz="1 0 0"/>
    <limit lower="0" upper="0.2" velocity="0.1" effort="10"/>
  </joint>
</robot>
"#;

fn write(name: &str, text: &str) -> String {
    let path = tmp(name);
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_string()
}

/// A CSV of `header` and rows at 10 Hz.
fn csv(name: &str, header: &str, rows: &[&[f64]]) -> String {
    let mut text = format!("{header}\n");
    for (i, row) in rows.iter().enumerate() {
        let values: Vec<String> = row.iter().map(|v| v.to_string()).collect();
        text.push_str(&format!("{},{}\n", i as f64 * 0.1, values.join(",")));
    }
    write(name, &text)
}

fn check(traj: &str, model: Option<&str>, more: &[&str]) -> (i32, String, String) {
    let mut args = vec!["robot", "check", traj];
    if let Some(m) = model {
        args.extend(["--model", m]);
    }
    args.extend(more);
    primo(&args)
}

#[test]
fn a_trajectory_within_the_limits_passes_in_any_column_order() {
    let model = write("planar.urdf", PLANAR);
    let traj = csv(
        "planar-ok.csv",
        "t,slide,shoulder,elbow",
        &[&[0.1, 0.0, 0.5], &[0.11, 0.05, 0.5], &[0.12, 0.1, 0.5]],
    );
    let (code, out, err) = check(&traj, Some(&model), &[]);
    assert_eq!(code, 0, "{out}{err}");
    assert_eq!(
        out,
        format!(
            "primo robot check: {traj} passes: 3 samples over 0.200 s within the limits of \
             planar (3 joints, base to hand)\n"
        )
    );
    assert!(err.is_empty(), "{err}");
    // The seven-joint arm, its chain from the mount's root link.
    let model = write("seven.urdf", &seven());
    let header = "t,q1,q2,q3,q4,q5,q6,q7";
    let traj = csv("seven-ok.csv", header, &[&[0.1; 7], &[0.2; 7], &[0.3; 7]]);
    let (code, out, err) = check(&traj, Some(&model), &[]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(
        out.contains("within the limits of seven (7 joints, world to hand)"),
        "{out}"
    );
    // A chain of its middle: --base and --tip.
    let traj = csv(
        "seven-mid.csv",
        "t,q3,q4",
        &[&[0.1, 0.0], &[0.2, 0.1], &[0.3, 0.2]],
    );
    let (code, out, err) = check(&traj, Some(&model), &["--base", "l2", "--tip", "l4"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("(2 joints, l2 to l4)"), "{out}");
}

#[test]
fn the_first_violation_is_the_answer_and_the_exit_status_1() {
    let model = write("planar.urdf", PLANAR);
    // The slide at 0.25 m, beyond its 0.2 m.
    let traj = csv(
        "planar-far.csv",
        "t,shoulder,elbow,slide",
        &[&[0.0, 0.0, 0.1], &[0.0, 0.0, 0.11], &[0.0, 0.0, 0.25]],
    );
    let (code, out, err) = check(&traj, Some(&model), &[]);
    assert_eq!(code, 1, "{out}{err}");
    assert_eq!(
        out,
        format!(
            "primo robot check: {traj} fails: joint slide at sample 2 (t = 0.200 s): 0.2500 m \
             beyond its upper limit 0.2000 m\n"
        )
    );
    assert_eq!(
        err,
        format!(
            "primo: robot check: {traj} does not keep to the limits of planar (3 joints, base \
             to hand)\n"
        )
    );
    // The elbow turning 0.15 rad in 0.1 s, beyond its 1 rad/s.
    let traj = csv(
        "planar-fast.csv",
        "t,shoulder,elbow,slide",
        &[&[0.0, 0.0, 0.1], &[0.0, 0.15, 0.1], &[0.0, 0.2, 0.1]],
    );
    let (code, out, _) = check(&traj, Some(&model), &[]);
    assert_eq!(code, 1, "{out}");
    assert!(
        out.contains(
            "fails: joint elbow at sample 1 (t = 0.100 s): 1.5000 rad/s (85.94 deg/s) beyond its \
             velocity limit 1.0000 rad/s (57.30 deg/s)"
        ),
        "{out}"
    );
    // Within its speed, but 0.5 rad/s gained in 0.1 s is 5 rad/s².
    let traj = csv(
        "planar-jerk.csv",
        "t,shoulder,elbow,slide",
        &[&[0.0, 0.0, 0.1], &[0.0, 0.0, 0.1], &[0.0, 0.05, 0.1]],
    );
    let (code, out, _) = check(&traj, Some(&model), &[]);
    assert_eq!(code, 0, "{out}");
    let (code, out, _) = check(&traj, Some(&model), &["--max-acceleration", "2"]);
    assert_eq!(code, 1, "{out}");
    assert!(
        out.contains("beyond the acceleration bound 2.0000 rad/s²"),
        "{out}"
    );
}

#[test]
fn the_built_in_lwr_4_takes_its_joint_names_and_aliases() {
    let still = [0.0, 0.5, 0.0, -1.0, 0.0, 0.5, 0.0];
    let traj = csv(
        "lwr.csv",
        "t,A1,A2,A3,A4,A5,A6,A7",
        &[&still, &still, &still],
    );
    let (code, out, err) = check(&traj, None, &[]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(
        out.contains("within the limits of lwr4 (7 joints, base to flange)"),
        "{out}"
    );
    let mut bent = still;
    bent[3] = -2.2;
    let traj = csv(
        "lwr-bent.csv",
        "t,a1,a2,a3,a4,a5,a6,a7",
        &[&still, &still, &bent],
    );
    let (code, out, _) = check(&traj, None, &[]);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("joint a4 at sample 2"), "{out}");
    // --base and --tip choose within a URDF.
    let (code, _, err) = check(&traj, None, &["--tip", "flange"]);
    assert_eq!(code, 2);
    assert!(err.contains("--model"), "{err}");
}

#[test]
fn columns_must_be_the_chains_joints_every_one() {
    let model = write("planar.urdf", PLANAR);
    let rows: &[&[f64]] = &[&[0.0, 0.0, 0.1], &[0.0, 0.0, 0.1], &[0.0, 0.0, 0.1]];
    let traj = csv("planar-wrist.csv", "t,shoulder,wrist,slide", rows);
    let (code, out, err) = check(&traj, Some(&model), &[]);
    assert_eq!((code, out.as_str()), (2, ""));
    assert_eq!(
        err,
        format!(
            "primo: {traj}: column 3 `wrist` names no joint; the columns after t are the joints \
             (shoulder, elbow, slide) or the tool pose (x,y,z,qw,qx,qy,qz)\n"
        )
    );
    let rows: &[&[f64]] = &[&[0.0, 0.0], &[0.0, 0.0], &[0.0, 0.0]];
    let traj = csv("planar-two.csv", "t,shoulder,elbow", rows);
    let (code, _, err) = check(&traj, Some(&model), &[]);
    assert_eq!(code, 2);
    assert!(err.contains("no column for joint `slide`"), "{err}");
    let traj = write("planar-bad.csv", "t,shoulder,elbow,slide\n0,0,0,x\n");
    let (code, _, err) = check(&traj, Some(&model), &[]);
    assert_eq!(code, 2);
    assert!(
        err.contains("planar-bad.csv:2:4: `x` is not a number"),
        "{err}"
    );
}

#[test]
fn a_urdf_that_cannot_be_checked_is_refused_at_its_line() {
    let rows: &[&[f64]] = &[&[0.0, 0.0], &[0.0, 0.0], &[0.0, 0.0]];
    let traj = csv("two.csv", "t,shoulder,elbow", rows);
    let refused = |name: &str, text: &str, more: &[&str]| {
        let model = write(name, text);
        let (code, out, err) = check(&traj, Some(&model), more);
        assert_eq!(code, 2, "{out}{err}");
        assert!(out.is_empty(), "{out}");
        let err = err.strip_prefix("primo: ").unwrap().trim_end().to_string();
        (model, err)
    };
    // Not well-formed: the line of the missing end tag.
    let broken = PLANAR.replace("<link name=\"hand\"/>", "<link name=\"hand\">");
    let (model, err) = refused("broken.urdf", &broken, &[]);
    assert!(err.starts_with(&format!("{model}:")), "{err}");
    assert!(err.contains("not well-formed XML"), "{err}");
    let line: u32 = err[model.len() + 1..]
        .split(':')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(line >= 3, "{err}");
    let xacro = "<robot name=\"x\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\">\n\
                 <xacro:property name=\"l\" value=\"1\"/>\n</robot>\n";
    let (model, err) = refused("arm.urdf.xacro", xacro, &[]);
    assert!(
        err.starts_with(&format!("{model}:2:1: this is a xacro file")),
        "{err}"
    );
    let mimic = PLANAR.replace(
        "<limit lower=\"-2\" upper=\"2\" velocity=\"1\" effort=\"10\"/>\n  </joint>\n  <joint name=\"slide\"",
        "<limit lower=\"-2\" upper=\"2\" velocity=\"1\" effort=\"10\"/>\n    <mimic joint=\"shoulder\"/>\n  </joint>\n  <joint name=\"slide\"",
    );
    assert_ne!(mimic, PLANAR);
    let (model, err) = refused("mimic.urdf", &mimic, &[]);
    assert!(
        err.starts_with(&format!("{model}:8:3: joint `elbow`: it mimics `shoulder`")),
        "{err}"
    );
    let unlimited = PLANAR.replacen(
        "<limit lower=\"-2\" upper=\"2\" velocity=\"1\" effort=\"10\"/>",
        "",
        1,
    );
    let (model, err) = refused("unlimited.urdf", &unlimited, &[]);
    assert!(
        err.starts_with(&format!("{model}:4:3: joint `shoulder`: it has no")),
        "{err}"
    );
    let model = write("planar.urdf", PLANAR);
    let (code, _, err) = check(&traj, Some(&model), &["--base", "fore", "--tip", "upper"]);
    assert_eq!(code, 2);
    assert!(
        err.contains("tip link `upper` is not below the base link `fore`"),
        "{err}"
    );
    let (code, _, err) = check(&traj, Some(&tmp("none.urdf").to_string_lossy()), &[]);
    assert_eq!(code, 2);
    assert!(err.contains("--model "), "{err}");
}

/// The planar arm's tool pose at `q`: the slide's hand on the x axis of
/// the forearm, turned by the two angles.
fn pose(q: [f64; 3]) -> [f64; 7] {
    let (a, b) = (q[0], q[0] + q[1]);
    let reach = 0.3 + q[2];
    [
        0.4 * a.cos() + reach * b.cos(),
        0.4 * a.sin() + reach * b.sin(),
        0.0,
        (b / 2.0).cos(),
        0.0,
        0.0,
        (b / 2.0).sin(),
    ]
}

#[test]
fn a_tool_trajectory_is_solved_and_its_first_unreachable_pose_named() {
    let model = write("planar.urdf", PLANAR);
    let header = "t,x,y,z,qw,qx,qy,qz";
    let path: Vec<[f64; 7]> = (0..5)
        .map(|i| pose([0.3 + 0.02 * i as f64, 0.8, 0.1]))
        .collect();
    let rows: Vec<&[f64]> = path.iter().map(|p| p.as_slice()).collect();
    let traj = csv("tool-ok.csv", header, &rows);
    let (code, out, err) = check(&traj, Some(&model), &[]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("passes: 5 samples over 0.400 s"), "{out}");
    // The fourth pose 1 m out: the arm reaches 0.9 m.
    let mut far = path.clone();
    far[3] = [1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
    let rows: Vec<&[f64]> = far.iter().map(|p| p.as_slice()).collect();
    let traj = csv("tool-far.csv", header, &rows);
    let (code, out, _) = check(&traj, Some(&model), &[]);
    assert_eq!(code, 1, "{out}");
    assert!(
        out.contains(
            "fails: sample 3 (t = 0.300 s): tool pose [1.000, 0.000, 0.000, 1.000, 0.000, 0.000, \
             0.000]: inverse kinematics did not converge"
        ),
        "{out}"
    );
    // A pose column missing.
    let traj = write(
        "tool-short.csv",
        "t,x,y,z,qw,qx,qy\n0,0,0,0,1,0,0\n1,0,0,0,1,0,0\n2,0,0,0,1,0,0\n",
    );
    let (code, _, err) = check(&traj, Some(&model), &[]);
    assert_eq!(code, 2);
    assert!(err.contains("no column `qz`"), "{err}");
}

#[test]
fn a_start_posture_names_every_joint_within_its_limits() {
    let model = write("planar.urdf", PLANAR);
    let start = [0.3, 0.8, 0.1];
    let path: Vec<[f64; 7]> = (0..5)
        .map(|i| pose([start[0] + 0.02 * i as f64, start[1], start[2]]))
        .collect();
    let rows: Vec<&[f64]> = path.iter().map(|p| p.as_slice()).collect();
    let traj = csv("tool-start.csv", "t,x,y,z,qw,qx,qy,qz", &rows);
    let given = "--start=slide=0.1,shoulder=0.3,elbow=0.8";
    let (code, out, err) = check(&traj, Some(&model), &[given]);
    assert_eq!(code, 0, "{out}{err}");
    let refused = |start: &str, traj: &str| {
        let (code, out, err) = check(traj, Some(&model), &["--start", start]);
        assert_eq!((code, out.as_str()), (2, ""), "{start}: {err}");
        err
    };
    let err = refused("shoulder=0.3,elbow=0.8", &traj);
    assert!(
        err.contains("--start: no position for joint `slide`"),
        "{err}"
    );
    let err = refused("shoulder=0.3,elbow=0.8,slide=0.1,wrist=0", &traj);
    assert!(
        err.contains("--start: `wrist` names no joint of planar"),
        "{err}"
    );
    let err = refused("shoulder=0.3,elbow=0.8,slide=0.3", &traj);
    assert!(
        err.contains("--start: joint `slide`: 0.3000 m is outside its limits 0.0000 m to 0.2000 m"),
        "{err}"
    );
    let err = refused("shoulder=0.3,elbow", &traj);
    assert!(err.contains("`elbow`: give JOINT=POSITION"), "{err}");
    let err = refused("shoulder=0.3,elbow=far,slide=0", &traj);
    assert!(err.contains("the position `far` is not a number"), "{err}");
    // A joint trajectory starts where its first sample is.
    let joints = csv(
        "joints-start.csv",
        "t,shoulder,elbow,slide",
        &[&start, &start, &start],
    );
    let err = refused("shoulder=0.3,elbow=0.8,slide=0.1", &joints);
    assert!(
        err.contains("a start posture is for a tool trajectory"),
        "{err}"
    );
}
