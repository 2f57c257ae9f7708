//! The paper's experiments on the simulated cell.
//!
//! - [`golden`](mod@golden) (Fig. 3): error learning for several bottle volumes, with
//!   the paper's golden section and with Illinois, in Cartesian space.
//! - [`power`](mod@power) (Figs. 5 and 6): extended against ordinary PoWER in joint
//!   space, many seeded runs: per update the mean, std and the range of
//!   the middle 90 % of runs.
//!
//! An experiment claims its output directory before its runs begin
//! ([`claim`](mod@claim)): held by it alone, an earlier result replaced
//! only when forced.
//!
//! Runs are independent and seeded, and spread over all cores; the results
//! do not depend on how many cores there are. One seeded run of each is
//! one function ([`golden::golden_run`], [`power::power_run`]): the command line's
//! parallel loops and the Python package's sweeps (local processes or
//! Ray) call the same.

pub mod claim;
pub mod golden;
pub mod parallel;
pub mod power;

pub use golden::write_golden;
pub use golden::{
    MAX_VOLUMES, SearchRun, check_volumes, golden, golden_run, golden_settings, golden_skill,
    median_rollouts,
};
pub use parallel::{Done, parallel, parallel_reporting};
pub use power::{
    Curve, MAX_EXPERIMENT_ROLLOUTS, MAX_RUNS, MAX_UPDATES, PER_UPDATE, PowerComparison,
    PowerCurves, PowerRun, PowerSetup, PowerStats, PowerSummary, SPREAD, THRESHOLDS, Variant,
    check_power, power, power_budget, power_run, power_skill, write_power, write_power_experiment,
};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Error;
    use crate::algorithm::Algorithm;
    use primo_sim::cell::{CellConfig, GlassKind};
    use std::sync::Mutex;

    #[test]
    fn one_seeded_run_is_the_experiments_run_of_that_seed() {
        let (cell, skill) = power_skill(GlassKind::Small, 4).unwrap();
        let heard = Mutex::new(Vec::new());
        let hear = |d: Done| heard.lock().unwrap().push(d);
        let curves = power(&skill, &cell, 2, 1, 7, hear).unwrap();
        let mut heard = heard.into_inner().unwrap();
        heard.sort_by_key(|d| d.runs);
        let all: Vec<Done> = (1..=6).map(|runs| Done { runs, of: 6 }).collect();
        assert_eq!(heard, all, "every run finished is reported once");
        for (variant, curves) in Variant::ALL.iter().zip(curves) {
            let alone = power_run(&skill, &cell, *variant, 1, 8).unwrap();
            assert_eq!(alone.len(), 5);
            assert_eq!(curves.runs[1], PowerRun::of(8, &alone));
        }
        let (cell, skill) = golden_skill().unwrap();
        let runs = golden(&skill, &cell, &[0.5], 0.002, 3, |_| {}).unwrap();
        let alone = golden_run(&skill, &cell, 0.5, Algorithm::Secant, 0.002, 3).unwrap();
        assert_eq!(runs[2].records, alone.records);
    }

    #[test]
    fn settings_out_of_range_are_refused() {
        assert_eq!(power_budget(100).unwrap(), 401);
        for updates in [0, MAX_UPDATES + 1, u32::MAX / 2] {
            assert!(matches!(power_budget(updates), Err(Error::Setting { .. })));
        }
        check_power(20, 100).unwrap();
        let e = check_power(100_000_000, 1).unwrap_err().to_string();
        assert_eq!(e, "runs 100000000: must be from 1 to 10000 runs");
        let e = check_power(10_000, 10_000).unwrap_err().to_string();
        assert!(e.contains("at most 1000000 in one experiment"), "{e}");
        // Refused before anything is allocated (this would need terabytes).
        let (cell, skill) = power_skill(GlassKind::Small, 4).unwrap();
        let refused = power(&skill, &cell, MAX_RUNS + 1, 1, 1, |_| {});
        assert!(matches!(refused, Err(Error::Setting { .. })));
        let (cell, skill) = golden_skill().unwrap();
        let volumes = vec![0.5; MAX_VOLUMES + 1];
        let refused = golden(&skill, &cell, &volumes, 0.002, 1, |_| {});
        assert!(matches!(refused, Err(Error::Setting { .. })));
        let cell = CellConfig::standard(GlassKind::Normal);
        for (volume, method) in [(0.5, Algorithm::Power), (1.2, Algorithm::Golden)] {
            let refused = golden_settings(&cell, volume, method, 0.002, 1);
            assert!(
                matches!(refused, Err(Error::Invalid(_))),
                "{volume} {method:?}"
            );
        }
    }
}
