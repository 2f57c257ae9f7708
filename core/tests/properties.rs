//! Property tests of the invariants the learners rely on.
use primo_core::dmp::{Dmp, FitOptions};
use primo_core::generalize::{Generalizer, Method};
use primo_core::power::{Block, Power, PowerConfig};
use proptest::prelude::*;

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 64,
        failure_persistence: Some(Box::new(
            proptest::test_runner::FileFailurePersistence::WithSource("regressions"),
        )),
        ..ProptestConfig::default()
    }
}

proptest! {
    #![proptest_config(config())]

    /// Whatever the weights (|w| ≤ 1000), start, goal and τ, the forcing
    /// stops at τ and the spring settles on the goal by 3τ, finitely.
    #[test]
    fn dmp_reaches_its_goal_for_bounded_weights(
        weights in prop::collection::vec(-1000.0f32..1000.0, 2 * 12),
        start in prop::array::uniform2(-10.0f32..10.0),
        goal in prop::array::uniform2(-10.0f32..10.0),
        tau in 0.2f32..5.0,
    ) {
        let t: Vec<f32> = (0..50).map(|i| i as f32 / 49.0).collect();
        let y: Vec<f32> = t.iter().flat_map(|&t| [t, 2.0 * t]).collect();
        let mut dmp = Dmp::<2, 12>::fit(&t, &y, 2, 12, &FitOptions::default()).unwrap();
        let mut theta = vec![0.0; dmp.param_len()];
        dmp.params(&mut theta).unwrap();
        theta[..24].copy_from_slice(&weights);
        dmp.set_params(&theta).unwrap();
        let mut exec = dmp.execution();
        exec.tau = tau;
        exec.start.copy_from_slice(&start);
        exec.goal.copy_from_slice(&goal);
        let mut run = dmp.start(&exec).unwrap();
        let dt = 0.002;
        let steps = (3.0 * tau / dt) as usize;
        for _ in 0..steps {
            run.step(&dmp, dt).unwrap();
            prop_assert!(run.position().iter().all(|v| v.is_finite()));
        }
        for (p, g) in run.position().iter().zip(goal) {
            prop_assert!((p - g).abs() < 1e-3 * (1.0 + g.abs()), "ends at {p}, goal {g}");
        }
    }

    /// Noise-free GPR returns every example's parameters at its query (with
    /// the length scale at the smallest spacing, a well-conditioned
    /// covariance); both methods, at their defaults, reproduce parameters
    /// that are linear in the query.
    #[test]
    fn generalization_is_exact_at_the_examples(
        offsets in prop::collection::vec(0.0f32..0.5, 3..8),
        values in prop::collection::vec(-100.0f32..100.0, 8),
        slope in -10.0f32..10.0,
    ) {
        // Queries at least 0.5 apart: a well-posed interpolation problem.
        let queries: Vec<f32> = offsets.iter().enumerate().map(|(i, o)| i as f32 + o).collect();
        let spacing = queries.windows(2).fold(f32::INFINITY, |m, w| m.min(w[1] - w[0]));
        let gpr = Method::Gpr { length_scale: Some(spacing), noise: 0.0 };
        for method in [gpr, Method::Gpr { length_scale: None, noise: 0.0 }, Method::Lwr { bandwidth: None }] {
            let mut g = Generalizer::<8, 1, 2>::new(1, 2, method);
            for (q, v) in queries.iter().zip(&values) {
                g.add_example(&[*q], &[*v, slope * q + 1.0]).unwrap();
            }
            g.build().unwrap();
            for (q, v) in queries.iter().zip(&values) {
                let mut out = [0.0; 2];
                g.generalize(&[*q], &mut out).unwrap();
                if method == gpr {
                    prop_assert!((out[0] - v).abs() < 1e-3 * (1.0 + v.abs()), "GPR at {q}: {} vs {v}", out[0]);
                }
                let lin = slope * q + 1.0;
                prop_assert!((out[1] - lin).abs() < 1e-2 * (1.0 + lin.abs()), "{method:?} linear at {q}: {} vs {lin}", out[1]);
            }
        }
    }

    /// The importance sampler always holds the best L rewards seen, best
    /// first, and the mean stays a reward-weighted step inside their hull.
    #[test]
    fn power_sampler_is_the_sorted_best_l(rewards in prop::collection::vec(0.0f32..10.0, 1..60), l in 1usize..=5) {
        let block = [Block { len: 1, variance: 1.0, decay: 1.0 }];
        let cfg = PowerConfig { sampler: l, ..PowerConfig::paper(&block).unwrap() };
        let made = Power::<1, 4>::new(&[0.0], cfg, 1);
        if l > 4 {
            // Beyond the capacity: refused, never silently truncated.
            prop_assert!(made.is_err());
            return Ok(());
        }
        let mut p = made.unwrap();
        let mut seen = Vec::new();
        for r in &rewards {
            p.ask();
            p.tell(*r).unwrap();
            seen.push(*r);
        }
        let mut best = seen.clone();
        best.sort_by(|a, b| b.partial_cmp(a).unwrap());
        best.truncate(l);
        let kept: Vec<f32> = p.sampler().map(|(_, r)| r).collect();
        prop_assert_eq!(kept, best);
        prop_assert!(p.mean().iter().all(|v| v.is_finite()));
    }
}
