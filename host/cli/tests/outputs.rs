//! No output destroys data: an output that is an input (under any name) is
//! refused, a write-protected file is refused and a replaced one keeps its
//! mode, and an experiment's earlier result is replaced only with --force.
mod common;
use std::os::unix::fs::{PermissionsExt, symlink};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::Command;

use common::{primo, tmp};

fn reach() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/reach.csv")
}

/// A copy of the example demonstration at `name`.
fn demo_copy(name: &str) -> PathBuf {
    let file = tmp(name);
    std::fs::copy(reach(), &file).unwrap();
    file
}

fn refused_as_same_file(args: &[&str], input: &Path, before: &[u8]) {
    let (code, out, err) = primo(args);
    assert_eq!(code, 2, "{args:?}: {out}{err}");
    assert!(err.contains("is the same file as"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert_eq!(std::fs::read(input).unwrap(), before, "{args:?}");
}

#[test]
fn an_output_that_is_an_input_is_refused_under_any_name() {
    let demo = demo_copy("same-demo.csv");
    let before = std::fs::read(&demo).unwrap();
    let d = demo.to_str().unwrap();
    let soft = tmp("same-soft.csv");
    symlink(&demo, &soft).unwrap();
    let hard = tmp("same-hard.csv");
    std::fs::hard_link(&demo, &hard).unwrap();
    let dotted = demo.parent().unwrap().join(".").join("same-demo.csv");
    for out in [&demo, &soft, &hard, &dotted] {
        let args = ["dmp", "fit", "--demo", d, "--out", out.to_str().unwrap()];
        refused_as_same_file(&args, &demo, &before);
    }
    // A DMP run onto its DMP file.
    let dmp = tmp("same.json");
    let (code, _, err) = primo(&["dmp", "fit", "--demo", d, "--out", dmp.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let json = std::fs::read(&dmp).unwrap();
    let g = dmp.to_str().unwrap();
    refused_as_same_file(&["dmp", "run", g, "--out", g], &dmp, &json);
    // A roll-out's series onto its parameters.
    let (code, start, err) = primo(&["rollout", "--print-start"]);
    assert_eq!(code, 0, "{err}");
    let theta = tmp("same-theta.json");
    std::fs::write(&theta, &start).unwrap();
    let t = theta.to_str().unwrap();
    refused_as_same_file(
        &["rollout", "--params", t, "--series", t],
        &theta,
        start.as_bytes(),
    );
}

fn mode(path: &Path) -> u32 {
    std::fs::metadata(path).unwrap().permissions().mode() & 0o7777
}

#[test]
fn a_replaced_file_keeps_its_mode() {
    let out = tmp("private.json");
    std::fs::write(&out, "old").unwrap();
    std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o600)).unwrap();
    let (code, _, err) = primo(&[
        "dmp",
        "fit",
        "--demo",
        reach().to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(std::fs::read_to_string(&out).unwrap().contains("primo-dmp"));
    assert_eq!(mode(&out), 0o600);
}

/// The user `nobody`'s uid and gid, when this test runs as root (which
/// writes any file): the refusal is then tested as `nobody`.
fn unprivileged() -> Option<(u32, u32)> {
    let root = Command::new("id").arg("-u").output().unwrap().stdout == b"0\n";
    if !root {
        return None;
    }
    let entry = Command::new("getent")
        .args(["passwd", "nobody"])
        .output()
        .unwrap();
    let entry = String::from_utf8_lossy(&entry.stdout).into_owned();
    let fields: Vec<&str> = entry.trim().split(':').collect();
    Some((fields.get(2)?.parse().ok()?, fields.get(3)?.parse().ok()?))
}

#[test]
fn a_write_protected_file_is_refused_and_left_as_it_is() {
    let dir = tmp("protected");
    std::fs::create_dir_all(&dir).unwrap();
    let keep = dir.join("keep.json");
    std::fs::write(&keep, "keep me\n").unwrap();
    std::fs::set_permissions(&keep, std::fs::Permissions::from_mode(0o444)).unwrap();
    let mut command = Command::new(env!("CARGO_BIN_EXE_primo"));
    command.args([
        "dmp",
        "fit",
        "--demo",
        reach().to_str().unwrap(),
        "--out",
        keep.to_str().unwrap(),
    ]);
    match unprivileged() {
        // The directory and the file are nobody's, as a user's own are.
        Some((uid, gid)) => {
            for p in [&dir, &keep] {
                std::os::unix::fs::chown(p, Some(uid), Some(gid)).unwrap();
            }
            command.uid(uid).gid(gid);
        }
        None if Command::new("id").arg("-u").output().unwrap().stdout == b"0\n" => {
            eprintln!("skipped: running as root and there is no user `nobody`");
            return;
        }
        None => {}
    }
    let out = command.output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&format!(
            "--out {}: not writable by this user (mode 444)",
            keep.display()
        )),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(&keep).unwrap(), "keep me\n");
    assert_eq!(mode(&keep), 0o444);
}

#[test]
fn an_experiments_result_is_replaced_only_with_force() {
    for (name, args) in [
        ("golden", &["experiment", "golden", "--volumes", "0.5"][..]),
        (
            "power",
            &[
                "experiment",
                "power",
                "--runs",
                "1",
                "--updates",
                "1",
                "--kernels",
                "4",
            ],
        ),
    ] {
        let dir = tmp(&format!("experiment-{name}"));
        let d = dir.to_str().unwrap();
        let with = |extra: &[&str]| {
            let mut all = args.to_vec();
            all.extend(["--out", d]);
            all.extend(extra);
            primo(&all)
        };
        let (code, _, err) = with(&[]);
        assert_eq!(code, 0, "{name}: {err}");
        std::fs::write(dir.join("summary.json"), "the earlier result").unwrap();
        let (code, _, err) = with(&[]);
        assert_eq!(code, 2, "{name}: {err}");
        assert!(
            err.contains(": an earlier result is here")
                && err.contains("give --force to replace it"),
            "{name}: {err}"
        );
        let summary = std::fs::read_to_string(dir.join("summary.json")).unwrap();
        assert_eq!(summary, "the earlier result");
        let (code, _, err) = with(&["--force"]);
        assert_eq!(code, 0, "{name}: {err}");
        let summary = std::fs::read_to_string(dir.join("summary.json")).unwrap();
        assert!(summary.starts_with('{'), "{name}: {summary}");
    }
}
