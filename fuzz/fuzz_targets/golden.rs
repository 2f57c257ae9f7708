//! Golden-section and Illinois error learning fed arbitrary settings and
//! errors (NaN, ±∞ and huge ones too): no panic; a learner starts only on
//! valid settings; every query is finite and strictly inside the bracket;
//! the bracket never grows; invalid errors and tells after the end are
//! refused without a change; the budget and the best roll-out hold.
#![no_main]

use std::fmt::Debug;

use arbitrary::{Result, Unstructured};
use libfuzzer_sys::fuzz_target;
use primo_core::golden::{ErrorLearner, GoldenSection, SearchConfig, Status};
use primo_core::illinois::Illinois;
use primo_fuzz::{check_told, num};

fn drive<L: ErrorLearner + Clone + PartialEq + Debug>(
    u: &mut Unstructured,
    mut learner: L,
    cfg: &SearchConfig,
) -> Result<()> {
    // Half the runs measure a monotone error around a root, so that the
    // searches converge or collapse; the others get arbitrary errors.
    let root = if u.arbitrary()? {
        Some(num(u, 1.0)?)
    } else {
        None
    };
    let mut best = f32::INFINITY;
    let mut told = 0;
    for _ in 0..200 {
        let (lo, hi) = learner.bracket();
        let asked = learner.ask();
        assert_eq!(asked.is_some(), learner.status() == Status::Running);
        let error = match (root, asked) {
            (Some(r), Some(q)) if u.ratio(7, 8)? => (r - q) * num(u, 1.0)?.abs(),
            _ => num(u, 1e3)?,
        };
        let before = learner.clone();
        let Some(q) = asked else {
            assert!(learner.tell(error).is_err(), "a tell after the end");
            assert_eq!(learner, before);
            break;
        };
        assert!(
            q.is_finite() && lo < q && q < hi,
            "{q} outside ({lo}, {hi})"
        );
        if !error.is_finite() {
            assert!(learner.tell(error).is_err());
            assert_eq!(learner, before);
            continue;
        }
        let status = learner.tell(error).expect("a finite error is taken");
        told += 1;
        best = best.min(error.abs());
        let (lo2, hi2) = learner.bracket();
        assert!(
            lo <= lo2 && hi2 <= hi,
            "({lo}, {hi}) grew to ({lo2}, {hi2})"
        );
        check_told(
            learner.rollouts(),
            told,
            cfg.max_rollouts,
            learner.best().map(|b| b.error.abs()),
            best,
            status == Status::Converged,
            cfg.precision,
        );
    }
    Ok(())
}

fuzz_target!(|data: &[u8]| {
    let mut u = Unstructured::new(data);
    let _ = (|| -> Result<()> {
        let cfg = SearchConfig {
            low: num(&mut u, 2.0)?,
            high: num(&mut u, 2.0)?,
            desired: num(&mut u, 2.0)?,
            precision: num(&mut u, 0.1)?,
            max_rollouts: u.int_in_range(0..=100)?,
        };
        // The documented settings, spelled out independently of validate().
        let valid = cfg.low < cfg.desired
            && cfg.desired < cfg.high
            && (cfg.high - cfg.low).is_finite()
            && cfg.precision > 0.0
            && cfg.precision.is_finite()
            && cfg.max_rollouts >= 1;
        if u.arbitrary()? {
            let made = GoldenSection::new(cfg);
            assert_eq!(made.is_ok(), valid);
            made.map_or(Ok(()), |l| drive(&mut u, l, &cfg))
        } else {
            let made = Illinois::new(cfg);
            assert_eq!(made.is_ok(), valid);
            made.map_or(Ok(()), |l| drive(&mut u, l, &cfg))
        }
    })();
});
