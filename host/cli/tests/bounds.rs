//! Every count, duration and size a user or an optimizer gives is checked
//! against its bound before any work: refused at once (exit 2, the bound
//! named), and `rollout --serve` answers such a request and goes on.
mod common;
use std::path::Path;
use std::time::Duration;

use common::{primo_within, tmp};

/// Long enough for a refusal, far too short for the work refused.
const AT_ONCE: Duration = Duration::from_secs(20);

fn refused(args: &[&str], says: &str) {
    let (code, out, err) = primo_within(args, b"", AT_ONCE);
    assert_eq!(code, 2, "{args:?}: {out}{err}");
    assert!(err.contains(says), "{args:?}: {err}");
    assert_eq!(err.lines().count(), 1, "{err}");
}

#[test]
fn experiment_sizes_are_bounded() {
    let out = tmp("bounded-experiment");
    let o = out.to_str().unwrap();
    refused(
        &[
            "experiment",
            "power",
            "--runs",
            "100000000",
            "--updates",
            "1",
            "--out",
            o,
        ],
        "--runs 100000000: must be from 1 to 10000 runs",
    );
    refused(
        &["experiment", "power", "--updates", "100000", "--out", o],
        "--updates 100000: must be from 1 to 10000 updates",
    );
    refused(
        &[
            "experiment",
            "power",
            "--runs",
            "10000",
            "--updates",
            "10000",
            "--out",
            o,
        ],
        "at most 1000000 in one experiment",
    );
    let volumes = vec!["0.5"; 1001].join(",");
    refused(
        &["experiment", "golden", "--volumes", &volumes, "--out", o],
        "at most 1000 volumes",
    );
    assert!(!out.exists(), "nothing was created");
}

#[test]
fn a_runs_budget_is_bounded() {
    let out = tmp("bounded-pour");
    let o = out.to_str().unwrap();
    refused(
        &["pour", "--max-rollouts", "4000000000", "--out", o],
        "--max-rollouts 4000000000: must be from 1 to 100000 roll-outs",
    );
    let throw = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/throw/throw.toml");
    refused(
        &[
            "learn",
            "--task",
            throw.to_str().unwrap(),
            "--max-rollouts",
            "200000",
            "--out",
            o,
        ],
        "--max-rollouts 200000: must be from 1 to 100000 roll-outs",
    );
    assert!(!out.exists(), "nothing was created");
}

#[test]
fn an_evaluators_timeout_is_bounded() {
    let throw = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/throw")
        .canonicalize()
        .unwrap();
    let text = std::fs::read_to_string(throw.join("throw.toml"))
        .unwrap()
        .replace("\"demos/", &format!("\"{}/demos/", throw.display()))
        .replace("timeout = 30", "timeout = 1e300");
    let task = tmp("huge-timeout.toml");
    std::fs::write(&task, text).unwrap();
    refused(
        &["learn", "--task", task.to_str().unwrap()],
        "[evaluate] timeout: an evaluator may take at most 86400 s",
    );
}

#[test]
fn a_demonstration_has_at_most_a_million_rows() {
    let demo = tmp("long-demo.csv");
    let mut text = String::from("t,x\n");
    for i in 0..=1_000_000 {
        text.push_str(&format!("{i},0\n"));
    }
    std::fs::write(&demo, text).unwrap();
    refused(
        &["dmp", "fit", "--demo", demo.to_str().unwrap()],
        "long-demo.csv:1000002: a demonstration has at most 1000000 data rows",
    );
}

/// `--print-start`'s vector.
fn start() -> Vec<f64> {
    let (code, out, err) = primo_within(&["rollout", "--print-start"], b"", AT_ONCE);
    assert_eq!(code, 0, "{err}");
    let start: serde_json::Value = serde_json::from_str(&out).unwrap();
    serde_json::from_value(start["start"].clone()).unwrap()
}

#[test]
fn a_roll_outs_duration_is_bounded_and_the_server_goes_on() {
    let good = start();
    // τ is the value before the query.
    let mut long = good.clone();
    let tau = long.len() - 2;
    long[tau] = 1e5;
    let [long, good] = [long, good].map(|x| serde_json::to_string(&x).unwrap());
    let input = format!("{long}\n{good}\n");
    let (code, out, err) = primo_within(&["rollout", "--serve"], input.as_bytes(), AT_ONCE);
    assert_eq!(code, 0, "{err}");
    let answers: Vec<serde_json::Value> = out
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(answers.len(), 2, "{out}");
    let why = answers[0]["invalid"]
        .as_str()
        .unwrap_or_else(|| panic!("{out}"));
    assert!(
        why.contains("τ 100000 s: a movement lasts more than 0 and at most 600 s"),
        "{why}"
    );
    assert!(answers[1]["reward"].is_number(), "{out}");
    let params = tmp("long-theta.json");
    std::fs::write(&params, &long).unwrap();
    refused(
        &["rollout", "--params", params.to_str().unwrap()],
        "at most 600 s",
    );
}

/// A precision that is 0 or infinite as the learners' f32 is refused
/// before a run starts, not by the learner in a run that can never go on.
#[test]
fn a_precision_beyond_f32_is_refused() {
    let out = tmp("precision-beyond-f32");
    let o = out.to_str().unwrap();
    for precision in ["1e-300", "1e300"] {
        // The value is said in full decimals.
        let says = ": must be a positive volume in litres";
        refused(&["pour", "--precision", precision, "--out", o], says);
        refused(
            &["experiment", "golden", "--precision", precision, "--out", o],
            says,
        );
    }
    assert!(!out.exists(), "nothing was created");
}
