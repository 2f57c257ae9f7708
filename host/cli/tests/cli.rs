//! `primo dmp` end to end: the binary on real files.
use std::path::Path;

mod common;
use common::{primo, tmp};

fn demo_path() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/reach.csv")
        .display()
        .to_string()
}

#[test]
fn fit_then_run_reproduces_the_demo_and_reaches_new_goals() {
    let json = tmp("reach.json");
    let (code, _, err) = primo(&[
        "dmp",
        "fit",
        "--demo",
        &demo_path(),
        "--kernels",
        "30",
        "--out",
        json.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let (code, csv, err) = primo(&["dmp", "run", json.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let demo = std::fs::read_to_string(demo_path()).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], "t,x,z");
    assert_eq!(
        lines.len(),
        demo.lines().count(),
        "one row per demo sample at the same dt"
    );
    for (a, b) in lines.iter().zip(demo.lines()).skip(1) {
        let a: Vec<f32> = a.split(',').map(|v| v.parse().unwrap()).collect();
        let b: Vec<f32> = b.split(',').map(|v| v.parse().unwrap()).collect();
        assert!((a[0] - b[0]).abs() < 1e-6);
        assert!(
            (a[1] - b[1]).abs() < 2e-3 && (a[2] - b[2]).abs() < 2e-3,
            "{a:?} vs {b:?}"
        );
    }
    // New start, goal and tau; output to a file; t runs 0..=tau inclusive.
    let traj = tmp("traj.csv");
    let (code, _, err) = primo(&[
        "dmp",
        "run",
        json.to_str().unwrap(),
        "--dt",
        "0.1",
        "--tau",
        "2",
        "--start",
        "-0.1,0.1",
        "--goal",
        "0.3,0.3",
        "--out",
        traj.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let text = std::fs::read_to_string(&traj).unwrap();
    let rows: Vec<&str> = text.lines().collect();
    assert_eq!(rows.len(), 1 + 21);
    assert!(rows[1].starts_with("0,-0.1,0.1"), "{}", rows[1]);
    let last: Vec<f32> = rows[21].split(',').map(|v| v.parse().unwrap()).collect();
    assert_eq!(last[0], 2.0);
    assert!(
        (last[1] - 0.3).abs() < 5e-3 && (last[2] - 0.3).abs() < 5e-3,
        "{last:?}"
    );
    assert_eq!(rows[10].split(',').next(), Some("0.9"));
}

/// A 1 kHz recording of two DoF at `origin` seconds: the same instants
/// whatever the origin (those a recorder stamping from `origin` can hold),
/// each stamp printed so that it reads back exactly.
fn recording_at(origin: f64) -> String {
    let mut text = String::from("t,x,z\n");
    for i in 0..=1000 {
        let since_first = (1.7e9 + f64::from(i) * 1e-3) - 1.7e9;
        let s = since_first as f32;
        let (x, z) = (
            s * s * (3.0 - 2.0 * s),
            0.25 * (std::f32::consts::PI * s).sin(),
        );
        text.push_str(&format!("{},{x},{z}\n", origin + since_first));
    }
    text
}

#[test]
fn a_recording_stamped_in_unix_time_fits_as_from_0() {
    let fit = |origin: f64| {
        let (demo, json) = (
            tmp(&format!("at-{origin}.csv")),
            tmp(&format!("at-{origin}.json")),
        );
        std::fs::write(&demo, recording_at(origin)).unwrap();
        let demo = demo.to_str().unwrap();
        let (code, _, err) = primo(&[
            "dmp",
            "fit",
            "--demo",
            demo,
            "--out",
            json.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{origin}: {err}");
        std::fs::read_to_string(json).unwrap()
    };
    let from_zero = fit(0.0);
    assert_eq!(fit(1.7e9), from_zero, "Unix time");
    assert_eq!(fit(-2.5), from_zero, "before 0");
}

/// A trajectory CSV's rows, its header skipped.
fn csv_rows(csv: &str) -> Vec<Vec<f64>> {
    csv.lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect()
}

/// `primo dmp fit --demo DEMO ARGS --out NAME` (in the test's directory):
/// the file written and its JSON.
fn fit_to(demo: &Path, args: &[&str], name: &str) -> (std::path::PathBuf, serde_json::Value) {
    let json = tmp(name);
    let mut all = vec!["dmp", "fit", "--demo", demo.to_str().unwrap()];
    all.extend(args);
    all.extend(["--out", json.to_str().unwrap()]);
    let (code, _, err) = primo(&all);
    assert_eq!(code, 0, "{args:?}: {err}");
    let file = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    (json, file)
}

/// A reach in `x` with `z` rising 0.1 m besides a via-point bump of
/// 0.25 m, at 1 kHz.
fn rise_and_bump() -> String {
    let mut text = String::from("t,x,z\n");
    for i in 0..=1000 {
        let t = i as f32 / 1000.0;
        let s = t * t * (3.0 - 2.0 * t);
        let z = 0.1 + 0.1 * s + 0.25 * (std::f32::consts::PI * t).sin().powi(2);
        text.push_str(&format!("{t},{},{z}\n", 0.6 * s));
    }
    text
}

#[test]
fn scaling_none_or_global_keeps_a_bump_whose_goal_meets_its_start() {
    let demo = tmp("bump.csv");
    std::fs::write(&demo, rise_and_bump()).unwrap();
    let height = |scaling: &str| {
        let (json, file) = fit_to(&demo, &["--scaling", scaling], &format!("{scaling}.json"));
        assert_eq!(file["version"], 6);
        assert_eq!(file["dmp"].get("reference").is_some(), scaling == "global");
        // z's goal onto its start.
        let (code, csv, err) = primo(&["dmp", "run", json.to_str().unwrap(), "--goal", "0.6,0.1"]);
        assert_eq!(code, 0, "{scaling}: {err}");
        let z = csv
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(2).unwrap().parse::<f32>().unwrap());
        (z.fold(0.0f32, |m, z| m.max((z - 0.1).abs())), json)
    };
    let (per_dof, json) = height("per-dof");
    assert!(per_dof < 1e-3, "per DoF the bump is flattened: {per_dof}");
    for scaling in ["none", "global"] {
        let (h, _) = height(scaling);
        assert!(h > 0.15, "{scaling}: {h} of the 0.25 m bump");
    }
    // A version 3 file (before the choice) scales per DoF, as it did.
    let text = std::fs::read_to_string(&json).unwrap();
    let old = tmp("v3.json");
    std::fs::write(&old, text.replace("\"version\": 5", "\"version\": 3")).unwrap();
    let run =
        |f: &std::path::Path| primo(&["dmp", "run", f.to_str().unwrap(), "--goal", "0.6,0.1"]);
    assert_eq!(run(&old), run(&json));
    let (code, _, err) = primo(&[
        "dmp",
        "fit",
        "--demo",
        demo.to_str().unwrap(),
        "--scaling",
        "both",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("per-dof") && err.contains("global"), "{err}");
}

#[test]
fn malformed_input_gets_a_one_line_error_and_status_2() {
    let cases: &[(&str, &str)] = &[
        (
            "0,1\n0.5,2\n1,3\n",
            "bad.csv:1:1: first header column must be `t`",
        ),
        (
            "t,x\n0,1\n0.5,oops\n1,3\n",
            "bad.csv:3:2: `oops` is not a number",
        ),
        (
            "t,x\n0,1\n1,2\n0.5,3\n",
            "bad.csv:4:1: t = 0.5 does not increase",
        ),
        (
            "t,x\n0,1\n1000,2\n1000.00001,3\n",
            "bad.csv:4:1: t = 1000.00001 is 1.000e-5 s after the previous row: 1000.00001 s \
             into the recording, stamps must be at least 6.104e-5 s apart",
        ),
        ("t,x\n0,1\n1,2\n", "bad.csv: too few rows"),
    ];
    for (text, expect) in cases {
        let path = tmp("bad.csv");
        std::fs::write(&path, text).unwrap();
        let (code, out, err) = primo(&["dmp", "fit", "--demo", path.to_str().unwrap()]);
        assert_eq!(code, 2, "{text:?}: {err}");
        assert!(out.is_empty());
        assert_eq!(err.lines().count(), 1, "{err}");
        let shown = err.replace(&format!("{}/", path.parent().unwrap().display()), "");
        assert!(shown.contains(expect), "{shown} should contain {expect}");
    }
    let json = tmp("ok.json");
    let (code, _, _) = primo(&[
        "dmp",
        "fit",
        "--demo",
        &demo_path(),
        "--kernels",
        "10",
        "--out",
        json.to_str().unwrap(),
    ]);
    assert_eq!(code, 0);
    let (code, _, err) = primo(&["dmp", "run", json.to_str().unwrap(), "--goal", "1,2,3"]);
    assert_eq!(code, 2);
    assert!(
        err.contains("--goal: expected 2 values (one per DoF: x,z), found 3"),
        "{err}"
    );
    let (code, _, err) = primo(&["dmp", "run", json.to_str().unwrap(), "--start", "1,x"]);
    assert_eq!((code, err.lines().count()), (2, 1), "{err}");
    let (code, _, err) = primo(&[
        "dmp",
        "run",
        json.to_str().unwrap(),
        "--dt",
        "1e-9",
        "--tau",
        "100",
    ]);
    assert_eq!(code, 2, "{err}");
    let (code, _, err) = primo(&["dmp", "fit", "--demo", &demo_path(), "--kernels", "1"]);
    assert_eq!(code, 2, "{err}");
    // A corrupt or future DMP file.
    let broken = tmp("broken.json");
    std::fs::write(&broken, "{\"format\": \"primo-dmp\", \"version\": 1, \"names\": [\"x\"],\n \"dmp\": {\"tau\": 1.0,,}}").unwrap();
    let (code, _, err) = primo(&["dmp", "run", broken.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(err.contains("broken.json:2:"), "{err}");
    let written = std::fs::read_to_string(&json).unwrap();
    let future = written.replace("\"version\": 6", "\"version\": 7");
    std::fs::write(&broken, future).unwrap();
    let (code, _, err) = primo(&["dmp", "run", broken.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(err.contains("unsupported version 7"), "{err}");
    // Version 5 (no goal velocity), version 4 (no orientation axis either),
    // version 3 (no scaling reference either), version 2 (no margin either)
    // and version 1 (no orientations either) files still run, with no
    // kernels beyond the ends.
    let margin = written
        .lines()
        .find(|l| l.trim_start().starts_with("\"margin\":"))
        .unwrap();
    let v5 = written.replace("\"version\": 6", "\"version\": 5");
    let v4 = v5.replace("\"version\": 5", "\"version\": 4");
    let v3 = v4.replace("\"version\": 4", "\"version\": 3");
    let v2 = v3
        .replace("\"version\": 3", "\"version\": 2")
        .replace(&format!("{margin}\n"), "");
    let v1 = v2
        .replace("\"version\": 2", "\"version\": 1")
        .replace("  \"orientations\": [],\n", "");
    assert!(
        !v1.contains("orientations") && !v2.contains("margin"),
        "{v1}"
    );
    for old in [v5, v4, v3, v2, v1] {
        std::fs::write(&broken, old).unwrap();
        let (code, _, err) = primo(&["dmp", "run", broken.to_str().unwrap()]);
        assert_eq!(code, 0, "{err}");
    }
    // A margin that leaves no kernel spacing between the ends, or no number.
    for bad in ["14.5", "-1", "nan", "wide"] {
        let (code, _, err) = primo(&["dmp", "fit", "--demo", &demo_path(), "--margin", bad]);
        assert_eq!((code, err.lines().count()), (2, 1), "{err}");
        assert!(err.contains(&format!("--margin: `{bad}`")), "{err}");
    }
    let (code, out, err) = primo(&["dmp", "fit", "--demo", &demo_path(), "--margin", "0"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("\"margin\": 0.0"), "{out}");
}

#[test]
fn a_failed_fit_leaves_the_existing_output_intact() {
    let json = tmp("keep.json");
    std::fs::write(&json, "previous content").unwrap();
    let bad = tmp("keep.csv");
    std::fs::write(&bad, "t,x\n0,1\n").unwrap();
    let (code, _, _) = primo(&[
        "dmp",
        "fit",
        "--demo",
        bad.to_str().unwrap(),
        "--out",
        json.to_str().unwrap(),
    ]);
    assert_eq!(code, 2);
    assert_eq!(std::fs::read_to_string(&json).unwrap(), "previous content");
}

#[test]
fn accepts_twelve_dof_and_a_hundred_kernels() {
    let mut text = String::from("t");
    for d in 0..12 {
        text.push_str(&format!(",j{d}"));
    }
    text.push('\n');
    for i in 0..=1000 {
        let t = i as f32 / 1000.0;
        text.push_str(&format!("{t}"));
        for d in 0..12 {
            text.push_str(&format!(
                ",{}",
                (d as f32 + 1.0) * t * t * (3.0 - 2.0 * t) + 0.1 * (9.0 * t).sin()
            ));
        }
        text.push('\n');
    }
    let csv = tmp("twelve.csv");
    std::fs::write(&csv, text).unwrap();
    let json = tmp("twelve.json");
    let (code, _, err) = primo(&[
        "dmp",
        "fit",
        "--demo",
        csv.to_str().unwrap(),
        "--kernels",
        "100",
        "--out",
        json.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let (code, out, err) = primo(&["dmp", "run", json.to_str().unwrap(), "--dt", "0.01"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(out.lines().count(), 102);
    assert_eq!(out.lines().next().unwrap().split(',').count(), 13);
}

/// `[w, x, y, z]` of a yaw by `deg` degrees.
fn yaw(deg: f64) -> [f64; 4] {
    let h = deg.to_radians() / 2.0;
    [h.cos(), 0.0, 0.0, h.sin()]
}

#[test]
fn orientation_columns_fit_and_run_as_a_quaternion_dmp() {
    // A pour's yaw sweeping 170° → 190° through ±180°, recorded with the
    // sign of its quaternions flipping every tenth row, and a position.
    let smooth = |s: f64| s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
    let angle = |t: f64| 170.0 + 20.0 * smooth(t);
    let mut csv = String::from("t,x,qw,qx,qy,qz\n");
    for i in 0..=200 {
        let t = i as f64 / 200.0;
        let sign = if i % 10 == 5 { -1.0 } else { 1.0 };
        let q = yaw(angle(t)).map(|v| sign * v);
        csv += &format!(
            "{t},{},{},{},{},{}\n",
            0.3 * smooth(t),
            q[0],
            q[1],
            q[2],
            q[3]
        );
    }
    let demo = tmp("pour-yaw.csv");
    std::fs::write(&demo, csv).unwrap();
    let (json, file) = fit_to(&demo, &[], "pour-yaw.json");
    assert_eq!(file["version"], 6);
    assert_eq!(
        file["orientations"][0]["columns"],
        serde_json::json!(["qw", "qx", "qy", "qz"])
    );
    let (code, out, err) = primo(&["dmp", "run", json.to_str().unwrap(), "--dt", "0.005"]);
    assert_eq!(code, 0, "{err}");
    let mut worst = 0.0f64;
    for line in out.lines().skip(1) {
        let v: Vec<f64> = line.split(',').map(|v| v.parse().unwrap()).collect();
        let norm = v[2..6].iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!((norm - 1.0).abs() < 1e-6, "{line}");
        let exact = yaw(angle(v[0]));
        let dot: f64 = v[2..6].iter().zip(exact).map(|(a, b)| a * b).sum();
        worst = worst.max(2.0 * dot.abs().min(1.0).acos().to_degrees());
    }
    assert!(worst < 0.05, "off by {worst}° at worst");
    // A new goal orientation (yaw 200°) and position.
    let g = yaw(200.0);
    let goal = format!("0.5,{},{},{},{}", g[0], g[1], g[2], g[3]);
    let (code, out, err) = primo(&[
        "dmp",
        "run",
        json.to_str().unwrap(),
        "--goal",
        &goal,
        "--tau",
        "3",
    ]);
    assert_eq!(code, 0, "{err}");
    let last: Vec<f64> = out
        .lines()
        .last()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    let dot: f64 = last[2..6].iter().zip(g).map(|(a, b)| a * b).sum();
    assert!((last[1] - 0.5).abs() < 5e-3, "{last:?}");
    // The new goal leaves the start where it was demonstrated.
    let first: Vec<f64> = out
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    let dot_start: f64 = first[2..6]
        .iter()
        .zip(yaw(angle(0.0)))
        .map(|(a, b)| a * b)
        .sum();
    assert!(
        2.0 * dot_start.abs().min(1.0).acos().to_degrees() < 0.01,
        "starts at {first:?}"
    );
    assert!(
        2.0 * dot.abs().min(1.0).acos().to_degrees() < 0.5,
        "{last:?}"
    );
    // An orientation that is not one.
    let (code, _, err) = primo(&[
        "dmp",
        "run",
        json.to_str().unwrap(),
        "--goal",
        "0.5,0,0,0,0",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--goal: qw…: not an orientation"), "{err}");
}

/// `[w, x, y, z]` products and the rotation `exp(r)`, in f64 for the
/// recordings below.
fn qmul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

fn qexp(r: [f64; 3]) -> [f64; 4] {
    let angle = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
    if angle < 1e-12 {
        return [1.0, 0.0, 0.0, 0.0];
    }
    let k = (angle / 2.0).sin() / angle;
    [(angle / 2.0).cos(), k * r[0], k * r[1], k * r[2]]
}

/// The angle between two unit quaternions, degrees (from the relative
/// rotation's vector part: `acos` of a dot product near 1 would lose the
/// printed values' precision).
fn degrees_apart(a: &[f64], b: [f64; 4]) -> f64 {
    let d = qmul([a[0], a[1], a[2], a[3]], [b[0], -b[1], -b[2], -b[3]]);
    let v = (d[1] * d[1] + d[2] * d[2] + d[3] * d[3]).sqrt();
    2.0 * v.atan2(d[0].abs()).to_degrees()
}

#[test]
fn a_screw_of_540_degrees_fits_replays_and_keeps_its_start_under_a_new_goal() {
    // Driving a screw: 540° about the tool's axis, which wobbles by 1°,
    // while the tool advances 3 cm; 1.5 s at about 500 Hz with jittered
    // stamps, the quaternion's sign flipped on pseudo-random rows.
    let smooth = |s: f64| s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
    let seconds = 1.5;
    let pose = qexp([0.4, -0.3, 0.2]);
    let screw = |t: f64| {
        let u = (t / seconds).clamp(0.0, 1.0);
        let w = 1f64.to_radians();
        let wobble = qexp([w * (5.0 * u).sin(), w * (3.0 * u).cos(), 0.0]);
        let spin = qexp([0.0, 0.0, 540f64.to_radians() * smooth(u)]);
        qmul(qmul(pose, wobble), spin)
    };
    let mut seed = 0x2545_f491u32;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        seed as f64 / u32::MAX as f64
    };
    let rows = 750;
    let mut csv = String::from("t,x,y,z,tool_qw,tool_qx,tool_qy,tool_qz\n");
    for i in 0..=rows {
        let t = match i {
            0 => 0.0,
            i if i == rows => seconds,
            i => i as f64 / 500.0 + (next() - 0.5) * 8e-4,
        };
        let sign = if next() < 0.3 { -1.0 } else { 1.0 };
        let q = screw(t).map(|v| sign * v);
        let z = 0.2 - 0.03 * smooth(t / seconds);
        csv += &format!("{t},0.5,0.1,{z},{},{},{},{}\n", q[0], q[1], q[2], q[3]);
    }
    let demo = tmp("screw-540.csv");
    std::fs::write(&demo, csv).unwrap();
    let json = tmp("screw-540.json");
    let (code, _, err) = primo(&[
        "dmp",
        "fit",
        "--demo",
        demo.to_str().unwrap(),
        "--kernels",
        "30",
        "--out",
        json.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(file["version"], 6);
    let axis = file["orientations"][0]["axis"]
        .as_array()
        .expect("charted about its axis");
    assert_eq!(axis.len(), 3);
    // The replay: within 0.1° of the recording all along (a turn beyond
    // 270° charted as the rotation vector replayed such wobbling screws
    // degrees off: see core/core/tests/orientation.rs).
    let (code, out, err) = primo(&["dmp", "run", json.to_str().unwrap(), "--dt", "0.002"]);
    assert_eq!(code, 0, "{err}");
    let replay = csv_rows(&out);
    let worst = replay
        .iter()
        .map(|v| degrees_apart(&v[4..8], screw(v[0])))
        .fold(0.0, f64::max);
    assert!(worst < 0.1, "off by {worst}° at worst");
    // A new goal: 20° further about a tilted axis and another depth. The
    // start stays the demonstrated pose, the goal is reached.
    let goal = qmul(qexp([0.2, 0.0, 0.3]), screw(seconds));
    let goal_arg = format!(
        "0.5,0.1,0.15,{},{},{},{}",
        goal[0], goal[1], goal[2], goal[3]
    );
    let (code, out, err) = primo(&[
        "dmp",
        "run",
        json.to_str().unwrap(),
        "--goal",
        &goal_arg,
        "--tau",
        "3",
    ]);
    assert_eq!(code, 0, "{err}");
    let run = csv_rows(&out);
    let first = &run[0];
    assert!(
        degrees_apart(&first[4..8], screw(0.0)) < 0.01,
        "starts at {first:?}"
    );
    assert!((first[3] - 0.2).abs() < 1e-6, "{first:?}");
    let last = run.last().unwrap();
    assert!(degrees_apart(&last[4..8], goal) < 0.5, "ends at {last:?}");
    for w in run.windows(2) {
        assert!(degrees_apart(&w[1][4..8], [w[0][4], w[0][5], w[0][6], w[0][7]]) < 5.0);
    }
}

#[test]
fn a_rhythmic_fit_replays_faster_and_wider() {
    // Two periods of a wipe, 0.8 s each, at 250 Hz; fit the first.
    let wipe = |t: f64| {
        let p = std::f64::consts::TAU * t / 0.8;
        [
            0.5 + 0.1 * p.sin() + 0.02 * (2.0 * p).cos(),
            0.2 + 0.05 * (p + 0.3).cos(),
        ]
    };
    let mut csv = String::from("t,x,y\n");
    for i in 0..=400 {
        let t = i as f64 / 250.0;
        let [x, y] = wipe(t);
        csv += &format!("{t},{x},{y}\n");
    }
    let demo = tmp("wipe.csv");
    std::fs::write(&demo, csv).unwrap();
    let json = tmp("wipe.json");
    let (code, _, err) = primo(&[
        "dmp",
        "fit",
        "--demo",
        demo.to_str().unwrap(),
        "--rhythmic",
        "--period",
        "0.8",
        "--kernels",
        "25",
        "--out",
        json.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let run = |args: &[&str]| {
        let mut all = vec!["dmp", "run", json.to_str().unwrap()];
        all.extend_from_slice(args);
        let (code, out, err) = primo(&all);
        assert_eq!(code, 0, "{err}");
        out.lines()
            .skip(1)
            .map(|l| {
                l.split(',')
                    .map(|v| v.parse::<f64>().unwrap())
                    .collect::<Vec<_>>()
            })
            .collect::<Vec<_>>()
    };
    // Three periods at the demonstrated rate and size.
    let rows = run(&[]);
    assert_eq!(rows.len(), 2401);
    let worst = rows
        .iter()
        .map(|r| {
            let w = wipe(r[0]);
            (r[1] - w[0]).abs().max((r[2] - w[1]).abs())
        })
        .fold(0.0, f64::max);
    assert!(worst < 1e-4, "off by {worst}");
    // Twice as fast, 1.5 times as wide: after settling, x spans 1.5 times
    // the demonstrated range.
    let rows = run(&[
        "--frequency",
        "2.5",
        "--amplitude",
        "1.5,1.5",
        "--duration",
        "2",
    ]);
    let settled: Vec<f64> = rows[1000..].iter().map(|r| r[1]).collect();
    let span = settled.iter().cloned().fold(f64::MIN, f64::max)
        - settled.iter().cloned().fold(f64::MAX, f64::min);
    let demo_span = (0..800)
        .map(|i| wipe(i as f64 / 1000.0)[0])
        .fold((f64::MAX, f64::MIN), |(lo, hi), x| (lo.min(x), hi.max(x)));
    let ratio = span / (demo_span.1 - demo_span.0);
    assert!((ratio - 1.5).abs() < 0.01, "{ratio}");
    // The same change made online at 2 s: the run is the plain one until
    // then, and settles on the new size after.
    let plain = run(&["--duration", "2"]);
    let changed = run(&[
        "--duration",
        "5",
        "--change",
        "2 frequency=2.5 amplitude=1.5,1.5",
    ]);
    assert_eq!(changed[..plain.len()], plain[..]);
    let late: Vec<f64> = changed[4000..].iter().map(|r| r[1]).collect();
    let span = late.iter().cloned().fold(f64::MIN, f64::max)
        - late.iter().cloned().fold(f64::MAX, f64::min);
    let ratio = span / (demo_span.1 - demo_span.0);
    assert!((ratio - 1.5).abs() < 0.01, "online: {ratio}");
    let (code, _, err) = primo(&[
        "dmp",
        "run",
        json.to_str().unwrap(),
        "--change",
        "soon frequency=2",
    ]);
    assert_eq!(code, 2);
    assert!(
        err.contains("--change \"soon frequency=2\": must start with a time"),
        "{err}"
    );
    let (code, _, err) = primo(&[
        "dmp",
        "run",
        json.to_str().unwrap(),
        "--change",
        "1 speed=2",
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("`speed=2`"), "{err}");
    let (code, _, err) = primo(&[
        "dmp",
        "run",
        json.to_str().unwrap(),
        "--change",
        "1 frequency=5000",
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("at 1 s: frequency 5000"), "{err}");
    // Rhythmic flags on a discrete DMP, and a bad period: refused.
    let reach = tmp("reach-rhythm.json");
    let (code, _, err) = primo(&[
        "dmp",
        "fit",
        "--demo",
        &demo_path(),
        "--out",
        reach.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let (code, _, err) = primo(&["dmp", "run", reach.to_str().unwrap(), "--frequency", "2"]);
    assert_eq!(code, 2);
    assert!(err.contains("not a rhythmic DMP"), "{err}");
    let (code, _, err) = primo(&[
        "dmp",
        "fit",
        "--demo",
        demo.to_str().unwrap(),
        "--rhythmic",
        "--period",
        "0",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--period"), "{err}");
}

/// `dmp run --obstacle`: a 0.6 m reach in `x` passing 1 cm from a 5 cm
/// ball's centre keeps out of it and ends at its goal (a little after τ);
/// a ball on the start, a malformed or misplaced obstacle and one that
/// blocks the way each get a one-line error and status 2.
#[test]
fn dmp_run_steers_round_an_obstacle_and_refuses_what_it_cannot() {
    let demo = tmp("straight.csv");
    let mut text = String::from("t,x,y,z\n");
    for i in 0..=100 {
        let t = i as f32 / 100.0;
        let s = t * t * t * (10.0 - 15.0 * t + 6.0 * t * t);
        text.push_str(&format!("{t},{},0.1,0.2\n", 0.6 * s));
    }
    std::fs::write(&demo, text).unwrap();
    let (json, _) = fit_to(&demo, &["--kernels", "20"], "straight.json");
    let json = json.to_str().unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec!["dmp", "run", json, "--dt", "0.002"];
        args.extend(extra);
        primo(&args)
    };
    let (code, csv, err) = run(&["--obstacle", "0.3,0.11,0.2,0.05"]);
    assert_eq!(code, 0, "{err}");
    let rows = csv_rows(&csv);
    let clearance = rows
        .iter()
        .map(|r| {
            ((r[1] - 0.3).powi(2) + (r[2] - 0.11).powi(2) + (r[3] - 0.2).powi(2)).sqrt() - 0.05
        })
        .fold(f64::INFINITY, f64::min);
    assert!(clearance > 0.0, "entered the ball: {clearance}");
    let last = rows.last().unwrap();
    assert!(last[0] >= 1.0 && last[0] < 3.0, "ended at {} s", last[0]);
    assert!(
        (last[1] - 0.6).abs() < 1e-3 && (last[2] - 0.1).abs() < 1e-3,
        "{last:?}"
    );
    for (args, says) in [
        (
            &["--obstacle", "0,0.1,0.2,0.05"][..],
            "obstacle 1 (centre 0,0.1,0.2, radius 0.05): out of range: an obstacle holds the \
             movement's start",
        ),
        (
            &["--obstacle", "0.3,0.1"],
            "--obstacle 0.3,0.1: expected four finite numbers X,Y,Z,R",
        ),
        (
            &["--obstacle", "0.3,0.1,0.2,-1"],
            "--obstacle 0.3,0.1,0.2,-1: the radius R must be >= 0",
        ),
        (
            &[
                "--obstacle",
                "0.3,0.1,0.2,0.1",
                "--obstacle-columns",
                "x,y,w",
            ],
            "obstacles: no position column `w` among x,y,z",
        ),
        (
            &["--obstacle", "0.3,0.1,0.2,0.2"],
            "the obstacles keep the movement",
        ),
    ] {
        let (code, out, err) = run(args);
        assert_eq!((code, out.as_str()), (2, ""), "{args:?}: {err}");
        assert!(
            err.contains(says) && err.lines().count() == 1,
            "{args:?}: {err}"
        );
    }
}

/// `dmp run --limit`: a joint that overshoots to 1.09 on its way to 0.8
/// stays under a limit at 0.95 and ends at its goal; a limit the goal lies
/// within the margin of, an unknown column and malformed limits each get a
/// one-line error and status 2.
#[test]
fn dmp_run_keeps_away_from_joint_limits() {
    let demo = tmp("overshoot.csv");
    let mut text = String::from("t,a1,a2\n");
    for i in 0..=200 {
        let t = f64::from(i) / 200.0;
        let a1 = 0.8 * t * t * (3.0 - 2.0 * t) + (std::f64::consts::PI * t).sin().powi(2) * t;
        text.push_str(&format!("{t},{a1},{}\n", -0.5 * t));
    }
    std::fs::write(&demo, text).unwrap();
    let (json, _) = fit_to(&demo, &[], "overshoot.json");
    let json = json.to_str().unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec!["dmp", "run", json, "--dt", "0.002"];
        args.extend(extra);
        primo(&args)
    };
    let top = |rows: &[Vec<f64>]| rows.iter().map(|r| r[1]).fold(f64::MIN, f64::max);
    let (code, free, err) = run(&[]);
    assert_eq!(code, 0, "{err}");
    assert!(top(&csv_rows(&free)) > 1.0);
    let (code, held, err) = run(&["--limit", "a1,-1,0.95", "--limit-margin", "0.1"]);
    assert_eq!(code, 0, "{err}");
    let held = csv_rows(&held);
    assert!(top(&held) < 0.95, "beyond the limit: {}", top(&held));
    let last = held.last().unwrap();
    assert!(
        (last[1] - 0.8).abs() < 1e-3 && (last[2] + 0.5).abs() < 1e-3,
        "{last:?}"
    );
    // One-sided: the same.
    let (code, above, err) = run(&["--limit", "a1,-inf,0.95", "--limit-margin", "0.1"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(csv_rows(&above), held);
    for (args, says) in [
        (
            &["--limit", "a1,-1,0.85", "--limit-margin", "0.1"][..],
            "joint limits: out of range: the movement's goal is within the margin of a joint \
             limit",
        ),
        (
            &["--limit", "a3,-1,1", "--limit-margin", "0.1"],
            "joint limits: no position column `a3` among a1,a2",
        ),
        (
            &["--limit", "a1,1,-1", "--limit-margin", "0.1"],
            "--limit a1,1,-1: expected a column and LOW < HIGH",
        ),
        (
            &["--limit", "a1,-1", "--limit-margin", "0.1"],
            "--limit a1,-1: expected COLUMN,LOW,HIGH",
        ),
        (
            &["--limit", "a1,-1,0.95", "--limit-margin", "-0.1"],
            "--limit-margin -0.1: must be a positive number",
        ),
    ] {
        let (code, out, err) = run(args);
        assert_eq!((code, out.as_str()), (2, ""), "{args:?}: {err}");
        assert!(
            err.contains(says) && err.lines().count() == 1,
            "{args:?}: {err}"
        );
    }
    let (code, _, err) = run(&["--limit", "a1,-1,0.95"]);
    assert_eq!(code, 2);
    assert!(err.contains("--limit-margin"), "{err}");
}

/// A throw fitted with `--final-velocity demonstrated` keeps its end's
/// speed (version 6 file, `goal_velocity`), `--goal-velocity` sets a new
/// one, reached at the goal at τ; `--via` passes a column through a value
/// at a time. Bad via-points and velocities get one line and status 2.
#[test]
fn dmp_run_reaches_a_goal_velocity_and_passes_via_points() {
    let demo = tmp("throw.csv");
    let mut text = String::from("t,x,y\n");
    for i in 0..=500 {
        let t = i as f64 / 500.0;
        let x = -0.5 * (std::f64::consts::PI * t).sin() + 0.8 * t.powi(3);
        text.push_str(&format!("{t},{x},{}\n", 0.1 * t * t * (3.0 - 2.0 * t)));
    }
    std::fs::write(&demo, text).unwrap();
    let (json, file) = fit_to(&demo, &["--final-velocity", "demonstrated"], "throw.json");
    assert_eq!(file["version"], 6);
    let v = file["dmp"]["goal_velocity"][0].as_f64().unwrap();
    // The recording ends at 0.5π + 2.4 ≈ 3.97 m/s.
    assert!((v - 3.97).abs() < 0.1, "{v}");
    let json = json.to_str().unwrap();
    let rows = |extra: &[&str]| -> Vec<Vec<f64>> {
        let mut args = vec!["dmp", "run", json, "--dt", "0.002"];
        args.extend(extra);
        let (code, csv, err) = primo(&args);
        assert_eq!(code, 0, "{extra:?}: {err}");
        csv_rows(&csv)
    };
    for (flag, speed) in [(None, v), (Some("1.5,0"), 1.5)] {
        let run = rows(&flag.map_or(vec![], |f| vec!["--goal-velocity", f]));
        let (a, b) = (&run[run.len() - 2], &run[run.len() - 1]);
        let end_speed = (b[1] - a[1]) / (b[0] - a[0]);
        assert!((b[1] - 0.8).abs() < 5e-3, "{flag:?}: ends at {}", b[1]);
        assert!(
            (end_speed - speed).abs() < 0.2,
            "{flag:?}: ends at {end_speed} m/s"
        );
    }
    let run = rows(&["--via", "0.5,y,0.3", "--via", "0.8,x,0.2"]);
    assert!(
        (run[250][0] - 0.5).abs() < 1e-9 && (run[250][2] - 0.3).abs() < 1e-4,
        "{:?}",
        run[250]
    );
    assert!((run[400][1] - 0.2).abs() < 1e-4, "{:?}", run[400]);
    for (args, says) in [
        (
            &["--via", "1.5,y,0.3"][..],
            "a via-point's time must lie within the movement",
        ),
        (
            &["--via", "0.5,w,0.3"],
            "via-point at 0.5 s: no position column `w` among x,y",
        ),
        (&["--via", "0.5,y"], "--via 0.5,y: expected T,COLUMN,VALUE"),
        (
            &["--via", "0.5,y,0.3", "--via", "0.5,y,0.4"],
            "two ask one DoF for two places at once",
        ),
        (
            &["--goal-velocity", "1"],
            "--goal-velocity: expected 2 values",
        ),
    ] {
        let mut all = vec!["dmp", "run", json];
        all.extend(args);
        let (code, out, err) = primo(&all);
        assert_eq!((code, out.as_str()), (2, ""), "{args:?}: {err}");
        assert!(
            err.contains(says) && err.lines().count() == 1,
            "{args:?}: {err}"
        );
    }
}

/// A ProMP of demonstrations 0.8 s long at 0.02 s (f32 times: their
/// duration is a hair over 0.8) runs at that step in 41 rows, strictly
/// increasing to its end: no last row 1e-8 s after the one before.
#[test]
fn promp_run_samples_each_step_once() {
    let mut args = vec![
        "promp".to_string(),
        "fit".into(),
        "--kernels".into(),
        "10".into(),
    ];
    for h in [0.5, 1.5] {
        let demo = tmp(&format!("promp-step-{h}.csv"));
        let rows: String = (0..=40)
            .map(|k| format!("{},{}\n", f64::from(k) * 0.02, h * f64::from(k) / 40.0))
            .collect();
        std::fs::write(&demo, format!("t,x\n{rows}")).unwrap();
        args.extend(["--demo".into(), demo.to_str().unwrap().to_string()]);
    }
    let file = tmp("step.promp.json");
    args.extend(["--out".into(), file.to_str().unwrap().to_string()]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let (code, _, err) = primo(&args);
    assert_eq!(code, 0, "{err}");
    let (code, csv, err) = primo(&["promp", "run", file.to_str().unwrap(), "--dt", "0.02"]);
    assert_eq!(code, 0, "{err}");
    let times: Vec<f64> = csv_rows(&csv).iter().map(|r| r[0]).collect();
    assert_eq!(times.len(), 41, "{times:?}");
    assert!(times.windows(2).all(|w| w[1] > w[0] + 0.019), "{times:?}");
}

/// `primo promp fit` over three reaches to different heights, `primo promp
/// run` of its mean (between them, with its spread) and conditioned on a
/// new goal; a single demonstration, an orientation, a via-point outside
/// the movement or of an unknown column, and a corrupt file each get a
/// one-line error and status 2.
#[test]
fn promp_fits_demonstrations_and_runs_its_conditioned_mean() {
    let mut demos = Vec::new();
    for (i, h) in [0.9, 1.0, 1.1].iter().enumerate() {
        let demo = tmp(&format!("promp-{i}.csv"));
        let mut text = String::from("t,x,y\n");
        for k in 0..=100 {
            let t = f64::from(k) / 100.0;
            let s = t * t * (3.0 - 2.0 * t);
            text.push_str(&format!("{t},{},{}\n", h * s, 0.5 * h * s));
        }
        std::fs::write(&demo, text).unwrap();
        demos.push(demo);
    }
    let file = tmp("reach.promp.json");
    let mut args = vec![
        "promp",
        "fit",
        "--kernels",
        "15",
        "--out",
        file.to_str().unwrap(),
    ];
    for d in &demos {
        args.extend(["--demo", d.to_str().unwrap()]);
    }
    let (code, _, err) = primo(&args);
    assert_eq!(code, 0, "{err}");
    let file = file.to_str().unwrap();
    let (code, csv, err) = primo(&["promp", "run", file, "--dt", "0.01", "--std"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(csv.lines().next(), Some("t,x,y,x_std,y_std"));
    let mean = csv_rows(&csv);
    let end = mean.last().unwrap();
    assert!(
        (end[0] - 1.0).abs() < 1e-6 && (end[1] - 1.0).abs() < 1e-3,
        "{end:?}"
    );
    // The demonstrations' ends spread by 0.1 in x: about that much.
    assert!(end[3] > 0.05 && end[3] < 0.15, "{end:?}");
    // A new goal for x: y follows its correlation (half of x).
    let (code, csv, err) = primo(&["promp", "run", file, "--dt", "0.01", "--via", "1,x,1.05"]);
    assert_eq!(code, 0, "{err}");
    let end = csv_rows(&csv).last().unwrap().clone();
    assert!(
        (end[1] - 1.05).abs() < 1e-4 && (end[2] - 0.525).abs() < 1e-2,
        "{end:?}"
    );
    let bad_file = tmp("bad.promp.json");
    std::fs::write(
        &bad_file,
        "{\"format\": \"primo-promp\", \"version\": 1, \"names\": [\"x\"], \"values\": [1, 2]}",
    )
    .unwrap();
    let quat = tmp("promp-quat.csv");
    std::fs::write(&quat, "t,qw,qx,qy,qz\n0,1,0,0,0\n0.5,1,0,0,0\n1,1,0,0,0\n").unwrap();
    let one = ["promp", "fit", "--demo", demos[0].to_str().unwrap()];
    let quats = [
        "promp",
        "fit",
        "--demo",
        quat.to_str().unwrap(),
        "--demo",
        quat.to_str().unwrap(),
    ];
    for (args, says) in [
        (&one[..], "a ProMP needs at least two demonstrations"),
        (&quats[..], "qw,qx,qy,qz is an orientation"),
        (
            &["promp", "run", file, "--via", "2,x,1"][..],
            "--via 2,x,1: 2 s is outside the movement",
        ),
        (
            &["promp", "run", file, "--via", "0.5,w,1"],
            "no column `w` among x,y",
        ),
        (
            &["promp", "run", bad_file.to_str().unwrap()],
            "not the values of a ProMP",
        ),
    ] {
        let (code, out, err) = primo(args);
        assert_eq!((code, out.as_str()), (2, ""), "{args:?}: {err}");
        assert!(
            err.contains(says) && err.lines().count() == 1,
            "{args:?}: {err}"
        );
    }
}
