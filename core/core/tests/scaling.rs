//! Property tests of the DMP's amplitude scalings: per DoF (the default),
//! none and global (Koutras & Doulgeri 2020).
use primo_core::dmp::{Dmp, Execution, FitOptions, Scaling};
use proptest::prelude::*;

type Dmp3 = Dmp<3, 30>;

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 32,
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

/// A reach in `x, y` from `start` by `span` with a via-point bump of
/// `bump` in `z` (which starts and ends at `start[2]`), 1 s at 500 Hz.
fn reach(start: [f32; 3], span: [f32; 2], bump: f32) -> (Vec<f32>, Vec<f32>) {
    let times: Vec<f32> = (0..=500).map(|i| i as f32 / 500.0).collect();
    let rows = times.iter().flat_map(|&t| {
        let s = t * t * (3.0 - 2.0 * t);
        let z = bump * (std::f32::consts::PI * t).sin().powi(2);
        [start[0] + span[0] * s, start[1] + span[1] * s, start[2] + z]
    });
    (times.clone(), rows.collect())
}

fn fit(times: &[f32], rows: &[f32], scaling: Scaling) -> Dmp3 {
    let options = FitOptions {
        scaling,
        ..FitOptions::default()
    };
    Dmp3::fit(times, rows, 3, 30, &options).unwrap()
}

/// The run's positions at 1 ms steps.
fn run(dmp: &Dmp3, start: &[f32], goal: &[f32]) -> Vec<[f32; 3]> {
    let exec = Execution {
        tau: dmp.tau(),
        start: start.iter().copied().collect(),
        goal: goal.iter().copied().collect(),
        goal_velocity: Default::default(),
    };
    let positions = dmp.trajectory(&exec, 1e-3).unwrap().map(|s| s.position);
    positions.collect()
}

/// The largest distance between two runs' samples.
fn apart(a: &[[f32; 3]], b: &[[f32; 3]]) -> f32 {
    assert_eq!(a.len(), b.len());
    (a.iter().zip(b))
        .flat_map(|(p, q)| p.iter().zip(q).map(|(x, y)| (x - y).abs()))
        .fold(0.0, f32::max)
}

/// The largest `|z − z0|` of a run.
fn height(run: &[[f32; 3]]) -> f32 {
    run.iter()
        .map(|p| (p[2] - run[0][2]).abs())
        .fold(0.0, f32::max)
}

proptest! {
    #![proptest_config(config())]

    /// Unscaled: moved anywhere, the run is the demonstrated one's shape
    /// translated (start and goal moved alike), and a new goal only adds
    /// the spring's own response: the bump is kept at any goal.
    #[test]
    fn none_translates_the_shape(
        start in prop::array::uniform3(-1.0f32..1.0),
        span in prop::array::uniform2(0.2f32..1.0),
        bump in 0.05f32..0.3,
        offset in prop::array::uniform3(-2.0f32..2.0),
    ) {
        let (times, rows) = reach(start, span, bump);
        let dmp = fit(&times, &rows, Scaling::Never);
        let goal = dmp.goal().to_vec();
        let own = run(&dmp, &start, &goal);
        let moved = |p: &[f32]| -> Vec<f32> { p.iter().zip(offset).map(|(a, o)| a + o).collect() };
        let translated: Vec<[f32; 3]> = own
            .iter()
            .map(|p| [p[0] + offset[0], p[1] + offset[1], p[2] + offset[2]])
            .collect();
        let there = run(&dmp, &moved(&start), &moved(&goal));
        prop_assert!(apart(&there, &translated) < 2e-5, "{}", apart(&there, &translated));
        // The goal's x onto the start's: the bump stays whole.
        let flat = [start[0], goal[1], goal[2]];
        let h = height(&run(&dmp, &start, &flat));
        prop_assert!((h - height(&own)).abs() < 1e-4 * (1.0 + bump), "{h} vs {}", height(&own));
    }

    /// Global: a goal turned (about an axis across the demonstrated
    /// `g − y0`, so the turn is the smallest onto it) and stretched about
    /// the start gives the demonstrated run turned and stretched alike.
    #[test]
    fn global_turns_and_stretches_the_shape(
        start in prop::array::uniform3(-1.0f32..1.0),
        span in prop::array::uniform2(0.2f32..1.0),
        bump in 0.05f32..0.3,
        across in prop::array::uniform3(-1.0f32..1.0),
        angle in -3.0f32..3.0,
        stretch in 0.3f32..3.0,
    ) {
        let a = [f64::from(span[0]), f64::from(span[1]), 0.0];
        let r = across.map(f64::from);
        let axis = [a[1] * r[2] - a[2] * r[1], a[2] * r[0] - a[0] * r[2], a[0] * r[1] - a[1] * r[0]];
        let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
        prop_assume!(n > 0.05);
        let k = axis.map(|x| x / n);
        let (c, s) = (f64::from(angle).cos(), f64::from(angle).sin());
        // Rodrigues' rotation by `angle` about `k`, stretched, about the start.
        let turn = |p: [f32; 3]| -> [f32; 3] {
            let v = [0, 1, 2].map(|d| f64::from(p[d] - start[d]));
            let kv = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
            let cross = [k[1] * v[2] - k[2] * v[1], k[2] * v[0] - k[0] * v[2], k[0] * v[1] - k[1] * v[0]];
            [0, 1, 2].map(|d| {
                let r = v[d] * c + cross[d] * s + k[d] * kv * (1.0 - c);
                start[d] + (f64::from(stretch) * r) as f32
            })
        };
        let (times, rows) = reach(start, span, bump);
        let dmp = fit(&times, &rows, Scaling::Global(0b111));
        let own = run(&dmp, &start, dmp.goal());
        let goal = turn([dmp.goal()[0], dmp.goal()[1], dmp.goal()[2]]);
        let there = run(&dmp, &start, &goal);
        let expected: Vec<[f32; 3]> = own.iter().map(|p| turn(*p)).collect();
        let scale = stretch * (1.0 + bump);
        prop_assert!(apart(&there, &expected) < 1e-4 * scale, "{}", apart(&there, &expected));
    }

    /// A coordinate's goal moved onto its start: per DoF, its forcing
    /// term vanishes and the via-point bump with it; unscaled, the run
    /// only adds the spring's own response to the goal's move,
    /// `Δg·(1 − (1 + αs/2)e^(−αs/2))` to the whole demonstrated shape;
    /// global, the shape is turned onto the new goal, and over half of
    /// the bump stays (turned by at most 35° here, stretched by its
    /// cosine).
    #[test]
    fn a_goal_on_its_start_keeps_its_shape_unless_per_dof(
        span in prop::array::uniform2(0.2f32..1.0),
        rise in 0.05f32..0.2,
        bump in 0.1f32..0.3,
    ) {
        // z rises by `rise` besides the bump, so per DoF it is scaled.
        let (times, mut rows) = reach([0.0; 3], span, bump);
        for (i, row) in rows.chunks_exact_mut(3).enumerate() {
            let t = times[i];
            row[2] += rise * t * t * (3.0 - 2.0 * t);
        }
        let flat_goal = |dmp: &Dmp3| [dmp.goal()[0], dmp.goal()[1], 0.0];
        let per_dof = fit(&times, &rows, Scaling::Auto);
        prop_assert!(per_dof.is_scaled(2));
        prop_assert!(height(&run(&per_dof, &[0.0; 3], &flat_goal(&per_dof))) < 1e-4);
        for scaling in [Scaling::Never, Scaling::Global(0b111)] {
            let dmp = fit(&times, &rows, scaling);
            let flat = run(&dmp, &[0.0; 3], &flat_goal(&dmp));
            if scaling != Scaling::Never {
                let h = height(&flat);
                prop_assert!(h > 0.5 * bump, "{scaling:?}: {h} of {bump}");
            } else {
                let own = run(&dmp, &[0.0; 3], dmp.goal());
                let moved = -dmp.goal()[2];
                for (i, (p, q)) in flat.iter().zip(&own).enumerate() {
                    let u = f64::from(i as f32 * 1e-3 / dmp.tau()).min(1.0);
                    let spring = 1.0 - (1.0 + 12.5 * u) * (-12.5 * u).exp();
                    let expected = f64::from(q[2]) + f64::from(moved) * spring;
                    prop_assert!((f64::from(p[2]) - expected).abs() < 1e-5, "{i}: {} vs {expected}", p[2]);
                    prop_assert_eq!((p[0], p[1]), (q[0], q[1]));
                }
            }
        }
    }
}
