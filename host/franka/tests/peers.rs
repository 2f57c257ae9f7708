//! primo's FCI against independent peers from the Python registry:
//! primo's client executing roll-outs on franka-sim (a simulated FR3
//! server), and Franka's own client, pylibfranka, driving primo's
//! simulated controller.
//!
//! They need the peers' environment (`tests/peers/setup.sh` prints its
//! path; set `PRIMO_PEERS_VENV` to it) and a network namespace with
//! loopback only (franka-sim binds every interface; libfranka's
//! controller port is fixed): `unshare -n sh -c 'ip link set lo up &&
//! cargo test --offline -p primo-franka --test peers'`, as `test.sh`
//! runs them. Otherwise each says why it is skipped and passes.

mod common;

use std::fs::File;
use std::net::TcpStream;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use common::{HOME, client, rollout};
use primo_franka::net::play;
use primo_sim::fci::{FciConfig, SimFci};

/// The peers' environment, if set and the network is loopback only.
fn peers(test: &str) -> Option<PathBuf> {
    let Some(venv) = std::env::var_os("PRIMO_PEERS_VENV") else {
        eprintln!("{test}: skipped: PRIMO_PEERS_VENV is not set (tests/peers/setup.sh prints it)");
        return None;
    };
    let dev = std::fs::read_to_string("/proc/net/dev").unwrap_or_default();
    let others: Vec<&str> = dev
        .lines()
        .skip(2)
        .filter_map(|l| l.split(':').next().map(str::trim))
        .filter(|name| *name != "lo")
        .collect();
    if !others.is_empty() {
        eprintln!(
            "{test}: skipped: the network has {others:?} besides loopback; run it in `unshare -n`"
        );
        return None;
    }
    Some(PathBuf::from(venv))
}

/// A peer process in a process group of its own, the whole group killed
/// when dropped (`timeout` and the peer it started: killing `timeout`
/// alone left the peer running); its stderr kept in a file.
struct Peer {
    child: Child,
    stderr: PathBuf,
}

impl Peer {
    fn start(mut command: Command, name: &str) -> Peer {
        let stderr = std::env::temp_dir().join(format!("primo-{name}-{}.log", std::process::id()));
        let file = File::create(&stderr).expect("a log file");
        let child = command
            .process_group(0)
            .stdout(Stdio::null())
            .stderr(file)
            .spawn()
            .unwrap_or_else(|e| panic!("cannot start {name}: {e}"));
        Peer { child, stderr }
    }

    /// Its stderr's last lines.
    fn log(&self) -> String {
        let text = std::fs::read_to_string(&self.stderr).unwrap_or_default();
        let lines: Vec<&str> = text.lines().collect();
        lines[lines.len().saturating_sub(30)..].join("\n")
    }

    /// Waits until it accepts TCP connections on `port`.
    fn wait_for(&mut self, port: u16) {
        let deadline = Instant::now() + Duration::from_secs(20);
        while TcpStream::connect(("127.0.0.1", port)).is_err() {
            if let Ok(Some(status)) = self.child.try_wait() {
                panic!("the peer exited ({status}):\n{}", self.log());
            }
            assert!(
                Instant::now() < deadline,
                "the peer never listened on {port}:\n{}",
                self.log()
            );
            std::thread::sleep(Duration::from_millis(50));
        }
    }
}

impl Drop for Peer {
    fn drop(&mut self) {
        let group = format!("-{}", self.child.id());
        let _ = Command::new("kill").args(["-KILL", "--", &group]).status();
        let _ = self.child.kill();
        let _ = self.child.wait();
        let _ = std::fs::remove_file(&self.stderr);
    }
}

fn franka_sim(venv: &Path, port: u16, extra: &[&str]) -> Peer {
    let mut c = Command::new("timeout");
    c.arg("120")
        .arg(venv.join("bin/run-franka-sim-server"))
        .args(["--no-gripper", "--port", &port.to_string()])
        .args(extra)
        .env("FR3_MJCF", venv.join("fr3.xml"));
    let mut peer = Peer::start(c, &format!("franka-sim-{port}"));
    peer.wait_for(port);
    peer
}

fn run_on_franka_sim(test: &str, port: u16, extra: &[&str]) {
    let Some(venv) = peers(test) else { return };
    let sim = franka_sim(&venv, port, extra);
    // Connecting at TCP port readiness can race its accept loop a little.
    std::thread::sleep(Duration::from_millis(200));
    let path = rollout(HOME, 2.0);
    let addr = ([127, 0, 0, 1], port).into();
    // franka-sim is a Python process at normal priority: on a loaded test
    // machine it stalls for more than the 100 ms a real controller's
    // silence may last.
    let mut cfg = client();
    cfg.session.state_timeout = Duration::from_secs(2);
    let report =
        play(addr, &path, &cfg, &AtomicBool::new(false), &mut |_| {}).unwrap_or_else(|e| {
            panic!(
                "the roll-out on franka-sim failed: {e}\nfranka-sim:\n{}",
                sim.log()
            )
        });
    assert_eq!(report.commands as usize, report.planned, "{report:?}");
    let end = path.rows().last().expect("a sample");
    for (j, (q, want)) in report.last_q.iter().zip(end).enumerate() {
        // franka-sim's MuJoCo arm follows through its joint servos.
        assert!(
            (q - want).abs() < 0.05 && report.max_error[j] < 0.05,
            "joint {} ended at {q} for {want}: {report:?}\nfranka-sim:\n{}",
            j + 1,
            sim.log()
        );
    }
}

#[test]
fn primo_runs_a_rollout_on_franka_sim() {
    run_on_franka_sim("primo_runs_a_rollout_on_franka_sim", 4311, &[]);
}

/// franka-sim's own check of the FCI's motion limits (position,
/// velocity, acceleration, jerk) passes what primo's plan streams.
#[test]
fn franka_sims_motion_limits_pass_primos_checked_rollout() {
    run_on_franka_sim(
        "franka_sims_motion_limits_pass_primos_checked_rollout",
        4312,
        &["--enforce-motion-limits"],
    );
}

#[test]
fn pylibfranka_drives_primos_simulated_controller() {
    let test = "pylibfranka_drives_primos_simulated_controller";
    let Some(venv) = peers(test) else { return };
    // libfranka's controller port is fixed: 1337.
    let sim = SimFci::new(FciConfig::new(1337)).expect("the simulated controller listens on 1337");
    let stop = AtomicBool::new(false);
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/peers/plf_drive.py");
    let (output, report) = std::thread::scope(|scope| {
        let server = scope.spawn(|| sim.run(&stop));
        let output = Command::new("timeout")
            .arg("60")
            .arg(venv.join("bin/python"))
            .arg(&script)
            .output();
        stop.store(true, Ordering::Relaxed);
        let report = server.join().expect("the controller's thread");
        (output, report)
    });
    let output = output.expect("pylibfranka's script runs");
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.success(),
        "pylibfranka: {}\nstdout: {stdout}\nstderr: {stderr}",
        output.status
    );
    assert!(stdout.contains("\"cycles\": "), "{stdout}");
    let report = report.expect("the controller ran");
    assert_eq!(
        (report.motions, report.finished, report.malformed),
        (1, 1, 0),
        "{report:?}"
    );
    // Answered (in time or not: pylibfranka runs at normal priority here,
    // and a loaded machine makes it late).
    assert!(report.on_time + report.late > 0, "{report:?}");
}
