//! What the Franka tests share: a path on the built-in FR3 and primo's
//! simulated controller on a thread of the test.

#![allow(dead_code)]

use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, Ordering};

use primo_franka::FrankaError;
use primo_franka::net::{PlayConfig, play};
use primo_franka::plan::fr3;
use primo_franka::session::Report;
use primo_robot::JointPath;
use primo_robot::safety::check_path;
use primo_sim::fci::{FciConfig, FciReport, SimFci};

/// The FR3's start in franka-sim and primo's simulated controller.
pub const HOME: [f64; 7] = [0.0, 0.0, 0.0, -1.57, 0.0, 1.57, 0.785];

/// A minimum-jerk move of joints 1 and 4 from `from` over `seconds`,
/// sampled every 10 ms, checked against the FR3's limits.
pub fn rollout(from: [f64; 7], seconds: f64) -> JointPath {
    let n = (seconds / 0.01).round() as usize;
    let mut times = Vec::new();
    let mut rows = Vec::new();
    for k in 0..=n {
        let s = k as f64 / n as f64;
        let b = s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
        let mut q = from;
        q[0] += 0.3 * b;
        q[3] += 0.2 * b;
        times.push(k as f64 * 0.01);
        rows.extend(q);
    }
    check_path(&fr3(), times, rows, None).expect("a path within the FR3's limits")
}

/// The client's settings in the tests: the defaults, real-time
/// scheduling where the OS grants it (a loaded test machine otherwise
/// makes the 1 kHz loop miss cycles).
pub fn client() -> PlayConfig {
    PlayConfig::default()
}

/// Runs `path` against primo's simulated controller set up by `setup`
/// (on 127.0.0.1, an ephemeral port): the client's outcome and the
/// controller's report.
pub fn against_sim(
    setup: impl FnOnce(&mut FciConfig),
    path: &JointPath,
) -> (Result<Report, FrankaError>, FciReport) {
    let mut cfg = FciConfig::new(0);
    setup(&mut cfg);
    let sim = SimFci::new(cfg).expect("the simulated controller listens");
    let addr: SocketAddr = sim.local_addr().expect("its address");
    let stop = AtomicBool::new(false);
    std::thread::scope(|scope| {
        let server = scope.spawn(|| sim.run(&stop));
        let outcome = play(addr, path, &client(), &AtomicBool::new(false), &mut |_| {});
        stop.store(true, Ordering::Relaxed);
        let report = server
            .join()
            .expect("the controller's thread")
            .expect("the controller ran");
        (outcome, report)
    })
}
