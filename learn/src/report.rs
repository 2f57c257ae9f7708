//! What the learning commands write: roll-out tables (CSV), summaries
//! (JSON) and convergence charts (PNG), each written atomically.

use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use crate::Error;
use crate::experiment::{
    PowerComparison, PowerCurves, SearchRun, THRESHOLDS, Variant, power_budget,
};
use crate::learning::{Algorithm, ERROR_LEARNERS, Record, Settings};
use crate::output::write_file;
use crate::plot::{Line, Panel, render_png};

/// Header of `rollouts.csv`.
pub const ROLLOUT_HEADER: &str =
    "rollout,update,mean,query,poured_l,spilled_l,error_l,reward,rejected";

/// One `rollouts.csv` row.
pub fn rollout_row(r: &Record) -> String {
    let t = &r.trial;
    let why = t
        .rejected
        .as_deref()
        .map(|w| format!("\"{}\"", w.replace('"', "'")))
        .unwrap_or_default();
    format!(
        "{},{},{},{},{:.6},{:.6},{:.6},{:.6},{}",
        r.rollout,
        r.update,
        r.mean,
        r.volume(),
        t.poured,
        t.spilled,
        t.error,
        t.reward,
        why
    )
}

/// The one-line report of a roll-out.
pub fn rollout_line(r: &Record) -> String {
    let t = &r.trial;
    match &t.rejected {
        Some(why) => format!(
            "roll-out {:>3}: q {:.4} l  REJECTED ({why})  reward 0",
            r.rollout,
            r.volume()
        ),
        None => format!(
            "roll-out {:>3}: q {:.4} l  poured {:6.1} ml  spilled {:5.1} ml  error {:+6.1} ml  reward {:.3}{}",
            r.rollout,
            r.volume(),
            t.poured * 1e3,
            t.spilled * 1e3,
            t.error * 1e3,
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
    pub space: primo_skill::Space,
    /// Parameters learned (θ plus the query for PoWER, the query otherwise).
    pub parameters: usize,
    /// Roll-outs executed.
    pub rollouts: usize,
    /// Reached |error| < precision (error learning) at this roll-out.
    pub converged_at: Option<u32>,
    /// The last roll-out (PoWER: the last roll-out of the mean).
    pub last: RolloutSummary,
    /// The best executed roll-out (highest reward, the later of equals):
    /// `series.csv` is its time series.
    pub best: Option<RolloutSummary>,
    /// Wall-clock time, s.
    pub seconds: f64,
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
    pub fn of(r: &Record) -> Self {
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

/// A linear panel over the roll-outs.
fn per_rollout<'a>(title: &'a str, y_label: &'a str, series: &'a [Line<'a>]) -> Panel<'a> {
    Panel {
        title,
        x_label: "roll-out",
        y_label,
        series,
        log_y: false,
        hline: None,
    }
}

fn json(value: &impl Serialize) -> Result<Vec<u8>, Error> {
    let mut s =
        serde_json::to_string_pretty(value).map_err(|e| Error::Report(format!("summary: {e}")))?;
    s.push('\n');
    Ok(s.into_bytes())
}

fn png(path: &Path, panels: &[Panel<'_>], height: u32) -> Result<(), Error> {
    let bytes = render_png(panels, 1000, height)
        .map_err(|e| Error::Report(format!("{}: {e}", path.display())))?;
    write_file(path, &bytes)
}

/// Writes a task run's `convergence.png`: the largest error component
/// (error learning) or the reward (PoWER) of every roll-out, and the query.
pub fn write_task_chart(
    dir: &Path,
    task: &crate::task::Task,
    records: &[&Record<crate::teach::TaskTrial>],
) -> Result<(), Error> {
    let x = |r: &Record<crate::teach::TaskTrial>| f64::from(r.rollout);
    let power = task.learner.method.is_power();
    let error: Vec<(f64, f64)> = records
        .iter()
        .filter(|r| r.mean)
        .filter_map(|r| Some((x(r), r.trial.worst_error()?)))
        .collect();
    let reward: Vec<(f64, f64)> = records.iter().map(|r| (x(r), r.trial.reward)).collect();
    let queries: Vec<Vec<(f64, f64)>> = (0..task.query_dim())
        .map(|i| {
            records
                .iter()
                .filter(|r| r.mean)
                .filter_map(|r| Some((x(r), f64::from(*r.query.get(i)?))))
                .collect()
        })
        .collect();
    let labels: Vec<String> = (1..=queries.len()).map(|i| format!("q{i}")).collect();
    let q: Vec<Line> = queries
        .iter()
        .zip(&labels)
        .map(|(points, label)| Line {
            label,
            points,
            spread: None,
        })
        .collect();
    let e = [Line {
        label: "max |error|",
        points: &error,
        spread: None,
    }];
    let w = [Line {
        label: "reward",
        points: &reward,
        spread: None,
    }];
    let mut panels = vec![Panel {
        title: if power {
            "Largest error of the mean policy"
        } else {
            "Largest error"
        },
        x_label: "roll-out",
        y_label: "max |desired - measured|",
        series: &e,
        log_y: true,
        hline: (!power).then_some((task.goal.precision, "precision")),
    }];
    if power {
        panels.push(per_rollout("Reward of every roll-out", "reward", &w));
    }
    panels.push(per_rollout("Learned query", "q", &q));
    png(
        &dir.join("convergence.png"),
        &panels,
        300 * panels.len() as u32,
    )
}

/// Writes `rollouts.csv`, `summary.json` and `convergence.png` into `dir`.
pub fn write_pour(dir: &Path, records: &[Record], summary: &PourSummary) -> Result<(), Error> {
    let mut csv = String::from(ROLLOUT_HEADER);
    csv.push('\n');
    for r in records {
        csv += &rollout_row(r);
        csv.push('\n');
    }
    write_file(&dir.join("rollouts.csv"), csv.as_bytes())?;
    write_file(&dir.join("summary.json"), &json(summary)?)?;
    let precision_ml = summary.settings.precision * 1e3;
    let power = summary.settings.method.is_power();
    let shown: Vec<&Record> = records
        .iter()
        .filter(|r| r.mean && r.trial.rejected.is_none())
        .collect();
    let x = |r: &Record| f64::from(r.rollout);
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
    let reward: Vec<(f64, f64)> = records.iter().map(|r| (x(r), r.trial.reward)).collect();
    let one = |label, points| {
        [Line {
            label,
            points,
            spread: None,
        }]
    };
    let (e, s, q, w) = (
        one("|error|", &error),
        one("spilled", &spilled),
        one("query", &query),
        one("reward", &reward),
    );
    let mut panels = vec![Panel {
        title: if power {
            "Pouring error of the mean policy"
        } else {
            "Pouring error"
        },
        x_label: "roll-out",
        y_label: "|poured - target| [ml]",
        series: &e,
        log_y: true,
        hline: Some((precision_ml, "precision")),
    }];
    if power {
        panels.push(per_rollout(
            "Spilled by the mean policy",
            "spilled [ml]",
            &s,
        ));
        panels.push(per_rollout("Reward of every roll-out", "reward", &w));
    }
    panels.push(per_rollout("Learned query", "q [l]", &q));
    png(
        &dir.join("convergence.png"),
        &panels,
        300 * panels.len() as u32,
    )
}

/// `summary.json` of `primo experiment golden`.
#[derive(Debug, Serialize)]
struct GoldenSummary<'a> {
    precision: f64,
    runs: &'a [SearchRun],
    median_rollouts: [(Algorithm, Option<f64>); ERROR_LEARNERS.len()],
}

/// The median roll-outs to precision of `method` (runs that never reach it
/// count as their budget: a lower bound).
pub fn median_rollouts(runs: &[SearchRun], method: Algorithm) -> Option<f64> {
    let counts: Vec<f64> = runs
        .iter()
        .filter(|r| r.method == method)
        .map(|r| f64::from(r.rollouts_to_precision.unwrap_or(r.records.len() as u32)))
        .collect();
    (!counts.is_empty()).then(|| crate::stats::median(&counts))
}

/// Writes `golden.csv`, `golden.png` and `summary.json` into `dir`.
pub fn write_golden(dir: &Path, runs: &[SearchRun], precision: f64) -> Result<(), Error> {
    let mut csv = String::from("volume_l,method,rollout,query_l,poured_l,error_l\n");
    for run in runs {
        for r in &run.records {
            let _ = writeln!(
                csv,
                "{},{:?},{},{},{:.6},{:.6}",
                run.volume,
                run.method,
                r.rollout,
                r.volume(),
                r.trial.poured,
                r.trial.error
            );
        }
    }
    write_file(&dir.join("golden.csv"), csv.as_bytes())?;
    let summary = GoldenSummary {
        precision,
        runs,
        median_rollouts: ERROR_LEARNERS.map(|m| (m, median_rollouts(runs, m))),
    };
    write_file(&dir.join("summary.json"), &json(&summary)?)?;
    let points = |m: Algorithm, f: &dyn Fn(&Record) -> f64| -> Vec<(String, Vec<(f64, f64)>)> {
        runs.iter()
            .filter(|r| r.method == m)
            .map(|run| {
                (
                    format!("{} l", run.volume),
                    run.records
                        .iter()
                        .map(|r| (f64::from(r.rollout), f(r)))
                        .collect(),
                )
            })
            .collect()
    };
    let error = |r: &Record| r.trial.error.abs() * 1e3;
    let titles = ERROR_LEARNERS.map(|m| format!("{}: pouring error", m.name()));
    let sets: Vec<(&str, &str, _, bool)> = ERROR_LEARNERS
        .iter()
        .zip(&titles)
        .map(|(m, title)| (title.as_str(), "|error| [ml]", points(*m, &error), true))
        .collect();
    let series: Vec<Vec<Line>> = sets
        .iter()
        .map(|(_, _, s, _)| {
            s.iter()
                .map(|(label, p)| Line {
                    label,
                    points: p,
                    spread: None,
                })
                .collect()
        })
        .collect();
    let panels: Vec<Panel> = sets
        .iter()
        .zip(&series)
        .map(|((title, y, _, log), s)| Panel {
            title,
            x_label: "roll-out",
            y_label: y,
            series: s,
            log_y: *log,
            hline: log.then_some((precision * 1e3, "precision")),
        })
        .collect();
    png(&dir.join("golden.png"), &panels, 300 * panels.len() as u32)
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
    /// The query error-learned (gain 1), s1 = 0, s2 = 0.05.
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

/// A curve's points and its ± spread.
type Band = (Vec<(f64, f64)>, Vec<f64>);

/// Writes `power.csv`, `power_runs.csv` (one row per variant and seed),
/// `power.png` and `summary.json` into `dir`.
pub fn write_power(dir: &Path, s: &PowerSummary) -> Result<(), Error> {
    let mut runs = String::from("variant,seed");
    for level in THRESHOLDS {
        let _ = write!(runs, ",rollouts_to_{level},updates_to_{level}");
    }
    runs += ",regret,final_error_l,final_spilled_l,final_reward\n";
    for (name, c) in s.variants().map(|(v, c)| (v.name(), c)) {
        for r in &c.runs {
            let _ = write!(runs, "{name},{}", r.seed);
            for k in 0..THRESHOLDS.len() {
                let cell = |v: Option<u32>| v.map_or(String::new(), |v| v.to_string());
                let _ = write!(
                    runs,
                    ",{},{}",
                    cell(r.rollouts_to[k]),
                    cell(r.updates_to[k])
                );
            }
            let _ = writeln!(
                runs,
                ",{:.4},{:.6},{:.6},{:.6}",
                r.regret, r.error, r.spilled, r.reward
            );
        }
    }
    write_file(&dir.join("power_runs.csv"), runs.as_bytes())?;
    let mut csv = String::from(
        "update,variant,error_mean_l,error_std_l,spilled_mean_l,spilled_std_l,reward_mean,reward_std\n",
    );
    for (name, c) in s.variants().map(|(v, c)| (v.name(), c)) {
        for u in 0..c.error.mean.len() {
            let _ = writeln!(
                csv,
                "{u},{name},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6}",
                c.error.mean[u],
                c.error.std[u],
                c.spilled.mean[u],
                c.spilled.std[u],
                c.reward.mean[u],
                c.reward.std[u]
            );
        }
    }
    write_file(&dir.join("power.csv"), csv.as_bytes())?;
    write_file(&dir.join("summary.json"), &json(s)?)?;
    let curve = |c: &crate::experiment::Curve, scale: f64| -> Band {
        (
            c.mean
                .iter()
                .enumerate()
                .map(|(u, m)| (u as f64, m * scale))
                .collect(),
            c.std.iter().map(|v| v * scale).collect(),
        )
    };
    let pick = |f: &dyn Fn(&PowerCurves) -> Band| s.variants().map(|(_, c)| f(c));
    let error = pick(&|c| curve(&c.error, 1e3));
    let spilled = pick(&|c| curve(&c.spilled, 1e3));
    let reward = pick(&|c| curve(&c.reward, 1.0));
    fn lines(d: &[Band; 3]) -> [Line<'_>; 3] {
        std::array::from_fn(|i| Line {
            label: Variant::ALL[i].label(),
            points: &d[i].0,
            spread: Some(&d[i].1),
        })
    }
    let (e, sp, r) = (lines(&error), lines(&spilled), lines(&reward));
    let panels = [
        Panel {
            title: "Pouring error (mean ± std over runs)",
            x_label: "update",
            y_label: "|error| [ml]",
            series: &e,
            log_y: false,
            hline: None,
        },
        Panel {
            title: "Spilled volume",
            x_label: "update",
            y_label: "spilled [ml]",
            series: &sp,
            log_y: false,
            hline: None,
        },
        Panel {
            title: "Reward",
            x_label: "update",
            y_label: "reward",
            series: &r,
            log_y: false,
            hline: None,
        },
    ];
    png(&dir.join("power.png"), &panels, 1000)
}
