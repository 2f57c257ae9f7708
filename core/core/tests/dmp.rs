//! The DMP properties the issue asks for, on the demos it names.
use primo_core::dmp::{AUTO_MARGIN, Dmp, FitOptions, MIN_ALPHA, MIN_TAU, Margin, Scaling, Shape};
use std::f32::consts::PI;

mod common;
use common::{assert_no_worse_when_denser, hash, stamps};

fn min_jerk(t: f32) -> f32 {
    t * t * t * (10.0 - 15.0 * t + 6.0 * t * t)
}

fn bump(t: f32) -> f32 {
    (PI * t).sin().powi(2)
}

/// 2-D minimum jerk plus a bump, 1001 samples over 1 s, row-major.
fn demo_2d() -> (Vec<f32>, Vec<f32>) {
    let t: Vec<f32> = (0..1001).map(|i| i as f32 / 1000.0).collect();
    let y = t
        .iter()
        .flat_map(|&t| {
            [
                min_jerk(t) + 0.3 * bump(t),
                0.5 - 1.0 * min_jerk(t) - 0.2 * (2.0 * PI * t).sin().powi(2),
            ]
        })
        .collect();
    (t, y)
}

fn positions<const D: usize, const K: usize>(
    dmp: &Dmp<D, K>,
    exec: &primo_core::dmp::Execution<D>,
    dt: f32,
) -> Vec<[f32; D]> {
    dmp.trajectory(exec, dt)
        .unwrap()
        .map(|s| s.position)
        .collect()
}

#[test]
fn reproduces_min_jerk_plus_bump_within_movement_primitives_rmse() {
    let (t, y) = demo_2d();
    let dmp = Dmp::<2, 30>::fit(&t, &y, 2, 30, &FitOptions::default()).unwrap();
    let out = positions(&dmp, &dmp.execution(), 0.001);
    assert_eq!(out.len(), 1001);
    let sse: f32 = out
        .iter()
        .zip(y.chunks(2))
        .map(|(p, d)| (p[0] - d[0]).powi(2) + (p[1] - d[1]).powi(2))
        .sum();
    let rmse = (sse / (2.0 * 1001.0)).sqrt();
    println!("RMSE 2-D min-jerk + bump, 30 kernels: {rmse}");
    assert!(rmse <= 0.0012, "RMSE {rmse}");
}

#[test]
fn goal_near_start_shrinks_the_shape_instead_of_overshooting() {
    let t: Vec<f32> = (0..1001).map(|i| i as f32 / 1000.0).collect();
    let y: Vec<f32> = t.iter().map(|&t| min_jerk(t) + 0.3 * bump(t)).collect();
    let dmp = Dmp::<1, 30>::fit(&t, &y, 1, 30, &FitOptions::default()).unwrap();
    let mut exec = dmp.execution();
    exec.goal[0] = 0.05;
    let out = positions(&dmp, &exec, 0.001);
    let last = out.last().unwrap()[0];
    assert!((last - 0.05).abs() < 1e-3, "ends at {last}");
    // Never more than 5% of the demonstrated amplitude outside [0, 0.05].
    for p in &out {
        assert!(p[0] > -0.05 && p[0] < 0.1, "strays to {}", p[0]);
    }
}

#[test]
fn loop_demo_is_reproduced() {
    // Start equals goal: out and back.
    let t: Vec<f32> = (0..1001).map(|i| i as f32 / 1000.0).collect();
    let y: Vec<f32> = t
        .iter()
        .map(|&t| 0.2 + 0.8 * bump(t) - 0.3 * (2.0 * PI * t).sin().powi(3))
        .collect();
    let dmp = Dmp::<1, 30>::fit(&t, &y, 1, 30, &FitOptions::default()).unwrap();
    assert!(!dmp.is_scaled(0), "a loop cannot be amplitude-scaled");
    let out = positions(&dmp, &dmp.execution(), 0.001);
    let (lo, hi) = y
        .iter()
        .fold((f32::MAX, f32::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    let rmse = (out
        .iter()
        .zip(&y)
        .map(|(p, d)| (p[0] - d).powi(2))
        .sum::<f32>()
        / y.len() as f32)
        .sqrt();
    println!("loop RMSE {rmse}, amplitude {}", hi - lo);
    assert!(rmse <= 0.01 * (hi - lo), "RMSE {rmse}");
    // A new start shifts the loop.
    let mut exec = dmp.execution();
    exec.start[0] = 1.2;
    exec.goal[0] = 1.2;
    let shifted = positions(&dmp, &exec, 0.001);
    for (a, b) in shifted.iter().zip(&out) {
        assert!((a[0] - b[0] - 1.0).abs() < 1e-3);
    }
}

#[test]
fn ends_at_goal_at_rest_and_time_scaling_keeps_the_path() {
    let (t, y) = demo_2d();
    let dmp = Dmp::<2, 30>::fit(&t, &y, 2, 30, &FitOptions::default()).unwrap();
    let mut exec = dmp.execution();
    exec.goal[0] = 2.0;
    exec.goal[1] = -1.0;
    let samples: Vec<_> = dmp.trajectory(&exec, 0.001).unwrap().collect();
    let end = samples.last().unwrap();
    assert_eq!(end.time, 1.0);
    for d in 0..2 {
        assert!(
            (end.position[d] - exec.goal[d]).abs() < 2e-3,
            "DoF {d} ends at {}",
            end.position[d]
        );
        assert!(
            end.velocity[d].abs() < 0.05,
            "DoF {d} velocity {}",
            end.velocity[d]
        );
    }
    // Replay at 2τ: the same path, reached at twice the time.
    let mut slow = exec.clone();
    slow.tau = 2.0;
    let slow_samples: Vec<_> = dmp.trajectory(&slow, 0.001).unwrap().collect();
    assert_eq!(slow_samples.len(), 2001);
    for (i, s) in samples.iter().enumerate() {
        let z = &slow_samples[2 * i];
        assert!((z.time - 2.0 * s.time).abs() < 1e-5);
        for d in 0..2 {
            assert!(
                (z.position[d] - s.position[d]).abs() < 1e-3,
                "t={} DoF {d}",
                s.time
            );
            assert!((2.0 * z.velocity[d] - s.velocity[d]).abs() < 2e-2);
        }
    }
}

#[test]
fn step_by_step_equals_whole_trajectory_and_goal_can_move() {
    let (t, y) = demo_2d();
    let dmp = Dmp::<2, 30>::fit(&t, &y, 2, 30, &FitOptions::default()).unwrap();
    let exec = dmp.execution();
    let whole: Vec<_> = dmp.trajectory(&exec, 0.002).unwrap().collect();
    let mut run = dmp.start(&exec).unwrap();
    for s in &whole[1..] {
        run.step(&dmp, 0.002).unwrap();
        assert_eq!(run.position(), &s.position[..]);
    }
    // Goal change half way: ends at the new goal.
    let mut run = dmp.start(&exec).unwrap();
    for i in 0..1500 {
        if i == 500 {
            run.set_goal(&dmp, &[0.5, 0.0]).unwrap();
        }
        run.step(&dmp, 0.001).unwrap();
    }
    assert!(
        (run.position()[0] - 0.5).abs() < 1e-3 && run.position()[1].abs() < 1e-3,
        "{:?}",
        run.position()
    );
    assert!(run.sample().position.iter().all(|v| v.is_finite()));
}

#[test]
fn positions_alone_are_the_samples_positions_and_the_length_is_known_ahead() {
    let (t, y) = demo_2d();
    let dmp = Dmp::<2, 10>::fit(&t, &y, 2, 10, &FitOptions::default()).unwrap();
    let exec = dmp.execution();
    for dt in [0.002, 0.3, 0.25, 2.0, 1e4] {
        let whole: Vec<_> = dmp.trajectory(&exec, dt).unwrap().collect();
        let mut steps = dmp.trajectory(&exec, dt).unwrap();
        assert_eq!(
            steps.size_hint(),
            (whole.len(), Some(whole.len())),
            "dt {dt}"
        );
        for (i, s) in whole.iter().enumerate() {
            let (time, position) = steps.next_position().unwrap();
            assert_eq!((time, position), (s.time, &s.position[..]), "dt {dt}");
            let left = whole.len() - i - 1;
            assert_eq!(steps.size_hint(), (left, Some(left)));
        }
        assert_eq!(steps.next_position(), None);
    }
}

#[test]
fn trajectory_length_is_exact_for_any_dt() {
    let (t, y) = demo_2d();
    let dmp = Dmp::<2, 10>::fit(&t, &y, 2, 10, &FitOptions::default()).unwrap();
    let exec = dmp.execution();
    let times: Vec<f32> = dmp
        .trajectory(&exec, 0.3)
        .unwrap()
        .map(|s| s.time)
        .collect();
    assert_eq!(times, vec![0.0, 0.3, 0.6, 0.90000004, 1.0]);
    assert_eq!(dmp.trajectory(&exec, 0.25).unwrap().count(), 5);
    assert_eq!(
        dmp.trajectory(&exec, 2.0)
            .unwrap()
            .map(|s| s.time)
            .collect::<Vec<_>>(),
        vec![0.0, 1.0]
    );
    // τ far below dt: still the start and the end.
    let times: Vec<f32> = dmp
        .trajectory(&exec, 1e4)
        .unwrap()
        .map(|s| s.time)
        .collect();
    assert_eq!(times, vec![0.0, 1.0]);
}

#[test]
fn uneven_sampling_fits_as_well() {
    // Same curve sampled on a warped, uneven time grid.
    let t: Vec<f32> = (0..600)
        .map(|i| {
            let u = i as f32 / 599.0;
            u + 0.1 * (2.0 * PI * u).sin() / (2.0 * PI)
        })
        .collect();
    let y: Vec<f32> = t.iter().map(|&t| min_jerk(t) + 0.3 * bump(t)).collect();
    let dmp = Dmp::<1, 30>::fit(&t, &y, 1, 30, &FitOptions::default()).unwrap();
    let out = positions(&dmp, &dmp.execution(), 0.001);
    let rmse = (out
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let tt = i as f32 * 0.001;
            (p[0] - (min_jerk(tt) + 0.3 * bump(tt))).powi(2)
        })
        .sum::<f32>()
        / out.len() as f32)
        .sqrt();
    assert!(rmse < 2e-3, "RMSE {rmse}");
}

#[test]
fn parameters_and_serde_round_trip() {
    let (t, y) = demo_2d();
    let mut dmp = Dmp::<2, 30>::fit(&t, &y, 2, 30, &FitOptions::default()).unwrap();
    assert_eq!(dmp.param_len(), 2 * 30 + 2 + 1);
    let mut theta = vec![0.0; dmp.param_len()];
    dmp.params(&mut theta).unwrap();
    theta[62] = 1.5; // τ
    dmp.set_params(&theta).unwrap();
    assert_eq!(dmp.tau(), 1.5);
    let json = serde_json::to_string(&dmp).unwrap();
    let back: Dmp<2, 30> = serde_json::from_str(&json).unwrap();
    assert_eq!(back, dmp);
    // Inconsistent or invalid documents are rejected.
    let bad = json.replace("\"tau\":1.5", "\"tau\":-1.0");
    assert!(serde_json::from_str::<Dmp<2, 30>>(&bad).is_err());
    assert!(
        serde_json::from_str::<Dmp<1, 30>>(&json).is_err(),
        "capacity exceeded"
    );
    theta[0] = f32::NAN;
    assert!(dmp.set_params(&theta).is_err());
    assert_eq!(back, dmp, "failed set_params leaves the DMP unchanged");
    // Saved before margins existed: none. A margin leaving no spacing
    // between the ends is refused.
    let margin = format!("\"margin\":{:?},", dmp.margin());
    assert!(json.contains(&margin), "{json}");
    let old: Dmp<2, 30> = serde_json::from_str(&json.replace(&margin, "")).unwrap();
    assert_eq!(old.margin(), 0.0);
    for bad in ["\"margin\":14.5,", "\"margin\":-1.0,"] {
        assert!(serde_json::from_str::<Dmp<2, 30>>(&json.replace(&margin, bad)).is_err());
    }
}

/// RMSE of a `K`-kernel fit of `demo_2d` with `margin`, replayed at 1 ms.
fn rmse_with<const K: usize>(margin: Margin) -> (f32, f32) {
    let (t, y) = demo_2d();
    let options = FitOptions {
        margin,
        ..FitOptions::default()
    };
    let dmp = Dmp::<2, K>::fit(&t, &y, 2, K, &options).unwrap();
    let out = positions(&dmp, &dmp.execution(), 0.001);
    let sse: f32 = out
        .iter()
        .zip(y.chunks(2))
        .map(|(p, d)| (p[0] - d[0]).powi(2) + (p[1] - d[1]).powi(2))
        .sum();
    ((sse / (2.0 * out.len() as f32)).sqrt(), dmp.margin())
}

#[test]
fn kernels_beyond_the_ends_fit_a_resolved_movement_better_and_auto_keeps_the_better() {
    let (none, _) = rmse_with::<30>(Margin::Spacings(0.0));
    let (one, _) = rmse_with::<30>(Margin::Spacings(AUTO_MARGIN));
    let (auto, chosen) = rmse_with::<30>(Margin::Auto);
    println!("30 kernels: RMSE {none:.2e} on the ends, {one:.2e} one beyond, auto {auto:.2e}");
    // Resolved by 30 kernels, the movement's error is at its ends.
    assert!(one < 0.5 * none, "{one} vs {none}");
    assert_eq!((auto, chosen), (one, AUTO_MARGIN));
    // Whichever is better, Auto keeps it.
    let (none, _) = rmse_with::<6>(Margin::Spacings(0.0));
    let (one, _) = rmse_with::<6>(Margin::Spacings(AUTO_MARGIN));
    let (auto, _) = rmse_with::<6>(Margin::Auto);
    println!("6 kernels: RMSE {none:.2e} on the ends, {one:.2e} one beyond, auto {auto:.2e}");
    assert_eq!(auto, none.min(one));
    // Three kernels leave no spacing between the ends with a margin of 1.
    assert_eq!(rmse_with::<3>(Margin::Auto).1, 0.0);
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let o = FitOptions::default();
    let t = [0.0, 0.5, 1.0];
    assert!(
        Dmp::<1, 5>::fit(&t, &[0.0, 1.0, 2.0], 1, 6, &o).is_err(),
        "too many kernels"
    );
    assert!(
        Dmp::<1, 5>::fit(&t, &[0.0, 1.0, 2.0], 1, 1, &o).is_err(),
        "one kernel"
    );
    assert!(
        Dmp::<1, 5>::fit(&t, &[0.0, 1.0, 2.0], 2, 5, &o).is_err(),
        "too many DoF"
    );
    assert!(
        Dmp::<1, 5>::fit(&t, &[0.0, 1.0], 1, 5, &o).is_err(),
        "length mismatch"
    );
    assert!(
        Dmp::<1, 5>::fit(&[0.0, 1.0, 1.0], &[0.0, 1.0, 2.0], 1, 5, &o).is_err(),
        "repeated time"
    );
    assert!(
        Dmp::<1, 5>::fit(&t, &[0.0, f32::NAN, 2.0], 1, 5, &o).is_err(),
        "NaN"
    );
    assert!(
        Dmp::<1, 5>::fit(&t[..2], &[0.0, 1.0], 1, 2, &o).is_err(),
        "two samples"
    );
    let o2 = FitOptions {
        scaling: Scaling::Always,
        ..o
    };
    assert!(
        Dmp::<1, 5>::fit(&t, &[0.0, 1.0, 0.0], 1, 2, &o2).is_err(),
        "scaled loop"
    );
    for margin in [-0.5, f32::NAN, f32::INFINITY, 1.0] {
        let o = FitOptions {
            margin: Margin::Spacings(margin),
            ..o
        };
        assert!(
            Dmp::<1, 5>::fit(&t, &[0.0, 1.0, 2.0], 1, 3, &o).is_err(),
            "margin {margin} with 3 kernels"
        );
    }
    let dmp = Dmp::<1, 5>::fit(&t, &[0.0, 1.0, 2.0], 1, 3, &o).unwrap();
    let mut exec = dmp.execution();
    assert!(dmp.trajectory(&exec, 0.0).is_err());
    assert!(dmp.trajectory(&exec, f32::NAN).is_err());
    exec.tau = -1.0;
    assert!(dmp.start(&exec).is_err());
    exec.tau = 1.0;
    exec.goal[0] = f32::INFINITY;
    assert!(dmp.start(&exec).is_err());
}

/// Cases an independent review found to give NaN or a wrong end time.
#[test]
fn review_findings_stay_fixed() {
    // Very narrow kernels: every raw activation underflows between kernels.
    let t = [0.0, 0.01, 0.02, 0.98, 0.99, 1.0];
    let y = [0.0, 0.0, 0.0, 1.0, 1.0, 1.0];
    let o = FitOptions {
        overlap: 1000.0,
        ..FitOptions::default()
    };
    if let Ok(dmp) = Dmp::<1, 2>::fit(&t, &y, 1, 2, &o) {
        let mut f = [0.0];
        dmp.forcing(0.5, &mut f);
        assert!(f[0].is_finite());
        assert!(
            dmp.trajectory(&dmp.execution(), 0.01)
                .unwrap()
                .all(|s| s.position[0].is_finite())
        );
    }
    let (t, y) = demo_2d();
    let mut dmp = Dmp::<2, 30>::fit(&t, &y, 2, 30, &FitOptions::default()).unwrap();
    // A huge step on the shortest τ: the spring has settled, not 0·∞.
    let mut exec = dmp.execution();
    exec.tau = MIN_TAU;
    let mut run = dmp.start(&exec).unwrap();
    run.step(&dmp, 1e10).unwrap();
    assert!(run.position().iter().all(|v| v.is_finite()));
    run.step(&dmp, 3e38).unwrap();
    assert!(run.position().iter().all(|v| v.is_finite()));
    assert!(run.step(&dmp, 3e38).is_err(), "time would overflow");
    assert!(run.time().is_finite());
    // Weights beyond the documented bound are refused.
    let mut theta = vec![0.0; dmp.param_len()];
    dmp.params(&mut theta).unwrap();
    theta[3] = 3e38;
    assert!(dmp.set_params(&theta).is_err());
    // τ off the dt grid ends exactly at τ, with the forcing switched off.
    let exec = dmp.execution();
    for (tau, rows) in [(1.0005f32, 1002usize), (0.9996, 1001)] {
        let mut e = exec.clone();
        e.tau = tau;
        let samples: Vec<_> = dmp.trajectory(&e, 0.001).unwrap().collect();
        assert_eq!(samples.len(), rows, "tau {tau}");
        assert_eq!(samples.last().unwrap().time, tau);
        assert!(samples[rows - 2].time < tau);
    }
}

/// Crashes the `dmp` fuzz target found (fuzz/seeds/dmp/regression-*): a
/// subnormal `α` (stiffness `α²/4` = 0, equilibrium ∞) and a `τ` of 1e−35 s
/// (acceleration ∞) made NaN or ∞ samples. Both are now refused, and the
/// same DMPs at the documented bounds integrate finitely.
#[test]
fn fuzz_findings_stay_fixed() {
    let finite = |dmp: &Dmp<1, 5>, exec| {
        dmp.trajectory(exec, 3.7e-4).unwrap().all(|s| {
            [s.position[0], s.velocity[0], s.acceleration[0]]
                .iter()
                .all(|v| v.is_finite())
        })
    };
    let shape = |alpha| Shape {
        alpha,
        width: 3.914_819e-11,
        margin: 0.0,
        scaled: 1,
    };
    let theta = [
        -18.187_683,
        -18.187_218,
        -18.187_777,
        -18.187_37,
        -18.187_546,
        274.6582,
        1.171_890_3,
    ];
    assert!(Dmp::<1, 5>::from_shape(&shape(1.469_368e-39), 1, 5, &[345_092.78], &theta).is_err());
    let dmp = Dmp::<1, 5>::from_shape(&shape(MIN_ALPHA), 1, 5, &[345_092.78], &theta).unwrap();
    let mut exec = dmp.execution();
    exec.goal[0] = -0.547_180_2;
    assert!(finite(&dmp, &exec));

    let theta = [
        -0.889_420_6,
        -0.889_434_7,
        -0.889_432_2,
        -0.889_444_4,
        -0.889_452_2,
        82_305.91,
        2.0,
    ];
    let dmp = Dmp::<1, 5>::from_shape(&shape(4.116_821_3), 1, 5, &[345_092.78], &theta).unwrap();
    let mut exec = dmp.execution();
    exec.tau = 1.930_191_1e-35;
    assert!(dmp.start(&exec).is_err());
    exec.tau = MIN_TAU;
    assert!(finite(&dmp, &exec));
    let t = [0.0, 1e-4, 2e-4];
    let fit = Dmp::<1, 5>::fit(&t, &[0.0, 1.0, 2.0], 1, 2, &FitOptions::default());
    assert!(fit.is_err(), "a demo shorter than MIN_TAU");
}

/// Max error of a 30-kernel fit of the 1 s movement (minimum jerk
/// 0 → 0.6 plus a 0.15 bump) sampled at `times`, with `noise` added to the
/// recorded positions, replayed at 1 ms against the exact movement.
fn reproduction_error(times: &[f32], noise: &dyn Fn(usize) -> f32) -> f32 {
    let exact = |t: f32| 0.6 * min_jerk(t) + 0.15 * bump(t);
    let y: Vec<f32> = times
        .iter()
        .enumerate()
        .map(|(i, &t)| exact(t) + noise(i))
        .collect();
    let dmp = Dmp::<1, 30>::fit(times, &y, 1, 30, &FitOptions::default()).unwrap();
    dmp.trajectory(&dmp.execution(), 0.001)
        .unwrap()
        .map(|s| (s.position[0] - exact(s.time)).abs())
        .fold(0.0, f32::max)
}

#[test]
fn a_denser_recording_fits_as_well_or_better() {
    let none = |_: usize| 0.0;
    let rates = [100usize, 1_000, 10_000, 100_000];
    let mut errors = Vec::new();
    for n in rates {
        // Even, and with recorder jitter: every inner stamp off by up to
        // ±20 % of a period.
        let [e, j] = [0.0, 0.2].map(|jitter| reproduction_error(&stamps(n, jitter), &none));
        println!("{n} Hz: max error {e:.2e} even, {j:.2e} jittered");
        errors.push(f64::from(e.max(j)));
    }
    // At 100 Hz already within 1e-5; no denser rate does worse (beyond
    // f32 rounding of the replay).
    assert_no_worse_when_denser(&errors, "max error by rate");
}

#[test]
fn measurement_noise_averages_out_with_more_samples() {
    // 0.1 mm of uniform noise on every recorded position.
    let noisy = |i: usize| (2e-4 * hash(i, 11)) as f32;
    let error = |n: usize| {
        let t: Vec<f32> = (0..=n).map(|i| i as f32 / n as f32).collect();
        reproduction_error(&t, &noisy)
    };
    let (e100, e10k) = (error(100), error(10_000));
    println!("0.1 mm noise: max error {e100:.2e} at 100 Hz, {e10k:.2e} at 10 kHz");
    assert!(e100 < 1e-4, "{e100}");
    assert!(e10k < e100, "{e10k} vs {e100}");
}
