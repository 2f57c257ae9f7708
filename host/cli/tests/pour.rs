//! `primo pour`, `primo rollout`, `primo demo synth` and `primo experiment`
//! end to end: the binary, its files and its JSON.
mod common;
use common::{primo, primo_with_input, tmp};

#[test]
fn pour_learns_and_writes_its_reports() {
    let dir = tmp("golden");
    let (code, out, err) = primo(&["pour", "--out", dir.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("roll-out   1: q 0.5000 l"), "{out}");
    let last = out.lines().last().unwrap();
    assert!(
        last.starts_with("primo pour: converged to |error| < 2 ml in"),
        "{last}"
    );
    let csv = std::fs::read_to_string(dir.join("rollouts.csv")).unwrap();
    let rows = csv.lines().count() - 1;
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["rollouts"], rows);
    assert!(summary["last"]["error"].as_f64().unwrap().abs() < 0.002);
    let png = std::fs::read(dir.join("convergence.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
}

/// The most any roll-out of a golden-section pour from a 0.9 l bottle let
/// leave the bottle and spilled, l, with `extra` flags.
fn golden_from_a_full_bottle(name: &str, extra: &[&str]) -> (f64, f64) {
    let dir = tmp(name);
    let mut args = vec!["pour", "--bottle", "0.9", "--out", dir.to_str().unwrap()];
    args.extend(extra);
    let (code, _, err) = primo(&args);
    assert_eq!(code, 0, "{err}");
    let csv = std::fs::read_to_string(dir.join("rollouts.csv")).unwrap();
    csv.lines().skip(1).fold((0.0, 0.0), |(out, spilled), l| {
        let v: Vec<f64> = l
            .split(',')
            .skip(4)
            .take(2)
            .map(|v| v.parse().unwrap())
            .collect();
        (f64::max(out, v[0] + v[1]), f64::max(spilled, v[1]))
    })
}

#[test]
fn golden_section_never_overflows_the_glass() {
    // The normal glass holds 0.423 l. Searching all of [0.1, 1.5] l, the
    // low end lets more than that out of a 0.9 l bottle.
    let (out, spilled) = golden_from_a_full_bottle("unbounded", &["--glass-holds", "100"]);
    assert!(out > 0.423 && spilled > 0.05, "{out} {spilled}");
    let (out, spilled) = golden_from_a_full_bottle("bounded", &[]);
    assert!(out < 0.423 && spilled == 0.0, "{out} {spilled}");
    let (code, _, err) = primo(&[
        "pour",
        "--glass-holds",
        "0.1",
        "--out",
        tmp("small").to_str().unwrap(),
    ]);
    assert_eq!(code, 2);
    assert!(
        err.contains(
            "--target 0.2 with --glass-holds 0.100: the glass holds no more than the target"
        ),
        "{err}"
    );
}

#[test]
fn power_pour_runs_in_joint_space() {
    let dir = tmp("power");
    let (code, out, err) = primo(&[
        "pour",
        "--method",
        "power",
        "--glass",
        "small",
        "--kernels",
        "10",
        "--max-rollouts",
        "8",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("Joint space, 79 learned parameter(s)"),
        "{out}"
    );
    assert_eq!(
        out.lines().filter(|l| l.contains("(mean)")).count(),
        2,
        "{out}"
    );
}

#[test]
fn rollout_prints_the_start_and_serves_json_lines() {
    let (code, out, err) = primo(&["rollout", "--print-start", "--glass", "small"]);
    assert_eq!(code, 0, "{err}");
    let start: serde_json::Value = serde_json::from_str(&out).unwrap();
    let x = start["start"].as_array().unwrap();
    assert_eq!(x.len(), 219);
    assert_eq!(start["std"].as_array().unwrap().len(), 219);
    assert_eq!(x[218].as_f64().unwrap(), 0.5);

    // The start executed directly is the generalized movement.
    let file = tmp("theta.json");
    std::fs::write(&file, serde_json::to_string(x).unwrap()).unwrap();
    let (code, out, err) = primo(&[
        "rollout",
        "--glass",
        "small",
        "--params",
        file.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let one: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(one["safe"], true);
    assert!(one["spilled"].as_f64().unwrap() > 0.03, "{one}");

    // --print-start's own output is a --params file.
    let printed = tmp("start.json");
    std::fs::write(&printed, serde_json::to_string(&start).unwrap()).unwrap();
    let (code, again, err) = primo(&["rollout", "--params", printed.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(again, out, "the same cell by default as experiment power");

    // Serve: one answer per line, whatever the line; bad lines answered
    // with `invalid` (never the volume error's key), and the server goes on.
    let mut far = x.clone();
    far[0] = serde_json::json!(1e6); // a huge weight: an unsafe movement
    let mut input = format!(
        "{}\nnot json\n[1, 2]\n\n",
        serde_json::to_string(x).unwrap(),
    )
    .into_bytes();
    input.extend_from_slice(b"\xff\xfe[\n");
    input.extend(format!("{}\n", serde_json::to_string(&far).unwrap()).bytes());
    let (code, out, err) = primo_with_input(&["rollout", "--serve", "--glass", "small"], &input);
    assert_eq!(code, 0, "{err}");
    let lines: Vec<serde_json::Value> = out
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 6, "{out}");
    assert_eq!(lines[0]["poured"], one["poured"]);
    assert!(lines[0]["error"].is_number(), "{}", lines[0]);
    for (line, says) in [
        (1, "stdin line 2: `not json` is not a JSON array"),
        (2, "stdin line 3: 2 values, the layout needs 219"),
        (3, "stdin line 4: blank"),
        (4, "stdin line 5: not UTF-8"),
    ] {
        let why = lines[line]["invalid"].as_str().unwrap_or_default();
        assert!(why.contains(says), "{}", lines[line]);
        assert!(lines[line].get("error").is_none(), "{}", lines[line]);
    }
    assert_eq!(lines[5]["safe"], false);
    assert_eq!(lines[5]["reward"], 0.0);
    assert!(
        lines[5]["rejected"].as_str().unwrap().contains("limit"),
        "{}",
        lines[5]
    );
}

#[test]
fn demo_synth_writes_a_demonstration_csv() {
    let file = tmp("demo.csv");
    for (space, header) in [
        ("cartesian", "t,x,y,z,qw,qx,qy,qz"),
        ("joint", "t,a1,a2,a3,a4,a5,a6,a7"),
    ] {
        let (code, _, err) = primo(&[
            "demo",
            "synth",
            "--space",
            space,
            "--bottle",
            "0.7",
            "--pour",
            "0.2",
            "--out",
            file.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{err}");
        assert!(err.contains("the expert poured"), "{err}");
        let csv = std::fs::read_to_string(&file).unwrap();
        assert_eq!(csv.lines().next().unwrap(), header);
        assert!(csv.lines().count() > 500);
    }
    // The demo feeds `primo pour --demo`.
    let other = tmp("demo2.csv");
    primo(&[
        "demo",
        "synth",
        "--bottle",
        "0.3",
        "--out",
        other.to_str().unwrap(),
    ]);
    let cart = tmp("demo3.csv");
    primo(&[
        "demo",
        "synth",
        "--bottle",
        "1.0",
        "--seed",
        "2",
        "--out",
        cart.to_str().unwrap(),
    ]);
    let (code, out, err) = primo(&[
        "pour",
        "--demo",
        &format!("{}=0.3", other.display()),
        "--demo",
        &format!("{}=1.0", cart.display()),
        "--out",
        tmp("own").to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("converged"), "{out}");
    // The same demonstration in the earlier columns x,y,z,rx,ry,rz, its
    // rotation vector wrapped by 2π from row 300 on (the same rotations),
    // is converted, saying so, and learns the same.
    let text = std::fs::read_to_string(&cart).unwrap();
    let mut old = String::from("t,x,y,z,rx,ry,rz\n");
    for (i, line) in text.lines().skip(1).enumerate() {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        let n = (v[5] * v[5] + v[6] * v[6] + v[7] * v[7]).sqrt();
        let angle = 2.0 * n.atan2(v[4]);
        let angle = if i + 1 >= 300 {
            angle - std::f64::consts::TAU
        } else {
            angle
        };
        let r: Vec<String> = (5..8).map(|k| (angle * v[k] / n).to_string()).collect();
        old += &format!("{},{},{},{},{}\n", v[0], v[1], v[2], v[3], r.join(","));
    }
    let old_file = tmp("demo3-rotation-vector.csv");
    std::fs::write(&old_file, old).unwrap();
    let (code, out_old, err) = primo(&[
        "pour",
        "--demo",
        &format!("{}=0.3", other.display()),
        "--demo",
        &format!("{}=1.0", old_file.display()),
        "--out",
        tmp("own-old").to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains(&format!(
            "{}: columns x,y,z,rx,ry,rz (a rotation vector) read as x,y,z,qw,qx,qy,qz (its \
             quaternion, sign-continuous); the 2π jump at row 300 unwrapped",
            old_file.display()
        )),
        "{err}"
    );
    let verdict = |out: &str| {
        out.lines()
            .last()
            .unwrap()
            .split(';')
            .next()
            .unwrap()
            .to_string()
    };
    assert_eq!(verdict(&out_old), verdict(&out), "{out_old}");
    // A demo that is not there, or not a CSV, is an input error.
    let (code, _, err) = primo(&["pour", "--demo", "/nonexistent.csv=0.3"]);
    assert_eq!(code, 2, "{err}");
    let (code, _, err) = primo(&["pour", "--demo", "nonsense"]);
    assert_eq!(code, 2);
    assert!(err.contains("expected FILE=VOLUME"), "{err}");
}

#[test]
fn experiment_golden_writes_its_figure_data() {
    let dir = tmp("exp-golden");
    let (code, out, err) = primo(&[
        "experiment",
        "golden",
        "--volumes",
        "0.4,0.8",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("median: golden"), "{out}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    // Two volumes, five error learners.
    assert_eq!(summary["runs"].as_array().unwrap().len(), 10);
    assert!(dir.join("golden.png").exists() && dir.join("golden.csv").exists());
}

#[test]
fn experiment_power_writes_every_variants_curves() {
    let dir = tmp("exp-power");
    let (code, out, err) = primo(&[
        "experiment",
        "power",
        "--runs",
        "2",
        "--updates",
        "3",
        "--kernels",
        "10",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("79 parameters, 2 runs x 3 updates"), "{out}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    // The start and the mean after each of the 3 updates.
    assert_eq!(
        summary["extended"]["reward"]["mean"]
            .as_array()
            .unwrap()
            .len(),
        4
    );
    for variant in ["extended", "ordinary", "error_learned"] {
        let c = &summary[variant];
        assert_eq!(c["rollouts"], 2 * (4 * 3 + 1), "{variant}");
        let count = |k: &str| c[k].as_u64().unwrap();
        assert!(count("rejected") <= count("zero_reward") && count("zero_reward") <= 26);
    }
    assert!(out.contains("% of roll-outs reward 0"), "{out}");
    let ratio = &summary["comparison"]["spill_ratio"];
    assert!(
        ratio["value"].is_number() || ratio["value"].is_null(),
        "{ratio}"
    );
    assert!(dir.join("power.png").exists() && dir.join("power.csv").exists());
    // One row per variant and seed; regret within its bounds; a level
    // reached within the budget, its update no later than the last.
    let runs = std::fs::read_to_string(dir.join("power_runs.csv")).unwrap();
    let rows: Vec<Vec<&str>> = runs
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 6, "{runs}");
    for row in &rows {
        let regret: f64 = row[6].parse().unwrap();
        assert!((0.0..=13.0).contains(&regret), "{row:?}");
        if let (Ok(n), Ok(u)) = (row[2].parse::<u32>(), row[3].parse::<u32>()) {
            assert!(n <= 13 && u <= 3, "{row:?}");
        }
    }
    assert!(
        out.contains("to mean reward 0.95: roll-outs, median [90 % CI]"),
        "{out}"
    );
}

/// Checks a `series.csv`: its header, strictly increasing time, volume
/// conserved on every row, and the settled end: the scale stable, its
/// display the reported `poured`, the glass within the scale's digits of it.
fn check_series(csv: &str, coordinates: &str, initial: f64, poured: f64) -> usize {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let expected = format!(
        "t,{coordinates},tilt_rad,mouth_x_m,mouth_y_m,mouth_z_m,flow_l_per_s,bottle_l,in_flight_l,glass_l,spilled_l,scale_g,stable"
    );
    assert_eq!(header.join(","), expected);
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert!(rows.len() > 1000, "{} rows", rows.len());
    let mut last_t = 0.0;
    for row in &rows {
        assert_eq!(row.len(), header.len());
        let t = row[0];
        assert!(t > last_t, "time {t} after {last_t}");
        last_t = t;
        let sum: f64 = ["bottle_l", "in_flight_l", "glass_l", "spilled_l"]
            .iter()
            .map(|c| row[col(c)])
            .sum();
        assert!((sum - initial).abs() < 1e-9, "t {t}: {sum} l in all");
        assert!(row[col("flow_l_per_s")] >= 0.0);
    }
    let first = &rows[0];
    assert!((first[0] - 0.002).abs() < 1e-9 && (first[col("bottle_l")] - initial).abs() < 1e-4);
    let end = rows.last().unwrap();
    assert_eq!(end[col("stable")], 1.0);
    assert_eq!(end[col("in_flight_l")], 0.0);
    let shown = end[col("scale_g")] / 998.0;
    assert!(
        (shown - poured).abs() < 1e-9,
        "display {shown} l vs {poured} l"
    );
    // 0.01 g digits, 2 mg noise: the glass within 3 digits of the display.
    let glass = end[col("glass_l")];
    assert!(
        (glass - poured).abs() < 0.03e-3,
        "glass {glass} l vs {poured} l"
    );
    rows.len()
}

#[test]
fn rollout_writes_the_executed_time_series() {
    let (code, out, err) = primo(&["rollout", "--print-start", "--glass", "small"]);
    assert_eq!(code, 0, "{err}");
    let start: serde_json::Value = serde_json::from_str(&out).unwrap();
    let theta = tmp("series-theta.json");
    std::fs::write(&theta, start["start"].to_string()).unwrap();
    let csv = tmp("series.csv");
    let args = [
        "rollout",
        "--glass",
        "small",
        "--params",
        theta.to_str().unwrap(),
        "--series",
        csv.to_str().unwrap(),
    ];
    let (code, out, err) = primo(&args);
    assert_eq!(code, 0, "{err}");
    let answer: serde_json::Value = serde_json::from_str(&out).unwrap();
    let text = std::fs::read_to_string(&csv).unwrap();
    check_series(
        &text,
        "a1,a2,a3,a4,a5,a6,a7",
        0.5,
        answer["poured"].as_f64().unwrap(),
    );
    // The generalized start spills: the series shows it on the table.
    let spilled: f64 = text
        .lines()
        .last()
        .unwrap()
        .split(',')
        .nth(16)
        .unwrap()
        .parse()
        .unwrap();
    assert!((spilled - answer["spilled"].as_f64().unwrap()).abs() < 1e-12 && spilled > 0.03);

    // A rejected roll-out never ran: the header and no rows.
    let mut far: Vec<f64> = serde_json::from_value(start["start"].clone()).unwrap();
    far[0] = 1e6;
    std::fs::write(&theta, serde_json::to_string(&far).unwrap()).unwrap();
    let (code, out, err) = primo(&args);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("\"safe\":false"), "{out}");
    assert_eq!(std::fs::read_to_string(&csv).unwrap().lines().count(), 1);
    // --series needs --params.
    let (code, _, err) = primo(&["rollout", "--serve", "--series", "x.csv"]);
    assert_eq!(code, 2, "{err}");
}

#[test]
fn pour_writes_the_best_rollouts_time_series() {
    let dir = tmp("series-pour");
    let (code, out, err) = primo(&["pour", "--out", dir.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let best = &summary["best"];
    // The best reward of all roll-outs in rollouts.csv, the later of equals.
    let table = std::fs::read_to_string(dir.join("rollouts.csv")).unwrap();
    let rewards: Vec<(u64, f64)> = table
        .lines()
        .skip(1)
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            (c[0].parse().unwrap(), c[7].parse().unwrap())
        })
        .collect();
    let top = rewards.iter().map(|r| r.1).fold(f64::MIN, f64::max);
    let expected = rewards.iter().rev().find(|r| r.1 == top).unwrap().0;
    assert_eq!(best["rollout"], expected);
    assert!(
        out.contains(&format!("series.csv: roll-out {expected} (best reward)")),
        "{out}"
    );
    let text = std::fs::read_to_string(dir.join("series.csv")).unwrap();
    check_series(
        &text,
        "x,y,z,qw,qx,qy,qz",
        0.5,
        best["poured"].as_f64().unwrap(),
    );
}

/// `text` (a demonstration CSV) linearly resampled to `rows` rows.
fn resample(text: &str, rows: usize) -> String {
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let data: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    let (t0, t1) = (data[0][0], data[data.len() - 1][0]);
    let mut out = format!("{header}\n");
    let mut j = 0;
    for i in 0..rows {
        let t = t0 + (t1 - t0) * i as f64 / (rows - 1) as f64;
        while j + 2 < data.len() && data[j + 1][0] < t {
            j += 1;
        }
        let (a, b) = (&data[j], &data[j + 1]);
        let w = ((t - a[0]) / (b[0] - a[0])).clamp(0.0, 1.0);
        let row: Vec<String> = std::iter::once(t)
            .chain((1..a.len()).map(|k| a[k] + (b[k] - a[k]) * w))
            .map(|v| v.to_string())
            .collect();
        out += &row.join(",");
        out.push('\n');
    }
    out
}

#[test]
fn demonstrations_recorded_at_4_khz_learn_as_the_100_hz_ones() {
    // The built-in pair, written out at the expert's 100 Hz and resampled
    // to 40,000 rows (about 4 kHz, a robot's rate).
    let mut demos = Vec::new();
    for (bottle, elbow, seed) in [("0.3", "0.4", "1"), ("1.0", "-0.4", "2")] {
        let (code, csv, err) = primo(&[
            "demo", "synth", "--bottle", bottle, "--elbow", elbow, "--seed", seed,
        ]);
        assert_eq!(code, 0, "{err}");
        let dense = tmp(&format!("dense-{bottle}.csv"));
        std::fs::write(&dense, resample(&csv, 40_000)).unwrap();
        demos.push(format!("{}={bottle}", dense.display()));
    }
    let run = |args: &[&str], out: &str| {
        let dir = tmp(out);
        let mut all = vec!["pour", "--out", dir.to_str().unwrap()];
        all.extend_from_slice(args);
        let (code, out, err) = primo(&all);
        assert_eq!(code, 0, "{err}");
        out.lines().last().unwrap().to_string()
    };
    let built_in = run(&[], "dense-built-in");
    let dense = run(&["--demo", &demos[0], "--demo", &demos[1]], "dense");
    assert!(built_in.contains("converged"), "{built_in}");
    // The same verdict, roll-outs and last query: the fits agree.
    let verdict = |line: &str| line.split("; series").next().unwrap().to_string();
    let (a, b) = (verdict(&built_in), verdict(&dense));
    let queries = |l: &str| l.split("q ").nth(1).unwrap()[..6].to_string();
    assert_eq!(a.split(';').next(), b.split(';').next(), "{a}\n{b}");
    assert_eq!(queries(&a), queries(&b), "{a}\n{b}");
}
