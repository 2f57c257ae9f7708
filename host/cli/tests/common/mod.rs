//! Helpers shared by the `primo` end-to-end tests.
// Each test binary uses only some of them.
#![allow(dead_code)]
use std::io::Write;
use std::path::PathBuf;
use std::process::{Command, Stdio};

/// Runs the `primo` binary: exit status, stdout, stderr.
pub fn primo(args: &[&str]) -> (i32, String, String) {
    primo_env(args, &[])
}

/// [`primo`] with these environment variables set.
pub fn primo_env(args: &[&str], env: &[(&str, &str)]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_primo"))
        .args(args)
        .envs(env.iter().copied())
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

/// A path in this test's own temporary directory.
pub fn tmp(name: &str) -> PathBuf {
    // One folder per test: the harness runs tests on threads named after
    // them, and two tests writing the same file name at once would read
    // each other's half-written files.
    let thread = std::thread::current();
    let test = thread.name().unwrap_or("main").replace("::", "-");
    let dir = std::env::temp_dir()
        .join(format!("primo-test-{}", std::process::id()))
        .join(test);
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

/// A URDF of seven revolute joints `q1`…`q7`, axes alternating z and y as
/// on the LWR, 0.2 m apart along z, each ±2.9 rad at 2 rad/s, on a fixed
/// mount (root link `world`), with a link `hand` 0.1 m beyond the last.
pub fn seven() -> String {
    let mut text = String::from("<robot name=\"seven\">\n<link name=\"world\"/>\n");
    text.push_str("<link name=\"l0\"/>\n<joint name=\"mount\" type=\"fixed\">");
    text.push_str("<parent link=\"world\"/><child link=\"l0\"/></joint>\n");
    for i in 1..=7 {
        let axis = if i % 2 == 1 { "0 0 1" } else { "0 1 0" };
        text.push_str(&format!(
            "<link name=\"l{i}\"/>\n<joint name=\"q{i}\" type=\"revolute\"><parent link=\"l{}\"/>\
             <child link=\"l{i}\"/><origin xyz=\"0 0 0.2\"/><axis xyz=\"{axis}\"/>\
             <limit lower=\"-2.9\" upper=\"2.9\" velocity=\"2\"/></joint>\n",
            i - 1
        ));
    }
    text.push_str(
        "<link name=\"hand\"/>\n<joint name=\"tcp\" type=\"fixed\"><parent link=\"l7\"/>\
         <child link=\"hand\"/><origin xyz=\"0 0 0.1\"/></joint>\n</robot>\n",
    );
    text
}
