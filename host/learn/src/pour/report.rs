//! What a pour writes: its roll-out table (`rollouts.csv`), its summary
//! (`summary.json`) and its convergence chart (`convergence.png`), each
//! written atomically; and its roll-out as a line of progress.

use std::path::Path;

use primo_mtsics::Fixed;
use primo_skill::csv::Csv;
use serde::Serialize;

use crate::Error;
use crate::clock::Seconds;
use crate::output::{write_file, write_json};
use crate::plot::panels::{per_rollout, reward_lines, rewards, write_convergence};
use crate::plot::{Line, Panel};
use crate::rollouts::{Record, Verdict};

use super::settings::Settings;
use super::trial::Trial;

/// The columns of `rollouts.csv`.
const ROLLOUT_COLUMNS: [&str; 9] = [
    "rollout",
    "update",
    "mean",
    "query",
    "poured_l",
    "spilled_l",
    "error_l",
    "reward",
    "rejected",
];

/// `rollouts.csv`: one row per roll-out, volumes in litres to the
/// microlitre.
fn rollouts_csv(records: &[Record<Trial>]) -> Vec<u8> {
    let mut csv = Csv::new();
    for column in ROLLOUT_COLUMNS {
        csv.text(column);
    }
    csv.end_row();
    for r in records {
        let t = &r.trial;
        csv.display(r.rollout)
            .display(r.update)
            .display(r.mean)
            .display(r.volume());
        for value in [t.poured, t.spilled, t.error, t.reward] {
            csv.display(format_args!("{value:.6}"));
        }
        csv.text(t.rejected.as_deref().unwrap_or(""));
        csv.end_row();
    }
    csv.into_bytes()
}

/// The one-line report of a roll-out.
pub fn rollout_line(r: &Record<Trial>) -> String {
    let t = &r.trial;
    match &t.rejected {
        Some(why) => format!(
            "roll-out {:>3}: q {:.4} l  REJECTED ({why})  reward 0",
            r.rollout,
            r.volume()
        ),
        None => format!(
            "roll-out {:>3}: q {:.4} l  poured {:6} ml  spilled {:5} ml  error {:+6} ml  reward {:.3}{}",
            r.rollout,
            r.volume(),
            Fixed(t.poured * 1e3, 1),
            Fixed(t.spilled * 1e3, 1),
            Fixed(t.error * 1e3, 1),
            t.reward,
            if r.mean { "  (mean)" } else { "" }
        ),
    }
}

/// `summary.json` of a `primo pour` run.
#[derive(Debug, Serialize)]
pub struct PourSummary<'a> {
    /// The settings.
    pub settings: &'a Settings,
    /// Coordinates of the movement.
    pub space: crate::pour::skill::Space,
    /// Parameters learned (θ plus the query for PoWER, the query otherwise).
    pub parameters: usize,
    /// Roll-outs executed.
    pub rollouts: usize,
    /// Reached |error| < precision (error learning) at this roll-out.
    pub converged_at: Option<u32>,
    /// How learning ended.
    #[serde(flatten)]
    pub verdict: Verdict,
    /// The last roll-out (PoWER: the last roll-out of the mean).
    pub last: RolloutSummary,
    /// The best executed roll-out (highest reward, the later of equals):
    /// `series.csv` is its time series.
    pub best: Option<RolloutSummary>,
    /// Error learning: the queries it searched, l, as it searched them:
    /// `settings.search` with its low end raised so that the glass does
    /// not overflow ([`Settings::search_bounds`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub searched: Option<[f32; 2]>,
    /// Wall-clock time, s: `seconds` over all the run's sessions,
    /// `session_seconds` this one's.
    #[serde(flatten)]
    pub seconds: Seconds,
}

/// One roll-out in a summary.
#[derive(Debug, Serialize)]
pub struct RolloutSummary {
    /// Roll-out number.
    pub rollout: u32,
    /// Query.
    pub query: f32,
    /// Poured, l.
    pub poured: f64,
    /// Spilled, l.
    pub spilled: f64,
    /// Poured − target, l.
    pub error: f64,
    /// Reward.
    pub reward: f64,
}

impl RolloutSummary {
    /// Of a record.
    pub fn of(r: &Record<Trial>) -> Self {
        RolloutSummary {
            rollout: r.rollout,
            query: r.volume(),
            poured: r.trial.poured,
            spilled: r.trial.spilled,
            error: r.trial.error,
            reward: r.trial.reward,
        }
    }
}

/// Errors below this are drawn at it on log axes, ml: a microlitre, far
/// below any scale's resolution (a simulated pour can hit the target to
/// 1e-13 ml, which says nothing).
pub const ERROR_FLOOR_ML: f64 = 1e-3;
/// Spills below this (none at all included) are drawn at it, ml.
pub const SPILL_FLOOR_ML: f64 = 1e-2;

/// Writes `rollouts.csv`, `summary.json` and `convergence.png` into `dir`.
pub fn write_pour(
    dir: &Path,
    records: &[Record<Trial>],
    summary: &PourSummary,
) -> Result<(), Error> {
    write_file(&dir.join("rollouts.csv"), &rollouts_csv(records))?;
    write_json(&dir.join("summary.json"), summary)?;
    let precision_ml = summary.settings.precision * 1e3;
    let power = summary.settings.method.is_power();
    let shown: Vec<&Record<Trial>> = records
        .iter()
        .filter(|r| r.mean && r.trial.rejected.is_none())
        .collect();
    let x = |r: &Record<Trial>| f64::from(r.rollout);
    let error: Vec<(f64, f64)> = shown
        .iter()
        .map(|r| (x(r), r.trial.error.abs() * 1e3))
        .collect();
    let spilled: Vec<(f64, f64)> = shown
        .iter()
        .map(|r| (x(r), r.trial.spilled * 1e3))
        .collect();
    let query: Vec<(f64, f64)> = shown
        .iter()
        .map(|r| (x(r), f64::from(r.volume())))
        .collect();
    let reward = rewards(records.iter().map(|r| (r.rollout, r.mean, r.trial.reward)));
    let (e, s, q, w) = (
        [Line::new("|error|", &error)],
        [Line::new("spilled", &spilled)],
        [Line::new("query", &query)],
        reward_lines(&reward),
    );
    let mut panels = vec![Panel {
        title: if power {
            "Pouring error of the mean policy"
        } else {
            "Pouring error"
        },
        x_label: "roll-out",
        y_label: "|error| [ml]",
        series: &e,
        log_y: true,
        floor: Some(ERROR_FLOOR_ML),
        hline: Some((precision_ml, "precision")),
    }];
    if power {
        panels.push(Panel {
            log_y: true,
            floor: Some(SPILL_FLOOR_ML),
            ..per_rollout("Spilled by the mean policy", "spilled [ml]", &s)
        });
        panels.push(per_rollout("Reward of every roll-out", "reward", &w));
    }
    panels.push(per_rollout("Learned query", "q [l]", &q));
    write_convergence(dir, &panels)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pour::trial::Measured;

    #[test]
    fn a_pour_of_a_hair_less_than_nothing_is_no_negative_zero() {
        let m = Measured {
            poured: -2e-6,
            spilled: -0.0,
            series: None,
            readings: None,
        };
        let r = Record {
            rollout: 1,
            update: 0,
            mean: true,
            query: vec![0.5],
            trial: Trial::scored(0.0, m),
        };
        let line = rollout_line(&r);
        assert!(
            line.contains("poured    0.0 ml  spilled   0.0 ml  error   +0.0 ml"),
            "{line}"
        );
    }
}
