//! What a task file's run writes: its roll-out table (`rollouts.csv`),
//! its summary (`summary.json`) and its convergence chart
//! (`convergence.png`), each written atomically.

use std::path::{Path, PathBuf};

use primo_skill::Skill;
use primo_skill::csv::Csv;
use serde::Serialize;

use crate::Error;
use crate::algorithm::Algorithm;
use crate::clock::Seconds;
use crate::output::{write_file, write_json};
use crate::plot::panels::{per_rollout, reward_lines, rewards, write_convergence};
use crate::plot::{Line, Panel};
use crate::rollouts::{Ending, Entry, Record, Scored, Stop, Verdict};

use super::Task;
use super::goals::point;
use super::trial::TaskTrial;

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub struct Finished {
    /// The last roll-out (PoWER: the last roll-out of the mean).
    pub last: Record<TaskTrial>,
    /// Error learning reached the precision at this roll-out.
    pub converged_at: Option<u32>,
    /// Why the learner stopped.
    pub stop: Stop,
    /// The best roll-out.
    pub best: Option<Record<TaskTrial>>,
    /// The output directory.
    pub dir: PathBuf,
}

/// `summary.json`.
#[derive(Debug, Serialize)]
struct Summary<'a> {
    task: &'a Path,
    method: Algorithm,
    query_dim: usize,
    desired: &'a [f32],
    #[serde(skip_serializing_if = "<[String]>::is_empty")]
    goals: &'a [String],
    parameters: usize,
    rollouts: usize,
    converged_at: Option<u32>,
    #[serde(flatten)]
    verdict: Verdict,
    last: &'a Record<TaskTrial>,
    best: Option<&'a Record<TaskTrial>>,
    #[serde(flatten)]
    seconds: Seconds,
}

/// Writes `rollouts.csv`, `summary.json` and `convergence.png` of the
/// run of `task` on `skill` into `dir`; `seconds` of wall-clock time.
pub fn write_task(
    dir: &Path,
    task: &Task,
    skill: &Skill,
    run: &[Entry<TaskTrial>],
    seconds: Seconds,
) -> Result<Finished, Error> {
    let power = task.learner.method.is_power();
    let ending = Ending::of(run, power, task.goal.precision, point)?;
    let records: Vec<&Record<TaskTrial>> = run.iter().map(|e| &e.record).collect();
    let dim = task.query_dim();
    let goals = goal_columns(&records);
    write_file(
        &dir.join("rollouts.csv"),
        &rollouts_csv(&records, dim, &goals),
    )?;
    let best = ending.best.map(|e| &e.record);
    let summary = Summary {
        task: &task.file,
        method: task.learner.method,
        query_dim: dim,
        desired: &task.goal.desired,
        goals: &goals,
        parameters: task.learner.method.learned_parameters(skill),
        rollouts: records.len(),
        converged_at: ending.converged_at,
        verdict: ending.stop.verdict(),
        last: ending.last,
        best,
        seconds,
    };
    write_json(&dir.join("summary.json"), &summary)?;
    write_chart(dir, task, &records, &goals)?;
    Ok(Finished {
        last: ending.last.clone(),
        converged_at: ending.converged_at,
        stop: ending.stop.clone(),
        best: best.cloned(),
        dir: dir.to_path_buf(),
    })
}

/// The columns whose goals the run learned (secant-goals), as its
/// roll-outs name them; none for every other learner.
fn goal_columns(records: &[&Record<TaskTrial>]) -> Vec<String> {
    (records
        .first()
        .map(|r| &r.trial.goals)
        .into_iter()
        .flatten())
    .map(|(c, _)| c.clone())
    .collect()
}

/// `rollouts.csv` of a query of `dim` values: a column per value of the
/// query, of each learned goal (`goal_COLUMN`), of the measurement and of
/// the error (`query1`, `query2`, … when there are several), blank where a
/// roll-out has none.
fn rollouts_csv(records: &[&Record<TaskTrial>], dim: usize, goals: &[String]) -> Vec<u8> {
    let mut csv = Csv::new();
    // `name`, or `name1`, `name2`, … for a query of several values.
    let per_value = |csv: &mut Csv, name: &str| {
        for i in 1..=dim {
            match dim {
                1 => csv.text(name),
                _ => csv.display(format_args!("{name}{i}")),
            };
        }
    };
    csv.text("rollout").text("update").text("mean");
    per_value(&mut csv, "query");
    for c in goals {
        csv.display(format_args!("goal_{c}"));
    }
    per_value(&mut csv, "measured");
    per_value(&mut csv, "error");
    csv.text("reward").text("rejected").text("failed");
    csv.end_row();
    for r in records {
        let t = &r.trial;
        csv.display(r.rollout).display(r.update).display(r.mean);
        for q in &r.query {
            csv.display(q);
        }
        for (_, g) in &t.goals {
            csv.display(g);
        }
        let error = (!t.error.is_empty()).then_some(&t.error);
        for values in [t.measured.as_ref(), error] {
            for i in 0..dim {
                match values.and_then(|v| v.get(i)) {
                    Some(v) => csv.display(v),
                    None => csv.text(""),
                };
            }
        }
        csv.display(t.reward)
            .text(t.rejected.as_deref().unwrap_or(""))
            .text(t.failed.as_deref().unwrap_or(""));
        csv.end_row();
    }
    csv.into_bytes()
}

/// Writes `convergence.png`: the largest error component
/// (error learning; PoWER: of the mean policy) on a log axis, PoWER's
/// reward of every roll-out, and the query (secant-goals: the `goals`).
fn write_chart(
    dir: &Path,
    task: &Task,
    records: &[&Record<TaskTrial>],
    goals: &[String],
) -> Result<(), Error> {
    let x = |r: &Record<TaskTrial>| f64::from(r.rollout);
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
                .filter_map(|r| Some((x(r), f64::from(*point(r).values.get(i)?))))
                .collect()
        })
        .collect();
    let labels: Vec<String> = match goals.is_empty() {
        true => (1..=queries.len()).map(|i| format!("q{i}")).collect(),
        false => goals.iter().map(|c| format!("goal {c}")).collect(),
    };
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
    panels.push(match goals.is_empty() {
        true => per_rollout("Learned query", "q", &q),
        false => per_rollout("Learned goals", "goal", &q),
    });
    write_convergence(dir, &panels)
}
