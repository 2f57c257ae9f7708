//! The rclpy peers of the ROS 2 tests (tests/peers/), started and stopped
//! by the tests themselves.
//!
//! The peers run in the environment `tests/peers/setup.sh` makes, named by
//! `PRIMO_PEERS_VENV`; without it the tests say they are skipped and pass,
//! so a bare `cargo test --workspace` stays green (`./test.sh` sets it).
//! DDS discovery must stay on this machine: the tests refuse to run unless
//! the network namespace has loopback alone (`unshare -n`, see test.sh),
//! and set `ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST` for rclpy; primo's
//! participant advertises only 127.0.0.1. Each test takes its own
//! `ROS_DOMAIN_ID`, so tests running in parallel never answer each
//! other's goals.

#![allow(dead_code)]

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{Receiver, channel};
use std::time::{Duration, Instant};

/// The peers' environment, or `None` (the test is skipped: it said so).
pub fn venv(test: &str) -> Option<PathBuf> {
    match std::env::var_os("PRIMO_PEERS_VENV") {
        Some(v) if !v.is_empty() => {
            assert_loopback_only();
            Some(PathBuf::from(v))
        }
        _ => {
            eprintln!(
                "{test}: skipped: PRIMO_PEERS_VENV is unset (tests/peers/setup.sh makes the \
                 environment; ./test.sh runs these tests in a loopback-only network namespace)"
            );
            None
        }
    }
}

/// Panics unless `lo` is the only network interface (`/proc/net/dev`,
/// which lists the namespace's own, unlike /sys/class/net).
pub fn assert_loopback_only() {
    let dev = std::fs::read_to_string("/proc/net/dev").unwrap_or_default();
    let interfaces: Vec<&str> = dev
        .lines()
        .skip(2)
        .filter_map(|l| l.split(':').next())
        .map(str::trim)
        .collect();
    assert!(
        interfaces == ["lo"],
        "refusing to run DDS discovery outside a loopback-only network namespace \
         (interfaces: {interfaces:?}); run these tests under `unshare -n` as test.sh does"
    );
}

/// The environment every ROS 2 process of a test gets.
pub fn ros_env(command: &mut Command, domain: u16) {
    command
        .env("ROS_DOMAIN_ID", domain.to_string())
        .env("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
        .env("ROS_DISTRO", "jazzy")
        .env_remove("ROS_STATIC_PEERS");
}

/// A peer process: killed when dropped; its stdout lines on a channel,
/// its stderr in a file for the failure message.
pub struct Peer {
    name: String,
    child: Child,
    lines: Receiver<String>,
    stderr: PathBuf,
    /// Every stdout line so far.
    pub said: Vec<String>,
}

/// The repository's root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

impl Peer {
    /// Starts `tests/peers/SCRIPT ARGS` in `venv` on `domain` (the peers
    /// end themselves after a minute) and waits (up to 30 s) for its first
    /// line, `{"event": "ready"}`.
    pub fn start(venv: &Path, domain: u16, script: &str, args: &[&str]) -> Peer {
        let stderr = std::env::temp_dir().join(format!(
            "primo-peer-{}-{domain}-{script}.stderr",
            std::process::id()
        ));
        let log = std::fs::File::create(&stderr).expect("peer stderr file");
        let mut command = Command::new(venv.join("bin/python"));
        command
            .arg(root().join("tests/peers").join(script))
            .args(args)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(log);
        ros_env(&mut command, domain);
        let mut child = command.spawn().expect("start the peer");
        let stdout = child.stdout.take().expect("the peer's stdout");
        let (tx, lines) = channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        let mut peer = Peer {
            name: format!("{script} {}", args.join(" ")),
            child,
            lines,
            stderr,
            said: Vec::new(),
        };
        peer.wait_for("\"ready\"", Duration::from_secs(30));
        peer
    }

    /// Waits for a stdout line containing `text`; panics with the peer's
    /// stderr after `limit`.
    pub fn wait_for(&mut self, text: &str, limit: Duration) -> String {
        let until = Instant::now() + limit;
        if let Some(line) = self.said.iter().find(|l| l.contains(text)) {
            return line.clone();
        }
        while let Some(left) = until.checked_duration_since(Instant::now()) {
            match self.lines.recv_timeout(left) {
                Ok(line) => {
                    self.said.push(line.clone());
                    if line.contains(text) {
                        return line;
                    }
                }
                Err(_) => break,
            }
        }
        panic!(
            "peer `{}` did not say {text} within {limit:?}; it said {:?}\n{}",
            self.name,
            self.said,
            self.stderr()
        )
    }

    /// Everything said on stdout so far (waiting up to `settle` for more).
    pub fn drain(&mut self, settle: Duration) -> &[String] {
        while let Ok(line) = self.lines.recv_timeout(settle) {
            self.said.push(line);
        }
        &self.said
    }

    /// Its standard error so far, for a failure message.
    pub fn stderr(&self) -> String {
        let text = std::fs::read_to_string(&self.stderr).unwrap_or_default();
        format!("--- stderr of peer `{}` ---\n{text}", self.name)
    }
}

impl Drop for Peer {
    fn drop(&mut self) {
        // SIGTERM first: rclpy shuts down cleanly; SIGKILL after 3 s.
        let _ = Command::new("kill")
            .args(["-TERM", &self.child.id().to_string()])
            .status();
        let until = Instant::now() + Duration::from_secs(3);
        while Instant::now() < until {
            if let Ok(Some(_)) = self.child.try_wait() {
                break;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
        let _ = std::fs::remove_file(&self.stderr);
    }
}
