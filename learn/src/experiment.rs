//! The paper's experiments on the simulated cell.
//!
//! - [`golden`] (Fig. 3): error learning for several bottle volumes, with
//!   the paper's golden section and with Illinois, in Cartesian space.
//! - [`power`] (Figs. 5 and 6): extended against ordinary PoWER in joint
//!   space, many seeded runs, mean ± std per update.
//!
//! Runs are independent and seeded, and spread over all cores; the results
//! do not depend on how many cores there are.

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use serde::Serialize;

use crate::Error;
use crate::learning::{Algorithm, Learner, Record, Settings, learn};
use primo_sim::cell::CellConfig;
use primo_skill::Skill;

/// Runs `job(0..n)` on all cores; results in index order.
pub fn parallel<T: Send>(n: usize, job: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(n.max(1));
    let next = AtomicUsize::new(0);
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

/// One learning run of the golden experiment.
#[derive(Debug, Clone, Serialize)]
pub struct SearchRun {
    /// Liquid in the bottle, l.
    pub volume: f64,
    /// The learner.
    pub method: Algorithm,
    /// First roll-out with |error| below the precision, if any.
    pub rollouts_to_precision: Option<u32>,
    /// Per roll-out: query and error (l).
    #[serde(skip)]
    pub records: Vec<Record>,
}

/// Fig. 3: golden section and Illinois for every volume.
pub fn golden(
    skill: &Skill,
    cell: &CellConfig,
    volumes: &[f64],
    precision: f64,
    seed: u64,
) -> Result<Vec<SearchRun>, Error> {
    let jobs: Vec<(f64, Algorithm)> = volumes
        .iter()
        .flat_map(|v| [(*v, Algorithm::Golden), (*v, Algorithm::Illinois)])
        .collect();
    parallel(jobs.len(), |i| {
        let (volume, method) = jobs[i];
        let mut s = Settings::paper(method, volume, 0.2, seed);
        s.precision = precision;
        let records = learn(skill, cell, &s, &mut Learner::local(), |_| {})?;
        Ok(SearchRun {
            volume,
            method,
            rollouts_to_precision: records
                .iter()
                .find(|r| r.trial.error.abs() < precision)
                .map(|r| r.rollout),
            records,
        })
    })
    .into_iter()
    .collect()
}

/// Mean and standard deviation over runs, per update.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Curve {
    /// Mean per update.
    pub mean: Vec<f64>,
    /// Standard deviation per update.
    pub std: Vec<f64>,
}

impl Curve {
    fn of(runs: &[Vec<f64>]) -> Curve {
        let len = runs.iter().map(Vec::len).min().unwrap_or(0);
        let n = runs.len().max(1) as f64;
        let mut c = Curve::default();
        for u in 0..len {
            let mean = runs.iter().map(|r| r[u]).sum::<f64>() / n;
            let var = runs.iter().map(|r| (r[u] - mean).powi(2)).sum::<f64>() / n;
            c.mean.push(mean);
            c.std.push(var.sqrt());
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
}

/// Figs. 5 and 6: `runs` seeded runs of extended (s1 = 0.2) and ordinary
/// (s1 = 0) PoWER from the same generalized start, `updates` updates of 4
/// roll-outs each, then one more roll-out of the final mean.
pub fn power(
    skill: &Skill,
    cell: &CellConfig,
    runs: usize,
    updates: u32,
    seed: u64,
) -> Result<[PowerCurves; 2], Error> {
    let per_update = 4;
    let jobs: Vec<(f32, u64)> = [0.2f32, 0.0]
        .iter()
        .flat_map(|s1| (0..runs as u64).map(move |r| (*s1, seed.wrapping_add(r))))
        .collect();
    let results = parallel(jobs.len(), |i| {
        let (s1, seed) = jobs[i];
        let mut s = Settings::paper(Algorithm::Power, 0.5, 0.2, seed);
        s.s1 = s1;
        s.max_rollouts = updates * per_update + 1;
        learn(skill, cell, &s, &mut Learner::local(), |_| {})
    })
    .into_iter()
    .collect::<Result<Vec<_>, Error>>()?;
    let mut out: [PowerCurves; 2] = Default::default();
    for (k, curves) in out.iter_mut().enumerate() {
        let mut error = Vec::new();
        let mut spilled = Vec::new();
        let mut reward = Vec::new();
        for records in &results[k * runs..(k + 1) * runs] {
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
    }
    Ok(out)
}
