//! A final velocity (Kober et al. 2010's hitting DMP): a throw fitted with
//! its end's speed replays it, a new velocity is reached at the goal, and
//! a DMP at rest runs as it always did.

use primo_core::dmp::{Dmp, FinalVelocity, FitOptions};

/// A throw: 0.5 m of wind-up back, then a swing forward ending at 0.8 m
/// moving at 0.5π + 2.4 ≈ 3.97 m/s, in one second at 500 Hz; a second
/// DoF at rest.
fn throw() -> (Vec<f32>, Vec<f32>) {
    let t: Vec<f32> = (0..=500).map(|i| i as f32 / 500.0).collect();
    let y = t
        .iter()
        .flat_map(|&t| {
            let x = -0.5 * (std::f32::consts::PI * t).sin() + 0.8 * t * t * t;
            [x, 0.1 * t * t * (3.0 - 2.0 * t)]
        })
        .collect();
    (t, y)
}

fn fit(final_velocity: FinalVelocity) -> Dmp<2, 30> {
    let (t, y) = throw();
    let options = FitOptions {
        final_velocity,
        ..FitOptions::default()
    };
    Dmp::fit(&t, &y, 2, 30, &options).unwrap()
}

/// Position and velocity of DoF 0 at τ of `dmp` run with `velocity` at the goal.
fn end(dmp: &Dmp<2, 30>, velocity: Option<f32>) -> (f32, f32, f32) {
    let mut exec = dmp.execution();
    if let Some(v) = velocity {
        exec.goal_velocity = [v, 0.0].into_iter().collect();
    }
    let mut worst = 0.0f32;
    let (t, y) = throw();
    let mut last = None;
    for (s, row) in dmp.trajectory(&exec, 0.002).unwrap().zip(y.chunks(2)) {
        if velocity.is_none() {
            worst = worst.max((s.position[0] - row[0]).abs());
        }
        last = Some(s);
    }
    assert_eq!(t.len(), 501);
    let s = last.unwrap();
    (s.position[0], s.velocity[0], worst)
}

#[test]
fn a_throw_fitted_with_its_final_velocity_replays_its_speed() {
    let hitting = fit(FinalVelocity::Demonstrated);
    // The demonstration's 3.97 m/s (the last 20 ms' slope: a little less).
    let demonstrated = 0.5 * std::f32::consts::PI + 2.4;
    let v = hitting.goal_velocity()[0];
    assert!((v - demonstrated).abs() < 0.1, "{v}");
    assert!(hitting.goal_velocity()[1].abs() < 1e-2);
    let (x, speed, worst) = end(&hitting, None);
    assert!((x - 0.8).abs() < 2e-3, "ends at {x}");
    assert!(
        (speed - demonstrated).abs() < 0.15,
        "ends moving at {speed}"
    );
    // As well as the classic DMP fitted to the same positions (4.9 mm off
    // at the swing's fastest with 30 kernels, both): the difference is
    // that its end's speed is a parameter now.
    let (_, _, classic) = end(&fit(FinalVelocity::AtRest), None);
    assert!(
        worst < classic + 1e-4,
        "replay off by {worst}, classic {classic}"
    );
}

/// A new velocity at the goal: reached at τ, at the goal.
#[test]
fn a_new_final_velocity_is_reached_at_the_goal() {
    let hitting = fit(FinalVelocity::Demonstrated);
    for v in [0.0f32, 1.0, 3.5] {
        let (x, speed, _) = end(&hitting, Some(v));
        assert!((x - 0.8).abs() < 5e-3, "{v}: ends at {x}");
        assert!((speed - v).abs() < 0.15, "{v}: ends moving at {speed}");
    }
}

/// A DMP at rest run with a zero goal velocity is the DMP as before, bit
/// for bit; its file has no `goal_velocity`, and one that has it reads back.
#[test]
fn at_rest_nothing_changes_and_files_round_trip() {
    let classic = fit(FinalVelocity::AtRest);
    assert!(classic.goal_velocity().is_empty());
    let mut exec = classic.execution();
    let plain: Vec<_> = classic.trajectory(&exec, 0.002).unwrap().collect();
    exec.goal_velocity = [0.0, 0.0].into_iter().collect();
    let zero: Vec<_> = classic.trajectory(&exec, 0.002).unwrap().collect();
    assert_eq!(plain, zero);
    let json = serde_json::to_string(&classic).unwrap();
    assert!(!json.contains("goal_velocity"));
    let hitting = fit(FinalVelocity::Demonstrated);
    let json = serde_json::to_string(&hitting).unwrap();
    assert!(json.contains("goal_velocity"));
    let back: Dmp<2, 30> = serde_json::from_str(&json).unwrap();
    assert_eq!(back, hitting);
    let bad = json.replacen("\"goal_velocity\":[", "\"goal_velocity\":[1e30,", 1);
    assert!(serde_json::from_str::<Dmp<2, 30>>(&bad).is_err());
}

/// The goal travels `ġτ`: a run over a huge `τ` with a tiny goal velocity
/// stays finite (the fuzzer's case: `4τ/α` alone overflowed f32), and a
/// travel beyond ±1e6 is refused before the run starts.
#[test]
fn the_goals_travel_is_bounded_not_its_duration() {
    let hitting = fit(FinalVelocity::Demonstrated);
    let mut exec = hitting.execution();
    exec.tau = 1.7e38;
    exec.goal_velocity = [2e-36, -5e-36].into_iter().collect();
    let run: Vec<_> = hitting
        .trajectory(&exec, 2.6e33)
        .unwrap()
        .take(100)
        .collect();
    for s in &run {
        assert!(s.position[..2].iter().all(|x| x.is_finite()), "{s:?}");
        assert!(s.velocity[..2].iter().all(|x| x.is_finite()), "{s:?}");
        assert!(s.acceleration[..2].iter().all(|x| x.is_finite()), "{s:?}");
    }
    exec.goal_velocity = [1e-30, 0.0].into_iter().collect();
    let refused = hitting.trajectory(&exec, 2.6e33).map(|_| ()).unwrap_err();
    assert!(
        refused.to_string().contains("goal would travel"),
        "{refused}"
    );
}
