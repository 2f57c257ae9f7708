//! `primo learn` of a task whose limits are a robot's, from its URDF: the
//! example throw on its arm's URDF, a Cartesian skill solved through a
//! seven-joint arm's inverse kinematics for its evaluator, and the robot's
//! settings refused before anything runs.
mod common;
use std::path::{Path, PathBuf};

use common::{primo, seven, tmp};

fn throw_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/throw")
        .canonicalize()
        .unwrap()
}

fn learn(task: &Path, out: &Path) -> (i32, String, String) {
    primo(&[
        "learn",
        "--task",
        task.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ])
}

#[test]
fn the_throw_on_its_arms_urdf_is_the_throw_on_the_same_limits_by_column() {
    let throw = throw_dir();
    let (by_urdf, by_column) = (tmp("out-throw-arm"), tmp("out-throw-columns"));
    let (code, stdout, err) = learn(&throw.join("throw-arm.toml"), &by_urdf);
    assert_eq!(code, 0, "{stdout}\n{err}");
    assert!(stdout.contains("reached the precision"), "{stdout}");
    let (code, _, err) = learn(&throw.join("throw.toml"), &by_column);
    assert_eq!(code, 0, "{err}");
    let rollouts = |dir: &Path| std::fs::read_to_string(dir.join("rollouts.csv")).unwrap();
    assert_eq!(rollouts(&by_urdf), rollouts(&by_column));
    let first = std::fs::read_to_string(by_urdf.join("trajectories/rollout-0001.csv")).unwrap();
    assert!(first.starts_with("t,shoulder,elbow\n"), "{first}");
}

/// The example throw's task with `edit` applied, in its own directory
/// beside a copy of the arm's URDF (`urdf` applied to it), the
/// demonstrations and the evaluator named absolutely.
fn throw_task(
    name: &str,
    edit: &dyn Fn(String) -> String,
    urdf: &dyn Fn(String) -> String,
) -> PathBuf {
    let dir = tmp(name);
    std::fs::create_dir_all(&dir).unwrap();
    let throw = throw_dir();
    let arm = std::fs::read_to_string(throw.join("arm.urdf")).unwrap();
    std::fs::write(dir.join("arm.urdf"), urdf(arm)).unwrap();
    let text = std::fs::read_to_string(throw.join("throw-arm.toml"))
        .unwrap()
        .replace("\"demos/", &format!("\"{}/demos/", throw.display()))
        .replace("\"throw.py\"", &format!("\"{}/throw.py\"", throw.display()));
    let file = dir.join("task.toml");
    std::fs::write(&file, edit(text)).unwrap();
    file
}

type Edit = Box<dyn Fn(String) -> String>;

#[test]
fn a_robots_settings_are_refused_before_anything_runs() {
    let robot = "robot = \"arm.urdf\"";
    let cases: Vec<(&str, Edit, Edit, &str)> = vec![
        (
            "missing file",
            Box::new(move |t| t.replace(robot, "robot = \"panda.urdf\"")),
            Box::new(|u| u),
            ":19: [movement] robot: `panda.urdf`: ",
        ),
        (
            "xacro",
            Box::new(|t| t),
            Box::new(|u| {
                u.replace(
                    "<robot name",
                    "<robot xmlns:xacro=\"http://www.ros.org/wiki/xacro\" name",
                )
                .replace(
                    "<link name=\"hand\"/>",
                    "<xacro:property name=\"l\" value=\"1\"/>",
                )
            }),
            "xacro",
        ),
        (
            "no limits",
            Box::new(|t| t),
            Box::new(|u| {
                u.replace(
                    "<limit lower=\"0\" upper=\"1.0\" velocity=\"5\" effort=\"50\"/>",
                    "",
                )
            }),
            "joint `elbow`: it has no a <limit> limit",
        ),
        (
            "limits widened",
            Box::new(|t| {
                t.replace(
                    "[goal]",
                    "[movement.limits]\nelbow = { min = 0.0, max = 1.0, max_speed = 9.0 }\n[goal]",
                )
            }),
            Box::new(|u| u),
            "are wider than its URDF's",
        ),
        (
            "limits for no joint",
            Box::new(|t| {
                t.replace(
                    "[goal]",
                    "[movement.limits]\nwrist = { min = 0.0, max = 1.0, max_speed = 1.0 }\n[goal]",
                )
            }),
            Box::new(|u| u),
            "limits given for `wrist`, which is no moving joint",
        ),
        (
            "tip not below",
            Box::new(move |t| {
                t.replace(
                    robot,
                    "robot = \"arm.urdf\"\nbase = \"hand\"\ntip = \"stand\"",
                )
            }),
            Box::new(|u| u),
            "tip link `stand` is not below the base link `hand`",
        ),
        (
            "base for the preset",
            Box::new(move |t| t.replace(robot, "robot = \"lwr4\"\nbase = \"stand\"")),
            Box::new(|u| u),
            "[movement] base: the preset `lwr4` is its own chain",
        ),
        (
            "workspace",
            Box::new(|t| {
                t.replace("[goal]", "[movement.workspace]\ncolumns = [\"x\", \"y\", \"z\"]\nmin = [0, 0, 0]\nmax = [1, 1, 1]\nmax_speed = 1.0\n[goal]")
            }),
            Box::new(|u| u),
            "a workspace box limits position columns, not a robot's joints",
        ),
        (
            "acceleration without a robot",
            Box::new(move |t| {
                t.replace(robot, "").replace("[goal]", "[movement.limits]\nshoulder = { min = -2.5, max = 1.0, max_speed = 10.0 }\nelbow = { min = 0.0, max = 1.0, max_speed = 5.0 }\n[goal]")
            }),
            Box::new(|u| u),
            "[movement] max_acceleration: a robot's setting",
        ),
        (
            "bad acceleration",
            Box::new(|t| t.replace("max_acceleration = 100.0", "max_acceleration = -1.0")),
            Box::new(|u| u),
            "[movement] max_acceleration: -1: must be a positive number",
        ),
        (
            "demonstration beyond narrowed limits",
            Box::new(|t| {
                t.replace("[goal]", "[movement.limits]\nshoulder = { min = -1.5, max = 1.0, max_speed = 10.0 }\n[goal]")
            }),
            Box::new(|u| u),
            "the demonstration itself is beyond the task's limits: joint shoulder at sample 0",
        ),
        (
            "demonstration beyond the acceleration",
            Box::new(|t| t.replace("max_acceleration = 100.0", "max_acceleration = 10.0")),
            Box::new(|u| u),
            "the demonstration itself is beyond the task's limits: joint shoulder at sample",
        ),
        (
            "start for a joint trajectory",
            Box::new(move |t| {
                t.replace(
                    robot,
                    "robot = \"arm.urdf\"\nstart = { shoulder = -2.0, elbow = 0.5 }",
                )
            }),
            Box::new(|u| u),
            "a start posture is for a tool trajectory",
        ),
        (
            "start naming no joint",
            Box::new(move |t| {
                t.replace(
                    robot,
                    "robot = \"arm.urdf\"\nstart = { shoulder = -2.0, knee = 0.5 }",
                )
            }),
            Box::new(|u| u),
            "[movement] start: `knee` names no joint of",
        ),
        (
            "start missing a joint",
            Box::new(move |t| {
                t.replace(robot, "robot = \"arm.urdf\"\nstart = { shoulder = -2.0 }")
            }),
            Box::new(|u| u),
            "[movement] start: no position for joint `elbow`",
        ),
        (
            "start beyond a limit",
            Box::new(move |t| {
                t.replace(
                    robot,
                    "robot = \"arm.urdf\"\nstart = { shoulder = -2.0, elbow = 2.0 }",
                )
            }),
            Box::new(|u| u),
            "[movement] start: joint `elbow`: 2.0000 rad (114.59 deg) is outside its limits",
        ),
        (
            "start without a robot",
            Box::new(move |t| {
                t.replace(robot, "start = { shoulder = -2.0, elbow = 0.5 }").replace("max_acceleration = 100.0", "").replace("[goal]", "[movement.limits]\nshoulder = { min = -2.5, max = 1.0, max_speed = 10.0 }\nelbow = { min = 0.0, max = 1.0, max_speed = 5.0 }\n[goal]")
            }),
            Box::new(|u| u),
            "[movement] start: a robot's setting",
        ),
        (
            "tool beyond reach",
            Box::new(move |t| {
                t.replace(
                    robot,
                    "robot = \"arm.urdf\"\ntool = { xyz = [0, 0, 2e3], rpy = [0, 0, 0] }",
                )
            }),
            Box::new(|u| u),
            "[movement] tool: xyz is farther than 1000 m from the tip",
        ),
        (
            "a column naming no joint",
            Box::new(|t| t),
            Box::new(|u| u.replace("\"elbow\"", "\"knee\"")),
            "column 3 `elbow` names no joint; the columns after t are the joints (shoulder, knee)",
        ),
    ];
    for (what, edit, urdf, expected) in cases {
        let name = what.replace(' ', "-");
        let file = throw_task(&name, &*edit, &*urdf);
        let out = tmp(&format!("out-{name}"));
        let (code, stdout, err) = learn(&file, &out);
        assert_eq!(code, 2, "{what}: {stdout}\n{err}");
        assert!(err.contains(expected), "{what}: {err}");
        assert!(!out.join("run.log").exists(), "{what}: a run began");
    }
    // Limits for a joint its URDF gives none: the run goes on with them.
    let file = throw_task(
        "limits-supplied",
        &|t| {
            t.replace(
                "[goal]",
                "[movement.limits]\nelbow = { min = 0.0, max = 1.0, max_speed = 5.0 }\n[goal]",
            )
        },
        &|u| {
            u.replace(
                "<limit lower=\"0\" upper=\"1.0\" velocity=\"5\" effort=\"50\"/>",
                "",
            )
        },
    );
    let (code, stdout, err) = learn(&file, &tmp("out-limits-supplied"));
    assert_eq!(code, 0, "{stdout}\n{err}");
}

/// The evaluator: checks that the joint columns primo solved reach each
/// row's tool pose (its own forward kinematics of [`seven`]), and
/// measures where the tool ends along x.
const REACH: &str = r#"import csv, json, math, sys

def rot(axis, a):
    c, s = math.cos(a), math.sin(a)
    return [[c, -s, 0], [s, c, 0], [0, 0, 1]] if axis == "z" else [[c, 0, s], [0, 1, 0], [-s, 0, c]]

def mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]

def forward(q):
    r, p = [[1, 0, 0], [0, 1, 0], [0, 0, 1]], [0.0, 0.0, 0.0]
    for i, a in enumerate(q):
        p = [p[k] + 0.2 * r[k][2] for k in range(3)]
        r = mul(r, rot("z" if i % 2 == 0 else "y", a))
    return [p[k] + 0.1 * r[k][2] for k in range(3)]

# The posture the robot starts from, if the task gives one: the first row
# must be solved to it.
start = json.loads(sys.argv[1]) if len(sys.argv) > 1 else None

for line in sys.stdin:
    request = json.loads(line)
    with open(request["csv"], newline="") as f:
        rows = list(csv.reader(f))
    header = rows[0]
    assert header == ["t", "x", "y", "z", "qw", "qx", "qy", "qz"] + ["q%d" % i for i in range(1, 8)], header
    for r in rows[1:]:
        values = [float(v) for v in r]
        reached = forward(values[8:15])
        assert all(abs(u - v) < 1e-5 for u, v in zip(reached, values[1:4])), (reached, values[1:4])
    first = [float(v) for v in rows[1][8:15]]
    assert start is None or all(abs(u - v) < 1e-3 for u, v in zip(first, start)), (first, start)
    print(json.dumps({"rollout": request["rollout"], "measured": [float(rows[-1][1])]}), flush=True)
"#;

/// Two demonstrations of the tool moving from one pose to another (the
/// arm's forward kinematics along a joint-space blend, its elbow out of
/// the plane), ending at x = `end_x[k]`, written as tool poses; with
/// `start`, the task gives the posture they were recorded from.
fn reach_task(name: &str, far: bool, start: bool) -> PathBuf {
    let dir = tmp(name);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("seven.urdf"), seven()).unwrap();
    std::fs::write(dir.join("reach.py"), REACH).unwrap();
    let urdf = primo_robot::urdf::Urdf::parse("seven.urdf", &seven()).unwrap();
    let chain = primo_robot::Chain::from_urdf(&urdf, &Default::default()).unwrap();
    let posture = [0.3, 0.6, 0.8, -1.2, -0.4, 0.8, 0.2];
    let mut queries = Vec::new();
    for (file, shoulder) in [("near.csv", 0.3), ("wide.csv", 0.6)] {
        let end = [0.3, shoulder, 0.8, -1.0, -0.4, 0.6, 0.2];
        let mut csv = String::from("t,x,y,z,qw,qx,qy,qz\n");
        let mut last = 0.0;
        for i in 0..=100 {
            let t = i as f64 / 100.0;
            let s = t * t * (3.0 - 2.0 * t);
            let q: Vec<f64> = posture
                .iter()
                .zip(&end)
                .map(|(a, b)| a + s * (b - a))
                .collect();
            let p = chain.forward(&q);
            let (v, r) = (p.translation.vector, p.rotation);
            let x = if far && i == 100 { 5.0 } else { v.x };
            csv += &format!("{t},{x},{},{},{},{},{},{}\n", v.y, v.z, r.w, r.i, r.j, r.k);
            last = v.x;
        }
        std::fs::write(dir.join(file), csv).unwrap();
        queries.push(last);
    }
    let (start, argument) = match start {
        true => {
            let named: Vec<String> = (posture.iter().enumerate())
                .map(|(i, q)| format!("q{} = {q}", i + 1))
                .collect();
            let start = format!("start = {{ {} }}\n", named.join(", "));
            (start, format!(", \"{posture:?}\""))
        }
        false => (String::new(), String::new()),
    };
    let file = dir.join("task.toml");
    std::fs::write(
        &file,
        format!(
            r#"version = 1
[[demo]]
file = "near.csv"
query = [{}]
[[demo]]
file = "wide.csv"
query = [{}]
[movement]
kernels = 15
robot = "seven.urdf"
tip = "hand"
{start}[goal]
desired = [{}]
low = [{}]
high = [{}]
precision = 0.001
[learner]
method = "secant"
max_rollouts = 8
[evaluate]
command = ["python3", "reach.py"{argument}]
"#,
            queries[0],
            queries[1],
            (queries[0] + queries[1]) / 2.0 + 0.01,
            queries[0],
            queries[1],
        ),
    )
    .unwrap();
    file
}

#[test]
fn a_tool_trajectory_reaches_its_evaluator_with_the_joints_it_was_solved_to() {
    let file = reach_task("reach", false, false);
    let out = tmp("out-reach");
    let (code, stdout, err) = learn(&file, &out);
    assert_eq!(code, 0, "{stdout}\n{err}");
    assert!(stdout.contains("reached the precision"), "{stdout}");
    // A demonstration the arm cannot reach is refused, its sample named.
    let file = reach_task("reach-far", true, false);
    let out = tmp("out-reach-far");
    let (code, _, err) = learn(&file, &out);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("near.csv: the demonstration itself is beyond the task's limits: sample 100 (t = 1.000 s): tool pose [5.000"),
        "{err}"
    );
    assert!(!out.join("run.log").exists());
}

#[test]
fn secant_goals_moves_a_tool_poses_goal_within_the_bounds_given() {
    let file = reach_task("reach-goals", false, false);
    let text = std::fs::read_to_string(&file).unwrap();
    let with = |keys: &str| {
        let lines = (text.lines())
            .filter(|l| !l.starts_with("low = ") && !l.starts_with("high = "))
            .map(|l| match l {
                "method = \"secant\"" => format!("method = \"secant-goals\"{keys}"),
                l => l.to_string(),
            });
        std::fs::write(&file, lines.collect::<Vec<_>>().join("\n")).unwrap();
    };
    // A tool pose's columns have no limits of their own: the robot's are
    // its joints'.
    with("");
    let (code, _, err) = learn(&file, &tmp("out-reach-goals-unbounded"));
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains(
            "[learner] goals_min: `x` has no limits of its own to bound its goal: give \
             goals_min and goals_max"
        ),
        "{err}"
    );
    with("\ngoals_min = [-2.0]\ngoals_max = [2.0]");
    let (code, stdout, err) = learn(&file, &tmp("out-reach-goals"));
    assert_eq!(code, 0, "{stdout}\n{err}");
    assert!(stdout.contains("reached the precision"), "{stdout}");
    assert!(stdout.contains("goals x = "), "{stdout}");
}

#[test]
fn a_tool_trajectory_is_solved_from_the_robots_start_posture() {
    let file = reach_task("reach-start", false, true);
    let out = tmp("out-reach-start");
    let (code, stdout, err) = learn(&file, &out);
    assert_eq!(code, 0, "{stdout}\n{err}");
    assert!(stdout.contains("reached the precision"), "{stdout}");
}
