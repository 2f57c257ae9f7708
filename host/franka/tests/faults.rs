//! primo's client against primo's simulated controller (on 127.0.0.1, no
//! peers needed): a roll-out, and each fault ending it with its typed
//! error.

mod common;

use common::{HOME, against_sim, rollout};
use primo_franka::FrankaError;
use primo_franka::wire::{Flags, MoveStatus};
use primo_sim::fci::Fault;

#[test]
fn a_rollout_runs_to_its_end() {
    let path = rollout(HOME, 1.0);
    let (outcome, sim) = against_sim(|_| {}, &path);
    let report = outcome.expect("the roll-out finishes");
    assert_eq!(report.commands as usize, report.planned);
    let end = path.rows().last().expect("a sample");
    for (q, want) in report.last_q.iter().zip(end) {
        assert!((q - want).abs() < 1e-4, "{report:?}");
    }
    assert_eq!((sim.motions, sim.finished), (1, 1));
}

#[test]
fn an_approach_leads_from_elsewhere_to_the_start() {
    let mut start = HOME;
    start[1] = 0.3;
    let path = rollout(start, 0.5);
    let (outcome, _) = against_sim(|cfg| cfg.start = HOME, &path);
    let report = outcome.expect("the roll-out finishes");
    assert!(report.approach > 100, "{report:?}");
}

#[test]
fn a_reflex_is_a_typed_error() {
    let flag = Flags::index("joint_reflex").expect("a flag");
    let (outcome, sim) = against_sim(
        |cfg| cfg.fault = Some(Fault::Reflex { after: 200, flag }),
        &rollout(HOME, 1.0),
    );
    match outcome {
        Err(FrankaError::Aborted { status, reflex, .. }) => {
            assert!(matches!(status, None | Some(MoveStatus::ReflexAborted)));
            assert_eq!(reflex, Flags::default().with(flag));
        }
        other => panic!("expected a reflex, got {other:?}"),
    }
    assert_eq!(sim.reflexes, 1);
}

#[test]
fn a_silent_stream_is_a_typed_error() {
    let (outcome, _) = against_sim(
        |cfg| cfg.fault = Some(Fault::Silent { after: 200 }),
        &rollout(HOME, 1.0),
    );
    assert!(
        matches!(outcome, Err(FrankaError::Silent(_))),
        "{outcome:?}"
    );
}

#[test]
fn a_dead_command_channel_is_a_typed_error() {
    let (outcome, _) = against_sim(
        |cfg| cfg.fault = Some(Fault::Hangup { after: 200 }),
        &rollout(HOME, 1.0),
    );
    assert!(matches!(outcome, Err(FrankaError::Closed)), "{outcome:?}");
}

#[test]
fn nobody_listening_is_a_network_error() {
    let addr = std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .expect("a free port");
    let outcome = primo_franka::net::play(
        addr,
        &rollout(HOME, 1.0),
        &common::client(),
        &std::sync::atomic::AtomicBool::new(false),
        &mut |_| {},
    );
    assert!(matches!(outcome, Err(FrankaError::Io(_))), "{outcome:?}");
}

#[test]
fn as_an_executor_it_reports_what_ran_before_a_reflex() {
    use primo_franka::net::FrankaRobot;
    use primo_robot::execute::Executor;
    use primo_sim::fci::{FciConfig, SimFci};
    use std::sync::atomic::{AtomicBool, Ordering};

    let mut cfg = FciConfig::new(0);
    cfg.fault = Some(Fault::Reflex {
        after: 300,
        flag: 6,
    });
    let sim = SimFci::new(cfg).expect("the simulated controller listens");
    let mut robot = FrankaRobot {
        addr: sim.local_addr().expect("its address"),
        cfg: common::client(),
    };
    let stop = AtomicBool::new(false);
    let failed = std::thread::scope(|scope| {
        scope.spawn(|| sim.run(&stop));
        let failed = robot.execute(&rollout(HOME, 1.0));
        stop.store(true, Ordering::Relaxed);
        failed
    })
    .expect_err("a reflex");
    assert!(
        failed.to_string().contains("reflex joint_reflex"),
        "{failed}"
    );
    // The robot's clock: 300 ms of motion, whatever states a loaded test
    // machine made the client pass over.
    let times = &failed.executed.times;
    let last = times.last().copied().unwrap_or(0.0);
    assert!((0.25..=0.31).contains(&last), "last state at {last} s");
    assert_eq!(failed.executed.positions.len(), 7 * times.len());
}
