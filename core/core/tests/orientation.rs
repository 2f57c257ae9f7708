//! Orientation and Cartesian DMPs: reproduction through ±180°, sign flips,
//! new starts and goals, goal changes, temporal scaling; unit norm and
//! reaching the goal for any weights within the bounds.
use primo_core::dmp::{Dmp, FitOptions, MAX_ABS_WEIGHT, Shape};
use primo_core::orientation::{CartesianDmp, OrientationDmp, OrientationExecution};
use primo_core::quaternion::Quaternion;
use proptest::prelude::*;

fn smooth(t: f32) -> f32 {
    t * t * t * (10.0 - 15.0 * t + 6.0 * t * t)
}

/// Yaw 0 → 270° with a pitch wobble, at rest at both ends, 2 s at 500 Hz:
/// beyond 180° from its start, through the ±180° of any Euler or
/// rotation-vector recording.
fn sweep(t: f32) -> Quaternion {
    let u = t / 2.0;
    let yaw = 270f32.to_radians() * smooth(u);
    let pitch = 0.3 * (std::f32::consts::PI * u).sin().powi(2);
    Quaternion::exp([0.0, 0.0, yaw]).mul(&Quaternion::exp([0.0, pitch, 0.0]))
}

fn recording() -> (Vec<f32>, Vec<f32>) {
    let t: Vec<f32> = (0..=1000).map(|i| i as f32 / 500.0).collect();
    let q = t.iter().flat_map(|&t| sweep(t).to_array()).collect();
    (t, q)
}

/// The angle between two orientations, rad (from the relative rotation's
/// vector part: `acos` of a dot product near 1 loses f32's precision).
fn angle(a: &Quaternion, b: &Quaternion) -> f32 {
    let d = a.mul(&b.conj());
    let v = (d.x * d.x + d.y * d.y + d.z * d.z).sqrt();
    2.0 * v.atan2(d.w.abs())
}

#[test]
fn a_sweep_through_180_degrees_is_reproduced() {
    let (t, q) = recording();
    let dmp = OrientationDmp::<30>::fit(&t, &q, 30, &FitOptions::default()).unwrap();
    let worst = dmp
        .trajectory(&dmp.execution(), 0.002)
        .unwrap()
        .map(|(time, q)| angle(&q, &sweep(time)))
        .fold(0.0, f32::max);
    println!("yaw 0 → 270°: max error {:.2e} deg", worst.to_degrees());
    assert!(worst.to_degrees() < 0.01, "{worst}");
}

#[test]
fn sign_flips_in_the_recording_change_nothing() {
    let (t, q) = recording();
    let mut flipped = q.clone();
    for (i, row) in flipped.chunks_exact_mut(4).enumerate() {
        if i % 7 == 3 || i > 900 {
            row.iter_mut().for_each(|v| *v = -*v);
        }
    }
    let a = OrientationDmp::<30>::fit(&t, &q, 30, &FitOptions::default()).unwrap();
    let b = OrientationDmp::<30>::fit(&t, &flipped, 30, &FitOptions::default()).unwrap();
    // The same rotations: the same motion (the goal's sign may differ).
    for ((_, x), (_, y)) in a
        .trajectory(&a.execution(), 0.01)
        .unwrap()
        .zip(b.trajectory(&b.execution(), 0.01).unwrap())
    {
        assert!(angle(&x, &y) < 1e-5);
    }
}

#[test]
fn new_start_and_goal_slower_and_a_goal_change_midway() {
    let (t, q) = recording();
    let dmp = OrientationDmp::<30>::fit(&t, &q, 30, &FitOptions::default()).unwrap();
    let start = Quaternion::exp([0.2, 0.0, 0.1]);
    let goal = Quaternion::exp([0.0, -0.3, 2.0]);
    let exec = OrientationExecution {
        tau: 4.0,
        start,
        goal,
    };
    let mut run = dmp.start(&exec).unwrap();
    assert!(angle(&run.orientation(), &start) < 1e-6);
    while run.time() < 4.0 {
        run.step(&dmp, 0.002).unwrap();
        assert!((run.orientation().norm() - 1.0).abs() < 1e-6);
    }
    // Settling: 2.5 τ more.
    for _ in 0..5000 {
        run.step(&dmp, 0.002).unwrap();
    }
    assert!(angle(&run.orientation(), &goal) < 1e-4);
    // Half way, the goal moves: the run turns to the new one, smoothly.
    let mut run = dmp.start(&exec).unwrap();
    while run.time() < 2.0 {
        run.step(&dmp, 0.002).unwrap();
    }
    let other = Quaternion::exp([0.5, 0.5, -1.0]);
    let before = run.orientation();
    run.set_goal(&dmp, other).unwrap();
    assert!(
        angle(&before, &run.orientation()) < 1e-5,
        "no jump at the change"
    );
    let mut last = run.orientation();
    for _ in 0..8000 {
        run.step(&dmp, 0.002).unwrap();
        let now = run.orientation();
        assert!(angle(&now, &last) < 0.02, "no jump while turning");
        last = now;
    }
    assert!(angle(&run.orientation(), &other) < 1e-4);
}

#[test]
fn temporal_scaling_keeps_the_path() {
    let (t, q) = recording();
    let dmp = OrientationDmp::<30>::fit(&t, &q, 30, &FitOptions::default()).unwrap();
    let normal: Vec<Quaternion> = dmp
        .trajectory(&dmp.execution(), 0.002)
        .unwrap()
        .map(|(_, q)| q)
        .collect();
    let mut slow = dmp.execution();
    slow.tau *= 3.0;
    let slow: Vec<Quaternion> = dmp
        .trajectory(&slow, 0.006)
        .unwrap()
        .map(|(_, q)| q)
        .collect();
    assert_eq!(normal.len(), slow.len());
    for (a, b) in normal.iter().zip(&slow) {
        assert!(angle(a, b) < 1e-5);
    }
}

#[test]
fn a_cartesian_dmp_runs_position_and_orientation_on_one_phase() {
    let (t, q) = recording();
    let p: Vec<f32> = t
        .iter()
        .flat_map(|&t| {
            let u = smooth(t / 2.0);
            let wave = (std::f32::consts::PI * t).sin().powi(2);
            [0.5 + 0.2 * u, 0.05 * wave, 0.4 - 0.1 * u]
        })
        .collect();
    let dmp = CartesianDmp::<30>::fit(&t, &p, &q, 30, &FitOptions::default()).unwrap();
    let mut exec = dmp.execution();
    exec.tau = 1.0; // twice as fast, both parts
    let mut run = dmp.start(&exec).unwrap();
    let mut worst: (f32, f32) = (0.0, 0.0);
    while run.time() < 1.0 - 1e-4 {
        run.step(&dmp, 0.001).unwrap();
        let demo_t = 2.0 * run.time();
        let (pos, ori) = run.pose();
        let i = (demo_t * 500.0).round() as usize;
        let e = (0..3)
            .map(|k| (pos[k] - p[3 * i + k]).abs())
            .fold(0.0, f32::max);
        worst = (worst.0.max(e), worst.1.max(angle(&ori, &sweep(demo_t))));
    }
    println!(
        "twice as fast: position {:.1e} m, orientation {:.1e} rad",
        worst.0, worst.1
    );
    assert!(worst.0 < 1e-4 && worst.1 < 2e-4, "{worst:?}");
}

#[test]
fn bad_recordings_are_errors() {
    let t = [0.0, 0.5, 1.0];
    let zero = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
    assert!(OrientationDmp::<5>::fit(&t, &zero, 5, &FitOptions::default()).is_err());
    let nan = [
        1.0,
        0.0,
        0.0,
        0.0,
        f32::NAN,
        0.0,
        0.0,
        0.0,
        1.0,
        0.0,
        0.0,
        0.0,
    ];
    assert!(OrientationDmp::<5>::fit(&t, &nan, 5, &FitOptions::default()).is_err());
    assert!(OrientationDmp::<5>::fit(&t, &zero[..8], 5, &FitOptions::default()).is_err());
}

fn quaternion() -> impl Strategy<Value = Quaternion> {
    prop::array::uniform4(-1.0f32..1.0)
        .prop_filter("non-zero", |q| q.iter().map(|v| v * v).sum::<f32>() > 1e-3)
        .prop_map(|q| Quaternion::from_array(q).normalized().unwrap())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// Any weights within the bounds, any start and goal, any `τ` and step:
    /// every orientation is a unit quaternion, and the run ends at the goal.
    #[test]
    fn unit_norm_always_and_the_goal_is_reached(
        weights in prop::collection::vec(-MAX_ABS_WEIGHT..MAX_ABS_WEIGHT, 3 * 8),
        scale in -9i32..=0,
        start in quaternion(),
        goal in quaternion(),
        tau in 0.05f32..5.0,
        steps in 20u32..400,
    ) {
        // Weights over every decade up to the bound.
        let w: Vec<f32> = weights.iter().map(|w| w * 10f32.powi(scale)).collect();
        let theta: Vec<f32> = w.iter().copied().chain([0.0; 3]).chain([tau]).collect();
        let shape = Shape { alpha: 25.0, width: 2.0 * 49.0, margin: 0.0, scaled: 0 };
        let log = Dmp::<3, 8>::from_shape(&shape, 3, 8, &[0.0; 3], &theta).unwrap();
        let dmp = OrientationDmp::from_parts(log, Quaternion::IDENTITY).unwrap();
        let exec = OrientationExecution { tau, start, goal };
        let mut run = dmp.start(&exec).unwrap();
        let dt = tau / steps as f32;
        // Through the movement and 4 τ of settling (2 s·α/… ≥ 50/α τ).
        for _ in 0..5 * steps {
            run.step(&dmp, dt).unwrap();
            let q = run.orientation();
            prop_assert!((q.norm() - 1.0).abs() < 1e-5, "{q:?}");
        }
        for _ in 0..100 {
            run.step(&dmp, tau).unwrap();
        }
        let q = run.orientation();
        prop_assert!(angle(&q, &goal) < 1e-3, "ends {:?}, goal {goal:?}", q);
    }
}

/// A screw: `turns` revolutions about an axis tilted 20° off z, at rest
/// at both ends, from a start tilted 30° about x; recorded over `seconds`
/// at about 500 Hz with stamps jittered by up to ±0.4 ms and the
/// quaternion's sign flipped on pseudo-random rows, as trackers record.
fn screw(turns: f32, seconds: f32, at: f32) -> Quaternion {
    let u = (at / seconds).clamp(0.0, 1.0);
    let tilt = 20f32.to_radians();
    let axis = [tilt.sin(), 0.0, tilt.cos()];
    let angle = turns * std::f32::consts::TAU * smooth(u);
    Quaternion::exp(axis.map(|a| a * angle)).mul(&Quaternion::exp([0.5, 0.0, 0.0]))
}

fn screw_recording(turns: f32, seconds: f32) -> (Vec<f32>, Vec<f32>) {
    recorded(seconds, 0x9e37_79b9, |at| screw(turns, seconds, at))
}

/// `orientation(t)` recorded over `seconds` at about 500 Hz, stamps
/// jittered by up to ±0.4 ms, the quaternion's sign flipped on
/// pseudo-random rows (from `seed`).
fn recorded(
    seconds: f32,
    seed: u32,
    orientation: impl Fn(f32) -> Quaternion,
) -> (Vec<f32>, Vec<f32>) {
    let rows = (seconds * 500.0) as usize;
    let mut seed = seed | 1;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        seed as f32 / u32::MAX as f32
    };
    let mut t: Vec<f32> = (0..=rows)
        .map(|i| i as f32 / 500.0 + (next() - 0.5) * 8e-4)
        .collect();
    t[0] = 0.0;
    t[rows] = seconds;
    let q = t
        .iter()
        .flat_map(|&at| {
            let q = orientation(at);
            if next() < 0.3 { q.neg() } else { q }.to_array()
        })
        .collect();
    (t, q)
}

#[test]
fn turns_of_any_number_of_revolutions_are_reproduced() {
    for turns in [370.0 / 360.0, 1.5, 2.0, 3.0, 3.5] {
        let seconds = 2.0 + turns;
        let (t, q) = screw_recording(turns, seconds);
        for kernels in [10, 30] {
            let dmp = OrientationDmp::<30>::fit(&t, &q, kernels, &FitOptions::default()).unwrap();
            let worst = dmp
                .trajectory(&dmp.execution(), 0.002)
                .unwrap()
                .map(|(time, q)| angle(&q, &screw(turns, seconds, time)))
                .fold(0.0, f32::max);
            println!(
                "{:.0}° screw, {kernels} kernels: max error {:.3}°",
                turns * 360.0,
                worst.to_degrees()
            );
            assert!(
                worst.to_degrees() < 0.2,
                "{turns} turns, {kernels}: {worst}"
            );
        }
    }
}

#[test]
fn a_new_goal_keeps_the_start_and_the_turns_to_go() {
    let (t, q) = screw_recording(2.5, 4.5);
    let dmp = OrientationDmp::<30>::fit(&t, &q, 30, &FitOptions::default()).unwrap();
    let demonstrated = dmp.start_orientation();
    assert!(angle(&demonstrated, &screw(2.5, 4.5, 0.0)) < 1e-4);
    let goal = Quaternion::exp([0.0, 0.2, 0.3]).mul(&dmp.goal());
    let exec = OrientationExecution {
        goal,
        ..dmp.execution()
    };
    let path: Vec<Quaternion> = dmp.trajectory(&exec, 0.002).unwrap().map(|s| s.1).collect();
    assert!(angle(&path[0], &demonstrated) < 1e-5, "the start stays");
    assert!(
        angle(path.last().unwrap(), &goal) < 1e-3,
        "the goal is reached"
    );
    // Still two and a half turns: the angle travelled, summed step by step.
    let travelled: f32 = path.windows(2).map(|w| angle(&w[0], &w[1])).sum();
    assert!(travelled > 2.3 * std::f32::consts::TAU, "{travelled}");
    // Online, half way: no jump, and the rest of the turn is still made.
    let mut run = dmp.start(&dmp.execution()).unwrap();
    while run.time() < 2.0 {
        run.step(&dmp, 0.002).unwrap();
    }
    let before = run.orientation();
    run.set_goal(&dmp, goal).unwrap();
    assert!(angle(&before, &run.orientation()) < 1e-5);
    let mut rest = 0.0;
    let mut last = before;
    for _ in 0..5000 {
        run.step(&dmp, 0.002).unwrap();
        rest += angle(&last, &run.orientation());
        last = run.orientation();
    }
    assert!(angle(&last, &goal) < 1e-3);
    assert!(rest > 0.8 * std::f32::consts::TAU, "{rest}");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Any total turn up to three and a half revolutions and any new goal:
    /// the run starts where it is told, moves continuously on unit
    /// quaternions and ends at the goal.
    #[test]
    fn any_turn_and_any_goal_start_kept_continuous_goal_reached(
        turns in 0.0f32..3.5,
        goal in quaternion(),
        start in quaternion(),
        new_start in any::<bool>(),
    ) {
        let seconds = 2.0 + turns;
        let (t, q) = screw_recording(turns, seconds);
        let dmp = OrientationDmp::<20>::fit(&t, &q, 20, &FitOptions::default()).unwrap();
        let exec = OrientationExecution {
            goal,
            start: if new_start { start } else { dmp.start_orientation() },
            ..dmp.execution()
        };
        let path: Vec<Quaternion> =
            dmp.trajectory(&exec, 0.002).unwrap().map(|s| s.1).collect();
        prop_assert!(angle(&path[0], &exec.start) < 1e-5);
        for w in path.windows(2) {
            prop_assert!((w[1].norm() - 1.0).abs() < 1e-5);
            prop_assert!(angle(&w[0], &w[1]) < 0.05, "a jump of {} rad", angle(&w[0], &w[1]));
        }
        let mut run = dmp.start(&exec).unwrap();
        for _ in 0..200 {
            run.step(&dmp, exec.tau).unwrap();
        }
        prop_assert!(angle(&run.orientation(), &goal) < 1e-3);
    }
}

/// A screw as a hand records it: the tool spins `deg` degrees about its
/// own axis while that axis wobbles by up to `wobble` rad, over
/// `seconds`, from a tilted start pose.
fn wobbling_screw(deg: f32, wobble: f32, seconds: f32, at: f32) -> Quaternion {
    let u = (at / seconds).clamp(0.0, 1.0);
    let pose = Quaternion::exp([0.4, -0.3, 0.2]);
    let w = Quaternion::exp([wobble * (5.0 * u).sin(), wobble * (3.0 * u).cos(), 0.0]);
    pose.mul(&w)
        .mul(&Quaternion::exp([0.0, 0.0, deg.to_radians() * smooth(u)]))
}

/// [`wobbling_screw`] recorded as [`recorded`] says.
fn wobbling_recording(deg: f32, wobble: f32, seconds: f32, seed: u32) -> (Vec<f32>, Vec<f32>) {
    recorded(seconds, seed, |at| wobbling_screw(deg, wobble, seconds, at))
}

/// The sweep of the total turn, with the tool axis wobbling by 0
/// to 3°: every turn within 0.1° at 30 kernels. (The rotation vector
/// `log(q ⊗ ḡ)` is singular where its norm crosses a whole turn: before
/// turns beyond 270° were charted by swing and twist about their axis,
/// a 1° wobble replayed 370° to 27°, 540° to 6.4°, 1080° to 3.9°; 3°,
/// 540° to 109°.)
#[test]
fn wobbling_screws_of_any_turn_are_reproduced() {
    for wobble in [0.0f32, 0.3, 1.0, 3.0] {
        for deg in [300.0f32, 350.0, 370.0, 400.0, 540.0, 720.0, 1080.0, 1440.0] {
            let (t, q) = wobbling_recording(deg, wobble.to_radians(), 2.0, 0x1234_5678);
            let mut line = format!("wobble {wobble}°, {deg}°:");
            for kernels in [10, 30] {
                let dmp =
                    OrientationDmp::<30>::fit(&t, &q, kernels, &FitOptions::default()).unwrap();
                let worst = dmp
                    .trajectory(&dmp.execution(), 0.002)
                    .unwrap()
                    .map(|(time, q)| {
                        angle(&q, &wobbling_screw(deg, wobble.to_radians(), 2.0, time))
                    })
                    .fold(0.0, f32::max)
                    .to_degrees();
                line += &format!(" {kernels} kernels {worst:.3}°");
                if kernels == 30 {
                    assert!(worst < 0.1, "{line}");
                }
            }
            println!("{line}");
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

    /// Any total turn up to four revolutions with a wobbling axis, any new
    /// goal given at the start or changed online at any time, any new
    /// start or the demonstrated one: the run starts exactly there, moves
    /// continuously on unit quaternions (no step longer than the fastest
    /// demonstrated one allows, none at the goal's change) and ends at the
    /// goal.
    #[test]
    fn any_turn_any_goal_change_start_kept_continuous_goal_reached(
        deg in 0.0f32..1440.0,
        wobble in 0.0f32..0.06,
        seed in any::<u32>(),
        goal in quaternion(),
        start in quaternion(),
        new_start in any::<bool>(),
        online in prop::option::of(0.0f32..1.2),
    ) {
        let seconds = 2.0 + deg / 360.0;
        let (t, q) = wobbling_recording(deg, wobble, seconds, seed);
        let dmp = OrientationDmp::<20>::fit(&t, &q, 20, &FitOptions::default()).unwrap();
        let demonstrated = dmp.start_orientation();
        prop_assert!(angle(&demonstrated, &wobbling_screw(deg, wobble, seconds, 0.0)) < 1e-4);
        let exec = OrientationExecution {
            goal: if online.is_some() { dmp.goal() } else { goal },
            start: if new_start { start } else { demonstrated },
            ..dmp.execution()
        };
        let dt = 0.002;
        let mut run = dmp.start(&exec).unwrap();
        prop_assert!(angle(&run.orientation(), &exec.start) < 1e-5, "the start is kept");
        let mut last = run.orientation();
        let mut changed = false;
        // 2 τ: through the movement and settling.
        for _ in 0..(2.0 * seconds / dt) as usize {
            if let Some(at) = online && !changed && run.time() >= at * seconds {
                run.set_goal(&dmp, goal).unwrap();
                prop_assert!(angle(&last, &run.orientation()) < 1e-5, "no jump at the change");
                changed = true;
            }
            run.step(&dmp, dt).unwrap();
            let now = run.orientation();
            prop_assert!((now.norm() - 1.0).abs() < 1e-5);
            // The demonstration's peak speed is 1.875 × its mean, ≤ 7.1
            // rad/s here; a new start or goal adds its own turn.
            prop_assert!(angle(&last, &now) < 0.06, "a jump of {} rad", angle(&last, &now));
            last = now;
        }
        for _ in 0..200 {
            run.step(&dmp, seconds).unwrap();
        }
        prop_assert!(angle(&run.orientation(), &goal) < 1e-3, "the goal is reached");
    }
}
