//! Closed-loop execution: a measured state fed back, coupling terms
//! added; a run's state kept and resumed.
use primo_core::dmp::{Dmp, FitOptions, Run};

/// A 1-D reach from 0 to 1 over 1 s (minimum jerk), 501 samples.
fn reach() -> Dmp<2, 20> {
    let t: Vec<f32> = (0..501).map(|i| i as f32 / 500.0).collect();
    let y: Vec<f32> = t
        .iter()
        .map(|&t| t * t * t * (10.0 - 15.0 * t + 6.0 * t * t))
        .collect();
    Dmp::fit(&t, &y, 1, 20, &FitOptions::default()).unwrap()
}

#[test]
fn feeding_back_its_own_state_is_the_open_loop_run_bit_for_bit() {
    let dmp = reach();
    let exec = dmp.execution();
    let (mut open, mut closed) = (dmp.start(&exec).unwrap(), dmp.start(&exec).unwrap());
    for _ in 0..1200 {
        let s = closed.sample();
        let (y, v) = (closed.position().to_vec(), s.velocity[..1].to_vec());
        closed.measured(&dmp, Some(&y), Some(&v)).unwrap();
        closed.step_coupled(&dmp, 0.001, &[0.0]).unwrap();
        open.step(&dmp, 0.001).unwrap();
        assert_eq!(closed, open);
    }
}

#[test]
fn a_lagging_measurement_moves_the_run_from_where_the_robot_is() {
    let dmp = reach();
    let exec = dmp.execution();
    let mut open = dmp.start(&exec).unwrap();
    let mut closed = dmp.start(&exec).unwrap();
    for _ in 0..300 {
        open.step(&dmp, 0.001).unwrap();
        closed.step(&dmp, 0.001).unwrap();
    }
    // The robot lags 5 cm behind and stands still.
    let lag = open.position()[0] - 0.05;
    closed.measured(&dmp, Some(&[lag]), Some(&[0.0])).unwrap();
    open.step(&dmp, 0.001).unwrap();
    closed.step(&dmp, 0.001).unwrap();
    assert!(closed.position()[0] < open.position()[0] - 0.04);
    assert!(
        (closed.position()[0] - lag).abs() < 1e-3,
        "one step from where it is"
    );
    // Both still reach the goal.
    for _ in 0..2000 {
        open.step(&dmp, 0.001).unwrap();
        closed.step(&dmp, 0.001).unwrap();
    }
    assert!((closed.position()[0] - 1.0).abs() < 1e-3 && (open.position()[0] - 1.0).abs() < 1e-3);
}

#[test]
fn a_constant_coupling_moves_the_rest_point_by_tau_squared_over_k() {
    let dmp = reach();
    let exec = dmp.execution();
    let mut run = dmp.start(&exec).unwrap();
    let c = 2.0;
    for _ in 0..5000 {
        run.step_coupled(&dmp, 0.001, &[c]).unwrap();
    }
    // At rest, K(g − y) + τ²c = 0 with K = α²/4: y = g + τ²c/K.
    let alpha = dmp.shape().alpha;
    let k = alpha * alpha / 4.0;
    let expected = 1.0 + exec.tau * exec.tau * c / k;
    assert!(
        (run.position()[0] - expected).abs() < 1e-4,
        "{} vs {expected}",
        run.position()[0]
    );
    // The goal itself did not move.
    let s = run.sample();
    assert!(
        s.acceleration[0].abs() > 1.0,
        "without the coupling it accelerates back"
    );
}

#[test]
fn refused_measurements_and_couplings_change_nothing() {
    let dmp = reach();
    let mut run = dmp.start(&dmp.execution()).unwrap();
    run.step(&dmp, 0.001).unwrap();
    let before = run.clone();
    assert!(run.measured(&dmp, Some(&[0.1, 0.2]), None).is_err());
    assert!(run.measured(&dmp, Some(&[0.1]), Some(&[f32::NAN])).is_err());
    assert!(run.measured(&dmp, Some(&[2e6]), None).is_err());
    assert!(run.step_coupled(&dmp, 0.001, &[f32::INFINITY]).is_err());
    assert!(run.step_coupled(&dmp, 0.001, &[3e38]).is_err());
    assert!(run.step_coupled(&dmp, 0.001, &[]).is_err());
    assert_eq!(run, before);
}

#[test]
fn a_run_resumed_from_its_state_goes_on_bit_for_bit() {
    let dmp = reach();
    let mut run = dmp.start(&dmp.execution()).unwrap();
    // Its state before any step (no step size yet) and mid-run.
    let fresh: Vec<f32> = run.state().collect();
    assert_eq!(fresh.len(), Run::<2>::STATE_LEN);
    // Bits: its step size is NaN, no step yet.
    let bits = |r: &Run<2>| r.state().map(f32::to_bits).collect::<Vec<_>>();
    assert_eq!(bits(&Run::from_state(&dmp, &fresh).unwrap()), bits(&run));
    for _ in 0..300 {
        run.step(&dmp, 0.001).unwrap();
    }
    run.set_goal(&dmp, &[0.7]).unwrap();
    let state: Vec<f32> = run.state().collect();
    let mut resumed = Run::from_state(&dmp, &state).unwrap();
    for _ in 0..500 {
        run.step(&dmp, 0.002).unwrap();
        resumed.step(&dmp, 0.002).unwrap();
        assert_eq!(resumed, run);
    }
}

#[test]
fn a_state_that_is_not_a_runs_is_refused() {
    let dmp = reach();
    let run = dmp.start(&dmp.execution()).unwrap();
    let state: Vec<f32> = run.state().collect();
    assert!(Run::from_state(&dmp, &state[1..]).is_err());
    for (i, bad) in [
        (0, 2.0),
        (0, 0.5),
        (1, 0.0),
        (2, f32::NAN),
        (20, f32::INFINITY),
    ] {
        let mut s = state.clone();
        s[i] = bad;
        assert!(Run::from_state(&dmp, &s).is_err(), "value {i} = {bad}");
    }
}
