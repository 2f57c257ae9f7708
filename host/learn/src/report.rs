//! What the learning commands write: roll-out tables (CSV), summaries
//! (JSON) and convergence charts (PNG), each written atomically.

use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use crate::Error;
use crate::experiment::{
    Curve, PER_UPDATE, PowerComparison, PowerCurves, SPREAD, SearchRun, THRESHOLDS, Variant,
    power_budget,
};
use crate::learning::{Algorithm, ERROR_LEARNERS, Record, Settings};
use crate::output::write_file;
use crate::plot::{Line, Panel, grid, render_png};

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

/// Errors below this are drawn at it on log axes, ml: a microlitre, far
/// below any scale's resolution (a simulated pour can hit the target to
/// 1e-13 ml, which says nothing).
const ERROR_FLOOR_ML: f64 = 1e-3;
/// Spills below this (none at all included) are drawn at it, ml.
const SPILL_FLOOR_ML: f64 = 1e-2;

/// Height of a row of panels, px.
const PANEL_HEIGHT: u32 = 350;

/// A linear panel over the roll-outs.
fn per_rollout<'a>(title: &'a str, y_label: &'a str, series: &'a [Line<'a>]) -> Panel<'a> {
    Panel {
        title,
        x_label: "roll-out",
        y_label,
        series,
        ..Panel::default()
    }
}

/// The reward of every roll-out from (roll-out, of the mean policy,
/// reward): the mean policy's, and the explorations' around it.
fn rewards(rows: impl Iterator<Item = (u32, bool, f64)>) -> [Vec<(f64, f64)>; 2] {
    let mut split = [Vec::new(), Vec::new()];
    for (rollout, mean, reward) in rows {
        split[usize::from(!mean)].push((f64::from(rollout), reward));
    }
    split
}

/// The reward panel's series: the mean policy's line, the explorations'
/// markers.
fn reward_lines(split: &[Vec<(f64, f64)>; 2]) -> [Line<'_>; 2] {
    [
        Line::new("mean policy", &split[0]),
        Line {
            scatter: true,
            ..Line::new("exploration", &split[1])
        },
    ]
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
/// (error learning; PoWER: of the mean policy) on a log axis, PoWER's
/// reward of every roll-out, and the query.
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
    let reward = rewards(records.iter().map(|r| (r.rollout, r.mean, r.trial.reward)));
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
        .map(|(points, label)| Line::new(label, points))
        .collect();
    let e = [Line::new("max |error|", &error)];
    let w = reward_lines(&reward);
    let precision = task.goal.precision;
    let mut panels = vec![Panel {
        title: if power {
            "Largest error of the mean policy"
        } else {
            "Largest error"
        },
        x_label: "roll-out",
        y_label: "max |error|",
        series: &e,
        log_y: true,
        // Far below the precision an error is as good as none (PoWER's
        // precision may be 0: no floor).
        floor: Some(precision * 1e-3),
        hline: (!power).then_some((precision, "precision")),
    }];
    if power {
        panels.push(per_rollout("Reward of every roll-out", "reward", &w));
    }
    panels.push(per_rollout("Learned query", "q", &q));
    png(
        &dir.join("convergence.png"),
        &panels,
        PANEL_HEIGHT * grid(panels.len()).0 as u32,
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
    png(
        &dir.join("convergence.png"),
        &panels,
        PANEL_HEIGHT * grid(panels.len()).0 as u32,
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
    // Per learner: its runs' errors, one line a volume.
    let learners: Vec<(String, Vec<Labelled>)> = ERROR_LEARNERS
        .iter()
        .map(|m| {
            let mine: Vec<&SearchRun> = runs.iter().filter(|r| r.method == *m).collect();
            let curves = mine
                .iter()
                .map(|run| {
                    let error = |r: &Record| (f64::from(r.rollout), r.trial.error.abs() * 1e3);
                    (
                        format!("{} l", run.volume),
                        run.records.iter().map(error).collect(),
                    )
                })
                .collect();
            (format!("{} (n = {} volumes)", key(*m), mine.len()), curves)
        })
        .collect();
    let series: Vec<Vec<Line>> = learners
        .iter()
        .map(|(_, curves)| {
            curves
                .iter()
                .map(|(label, p)| Line::new(label, p))
                .collect()
        })
        .collect();
    let mut panels: Vec<Panel> = learners
        .iter()
        .zip(&series)
        .map(|((title, _), s)| Panel {
            title,
            x_label: "roll-out",
            y_label: "|error| [ml]",
            series: s,
            log_y: true,
            floor: Some(ERROR_FLOOR_ML),
            hline: Some((precision * 1e3, "precision")),
        })
        .collect();
    // The learners side by side: roll-outs to the precision per volume.
    let keys = ERROR_LEARNERS.map(key);
    let reached: Vec<Vec<(f64, f64)>> = ERROR_LEARNERS
        .iter()
        .map(|m| {
            runs.iter()
                .filter(|r| r.method == *m)
                .map(|r| {
                    let n = r.rollouts_to_precision.map_or(f64::NAN, f64::from);
                    (r.volume, n)
                })
                .collect()
        })
        .collect();
    let compared: Vec<Line> = keys
        .iter()
        .zip(&reached)
        .map(|(k, p)| Line::new(k, p))
        .collect();
    let title = format!("Roll-outs to |error| < {} ml", precision * 1e3);
    panels.push(Panel {
        title: &title,
        x_label: "liquid in the bottle [l]",
        y_label: "roll-outs (not reached: no point)",
        series: &compared,
        ..Panel::default()
    });
    png(&dir.join("golden.png"), &panels, 1100)
}

/// A labelled curve.
type Labelled = (String, Vec<(f64, f64)>);

/// The learner's name on the command line and in files (`fixed-gain`).
fn key(m: Algorithm) -> String {
    match serde_json::to_value(m) {
        Ok(serde_json::Value::String(s)) => s,
        _ => format!("{m:?}"),
    }
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

/// A curve's points and its band, `(low, high)` per point.
type Band = (Vec<(f64, f64)>, Vec<(f64, f64)>);

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
        "update,variant,error_mean_l,error_std_l,spilled_mean_l,spilled_std_l,reward_mean,reward_std,\
         error_p05_l,error_p95_l,spilled_p05_l,spilled_p95_l,reward_p05,reward_p95\n",
    );
    for (name, c) in s.variants().map(|(v, c)| (v.name(), c)) {
        for u in 0..c.error.mean.len() {
            let _ = write!(csv, "{u},{name}");
            for q in [&c.error, &c.spilled, &c.reward] {
                let _ = write!(csv, ",{:.6},{:.6}", q.mean[u], q.std[u]);
            }
            for q in [&c.error, &c.spilled, &c.reward] {
                let _ = write!(csv, ",{:.6},{:.6}", q.low[u], q.high[u]);
            }
            csv.push('\n');
        }
    }
    write_file(&dir.join("power.csv"), csv.as_bytes())?;
    write_file(&dir.join("summary.json"), &json(s)?)?;
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
    png(&dir.join("power.png"), &panels, 1000)
}
