//! Helpers shared by the `primo` end-to-end tests.
// Each test binary uses only some of them.
#![allow(dead_code)]
use std::io::Write;
use std::path::PathBuf;
use std::process::{Command, Stdio};

/// Runs the `primo` binary: exit status, stdout, stderr.
pub fn primo(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_primo"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

/// Runs the `primo` binary with `input` on its stdin (closed after it):
/// exit status, stdout, stderr.
pub fn primo_with_input(args: &[&str], input: &[u8]) -> (i32, String, String) {
    outcome(started(args, input))
}

/// `primo` started with `input` on its stdin, closed after it.
fn started(args: &[&str], input: &[u8]) -> std::process::Child {
    let mut child = Command::new(env!("CARGO_BIN_EXE_primo"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(input).unwrap();
    child
}

/// A started `primo`'s exit status, stdout, stderr.
fn outcome(child: std::process::Child) -> (i32, String, String) {
    let out = child.wait_with_output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

/// A path in this test process's own temporary directory.
pub fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("primo-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// Runs the `primo` binary with `input` on its stdin, as [`primo_with_input`],
/// failing the test if it has not exited within `limit` (it is killed):
/// for what must be refused at once rather than computed.
pub fn primo_within(
    args: &[&str],
    input: &[u8],
    limit: std::time::Duration,
) -> (i32, String, String) {
    let mut child = started(args, input);
    let deadline = std::time::Instant::now() + limit;
    while child.try_wait().unwrap().is_none() {
        if std::time::Instant::now() > deadline {
            child.kill().unwrap();
            child.wait().unwrap();
            panic!("`primo {}` still ran after {limit:?}", args.join(" "));
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    outcome(child)
}
