//! Messages in the user's terms: no internal names, the values and what
//! they bound, and one answer for one fault whichever command meets it.
use std::path::Path;

mod common;
use common::{primo, tmp};

fn reach() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/reach.csv")
        .display()
        .to_string()
}

/// `reach.csv` fitted, in this test's own file.
fn fitted(name: &str) -> String {
    let json = tmp(name).display().to_string();
    let (code, _, err) = primo(&["dmp", "fit", "--demo", &reach(), "--out", &json]);
    assert_eq!(code, 0, "{err}");
    json
}

#[test]
fn a_spreadsheets_byte_order_mark_is_accepted() {
    let bom = tmp("bom.csv");
    let text = std::fs::read_to_string(reach()).unwrap();
    std::fs::write(&bom, format!("\u{feff}{text}")).unwrap();
    let (code, out, err) = primo(&["dmp", "fit", "--demo", bom.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("\"names\""), "{out}");
}

#[test]
fn a_csv_given_as_a_dmp_file_is_named_for_what_it_is() {
    let (code, _, err) = primo(&["dmp", "run", &reach()]);
    assert_eq!((code, err.lines().count()), (2, 1), "{err}");
    assert!(err.contains("not a primo DMP file"), "{err}");
    assert!(err.contains("primo dmp fit"), "{err}");
    assert!(!err.contains("expected ident"), "{err}");
}

#[test]
fn bounds_are_named_by_their_values_not_their_constants() {
    let json = fitted("bounds.json");
    for (args, says) in [
        (
            &["--tau", "1e-8"][..],
            "tau must be finite and at least 0.001 s",
        ),
        (
            &["--goal", "1e12,1"][..],
            "beyond ±1e6, the bound on any position",
        ),
    ] {
        let mut all = vec!["dmp", "run", json.as_str()];
        all.extend_from_slice(args);
        let (code, _, err) = primo(&all);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(
            !err.contains("MIN_TAU") && !err.contains("MAX_ABS"),
            "{err}"
        );
    }
}

#[test]
fn experiment_golden_names_its_five_learners() {
    let (code, out, _) = primo(&["experiment", "golden", "--help"]);
    assert_eq!(code, 0);
    let first = out.lines().next().unwrap_or("");
    for learner in [
        "golden section",
        "Illinois",
        "secant",
        "fixed gain",
        "weighted gain",
    ] {
        assert!(out.contains(learner), "{learner}: {first}");
    }
}

#[test]
fn the_real_cells_settings_without_it_are_refused_in_one_line() {
    for args in [
        &["pour", "--density", "0"][..],
        &["pour", "--baud", "19200"][..],
        &["learn", "--task", "t.toml", "--confirm"][..],
    ] {
        let (code, out, err) = primo(args);
        assert_eq!((code, err.lines().count()), (2, 1), "{args:?}: {err}");
        assert!(out.is_empty());
        assert!(err.contains("is for the real cell's scale"), "{err}");
        assert!(err.contains("--robot and --scale"), "{err}");
        assert!(!err.contains("required arguments"), "{err}");
    }
}

#[test]
fn the_robot_and_the_scale_are_asked_for_together_in_one_line() {
    for (args, says) in [
        (
            &["pour", "--scale", "/dev/null"][..],
            "--scale: is for the real cell: give it with --robot",
        ),
        (
            &["learn", "--task", "t.toml", "--robot", "fri:127.0.0.1"][..],
            "--robot: give --scale too",
        ),
    ] {
        let (code, out, err) = primo(args);
        assert_eq!((code, err.lines().count()), (2, 1), "{args:?}: {err}");
        assert!(out.is_empty());
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(!err.contains("required"), "{err}");
    }
}

#[test]
fn a_bad_port_gets_one_answer_from_every_command() {
    let not_a_port = "/dev/null: not a serial port: it is a device that is not a terminal";
    for (args, flag) in [
        (&["pour", "--coprocessor", "/dev/null"][..], "--coprocessor"),
        (&["scale", "read", "--port", "/dev/null"][..], "--port"),
        (
            &["scale", "read", "--port", "postcard:/dev/null"][..],
            "--port",
        ),
        (
            &[
                "pour",
                "--robot",
                "fri:127.0.0.1:49951",
                "--scale",
                "/dev/null",
                "--glass-holds",
                "none",
                "--out",
                tmp("bad-scale").to_str().unwrap(),
            ][..],
            "--scale",
        ),
    ] {
        let (code, _, err) = primo(args);
        let err = err.lines().last().unwrap_or("");
        assert_eq!(code, 2, "{args:?}: {err}");
        assert_eq!(err, format!("primo: {flag} {not_a_port}"), "{args:?}");
    }
    let (code, _, err) = primo(&["pour", "--coprocessor", "/no/such/tty"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--coprocessor /no/such/tty: no such file or device"),
        "{err}"
    );
}

#[test]
fn a_directory_given_as_a_file_is_named_a_directory() {
    let dir = tmp("a-directory");
    std::fs::create_dir_all(&dir).unwrap();
    let d = dir.to_str().unwrap();
    let task = tmp("dir-demo.toml");
    std::fs::write(
        &task,
        format!(
            "version = 1\n[[demo]]\nfile = \"{d}\"\nquery = [1.0]\n[[demo]]\nfile = \"{}\"\n\
             query = [2.0]\n[goal]\ndesired = [1.5]\nlow = [1.0]\nhigh = [2.0]\n\
             precision = 0.01\n[learner]\nmethod = \"golden\"\nmax_rollouts = 3\n\
             [evaluate]\ncommand = [\"true\"]\n",
            reach()
        ),
    )
    .unwrap();
    let first = format!("--demo {d}=0.2");
    let first: Vec<&str> = first.split(' ').collect();
    for (args, says) in [
        (
            &["pour", first[0], first[1], "--demo", "/tmp=0.3"][..],
            format!("--demo {d}: not a file: it is a directory"),
        ),
        (
            &["dmp", "fit", "--demo", d][..],
            format!("--demo {d}: not a file: it is a directory"),
        ),
        (
            &["rollout", "--params", d][..],
            format!("--params {d}: not a file: it is a directory"),
        ),
        (
            &["learn", "--task", task.to_str().unwrap()][..],
            format!("{d}: not a file: it is a directory"),
        ),
        (
            &["learn", "--task", d][..],
            format!("--task {d}: not a file: it is a directory"),
        ),
    ] {
        let (code, _, err) = primo(args);
        assert_eq!((code, err.lines().count()), (2, 1), "{args:?}: {err}");
        assert!(err.contains(&says), "{args:?}: {err}");
    }
}

/// A number of `summary.json` (pretty JSON: `"key": value` on its line).
fn field(summary: &str, key: &str) -> f64 {
    summary
        .lines()
        .find_map(|l| l.trim().strip_prefix(&format!("\"{key}\": ")))
        .and_then(|v| v.trim_end_matches(',').parse().ok())
        .unwrap_or_else(|| panic!("{key}: {summary}"))
}

#[test]
fn the_summary_gives_the_bounds_searched_and_the_time_over_every_session() {
    let out = tmp("summary");
    let dir = out.to_str().unwrap();
    let pour = [
        "pour",
        "--bottle",
        "1.0",
        "--target",
        "0.3",
        "--max-rollouts",
        "2",
    ];
    let (code, _, err) = primo(&[&pour[..], &["--out", dir]].concat());
    assert_eq!(code, 0, "{err}");
    let first = std::fs::read_to_string(out.join("summary.json")).unwrap();
    // The glass (0.423 l) raises the low end to 1.0 + 0.3 - 0.423.
    let searched: String = first
        .split("\"searched\": [")
        .nth(1)
        .and_then(|rest| rest.split(']').next())
        .unwrap_or_else(|| panic!("{first}"))
        .split_whitespace()
        .collect();
    assert_eq!(searched, "0.87667036,1.5", "{first}");
    let (total, session) = (field(&first, "seconds"), field(&first, "session_seconds"));
    assert_eq!(total, session, "{first}");
    // A second session (it only reports) adds to the first one's time.
    let (code, _, err) = primo(&["pour", "--resume", dir]);
    assert_eq!(code, 0, "{err}");
    let again = std::fs::read_to_string(out.join("summary.json")).unwrap();
    let (total, session) = (field(&again, "seconds"), field(&again, "session_seconds"));
    assert!(
        total >= field(&first, "seconds") + session,
        "{first}\n{again}"
    );
}

#[test]
fn a_kernel_count_out_of_range_is_named_by_its_flag() {
    // The library says it neutrally; the command line names its flag, once.
    let demo = reach();
    for (extra, message) in [
        (&[][..], "--kernels: 1 is outside 2..=128"),
        (
            &["--rhythmic"][..],
            "--kernels: 1 is outside 3..=128 for a rhythmic DMP",
        ),
    ] {
        let mut args = vec!["dmp", "fit", "--demo", &demo, "--kernels", "1"];
        args.extend_from_slice(extra);
        let (code, _, err) = primo(&args);
        assert_eq!((code, err.lines().count()), (2, 1), "{err}");
        assert!(err.contains(message), "{err}");
    }
}
