//! Orientation and Cartesian DMPs generalized over a query in the tangent
//! space at the goals' mean: exact at the examples, unit goals, the same
//! for `q` or `−q`, continuous across ±180°.
use primo_core::dmp::{Dmp, FitOptions, Scaling, Shape};
use primo_core::generalize::Method;
use primo_core::generalize::orientation::{CartesianGeneralizer, OrientationGeneralizer};
use primo_core::orientation::{CartesianDmp, OrientationDmp};
use primo_core::quaternion::Quaternion;
use proptest::prelude::*;

const K: usize = 6;
type Orientations = OrientationGeneralizer<8, 2, 40, K>;

fn yaw(deg: f32) -> Quaternion {
    Quaternion::exp([0.0, 0.0, deg.to_radians()])
}

/// The angle between two orientations, rad (from the relative rotation's
/// vector part: `acos` of a dot product near 1 loses f32's precision).
fn angle(a: &Quaternion, b: &Quaternion) -> f32 {
    let d = a.mul(&b.conj());
    let v = (d.x * d.x + d.y * d.y + d.z * d.z).sqrt();
    2.0 * v.atan2(d.w.abs())
}

fn gpr() -> Method {
    Method::Gpr {
        length_scale: None,
        noise: 0.0,
    }
}

/// An orientation DMP of weights `w`, start log coordinates `turn`, goal
/// `goal` and duration `tau`.
fn orientation(w: &[f32], turn: [f32; 3], goal: Quaternion, tau: f32) -> OrientationDmp<K> {
    let shape = Shape {
        alpha: 25.0,
        width: 2.0 * 25.0,
        margin: 0.0,
        scaled: 0,
    };
    let theta: Vec<f32> = w.iter().copied().chain([0.0; 3]).chain([tau]).collect();
    let log = Dmp::from_shape(&shape, 3, K, &turn, &theta).unwrap();
    OrientationDmp::from_parts(log, goal).unwrap()
}

/// `b` is `a` as an orientation DMP: the same movement, up to `tol`.
fn assert_same(a: &OrientationDmp<K>, b: &OrientationDmp<K>, tol: f32) {
    assert!(angle(&a.goal(), &b.goal()) < tol, "goals {a:?} {b:?}");
    let (mut pa, mut pb) = ([0.0; 3 * K + 4], [0.0; 3 * K + 4]);
    a.log_dmp().params(&mut pa).unwrap();
    b.log_dmp().params(&mut pb).unwrap();
    let scale = pa.iter().fold(1.0f32, |m, v| m.max(v.abs()));
    for (x, y) in pa.iter().zip(&pb) {
        assert!((x - y).abs() < tol * scale, "θ {pa:?} vs {pb:?}");
    }
    for (x, y) in a
        .log_dmp()
        .start_position()
        .iter()
        .zip(b.log_dmp().start_position())
    {
        assert!((x - y).abs() < tol, "starts {a:?} {b:?}");
    }
}

/// A yaw turn from `from`° to `to`° with a pitch wobble, fitted.
fn turn(from: f32, to: f32, wobble: f32) -> OrientationDmp<K> {
    let t: Vec<f32> = (0..=200).map(|i| i as f32 / 200.0).collect();
    let q: Vec<f32> = t
        .iter()
        .flat_map(|&t| {
            let s = t * t * (3.0 - 2.0 * t);
            let pitch = wobble * (std::f32::consts::PI * t).sin();
            yaw(from + (to - from) * s)
                .mul(&Quaternion::exp([0.0, pitch, 0.0]))
                .to_array()
        })
        .collect();
    OrientationDmp::fit(&t, &q, K, &FitOptions::default()).unwrap()
}

#[test]
fn fitted_turns_are_reproduced_at_their_queries_and_blended_between() {
    let examples = [
        turn(100.0, 170.0, 0.2),
        turn(120.0, 200.0, -0.1),
        turn(150.0, 230.0, 0.3),
    ];
    let queries = [[0.0f32, 0.0], [1.0, 0.0], [0.0, 1.0]];
    let pairs: Vec<(&[f32], &OrientationDmp<K>)> = queries
        .iter()
        .zip(&examples)
        .map(|(q, d)| (&q[..], d))
        .collect();
    for method in [gpr(), Method::Lwr { bandwidth: None }] {
        let g = Orientations::new(method, &pairs).unwrap();
        // Three examples on a plane: both methods interpolate them.
        for (q, example) in queries.iter().zip(&examples) {
            assert_same(&g.generalize(q).unwrap(), example, 1e-4);
        }
        let between = g.generalize(&[0.3, 0.3]).unwrap();
        assert!((between.goal().norm() - 1.0).abs() < 1e-6);
        for (_, q) in between.trajectory(&between.execution(), 0.01).unwrap() {
            assert!((q.norm() - 1.0).abs() < 1e-5);
        }
    }
}

#[test]
fn goals_on_both_sides_of_180_degrees_blend_through_it() {
    let (a, b) = (turn(140.0, 175.0, 0.0), turn(-140.0, -175.0, 0.0));
    // Two examples along one query dimension: LWR is the straight line.
    let g = OrientationGeneralizer::<8, 1, 40, K>::new(
        Method::Lwr { bandwidth: None },
        &[(&[0.0], &a), (&[1.0], &b)],
    )
    .unwrap();
    let mut previous = g.generalize(&[0.0]).unwrap().goal();
    for i in 1..=20 {
        let s = i as f32 / 20.0;
        let dmp = g.generalize(&[s]).unwrap();
        let goal = dmp.goal();
        // 10° in 20 steps: never a jump.
        assert!(angle(&goal, &previous).to_degrees() < 0.6, "at {s}");
        let expect = yaw(175.0 + 10.0 * s);
        assert!(
            angle(&goal, &expect).to_degrees() < 1e-3,
            "at {s}: {goal:?}"
        );
        // The start too: 140° → 220° through 180°.
        let start = dmp.start_orientation();
        assert!(angle(&start, &yaw(140.0 + 80.0 * s)).to_degrees() < 1e-3);
        previous = goal;
    }
}

#[test]
fn cartesian_dmps_generalize_position_and_orientation_together() {
    let t: Vec<f32> = (0..=100).map(|i| i as f32 / 100.0).collect();
    let options = FitOptions {
        scaling: Scaling::Mask(0b111),
        ..FitOptions::default()
    };
    let fit = |x: f32, deg: f32| {
        let p: Vec<f32> = t
            .iter()
            .flat_map(|&t| [x * t, 0.2 * t, 0.5 - t * t])
            .collect();
        let q: Vec<f32> = t.iter().flat_map(|&t| yaw(deg * t).to_array()).collect();
        CartesianDmp::<K>::fit(&t, &p, &q, K, &options).unwrap()
    };
    let examples = [fit(0.3, 170.0), fit(0.5, 190.0)];
    let g = CartesianGeneralizer::<4, 1, 60, K>::new(
        gpr(),
        &[(&[1.0], &examples[0]), (&[2.0], &examples[1])],
    )
    .unwrap();
    for (q, example) in [1.0f32, 2.0].iter().zip(&examples) {
        let d = g.generalize(&[*q]).unwrap();
        assert_same(&d.orientation, &example.orientation, 1e-4);
        let (mut a, mut b) = ([0.0; 3 * K + 4], [0.0; 3 * K + 4]);
        d.position.params(&mut a).unwrap();
        example.position.params(&mut b).unwrap();
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() < 1e-3 * (1.0 + y.abs()), "{a:?} {b:?}");
        }
    }
    let half = g.generalize(&[1.5]).unwrap();
    assert!(angle(&half.orientation.goal(), &yaw(180.0)).to_degrees() < 1e-3);
    assert!((half.position.goal()[0] - 0.4).abs() < 1e-4);
}

#[test]
fn examples_that_do_not_match_are_errors() {
    let a = turn(0.0, 10.0, 0.0);
    let t: Vec<f32> = (0..=50).map(|i| i as f32 / 50.0).collect();
    let q: Vec<f32> = t.iter().flat_map(|&t| yaw(20.0 * t).to_array()).collect();
    let other = OrientationDmp::<K>::fit(&t, &q, K - 1, &FitOptions::default()).unwrap();
    assert!(Orientations::new(gpr(), &[(&[0.0, 0.0], &a), (&[1.0, 0.0], &other)]).is_err());
    assert!(Orientations::new(gpr(), &[]).is_err());
    // No room for 6 kernels' vector (28 values).
    assert!(OrientationGeneralizer::<4, 1, 20, K>::new(gpr(), &[(&[0.0], &a)]).is_err());
    let g = Orientations::new(gpr(), &[(&[0.0, 0.0], &a), (&[1.0, 1.0], &a)]).unwrap();
    assert!(g.generalize(&[f32::NAN, 0.0]).is_err());
}

fn quaternion() -> impl Strategy<Value = Quaternion> {
    prop::array::uniform4(-1.0f32..1.0)
        .prop_filter("non-zero", |q| q.iter().map(|v| v * v).sum::<f32>() > 1e-3)
        .prop_map(|q| Quaternion::from_array(q).normalized().unwrap())
}

/// An example drawn: its goal's offset from the centre, weights, start's
/// log coordinates, `τ`, and whether a sign flip negates its goal.
type Raw = ([f32; 3], Vec<f32>, [f32; 3], f32, bool);

/// Up to six examples: goals within 60° of a centre anywhere, any
/// weights, starts up to 150° from the goal, durations.
fn examples() -> impl Strategy<Value = (Quaternion, Vec<Raw>)> {
    let example = (
        prop::array::uniform3(-0.6f32..0.6),
        prop::collection::vec(-50.0f32..50.0, 3 * K),
        prop::array::uniform3(-1.5f32..1.5),
        0.5f32..3.0,
        any::<bool>(),
    );
    (quaternion(), prop::collection::vec(example, 2..=6))
}

fn build(centre: Quaternion, raw: &[Raw], flip: bool) -> Vec<OrientationDmp<K>> {
    raw.iter()
        .map(|(offset, w, turn, tau, sign)| {
            let goal = Quaternion::exp(*offset).mul(&centre);
            let goal = if flip && *sign { goal.neg() } else { goal };
            orientation(w, *turn, goal, *tau)
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// GPR over a 1-D query: every example is reproduced at its query,
    /// and every query gives a valid orientation DMP (unit goal, unit
    /// orientations all along).
    #[test]
    fn exact_at_the_examples_and_valid_everywhere(
        (centre, raw) in examples(),
        at in 0.0f32..1.0,
    ) {
        let query = at * (raw.len() - 1) as f32;
        let dmps = build(centre, &raw, false);
        let queries: Vec<[f32; 2]> = (0..dmps.len()).map(|i| [i as f32, 0.0]).collect();
        let pairs: Vec<(&[f32], &OrientationDmp<K>)> =
            queries.iter().zip(&dmps).map(|(q, d)| (&q[..1], d)).collect();
        // A length scale of the spacing: the covariance is well
        // conditioned in f32 (the default, twice that, is exact to ~1e-3).
        let method = Method::Gpr { length_scale: Some(1.0), noise: 0.0 };
        let g = OrientationGeneralizer::<8, 1, 40, K>::new(method, &pairs).unwrap();
        for (q, dmp) in &pairs {
            assert_same(&g.generalize(q).unwrap(), dmp, 1e-4);
        }
        let dmp = g.generalize(&[query]).unwrap();
        prop_assert!((dmp.goal().norm() - 1.0).abs() < 1e-6);
        for (_, q) in dmp.trajectory(&dmp.execution(), 0.05).unwrap() {
            prop_assert!((q.norm() - 1.0).abs() < 1e-5);
        }
    }

    /// Negating any example's quaternions changes nothing, bit for bit.
    #[test]
    fn the_sign_of_the_examples_changes_nothing(
        (centre, raw) in examples(),
        at in 0.0f32..1.0,
    ) {
        let query = at * (raw.len() - 1) as f32;
        let queries: Vec<[f32; 1]> = (0..raw.len()).map(|i| [i as f32]).collect();
        let generalize = |flip: bool| {
            let dmps = build(centre, &raw, flip);
            let pairs: Vec<(&[f32], &OrientationDmp<K>)> =
                queries.iter().zip(&dmps).map(|(q, d)| (&q[..], d)).collect();
            let g = OrientationGeneralizer::<8, 1, 40, K>::new(
                Method::Lwr { bandwidth: None },
                &pairs,
            )
            .unwrap();
            g.generalize(&[query]).unwrap()
        };
        prop_assert_eq!(generalize(false), generalize(true));
    }
}

/// Screws of several turns charted about one axis generalize, each
/// reproduced at its query (its start, goal and chart kept); a DMP
/// charted about another axis, or as the rotation vector, is refused.
#[test]
fn screws_charted_about_one_axis_generalize_and_other_charts_are_refused() {
    let axis = [0.0, 0.0, 1.0];
    let screw = |turn: f32, goal: f32| {
        let log = orientation(&[0.0; 3 * K], [0.0, 0.05, -turn], yaw(goal), 1.0);
        OrientationDmp::from_chart(log.log_dmp().clone(), log.goal(), axis).unwrap()
    };
    let (a, b) = (screw(9.0, 10.0), screw(12.0, 40.0));
    assert_eq!(a.axis(), axis);
    let g = Orientations::new(gpr(), &[(&[0.0, 0.0], &a), (&[1.0, 0.0], &b)]).unwrap();
    for (q, example) in [([0.0, 0.0], &a), ([1.0, 0.0], &b)] {
        let made = g.generalize(&q).unwrap();
        assert_eq!(made.axis(), axis);
        assert_same(&made, example, 1e-4);
        assert!(angle(&made.start_orientation(), &example.start_orientation()) < 1e-4);
    }
    let tilted =
        OrientationDmp::from_chart(a.log_dmp().clone(), a.goal(), [0.0, 0.1, 1.0]).unwrap();
    let plain = OrientationDmp::from_parts(a.log_dmp().clone(), a.goal()).unwrap();
    for other in [&tilted, &plain] {
        let e = Orientations::new(gpr(), &[(&[0.0, 0.0], &a), (&[1.0, 0.0], other)]).unwrap_err();
        assert!(e.to_string().contains("chart axis"), "{e}");
    }
}
