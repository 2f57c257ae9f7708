//! Coupling terms: obstacles kept clear, joint limits kept, phase stopping,
//! what each refuses, and bounds on what any term adds.

use primo_core::Error;
use primo_core::coupling::{Coupling, JointLimits, Obstacles, PhaseStop, Sphere};
use primo_core::dmp::{Dmp, FitOptions};
use proptest::prelude::*;

/// A minimum-jerk reach from `a` to `b` in one second, 101 samples.
fn reach(a: [f32; 3], b: [f32; 3]) -> Dmp<3, 20> {
    let t: Vec<f32> = (0..=100).map(|i| i as f32 / 100.0).collect();
    let y: Vec<f32> = t
        .iter()
        .flat_map(|&t| {
            let s = t * t * t * (10.0 - 15.0 * t + 6.0 * t * t);
            [0, 1, 2].map(|i| a[i] + (b[i] - a[i]) * s)
        })
        .collect();
    Dmp::fit(&t, &y, 3, 20, &FitOptions::default()).unwrap()
}

/// The run to 2 s at 500 Hz with `terms`: every position.
fn run(dmp: &Dmp<3, 20>, terms: &[&dyn Coupling]) -> Vec<[f32; 3]> {
    let mut r = dmp.start(&dmp.execution()).unwrap();
    let mut path = vec![];
    while r.time() < 2.0 {
        r.step_with(dmp, 0.002, terms).unwrap();
        let p = r.position();
        path.push([p[0], p[1], p[2]]);
    }
    path
}

fn gap(a: [f32; 3], b: [f32; 3]) -> f32 {
    (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f32>().sqrt()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// A ball on or near the straight path of a reach (its centre 1 mm to
    /// 10 cm off it, anywhere between 30 % and 70 % of the way) is never
    /// entered, and the reach still ends at its goal.
    #[test]
    fn a_ball_near_the_path_is_kept_clear_and_the_goal_reached(
        start in prop::array::uniform3(-0.5f32..0.5),
        dir in prop::array::uniform3(-1.0f32..1.0),
        length in 0.3f32..1.0,
        along in 0.3f32..0.7,
        side in prop::array::uniform3(-1.0f32..1.0),
        off in 0.001f32..0.1,
        radius in 0.0f32..0.08,
    ) {
        let n = gap(dir, [0.0; 3]);
        prop_assume!(n > 0.1);
        let u = dir.map(|d| d / n);
        let goal = [0, 1, 2].map(|i| start[i] + length * u[i]);
        // `side` without its part along the path, to unit length.
        let s_along: f32 = (0..3).map(|i| side[i] * u[i]).sum();
        let perp = [0, 1, 2].map(|i| side[i] - s_along * u[i]);
        let m = gap(perp, [0.0; 3]);
        prop_assume!(m > 0.1);
        let center = [0, 1, 2].map(|i| start[i] + along * length * u[i] + off * perp[i] / m);
        let ball = Sphere { center, radius };
        prop_assume!(ball.distance(start) > 0.05 && ball.distance(goal) > 0.05);
        let dmp = reach(start, goal);
        let obstacles = Obstacles::<1>::new([0, 1, 2], &[ball], &start, &goal).unwrap();
        let path = run(&dmp, &[&obstacles]);
        let clearance = path.iter().map(|p| ball.distance(*p)).fold(f32::INFINITY, f32::min);
        prop_assert!(clearance > 0.0, "entered the ball: clearance {clearance}");
        let end = *path.last().unwrap();
        prop_assert!(gap(end, goal) < 1e-2, "ended {} from the goal", gap(end, goal));
    }

    /// Whatever the state, the terms add finite accelerations no larger
    /// than their bound (per obstacle; per DoF for the joint limits).
    #[test]
    fn terms_are_finite_and_bounded(
        position in prop::array::uniform3(-1e6f32..1e6),
        velocity in prop::array::uniform3(-1e6f32..1e6),
        near in prop::array::uniform3(-1e-3f32..1e-3),
        radius in 0.0f32..10.0,
        gain in 1e-3f32..1e3,
        power in 1.0f32..16.0,
    ) {
        // The ball's centre at, or right next to, the position.
        let center = [0, 1, 2].map(|i| position[i] + near[i]);
        let ball = Sphere { center, radius };
        let far = [0, 1, 2].map(|i| center[i] + radius + 1.0);
        let obstacles = Obstacles::<2>::new([2, 0, 1], &[ball, ball], &far, &far)
            .unwrap()
            .with_gains(gain, power, 50.0)
            .unwrap();
        let mut a = [0.0f32; 3];
        obstacles.add_to(&position, &velocity, &mut a).unwrap();
        prop_assert!(a.iter().all(|v| v.is_finite()));
        prop_assert!(gap(a, [0.0; 3]) <= 2.0 * 50.0 * 1.0001, "{a:?}");

        let limits = JointLimits::<3>::new(
            &[-1.0; 3], &[1.0; 3], 0.2, gain, gain * 10.0, &[0.0; 3], &[0.0; 3],
        ).unwrap();
        let mut a = [0.0f32; 3];
        limits.add_to(&position, &velocity, &mut a).unwrap();
        prop_assert!(a.iter().all(|v| v.is_finite() && v.abs() <= gain * 10.0 * 1.0001), "{a:?}");
    }
}

/// A ball behind the start, which the reach moves away from, leaves the
/// run as it was (the only push is on the settling's last micrometre
/// back).
#[test]
fn a_ball_the_reach_moves_away_from_changes_nothing() {
    let dmp = reach([0.0; 3], [0.6, 0.0, 0.0]);
    let ball = Sphere {
        center: [-0.2, 0.01, 0.0],
        radius: 0.05,
    };
    let o = Obstacles::<1>::new([0, 1, 2], &[ball], &[0.0; 3], &[0.6, 0.0, 0.0]).unwrap();
    let (pushed, free) = (run(&dmp, &[&o]), run(&dmp, &[]));
    let worst = pushed
        .iter()
        .zip(&free)
        .map(|(a, b)| gap(*a, *b))
        .fold(0.0, f32::max);
    assert!(worst < 1e-6, "moved by {worst}");
    // Up to the goal's first crossing, nothing at all.
    let crossing = free.iter().position(|p| p[0] >= 0.6).unwrap();
    assert_eq!(pushed[..crossing], free[..crossing]);
}

/// A ball that holds the start or the goal, a negative radius, an axis
/// twice or beyond the DoF, and more balls than room are refused.
#[test]
fn obstacles_refuse_what_cannot_be_avoided() {
    let (start, goal) = ([0.0f32; 3], [0.6f32, 0.0, 0.0]);
    let ball = |center, radius| Sphere { center, radius };
    let new = |spheres: &[Sphere], axes| Obstacles::<1>::new(axes, spheres, &start, &goal);
    let cases = [
        (
            new(&[ball([0.01, 0.0, 0.0], 0.05)], [0, 1, 2]),
            "an obstacle holds the movement's start",
        ),
        (
            new(&[ball([0.6, 0.0, 0.0], 0.0)], [0, 1, 2]),
            "an obstacle holds the movement's goal",
        ),
        (
            new(&[ball([0.3, 0.0, 0.0], -0.1)], [0, 1, 2]),
            "an obstacle's radius must be ≥ 0",
        ),
        (
            new(&[], [0, 1, 1]),
            "obstacle axes must be three different DoFs",
        ),
        (
            new(&[], [0, 1, 3]),
            "an obstacle axis is beyond the DMP's DoF",
        ),
    ];
    for (got, why) in cases {
        assert_eq!(got, Err(Error::OutOfRange(why)));
    }
    let two = [ball([0.3, 0.2, 0.0], 0.05), ball([0.3, -0.2, 0.0], 0.05)];
    assert!(matches!(
        new(&two, [0, 1, 2]),
        Err(Error::Capacity { capacity: 1, .. })
    ));
    assert_eq!(
        new(&[ball([f32::NAN, 0.0, 0.0], 0.1)], [0, 1, 2]),
        Err(Error::NotFinite("obstacle centre and radius"))
    );
}

/// A 1-DoF movement that overshoots to 1.09 before settling at 0.8 stays
/// below an upper limit of 0.95 with the joint-limit term, and is
/// untouched, bit for bit, by limits it keeps the margin from.
#[test]
fn joint_limits_hold_an_overshoot_back() {
    let t: Vec<f32> = (0..=200).map(|i| i as f32 / 200.0).collect();
    let y: Vec<f32> = t
        .iter()
        .map(|&t| {
            0.8 * (t * t * (3.0 - 2.0 * t)) + 1.0 * (std::f32::consts::PI * t).sin().powi(2) * t
        })
        .collect();
    let dmp = Dmp::<1, 30>::fit(&t, &y, 1, 30, &FitOptions::default()).unwrap();
    let peak = |terms: &[&dyn Coupling]| {
        let mut r = dmp.start(&dmp.execution()).unwrap();
        let mut ys = vec![];
        while r.time() < 2.0 {
            r.step_with(&dmp, 0.002, terms).unwrap();
            ys.push(r.position()[0]);
        }
        ys
    };
    let free = peak(&[]);
    let top = free.iter().copied().fold(f32::MIN, f32::max);
    assert!(top > 1.0, "the demonstration overshoots: {top}");
    // The reach from 0 to 0.8, margin 0.1, gain 50, between these limits.
    let between = |low: f32, high: f32| {
        JointLimits::<1>::new(&[low], &[high], 0.1, 50.0, 1e4, &[0.0], &[0.8])
    };
    let limits = between(-1.0, 0.95).unwrap();
    let held = peak(&[&limits]);
    let top = held.iter().copied().fold(f32::MIN, f32::max);
    assert!(top < 0.95, "beyond the limit: {top}");
    assert!((held.last().unwrap() - 0.8).abs() < 1e-3);
    let wide = between(-2.0, 2.0).unwrap();
    assert_eq!(peak(&[&wide]), free);
    // An infinite limit is none.
    let open = between(f32::NEG_INFINITY, f32::INFINITY).unwrap();
    assert_eq!(peak(&[&open]), free);
    let above = between(f32::NEG_INFINITY, 0.95).unwrap();
    assert_eq!(peak(&[&above]), held);
    assert_eq!(
        between(-1.0, 0.85),
        Err(Error::OutOfRange(
            "the movement's goal is within the margin of a joint limit, where the push would \
             hold it off its goal: give a smaller margin"
        ))
    );
    assert_eq!(
        between(-1.0, 0.7),
        Err(Error::OutOfRange(
            "the movement's goal is outside its joint limits"
        ))
    );
}

/// With the robot held at the start, phase stopping holds the command
/// back (at gain 1e4 per m², 2 s in, 6.5 cm of the 60 where the plain
/// run is at its goal); with the robot following
/// the command exactly, the run is the plain run, bit for bit.
#[test]
fn phase_stopping_waits_for_a_held_robot() {
    let dmp = reach([0.0; 3], [0.6, 0.0, 0.0]);
    let stop = PhaseStop::new(1e4).unwrap();
    let mut held = dmp.start(&dmp.execution()).unwrap();
    let mut followed = held.clone();
    let mut plain = held.clone();
    for _ in 0..1000 {
        let dt = stop.step(0.002, held.position(), &[0.0; 3]).unwrap();
        held.step(&dmp, dt).unwrap();
        let command = followed.position().to_vec();
        let dt = stop.step(0.002, &command, &command).unwrap();
        followed.step(&dmp, dt).unwrap();
        plain.step(&dmp, 0.002).unwrap();
    }
    // Two seconds of real time: the plain run is at its goal.
    assert!((plain.position()[0] - 0.6).abs() < 1e-3);
    assert!(
        held.position()[0] < 0.07,
        "ran away: {}",
        held.position()[0]
    );
    assert_eq!(followed, plain);
    assert!(PhaseStop::new(-1.0).is_err() && PhaseStop::new(f32::NAN).is_err());
}
