//! Orientation DMPs of movements that are no screw: tumbling about
//! changing axes through several turns, and a flip followed by a spin,
//! fitted in whichever chart `chart_axis` picks, replay closely.
use primo_core::dmp::FitOptions;
use primo_core::orientation::{OrientationDmp, chart_axis};
use primo_core::quaternion::Quaternion;
fn smooth(t: f32) -> f32 {
    t * t * t * (10.0 - 15.0 * t + 6.0 * t * t)
}
fn angle(a: &Quaternion, b: &Quaternion) -> f32 {
    let d = a.mul(&b.conj());
    2.0 * (d.x * d.x + d.y * d.y + d.z * d.z).sqrt().atan2(d.w.abs())
}
/// 40 tumbles: a turn of 4–12 rad about a random axis composed with a
/// wobble of up to 86° about another (40° to 1060° travelled).
/// The recording of `path` at times `t` (quaternions, row by row), and the
/// worst angle, rad, between a 30-kernel fit's replay at 2 ms and `path`.
fn replayed(t: &[f32], path: &impl Fn(f32) -> Quaternion) -> (Vec<f32>, f32) {
    let q: Vec<f32> = t.iter().flat_map(|&t| path(t).to_array()).collect();
    let dmp = OrientationDmp::<30>::fit(t, &q, 30, &FitOptions::default()).unwrap();
    let worst = dmp
        .trajectory(&dmp.execution(), 0.002)
        .unwrap()
        .map(|(tt, q)| angle(&q, &path(tt)))
        .fold(0.0, f32::max);
    (q, worst)
}

#[test]
fn tumbling_through_several_turns_is_reproduced() {
    let mut seed = 12345u32;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        seed as f32 / u32::MAX as f32 * 2.0 - 1.0
    };
    for case in 0..40 {
        let a1 = [next(), next(), next()];
        let a2 = [next(), next(), next()];
        let (k1, k2) = (8.0 * next().abs() + 4.0, 1.5 * next());
        let path = move |t: f32| {
            let u = smooth(t.clamp(0.0, 1.0));
            Quaternion::exp(a1.map(|v| v * k1 * u))
                .mul(&Quaternion::exp(a2.map(|v| v * k2 * (3.0 * u).sin())))
        };
        let t: Vec<f32> = (0..=500).map(|i| i as f32 / 500.0).collect();
        let (q, worst) = replayed(&t, &path);
        let travelled: f32 = t.windows(2).map(|w| angle(&path(w[0]), &path(w[1]))).sum();
        println!(
            "case {case}: axis {:?} travelled {:.0}° worst {:.3}°",
            chart_axis(&q).unwrap(),
            travelled.to_degrees(),
            worst.to_degrees()
        );
        assert!(
            worst.to_degrees() < 0.05,
            "case {case}: {}°",
            worst.to_degrees()
        );
    }
}
/// A flip of 60°–200° about x, then a spin of 400° or 720° about z: the
/// swing from the chart's axis is large, and stays short of 180°.
#[test]
fn a_flip_then_a_spin_is_reproduced() {
    for flip in [60.0f32, 120.0, 170.0, 180.0, 200.0] {
        for spin in [400.0f32, 720.0] {
            let path = move |t: f32| {
                let s1 = smooth((2.0 * t).clamp(0.0, 1.0));
                let s2 = smooth((2.0 * t - 1.0).clamp(0.0, 1.0));
                Quaternion::exp([0.0, 0.0, spin.to_radians() * s2]).mul(&Quaternion::exp([
                    flip.to_radians() * s1,
                    0.0,
                    0.0,
                ]))
            };
            let t: Vec<f32> = (0..=1000).map(|i| i as f32 / 500.0 / 2.0).collect();
            let (q, worst) = replayed(&t, &path);
            println!(
                "flip {flip} spin {spin}: axis {:?} worst {:.3}°",
                chart_axis(&q).unwrap(),
                worst.to_degrees()
            );
            assert!(
                worst.to_degrees() < 0.5,
                "flip {flip}, spin {spin}: {}°",
                worst.to_degrees()
            );
        }
    }
}

fn any_quaternion() -> impl proptest::strategy::Strategy<Value = Quaternion> {
    use proptest::prelude::*;
    prop::array::uniform4(-1.0f32..1.0)
        .prop_filter("non-zero", |q| q.iter().map(|v| v * v).sum::<f32>() > 1e-3)
        .prop_map(|q| Quaternion::from_array(q).normalized().unwrap())
}

proptest::proptest! {
    #![proptest_config(proptest::test_runner::Config { cases: 64, ..Default::default() })]

    /// Rough recordings (any orientation on every row, so turns of any
    /// size and either chart) fit, and every run of them, from any start
    /// to any goal, stays on unit quaternions, starts exactly where it is
    /// told and ends at its goal.
    #[test]
    fn rough_recordings_fit_and_run_in_either_chart(
        rows in proptest::collection::vec(any_quaternion(), 3..30),
        start in any_quaternion(),
        goal in any_quaternion(),
    ) {
        let t: Vec<f32> = (0..rows.len()).map(|i| i as f32 * 0.1).collect();
        let q: Vec<f32> = rows.iter().flat_map(|q| q.to_array()).collect();
        let dmp = OrientationDmp::<10>::fit(&t, &q, 10, &FitOptions::default()).unwrap();
        let exec = primo_core::orientation::OrientationExecution {
            start,
            goal,
            ..dmp.execution()
        };
        let mut run = dmp.start(&exec).unwrap();
        proptest::prop_assert!(angle(&run.orientation(), &start) < 1e-4);
        for _ in 0..400 {
            run.step(&dmp, exec.tau / 100.0).unwrap();
            let now = run.orientation();
            proptest::prop_assert!((now.norm() - 1.0).abs() < 1e-5, "{now:?}");
        }
        for _ in 0..200 {
            run.step(&dmp, exec.tau).unwrap();
        }
        proptest::prop_assert!(angle(&run.orientation(), &goal) < 1e-3);
    }
}
