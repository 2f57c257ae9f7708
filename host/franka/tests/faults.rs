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
