//! The power experiment (the paper's Figs. 5 and 6): extended against
//! ordinary PoWER in joint space, and PoWER with the query learned from
//! the error, over many seeded runs; and what it writes.

use std::path::Path;

use primo_sim::cell::{CellConfig, GlassKind};
use primo_skill::Skill;
use primo_skill::csv::Csv;
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::algorithm::Algorithm;
use crate::error::Setting;
use crate::learner::Learner;
use crate::output::{write_file, write_json};
use crate::plot::panels::write_png;
use crate::plot::{Line, Panel};
use crate::pour::report::{ERROR_FLOOR_ML, SPILL_FLOOR_ML};
use crate::pour::settings::Settings;
use crate::pour::simulate::learn;
use crate::pour::skill::{SkillSpec, Space};
use crate::pour::trial::Trial;
use crate::rollouts::Record;
use crate::stats::{Estimate, bootstrap, mean, median, quantile};

use super::parallel::{Done, parallel_reporting};

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
    pub fn of(seed: u64, records: &[Record<Trial>]) -> PowerRun {
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
    /// (`primo pour --method power-el`: s1 = 0, gain 1, sampler 2).
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

/// The most seeded runs per variant of a power experiment (the paper
/// made 20).
pub const MAX_RUNS: usize = 10_000;

/// The most PoWER updates per run (the paper made 100).
pub const MAX_UPDATES: u32 = 10_000;

/// The most roll-outs of a whole power experiment, all variants' runs
/// together (the paper's: 24 060): every roll-out is kept until the curves
/// are drawn, a few hundred bytes each.
pub const MAX_EXPERIMENT_ROLLOUTS: u64 = 1_000_000;

/// The roll-outs of a power-experiment run of `updates` updates: 4 per
/// update, then the final mean's.
pub fn power_budget(updates: u32) -> Result<u32, Error> {
    if !(1..=MAX_UPDATES).contains(&updates) {
        return Err(Error::setting(
            Setting::Updates,
            updates,
            format!("must be from 1 to {MAX_UPDATES} updates"),
        ));
    }
    Ok(updates * PER_UPDATE + 1)
}

/// Checks a power experiment's size before anything is allocated: `runs`
/// per variant and `updates` per run, each and together within bounds.
pub fn check_power(runs: usize, updates: u32) -> Result<(), Error> {
    if !(1..=MAX_RUNS).contains(&runs) {
        return Err(Error::setting(
            Setting::Runs,
            runs,
            format!("must be from 1 to {MAX_RUNS} runs"),
        ));
    }
    let budget = power_budget(updates)?;
    let all = (Variant::ALL.len() * runs) as u64 * u64::from(budget);
    if all > MAX_EXPERIMENT_ROLLOUTS {
        return Err(Error::Conflict {
            setting: Setting::Runs,
            value: runs.to_string(),
            other: Setting::Updates,
            other_value: updates.to_string(),
            why: format!(
                "{all} roll-outs ({} variants x {runs} runs x {budget}), at most \
                 {MAX_EXPERIMENT_ROLLOUTS} in one experiment",
                Variant::ALL.len()
            ),
        });
    }
    Ok(())
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
) -> Result<Vec<Record<Trial>>, Error> {
    let mut s = variant.settings(seed);
    s.max_rollouts = power_budget(updates)?;
    learn(skill, cell, &s, &mut Learner::local(), |_| {})
}

impl PowerCurves {
    /// The curves of one variant's runs, each its seed and roll-outs
    /// ([`power_run`]), in the order given.
    pub fn of(runs: &[(u64, Vec<Record<Trial>>)]) -> PowerCurves {
        let mut curves = PowerCurves::default();
        let mut error = Vec::new();
        let mut spilled = Vec::new();
        let mut reward = Vec::new();
        for (seed, records) in runs {
            curves.runs.push(PowerRun::of(*seed, records));
            let means: Vec<&Record<Trial>> = records.iter().filter(|r| r.mean).collect();
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
    check_power(runs, updates)?;
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
    let mut by_variant: [Vec<(u64, Vec<Record<Trial>>)>; 3] = Default::default();
    for (i, run) in results.into_iter().enumerate() {
        by_variant[i % Variant::ALL.len()].push(run);
    }
    Ok(by_variant.map(|runs| PowerCurves::of(&runs)))
}

/// `summary.json` of `primo experiment power`.
#[derive(Debug, Serialize)]
pub struct PowerSummary<'a> {
    /// Runs per variant.
    pub runs: usize,
    /// Updates per run (4 roll-outs each; the curves have `updates + 1`
    /// points, the start's and one after each update).
    pub updates: u32,
    /// DMP kernels per joint.
    pub kernels: usize,
    /// Learned parameters `[q̂, Δθ]`.
    pub parameters: usize,
    /// The glass.
    pub glass: primo_sim::cell::GlassKind,
    /// s1 = 0.2, s2 = 0.05.
    pub extended: &'a PowerCurves,
    /// s1 = 0, s2 = 0.05.
    pub ordinary: &'a PowerCurves,
    /// The query error-learned (gain 1), s1 = 0, s2 = 0.05, sampler 2.
    pub error_learned: &'a PowerCurves,
    /// The per-seed figures compared, with bootstrap intervals: roll-outs
    /// to reward thresholds, regret, final error and spill, and the
    /// ordinary/extended ratios.
    pub comparison: &'a PowerComparison,
    /// Wall-clock time, s.
    pub seconds: f64,
}

impl PowerSummary<'_> {
    /// Each variant's curves, in the order of [`Variant::ALL`].
    pub fn variants(&self) -> [(Variant, &PowerCurves); 3] {
        let [e, o, l] = Variant::ALL;
        [
            (e, self.extended),
            (o, self.ordinary),
            (l, self.error_learned),
        ]
    }
}

/// The settings of a power experiment, for its summary.
#[derive(Debug, Clone, Copy)]
pub struct PowerSetup {
    /// Updates per run.
    pub updates: u32,
    /// DMP kernels per joint.
    pub kernels: usize,
    /// Learned parameters `[q̂, Δθ]`.
    pub parameters: usize,
    /// The glass.
    pub glass: primo_sim::cell::GlassKind,
}

/// Writes what `primo experiment power` writes ([`write_power`]) for the
/// curves of the variants' runs (in the order of [`Variant::ALL`], the
/// same seeds, in order), compared seed by seed; `seconds` of wall-clock
/// time. Returns the comparison.
pub fn write_power_experiment(
    dir: &Path,
    setup: PowerSetup,
    [extended, ordinary, error_learned]: &[PowerCurves; 3],
    seconds: f64,
) -> Result<PowerComparison, Error> {
    let comparison = PowerComparison::of(
        [&extended.runs, &ordinary.runs, &error_learned.runs],
        power_budget(setup.updates)?,
    );
    write_power(
        dir,
        &PowerSummary {
            runs: [extended, ordinary, error_learned]
                .iter()
                .map(|c| c.runs.len())
                .max()
                .unwrap_or(0),
            updates: setup.updates,
            kernels: setup.kernels,
            parameters: setup.parameters,
            glass: setup.glass,
            extended,
            ordinary,
            error_learned,
            comparison: &comparison,
            seconds,
        },
    )?;
    Ok(comparison)
}

/// A curve's points and its band, `(low, high)` per point.
type Band = (Vec<(f64, f64)>, Vec<(f64, f64)>);

/// The files [`write_power`] writes.
pub const FILES: [&str; 4] = ["power.csv", "power_runs.csv", "power.png", "summary.json"];

/// Writes `power.csv`, `power_runs.csv` (one row per variant and seed),
/// `power.png` and `summary.json` into `dir`.
pub fn write_power(dir: &Path, s: &PowerSummary) -> Result<(), Error> {
    let mut runs = Csv::new();
    runs.text("variant").text("seed");
    for level in THRESHOLDS {
        runs.display(format_args!("rollouts_to_{level}"))
            .display(format_args!("updates_to_{level}"));
    }
    for column in ["regret", "final_error_l", "final_spilled_l", "final_reward"] {
        runs.text(column);
    }
    runs.end_row();
    let count = |v: Option<u32>| v.map_or(String::new(), |v| v.to_string());
    for (name, c) in s.variants().map(|(v, c)| (v.name(), c)) {
        for r in &c.runs {
            runs.text(name).display(r.seed);
            for k in 0..THRESHOLDS.len() {
                runs.text(&count(r.rollouts_to[k]))
                    .text(&count(r.updates_to[k]));
            }
            runs.display(format_args!("{:.4}", r.regret));
            for v in [r.error, r.spilled, r.reward] {
                runs.display(format_args!("{v:.6}"));
            }
            runs.end_row();
        }
    }
    write_file(&dir.join("power_runs.csv"), runs.as_bytes())?;
    let mut csv = Csv::new();
    for column in [
        "update",
        "variant",
        "error_mean_l",
        "error_std_l",
        "spilled_mean_l",
        "spilled_std_l",
        "reward_mean",
        "reward_std",
        "error_p05_l",
        "error_p95_l",
        "spilled_p05_l",
        "spilled_p95_l",
        "reward_p05",
        "reward_p95",
    ] {
        csv.text(column);
    }
    csv.end_row();
    for (name, c) in s.variants().map(|(v, c)| (v.name(), c)) {
        for u in 0..c.error.mean.len() {
            csv.display(u).text(name);
            for q in [&c.error, &c.spilled, &c.reward] {
                csv.display(format_args!("{:.6}", q.mean[u]))
                    .display(format_args!("{:.6}", q.std[u]));
            }
            for q in [&c.error, &c.spilled, &c.reward] {
                csv.display(format_args!("{:.6}", q.low[u]))
                    .display(format_args!("{:.6}", q.high[u]));
            }
            csv.end_row();
        }
    }
    write_file(&dir.join("power.csv"), csv.as_bytes())?;
    write_json(&dir.join("summary.json"), s)?;
    // Against the roll-outs made (the cost on a cell): the mean policy's
    // roll-out after `u` updates is roll-out PER_UPDATE · u + 1.
    let x = |u: usize| (u as f64) * f64::from(PER_UPDATE) + 1.0;
    let curve = |c: &Curve, scale: f64| -> Band {
        let at = |v: &[f64]| -> Vec<f64> { v.iter().map(|v| v * scale).collect() };
        let (mean, low, high) = (at(&c.mean), at(&c.low), at(&c.high));
        (
            mean.iter().enumerate().map(|(u, m)| (x(u), *m)).collect(),
            low.into_iter().zip(high).collect(),
        )
    };
    let pick = |f: &dyn Fn(&PowerCurves) -> Band| s.variants().map(|(_, c)| f(c));
    let error = pick(&|c| curve(&c.error, 1e3));
    let spilled = pick(&|c| curve(&c.spilled, 1e3));
    let reward = pick(&|c| curve(&c.reward, 1.0));
    fn lines(d: &[Band; 3]) -> [Line<'_>; 3] {
        std::array::from_fn(|i| Line {
            band: Some(&d[i].1),
            ..Line::new(Variant::ALL[i].label(), &d[i].0)
        })
    }
    let (e, sp, r) = (lines(&error), lines(&spilled), lines(&reward));
    let of_runs = format!(
        "mean, shaded: middle {:.0} % of runs (n = {} seeds)",
        SPREAD * 100.0,
        s.runs
    );
    let titles = ["Pouring error", "Spilled", "Reward"].map(|t| format!("{t}: {of_runs}"));
    let x_label = "roll-outs (4 per update)";
    let panels = [
        Panel {
            title: &titles[0],
            x_label,
            y_label: "|error| [ml]",
            series: &e,
            log_y: true,
            floor: Some(ERROR_FLOOR_ML),
            hline: None,
        },
        Panel {
            title: &titles[1],
            x_label,
            y_label: "spilled [ml]",
            series: &sp,
            log_y: true,
            floor: Some(SPILL_FLOOR_ML),
            hline: None,
        },
        Panel {
            title: &titles[2],
            x_label,
            y_label: "reward of the mean policy",
            series: &r,
            ..Panel::default()
        },
    ];
    write_png(&dir.join("power.png"), &panels, 1000)
}
