//! Property tests of the invariants the learners rely on.
use primo_core::dmp::{
    Dmp, MAX_ABS_POSITION, MAX_ABS_WEIGHT, MAX_ALPHA, MIN_ALPHA, MIN_TAU, Run, Shape,
};
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

/// `±10^e` for `e` uniform over twelve decades below `max`, or 0: every
/// scale up to the bound.
fn magnitude(max: f32) -> impl Strategy<Value = f32> {
    prop_oneof![
        1 => Just(0.0f32),
        9 => (any::<bool>(), -12.0f32..0.0).prop_map(move |(neg, e)| {
            let v = max * 10f32.powf(e);
            if neg { -v } else { v }
        }),
    ]
}

proptest! {
    #![proptest_config(config())]

    /// The documented goal bound (dmp.rs, "Bounds, and reaching the goal"):
    /// for any weights, starts, goals, `α` and `τ` within the DMP's bounds,
    /// every sample is finite, and from phase 1 on `|y − g|` shrinks by
    /// `(1 + αs/2)e^(−αs/2)` < 4e−10 within `s = 50/α` more `τ`.
    #[test]
    fn dmp_reaches_its_goal_for_any_weights_within_the_bounds(
        weights in prop::collection::vec(magnitude(MAX_ABS_WEIGHT), 2 * 12),
        start in prop::array::uniform2(magnitude(MAX_ABS_POSITION)),
        goal in prop::array::uniform2(magnitude(MAX_ABS_POSITION)),
        alpha in (MIN_ALPHA.ln()..MAX_ALPHA.ln()).prop_map(f32::exp),
        tau in MIN_TAU..10.0f32,
        scaled in 0u32..4,
    ) {
        let shape = Shape { alpha, width: 2.0 * 11.0 * 11.0, margin: 0.0, scaled };
        let theta: Vec<f32> = weights.iter().chain(&goal).chain([&tau]).copied().collect();
        let dmp = Dmp::<2, 12>::from_shape(&shape, 2, 12, &start, &theta).unwrap();
        let mut run = dmp.start(&dmp.execution()).unwrap();
        let finite = |run: &Run<2>| {
            let s = run.sample();
            s.position.iter().chain(&s.velocity).chain(&s.acceleration).all(|v| v.is_finite())
        };
        while run.phase() < 1.0 {
            run.step(&dmp, tau / 500.0).unwrap();
            prop_assert!(finite(&run), "{:?}", run.sample());
        }
        let s = run.sample();
        let deviation: Vec<f32> = (0..2)
            .map(|d| (s.position[d] - goal[d]).abs() + 2.0 * tau * s.velocity[d].abs() / alpha)
            .collect();
        let settle = 50.0 / alpha * tau;
        for _ in 0..100 {
            run.step(&dmp, settle / 100.0).unwrap();
            prop_assert!(finite(&run), "{:?}", run.sample());
        }
        for d in 0..2 {
            let (p, g) = (run.position()[d], goal[d]);
            let bound = 4e-10 * deviation[d] + 1e-6 * (1.0 + g.abs());
            prop_assert!((p - g).abs() <= bound, "ends at {p}, goal {g}, bound {bound}");
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

    /// The paper's case, two examples: both methods at their defaults are
    /// the straight line through them, so exact at both and linear between.
    #[test]
    fn two_examples_generalize_to_the_line_through_them(
        q0 in -10.0f32..10.0,
        gap in 0.1f32..10.0,
        a in prop::collection::vec(-100.0f32..100.0, 3),
        b in prop::collection::vec(-100.0f32..100.0, 3),
        t in 0.0f32..=1.0,
    ) {
        let q1 = q0 + gap;
        for method in [Method::Lwr { bandwidth: None }, Method::Gpr { length_scale: None, noise: 0.0 }] {
            let mut g = Generalizer::<2, 1, 3>::new(1, 3, method);
            g.add_example(&[q0], &a).unwrap();
            g.add_example(&[q1], &b).unwrap();
            g.build().unwrap();
            for (q, want) in [(q0, a.clone()), (q1, b.clone()), (q0 + t * gap, a.iter().zip(&b).map(|(x, y)| x + t * (y - x)).collect())] {
                let mut out = [0.0; 3];
                g.generalize(&[q], &mut out).unwrap();
                for (o, w) in out.iter().zip(&want) {
                    prop_assert!((o - w).abs() <= 1e-3 * (1.0 + w.abs()), "{:?} at {}: {} vs {}", method, q, o, w);
                }
            }
        }
    }

    /// The importance sampler always holds the best L roll-outs seen, best
    /// first, ties in the order they came (rewards from a small set force
    /// ties), each with its own parameters; every update moves the mean to
    /// a reward-weighted average of the sampler's parameters (inside their
    /// hull), or leaves it when every reward there is 0.
    #[test]
    fn power_sampler_is_the_sorted_best_l(
        rewards in prop::collection::vec(prop_oneof![0.0f32..10.0, prop::sample::select(vec![0.0f32, 0.5, 2.0])], 1..60),
        l in 1usize..=5,
    ) {
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
            let theta = p.ask()[0];
            let mean = p.mean()[0];
            let updated = p.tell(*r).unwrap();
            seen.push((*r, theta));
            if updated {
                let (lo, hi) = p.sampler().fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), (t, _)| (lo.min(t[0]), hi.max(t[0])));
                let m = p.mean()[0];
                if p.sampler().all(|(_, r)| r == 0.0) {
                    prop_assert_eq!(m, mean);
                } else {
                    let slack = 1e-5 * (1.0 + lo.abs().max(hi.abs()));
                    prop_assert!(lo - slack <= m && m <= hi + slack, "mean {} outside [{}, {}]", m, lo, hi);
                }
            }
        }
        // A stable sort: equal rewards keep their order.
        let mut best = seen.clone();
        best.sort_by(|a, b| b.0.partial_cmp(&a.0).unwrap());
        best.truncate(l);
        let kept: Vec<(f32, f32)> = p.sampler().map(|(t, r)| (r, t[0])).collect();
        prop_assert_eq!(kept, best);
    }
}
