//! Via-points: a DMP bent through given positions at given times.

use primo_core::Error;
use primo_core::dmp::{Dmp, FitOptions, ViaPoint};
use proptest::prelude::*;

/// Three DoF: a reach, a bump and a descent, one second at 200 Hz.
fn demo() -> Dmp<3, 30> {
    let t: Vec<f32> = (0..=200).map(|i| i as f32 / 200.0).collect();
    let y: Vec<f32> = t
        .iter()
        .flat_map(|&t| {
            let s = t * t * (3.0 - 2.0 * t);
            [
                0.6 * s,
                0.2 * (std::f32::consts::PI * t).sin(),
                0.3 - 0.2 * s,
            ]
        })
        .collect();
    Dmp::fit(&t, &y, 3, 30, &FitOptions::default()).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// Up to four via-points, anywhere from 10 % to 90 % of the movement
    /// (on the 1 ms grid) and up to 10 cm off the path, are passed within
    /// 10 µm; start, goal and τ stay, the run is where it was at τ, and it
    /// still settles on its goal.
    #[test]
    fn a_run_passes_its_via_points_and_keeps_its_ends(
        points in prop::collection::vec((100u32..900, 0usize..3, -0.1f32..0.1), 1..=4),
        goal_shift in -0.2f32..0.2,
    ) {
        let dmp = demo();
        let mut exec = dmp.execution();
        exec.goal[0] += goal_shift;
        let dt = 0.001;
        let plain: Vec<_> = dmp.trajectory(&exec, dt).unwrap().collect();
        let mut vias: Vec<ViaPoint> = vec![];
        for (step, dof, off) in points {
            // One place per DoF and time.
            if vias.iter().any(|v| v.dof == dof && (v.time - step as f32 * dt).abs() < 0.05) {
                continue;
            }
            let at = &plain[step as usize];
            vias.push(ViaPoint { time: at.time, dof, position: at.position[dof] + off });
        }
        let bent = dmp.through(&exec, dt, &vias).unwrap();
        prop_assert_eq!(bent.start_position(), dmp.start_position());
        prop_assert_eq!(bent.goal(), dmp.goal());
        prop_assert_eq!(bent.tau(), dmp.tau());
        let run: Vec<_> = bent.trajectory(&exec, dt).unwrap().collect();
        for v in &vias {
            let at = &run[(v.time / dt).round() as usize];
            prop_assert!((at.time - v.time).abs() < 1e-6);
            prop_assert!((at.position[v.dof] - v.position).abs() < 1e-5,
                "{v:?}: at {}", at.position[v.dof]);
        }
        // At τ, every DoF is where the plain run is (near its goal).
        let (end, plain_end) = (run.last().unwrap(), plain.last().unwrap());
        prop_assert!((end.time - exec.tau).abs() < 1e-6);
        for d in 0..3 {
            prop_assert!((end.position[d] - plain_end.position[d]).abs() < 1e-5,
                "DoF {}: {} at τ, plain {}", d, end.position[d], plain_end.position[d]);
        }
        // Settled (2τ), it is at its goal.
        let mut r = bent.start(&exec).unwrap();
        while r.time() < 2.0 * exec.tau {
            r.step(&bent, dt).unwrap();
        }
        for d in 0..3 {
            prop_assert!((r.position()[d] - exec.goal[d]).abs() < 1e-4);
        }
    }
}

/// A via-point on the path changes nothing that matters; the run before
/// the kernels reach the via-point's time is the plain run.
#[test]
fn a_via_point_on_the_path_leaves_the_run_as_it_was() {
    let dmp = demo();
    let exec = dmp.execution();
    let plain: Vec<_> = dmp.trajectory(&exec, 0.001).unwrap().collect();
    let on = ViaPoint {
        time: plain[500].time,
        dof: 1,
        position: plain[500].position[1],
    };
    let bent = dmp.through(&exec, 0.001, &[on]).unwrap();
    let run: Vec<_> = bent.trajectory(&exec, 0.001).unwrap().collect();
    let worst = run
        .iter()
        .zip(&plain)
        .map(|(a, b)| (a.position[1] - b.position[1]).abs())
        .fold(0.0, f32::max);
    assert!(worst < 1e-5, "{worst}");
}

/// Times outside the movement, a DoF beyond the DMP's, one DoF asked for
/// two places at once, and a DoF with amplitude 0 are refused.
#[test]
fn via_points_the_dmp_cannot_pass_are_refused() {
    let dmp = demo();
    let exec = dmp.execution();
    let via = |time, dof, position| ViaPoint {
        time,
        dof,
        position,
    };
    let outside = "a via-point's time must lie within the movement, after its start and before τ";
    for points in [
        [via(0.0, 0, 0.1)],
        [via(1.0, 0, 0.1)],
        [via(-0.5, 0, 0.1)],
        [via(f32::NAN, 0, 0.1)],
    ] {
        assert_eq!(
            dmp.through(&exec, 0.001, &points),
            Err(Error::OutOfRange(outside))
        );
    }
    assert_eq!(
        dmp.through(&exec, 0.001, &[via(0.5, 3, 0.1)]),
        Err(Error::OutOfRange("a via-point's DoF is beyond the DMP's"))
    );
    let twice = [via(0.5, 0, 0.1), via(0.5, 0, 0.2)];
    assert!(matches!(
        dmp.through(&exec, 0.001, &twice),
        Err(Error::Singular(_))
    ));
    // The bump's DoF starts and ends at 0: unscaled, it can still move.
    assert!(dmp.through(&exec, 0.001, &[via(0.5, 1, 0.3)]).is_ok());
    // A scaled DoF whose goal is moved onto its start cannot.
    let mut flat = exec;
    flat.goal[0] = flat.start[0];
    assert!(dmp.is_scaled(0));
    assert!(matches!(
        dmp.through(&flat, 0.001, &[via(0.5, 0, 0.1)]),
        Err(Error::Singular(_))
    ));
}
