//! The paper's experiments on the simulated cell.
//!
//! - [`golden`] (Fig. 3): error learning for several bottle volumes, with
//!   the paper's golden section and with Illinois, in Cartesian space.
//! - [`power`] (Figs. 5 and 6): extended against ordinary PoWER in joint
//!   space, many seeded runs: per update the mean, std and the range of
//!   the middle 90 % of runs.
//!
//! Runs are independent and seeded, and spread over all cores; the results
//! do not depend on how many cores there are. One seeded run of each is
//! one function ([`golden_run`], [`power_run`]): the command line's
//! parallel loops and the Python package's sweeps (local processes or
//! Ray) call the same.

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use serde::{Deserialize, Serialize};

use crate::Error;
use crate::learning::{Algorithm, ERROR_LEARNERS, Learner, Record, Settings, learn};
use crate::pour::SkillSpec;
use crate::pouring::built_in_skill;
use crate::stats::{Estimate, bootstrap, mean, median, quantile};
use primo_sim::cell::{CellConfig, GlassKind};
use primo_skill::{Skill, Space};

/// Runs `job(0..n)` on all cores; results in index order.
pub fn parallel<T: Send>(n: usize, job: impl Fn(usize) -> T + Sync) -> Vec<T> {
    parallel_reporting(n, job, |_| {})
}

/// [`parallel`], calling `done` with the number of jobs finished as each
/// finishes (from the worker that finished it).
pub fn parallel_reporting<T: Send>(
    n: usize,
    job: impl Fn(usize) -> T + Sync,
    done: impl Fn(usize) + Sync,
) -> Vec<T> {
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(n.max(1));
    let next = AtomicUsize::new(0);
    let finished = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<T>>> = Mutex::new((0..n).map(|_| None).collect());
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= n {
                        break;
                    }
                    let value = job(i);
                    if let Ok(mut r) = results.lock() {
                        r[i] = Some(value);
                    }
                    done(finished.fetch_add(1, Ordering::Relaxed) + 1);
                }
            });
        }
    });
    results
        .into_inner()
        .unwrap_or_default()
        .into_iter()
        .flatten()
        .collect()
}

/// How far an experiment is: reported as each of its runs finishes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Done {
    /// Runs finished.
    pub runs: usize,
    /// Runs in all.
    pub of: usize,
}

/// One learning run of the golden experiment.
#[derive(Debug, Clone, Serialize)]
pub struct SearchRun {
    /// Liquid in the bottle, l.
    pub volume: f64,
    /// The learner.
    pub method: Algorithm,
    /// First roll-out with |error| below the precision, if any.
    pub rollouts_to_precision: Option<u32>,
    /// The most poured beyond the target in any roll-out, l (0 if never):
    /// what a search spills over the glass's mark on a real cell.
    pub worst_overpour: f64,
    /// Per roll-out: query and error (l).
    #[serde(skip)]
    pub records: Vec<Record>,
}

impl SearchRun {
    /// The figures of a run's roll-outs, to `precision` (l).
    pub fn of(volume: f64, method: Algorithm, precision: f64, records: Vec<Record>) -> SearchRun {
        SearchRun {
            volume,
            method,
            rollouts_to_precision: records
                .iter()
                .find(|r| r.trial.error.abs() < precision)
                .map(|r| r.rollout),
            worst_overpour: records.iter().map(|r| r.trial.error).fold(0.0, f64::max),
            records,
        }
    }
}

/// The golden experiment's cell and skill: the normal glass, Cartesian
/// space, 30 kernels per DoF, fitted to the built-in demonstrations.
pub fn golden_skill() -> Result<(CellConfig, Skill), Error> {
    let cell = CellConfig::standard(GlassKind::Normal);
    let skill = built_in_skill(&cell, Space::Cartesian, 30)?;
    Ok((cell, skill))
}

/// The settings of one golden-experiment run, checked: the paper's for
/// the error learner `method` pouring 0.2 l from `volume` l in `cell`,
/// to `precision` (l), the scale's noise from `seed`. The message of a
/// refused volume does not name it (callers do).
pub fn golden_settings(
    cell: &CellConfig,
    volume: f64,
    method: Algorithm,
    precision: f64,
    seed: u64,
) -> Result<Settings, Error> {
    if !ERROR_LEARNERS.contains(&method) {
        return Err(Error::Invalid(format!(
            "{}: not an error learner",
            method.name()
        )));
    }
    let mut s = Settings::paper(method, volume, 0.2, seed);
    s.precision = precision;
    s.validate()?;
    let capacity = cell.bottle_litres();
    if volume > capacity {
        return Err(Error::Invalid(format!(
            "the cell's bottle holds {capacity:.3} l"
        )));
    }
    Ok(s)
}

/// One seeded run of the golden experiment (Fig. 3): `method` learns to
/// pour 0.2 l from `volume` l ([`golden_settings`]) on the skill of
/// [`golden_skill`]. [`golden`] runs it for every volume and learner.
pub fn golden_run(
    skill: &Skill,
    cell: &CellConfig,
    volume: f64,
    method: Algorithm,
    precision: f64,
    seed: u64,
) -> Result<SearchRun, Error> {
    let s = golden_settings(cell, volume, method, precision, seed)?;
    let records = learn(skill, cell, &s, &mut Learner::local(), |_| {})?;
    Ok(SearchRun::of(volume, method, precision, records))
}

/// Fig. 3: every error learner ([`ERROR_LEARNERS`]: golden section,
/// Illinois, secant, and the paper's fixed-gain rules) for every volume,
/// volume by volume; `progress` hears of every run finished.
pub fn golden(
    skill: &Skill,
    cell: &CellConfig,
    volumes: &[f64],
    precision: f64,
    seed: u64,
    progress: impl Fn(Done) + Sync,
) -> Result<Vec<SearchRun>, Error> {
    let jobs: Vec<(f64, Algorithm)> = volumes
        .iter()
        .flat_map(|v| ERROR_LEARNERS.map(|m| (*v, m)))
        .collect();
    let of = jobs.len();
    parallel_reporting(
        of,
        |i| {
            let (volume, method) = jobs[i];
            golden_run(skill, cell, volume, method, precision, seed)
        },
        |runs| progress(Done { runs, of }),
    )
    .into_iter()
    .collect()
}

/// The share of runs between a [`Curve`]'s `low` and `high`.
pub const SPREAD: f64 = 0.90;

/// Mean, standard deviation and the range of the middle [`SPREAD`] of runs,
/// per update.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Curve {
    /// Mean per update.
    pub mean: Vec<f64>,
    /// Standard deviation per update.
    pub std: Vec<f64>,
    /// The (1 − [`SPREAD`]) / 2 quantile over runs per update (the 5th
    /// percentile): unlike mean − std, a value some run had.
    pub low: Vec<f64>,
    /// The (1 + [`SPREAD`]) / 2 quantile (the 95th percentile).
    pub high: Vec<f64>,
}

impl Curve {
    fn of(runs: &[Vec<f64>]) -> Curve {
        let len = runs.iter().map(Vec::len).min().unwrap_or(0);
        let n = runs.len().max(1) as f64;
        let mut c = Curve::default();
        for u in 0..len {
            let at: Vec<f64> = runs.iter().map(|r| r[u]).collect();
            let mean = at.iter().sum::<f64>() / n;
            let var = at.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
            c.mean.push(mean);
            c.std.push(var.sqrt());
            c.low.push(quantile(&at, 0.5 * (1.0 - SPREAD)));
            c.high.push(quantile(&at, 0.5 * (1.0 + SPREAD)));
        }
        c
    }

    /// The last mean.
    pub fn last(&self) -> f64 {
        self.mean.last().copied().unwrap_or(f64::NAN)
    }
}

/// Learning curves of one PoWER variant: the mean policy's roll-out after
/// 0, 1, …, `updates` updates (its |error| and spill in litres, its
/// reward), and how informative the roll-outs were.
#[derive(Debug, Clone, Default, Serialize)]
pub struct PowerCurves {
    /// |poured − target|, l.
    pub error: Curve,
    /// Spilled, l.
    pub spilled: Curve,
    /// Reward.
    pub reward: Curve,
    /// Roll-outs over all runs (explorations and the mean's).
    pub rollouts: usize,
    /// Of those, roll-outs with reward 0 (the sampler averages nothing
    /// from them), rejected ones included.
    pub zero_reward: usize,
    /// Of those, roll-outs rejected by the safety check.
    pub rejected: usize,
    /// Every run, by seed.
    #[serde(skip)]
    pub runs: Vec<PowerRun>,
}

/// The mean policy's reward levels runs are timed to.
pub const THRESHOLDS: [f64; 2] = [0.95, 0.99];

/// One seeded run of a PoWER variant.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PowerRun {
    /// Its seed.
    pub seed: u64,
    /// Per [`THRESHOLDS`] level: the roll-outs made (all of them,
    /// explorations and the mean's, from 1) when the mean policy's
    /// roll-out first reached it; `None` if it never did.
    pub rollouts_to: [Option<u32>; 2],
    /// The same in updates completed.
    pub updates_to: [Option<u32>; 2],
    /// Cumulative regret `Σ (1 − r)` over every roll-out: what learning
    /// cost on a cell, in lost pours.
    pub regret: f64,
    /// The final mean policy's |error|, l.
    pub error: f64,
    /// Its spill, l.
    pub spilled: f64,
    /// Its reward.
    pub reward: f64,
}

impl PowerRun {
    /// The figures of the run of `seed` from its roll-outs ([`power_run`]).
    pub fn of(seed: u64, records: &[Record]) -> PowerRun {
        let reached = |level: f64| {
            records
                .iter()
                .find(|r| r.mean && r.trial.reward >= level)
                .map(|r| (r.rollout, r.update))
        };
        let last = records.iter().rev().find(|r| r.mean);
        PowerRun {
            seed,
            rollouts_to: THRESHOLDS.map(|l| reached(l).map(|(n, _)| n)),
            updates_to: THRESHOLDS.map(|l| reached(l).map(|(_, u)| u)),
            regret: records.iter().map(|r| 1.0 - r.trial.reward).sum(),
            error: last.map_or(f64::NAN, |r| r.trial.error.abs()),
            spilled: last.map_or(f64::NAN, |r| r.trial.spilled),
            reward: last.map_or(f64::NAN, |r| r.trial.reward),
        }
    }
}

/// How a variant did over its runs, each figure with its bootstrap
/// interval ([`crate::stats`]).
#[derive(Debug, Clone, Serialize)]
pub struct PowerStats {
    /// Per [`THRESHOLDS`] level: the median roll-outs to it (a run that
    /// never reached it counts as the budget plus one: a lower bound).
    pub rollouts_to: [Estimate; 2],
    /// Per level: how many runs reached it.
    pub reached: [usize; 2],
    /// The median updates to it (the same convention).
    pub updates_to: [Estimate; 2],
    /// Mean cumulative regret.
    pub regret: Estimate,
    /// Mean final |error|, l.
    pub error: Estimate,
    /// Mean final spill, l.
    pub spilled: Estimate,
}

/// The variants against ordinary PoWER on the same seeds (paired).
#[derive(Debug, Clone, Serialize)]
pub struct PowerComparison {
    /// Extended's figures.
    pub extended: PowerStats,
    /// Ordinary's.
    pub ordinary: PowerStats,
    /// The error-learned query's.
    pub error_learned: PowerStats,
    /// Per level: the median over seeds of (ordinary − extended) roll-outs
    /// to it: above 0, extended gets there sooner.
    pub rollouts_saved: [Estimate; 2],
    /// The same for (ordinary − error-learned).
    pub rollouts_saved_by_error_learning: [Estimate; 2],
    /// Ordinary's mean final |error| over extended's: the paper's claim is
    /// an order of magnitude.
    pub error_ratio: Estimate,
    /// The same for the spill.
    pub spill_ratio: Estimate,
}

impl PowerComparison {
    /// The figures of the variants' runs (in the order of
    /// [`Variant::ALL`], the same seeds, in order), with `budget`
    /// roll-outs per run.
    pub fn of(
        [extended, ordinary, error_learned]: [&[PowerRun]; 3],
        budget: u32,
    ) -> PowerComparison {
        let censored = |n: Option<u32>| f64::from(n.unwrap_or(budget + 1));
        let stats = |runs: &[PowerRun]| {
            let pick = |f: &dyn Fn(&PowerRun) -> f64, of: fn(&[f64]) -> f64, seed: u64| {
                bootstrap(
                    runs.len(),
                    |idx| of(&idx.iter().map(|i| f(&runs[*i])).collect::<Vec<_>>()),
                    seed,
                )
            };
            PowerStats {
                rollouts_to: [0, 1]
                    .map(|k| pick(&|r| censored(r.rollouts_to[k]), median, 1 + k as u64)),
                reached: [0, 1].map(|k| runs.iter().filter(|r| r.rollouts_to[k].is_some()).count()),
                updates_to: [0, 1]
                    .map(|k| pick(&|r| censored(r.updates_to[k]), median, 3 + k as u64)),
                regret: pick(&|r| r.regret, mean, 5),
                error: pick(&|r| r.error, mean, 6),
                spilled: pick(&|r| r.spilled, mean, 7),
            }
        };
        let n = extended.len().min(ordinary.len());
        let paired = |f: &dyn Fn(&[usize]) -> f64, seed| bootstrap(n, f, seed);
        let ratio = |get: fn(&PowerRun) -> f64| {
            move |idx: &[usize]| {
                let sum = |runs: &[PowerRun]| idx.iter().map(|i| get(&runs[*i])).sum::<f64>();
                sum(ordinary) / sum(extended)
            }
        };
        // Per level: the median of (ordinary − other) roll-outs, paired.
        let saved = |other: &[PowerRun], seed: u64| {
            let n = other.len().min(ordinary.len());
            [0, 1].map(|k| {
                bootstrap(
                    n,
                    |idx: &[usize]| {
                        median(
                            &idx.iter()
                                .map(|i| {
                                    censored(ordinary[*i].rollouts_to[k])
                                        - censored(other[*i].rollouts_to[k])
                                })
                                .collect::<Vec<_>>(),
                        )
                    },
                    seed + k as u64,
                )
            })
        };
        PowerComparison {
            extended: stats(extended),
            ordinary: stats(ordinary),
            error_learned: stats(error_learned),
            rollouts_saved: saved(extended, 11),
            rollouts_saved_by_error_learning: saved(error_learned, 15),
            error_ratio: paired(&ratio(|r| r.error), 13),
            spill_ratio: paired(&ratio(|r| r.spilled), 14),
        }
    }
}

/// The power experiment's PoWER variants.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Variant {
    /// Extended PoWER over `[q̂, Δθ]` (s1 = 0.2).
    Extended,
    /// Ordinary PoWER over Δθ (s1 = 0).
    Ordinary,
    /// PoWER over `[q̂, Δθ]` with the query learned from the error
    /// (`primo pour --method power-el`: s1 = 0, gain 1).
    ErrorLearned,
}

impl Variant {
    /// All, in the order the experiment reports them.
    pub const ALL: [Variant; 3] = [Variant::Extended, Variant::Ordinary, Variant::ErrorLearned];

    /// The learner's settings for a run of this variant.
    pub fn settings(self, seed: u64) -> Settings {
        let (method, s1) = match self {
            Variant::Extended => (Algorithm::Power, 0.2),
            Variant::Ordinary => (Algorithm::Power, 0.0),
            Variant::ErrorLearned => (Algorithm::PowerEl, 0.0),
        };
        Settings {
            s1,
            ..Settings::paper(method, 0.5, 0.2, seed)
        }
    }

    /// Its name in files: `extended`, `ordinary`, `error-learned`.
    pub fn name(self) -> &'static str {
        match self {
            Variant::Extended => "extended",
            Variant::Ordinary => "ordinary",
            Variant::ErrorLearned => "error-learned",
        }
    }

    /// Its label in plots.
    pub fn label(self) -> &'static str {
        match self {
            Variant::Extended => "extended PoWER (s1 = 0.2)",
            Variant::Ordinary => "ordinary PoWER (s1 = 0)",
            Variant::ErrorLearned => "PoWER, query error-learned (power-el)",
        }
    }
}

/// Roll-outs per PoWER update in the power experiment.
pub const PER_UPDATE: u32 = 4;

/// The roll-outs of a power-experiment run of `updates` updates: 4 per
/// update, then the final mean's.
pub fn power_budget(updates: u32) -> Result<u32, Error> {
    updates
        .checked_mul(PER_UPDATE)
        .and_then(|n| n.checked_add(1))
        .filter(|_| updates > 0)
        .ok_or_else(|| {
            Error::Invalid(format!(
                "--updates {updates}: must be at least 1 and at most {}",
                (u32::MAX - 1) / PER_UPDATE
            ))
        })
}

/// The power experiment's cell and skill: joint space, `kernels` per
/// joint, fitted to the built-in demonstrations, `glass` on the scale.
pub fn power_skill(glass: GlassKind, kernels: usize) -> Result<(CellConfig, Skill), Error> {
    SkillSpec {
        space: Space::Joint,
        glass,
        kernels,
        demos: Vec::new(),
    }
    .build()
    .map(|b| (b.cell, b.skill))
}

/// One seeded run of the power experiment (Figs. 5 and 6): `variant`
/// PoWER from the generalized start for a 0.5 l bottle, pouring 0.2 l,
/// `updates` updates of 4 roll-outs each, then one more roll-out of the
/// final mean ([`power_budget`]); every roll-out, in order. [`power`]
/// runs it for every variant and seed.
pub fn power_run(
    skill: &Skill,
    cell: &CellConfig,
    variant: Variant,
    updates: u32,
    seed: u64,
) -> Result<Vec<Record>, Error> {
    let mut s = variant.settings(seed);
    s.max_rollouts = power_budget(updates)?;
    learn(skill, cell, &s, &mut Learner::local(), |_| {})
}

impl PowerCurves {
    /// The curves of one variant's runs, each its seed and roll-outs
    /// ([`power_run`]), in the order given.
    pub fn of(runs: &[(u64, Vec<Record>)]) -> PowerCurves {
        let mut curves = PowerCurves::default();
        let mut error = Vec::new();
        let mut spilled = Vec::new();
        let mut reward = Vec::new();
        for (seed, records) in runs {
            curves.runs.push(PowerRun::of(*seed, records));
            let means: Vec<&Record> = records.iter().filter(|r| r.mean).collect();
            error.push(means.iter().map(|r| r.trial.error.abs()).collect());
            spilled.push(means.iter().map(|r| r.trial.spilled).collect());
            reward.push(means.iter().map(|r| r.trial.reward).collect());
            curves.rollouts += records.len();
            curves.zero_reward += records.iter().filter(|r| r.trial.reward == 0.0).count();
            curves.rejected += records
                .iter()
                .filter(|r| r.trial.rejected.is_some())
                .count();
        }
        curves.error = Curve::of(&error);
        curves.spilled = Curve::of(&spilled);
        curves.reward = Curve::of(&reward);
        curves
    }
}

/// Figs. 5 and 6: `runs` seeded runs (seeds `seed`, `seed + 1`, …) of
/// each [`Variant`] ([`power_run`]) from the same generalized start,
/// `updates` updates of 4 roll-outs each, then one more roll-out of the
/// final mean; the curves in the order of [`Variant::ALL`]. `progress`
/// hears of every run finished.
pub fn power(
    skill: &Skill,
    cell: &CellConfig,
    runs: usize,
    updates: u32,
    seed: u64,
    progress: impl Fn(Done) + Sync,
) -> Result<[PowerCurves; 3], Error> {
    // Seed by seed, every variant's run of a seed together: runs of one
    // variant take alike, so the finished share tracks the time spent.
    let jobs: Vec<(Variant, u64)> = (0..runs as u64)
        .flat_map(|r| Variant::ALL.map(|v| (v, seed.wrapping_add(r))))
        .collect();
    let of = jobs.len();
    let results = parallel_reporting(
        of,
        |i| {
            let (variant, seed) = jobs[i];
            Ok((seed, power_run(skill, cell, variant, updates, seed)?))
        },
        |runs| progress(Done { runs, of }),
    )
    .into_iter()
    .collect::<Result<Vec<_>, Error>>()?;
    let mut by_variant: [Vec<(u64, Vec<Record>)>; 3] = Default::default();
    for (i, run) in results.into_iter().enumerate() {
        by_variant[i % Variant::ALL.len()].push(run);
    }
    Ok(by_variant.map(|runs| PowerCurves::of(&runs)))
}

#[cfg(test)]
mod tests {
    use super::*;

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
        for updates in [0, u32::MAX / 2] {
            assert!(matches!(power_budget(updates), Err(Error::Invalid(_))));
        }
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
