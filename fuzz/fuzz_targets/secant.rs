//! The secant error learner fed arbitrary settings and error vectors (NaN,
//! ±∞, huge, wrong lengths): no panic; a learner starts only on valid
//! settings; every query has the settings' dimension, is finite and inside
//! the box; invalid errors and tells after the end are refused without a
//! change; the gain stays finite; the budget and the best roll-out hold.
#![no_main]

use arbitrary::{Result, Unstructured};
use heapless::Vec as HVec;
use libfuzzer_sys::fuzz_target;
use primo_core::golden::Status;
use primo_core::secant::{Rule, Secant, SecantConfig};
use primo_fuzz::{check_told, num, positive};
use primo_protocol::learner::MAX_QUERY;

/// Up to `MAX_QUERY` numbers; the length is `n` seven times in eight.
fn vector(u: &mut Unstructured, n: usize, scale: f32) -> Result<HVec<f32, MAX_QUERY>> {
    let len = if u.ratio(1, 8)? {
        u.int_in_range(0..=MAX_QUERY)?
    } else {
        n
    };
    let mut v = HVec::new();
    for _ in 0..len {
        let _ = v.push(num(u, scale)?);
    }
    Ok(v)
}

fn drive(
    u: &mut Unstructured,
    mut learner: Secant<MAX_QUERY>,
    cfg: &SecantConfig<MAX_QUERY>,
) -> Result<()> {
    let n = cfg.dim();
    // Half the runs measure a linear cell, ε = A (root − q), so that the
    // search converges, stalls or runs out; the others get arbitrary errors.
    let cell = if u.arbitrary()? {
        let mut a = [[0.0f32; MAX_QUERY]; MAX_QUERY];
        for v in a.iter_mut().flatten() {
            *v = num(u, 2.0)?;
        }
        Some((a, vector(u, n, 3.0)?))
    } else {
        None
    };
    let mut best = f32::INFINITY;
    let mut told = 0;
    for _ in 0..200 {
        let asked = learner.ask().map(<[f32]>::to_vec);
        assert_eq!(asked.is_some(), learner.status() == Status::Running);
        let error: Vec<f32> = match (&cell, &asked) {
            (Some((a, root)), Some(q)) if u.ratio(7, 8)? && root.len() == n => (0..n)
                .map(|i| (0..n).map(|j| a[i][j] * (root[j] - q[j])).sum())
                .collect(),
            _ => vector(u, n, 1e3)?.to_vec(),
        };
        let before = learner.clone();
        let Some(q) = asked else {
            assert!(learner.tell(&error).is_err(), "a tell after the end");
            assert_eq!(learner, before);
            break;
        };
        assert_eq!(q.len(), n);
        for ((v, lo), hi) in q.iter().zip(&cfg.low).zip(&cfg.high) {
            assert!(v.is_finite() && lo <= v && v <= hi, "{q:?} outside the box");
        }
        if error.len() != n || !error.iter().all(|e| e.is_finite()) {
            assert!(learner.tell(&error).is_err());
            assert_eq!(learner, before);
            continue;
        }
        let status = learner.tell(&error).expect("a finite error is taken");
        told += 1;
        best = best.min(error.iter().fold(0.0f32, |m, e| m.max(e.abs())));
        check_told(
            learner.rollouts(),
            told,
            cfg.max_rollouts,
            learner.best().map(|b| b.size),
            best,
            status == Status::Converged,
            cfg.precision,
        );
        assert!(learner.gain().flatten().all(|k| k.is_finite()));
    }
    Ok(())
}

fuzz_target!(|data: &[u8]| {
    let mut u = Unstructured::new(data);
    let _ = (|| -> Result<()> {
        let n = u.int_in_range(0..=MAX_QUERY)?;
        let cfg = SecantConfig {
            low: vector(&mut u, n, 2.0)?,
            high: vector(&mut u, n, 2.0)?,
            desired: vector(&mut u, n, 2.0)?,
            precision: positive(&mut u, 0.1)?,
            max_rollouts: u.int_in_range(0..=100)?,
            gain: num(&mut u, 3.0)?,
            rule: *u.choose(&[Rule::Broyden, Rule::Fixed, Rule::Weighted])?,
        };
        // The documented settings, spelled out independently of validate().
        let dim = cfg.desired.len();
        let valid = dim >= 1
            && cfg.low.len() == dim
            && cfg.high.len() == dim
            && (0..dim).all(|i| {
                let (l, h, d) = (cfg.low[i], cfg.high[i], cfg.desired[i]);
                l < h && l <= d && d <= h && (h - l).is_finite()
            })
            && cfg.precision > 0.0
            && cfg.precision.is_finite()
            && cfg.gain.is_finite()
            && cfg.gain != 0.0
            && cfg.max_rollouts >= 1;
        let made = Secant::new(cfg.clone());
        assert_eq!(made.is_ok(), valid, "{cfg:?}");
        made.map_or(Ok(()), |l| drive(&mut u, l, &cfg))
    })();
});
