//! Secant error learning on a task's goals (`method = "secant-goals"`):
//! the movement is generalized at the desired query, and the learner's
//! values change the goals of some of its position columns, one per value
//! of the error. Which columns and within what the task file says
//! ([`GoalSearch`]); they are found on the fitted skill here, before
//! anything runs.

use primo_protocol::learner::LearnerSetup;
use primo_robot::envelope::Limits;
use primo_skill::Skill;

use crate::Error;
use crate::algorithm::goals_setup;
use crate::rollouts::{Point, Record};

use super::trial::TaskTrial;
use super::{GoalSearch, Task};

/// The goals a secant-goals run changes, on the fitted skill.
#[derive(Debug, Clone, PartialEq)]
pub struct LearnedGoals {
    /// Their columns: value `i` changes column `i`'s goal.
    pub columns: Vec<String>,
    /// The first one's index in `θ`.
    pub first: usize,
    /// The goals of the movement generalized at the desired query (a
    /// change of 0).
    pub generalized: Vec<f32>,
    /// The changes' bounds: the goals' from `generalized`.
    pub low: Vec<f32>,
    /// See `low`.
    pub high: Vec<f32>,
}

impl LearnedGoals {
    /// The goals `task` learns on `skill` (the goals' default bounds
    /// `limits`' of their columns), if its learner is secant-goals.
    pub fn of_task(task: &Task, skill: &Skill, limits: &Limits) -> Result<Option<Self>, Error> {
        let Some(search) = &task.goals else {
            return Ok(None);
        };
        let refuse = |key: &str, why: String| {
            Error::Invalid(format!("{}: {key}: {why}", task.file.display()))
        };
        let dim = task.query_dim();
        let columns = columns(search, skill, dim).map_err(|why| refuse("[learner] goals", why))?;
        let first = skill.dof() * skill.kernels()
            + columns
                .first()
                .and_then(|c| skill.position_dof(c))
                .unwrap_or(0);
        let theta = skill.generalize(&task.goal.desired)?;
        let generalized = theta.get(first..first + dim).unwrap_or(&[]).to_vec();
        let bound = |given: &[f32], key: &str, of: fn((f64, f64)) -> f64| {
            columns
                .iter()
                .enumerate()
                .map(|(i, c)| match given.get(i) {
                    Some(v) => Ok(*v),
                    None => range(limits, c)
                        .map(|r| of(r) as f32)
                        .filter(|v| v.is_finite())
                        .ok_or_else(|| {
                            let why = format!(
                                "`{c}` has no limits of its own to bound its goal: give \
                                 goals_min and goals_max"
                            );
                            refuse(&format!("[learner] {key}"), why)
                        }),
                })
                .collect::<Result<Vec<f32>, Error>>()
        };
        let min = bound(&search.min, "goals_min", |r| r.0)?;
        let max = bound(&search.max, "goals_max", |r| r.1)?;
        for (((c, g), lo), hi) in columns.iter().zip(&generalized).zip(&min).zip(&max) {
            if !(lo < g && g < hi) {
                return Err(refuse(
                    "[learner] goals_min, goals_max",
                    format!(
                        "the movement generalized to the desired query ends `{c}` at {g}, \
                         outside ({lo}, {hi}), where its goal may go: widen them or change \
                         [goal] desired"
                    ),
                ));
            }
        }
        let from = |b: &[f32]| b.iter().zip(&generalized).map(|(b, g)| b - g).collect();
        Ok(Some(LearnedGoals {
            low: from(&min),
            high: from(&max),
            columns,
            first,
            generalized,
        }))
    }

    /// The learner's setup for `task`.
    pub fn setup(&self, task: &Task) -> Result<LearnerSetup, Error> {
        let l = &task.learner;
        let settings = (task.goal.precision as f32, l.max_rollouts, l.gain);
        let bounds = (&self.low[..], &self.high[..]);
        goals_setup(bounds, settings, &task.goal.desired, self.first)
    }

    /// The goals `θ = G(q̂) + Δθ` ends at, by column.
    pub fn rolled_out(&self, delta: &[f32]) -> Vec<(String, f32)> {
        let change = delta.get(self.first..).unwrap_or(&[]);
        (self.columns.iter().cloned())
            .zip(self.generalized.iter().zip(change).map(|(g, d)| g + d))
            .collect()
    }

    /// The goals of [`LearnedGoals::rolled_out`] as a [`Point`].
    pub fn point(&self, delta: &[f32]) -> Point {
        let (goals, values) = self.rolled_out(delta).into_iter().unzip();
        Point { values, goals }
    }
}

/// The columns `search` names (default: the first `dim`), each a position
/// column, consecutive in the skill's order: the learner changes one run of
/// goals.
fn columns(search: &GoalSearch, skill: &Skill, dim: usize) -> Result<Vec<String>, String> {
    let names = skill.names();
    let columns = match search.columns.is_empty() {
        true => names.iter().take(dim).cloned().collect(),
        false => search.columns.clone(),
    };
    if columns.len() != dim {
        return Err(format!(
            "the demonstrations have {} column(s), the error {dim} value(s): one goal is \
             learned per value",
            names.len()
        ));
    }
    let mut dofs = Vec::new();
    for c in &columns {
        let dof = skill.position_dof(c).ok_or_else(|| {
            format!(
                "`{c}` is no position column of the demonstrations ({}): name the columns \
                 whose goals are learned",
                names.join(", ")
            )
        })?;
        dofs.push(dof);
    }
    if dofs.windows(2).any(|w| w[1] != w[0] + 1) {
        return Err(format!(
            "{}: the learner changes consecutive columns' goals, in the demonstrations' order \
             ({})",
            columns.join(", "),
            names.join(", ")
        ));
    }
    Ok(columns)
}

/// The range of `column` in `limits`: a joint's, or the column's own.
fn range(limits: &Limits, column: &str) -> Option<(f64, f64)> {
    match limits {
        Limits::Robot(r) => {
            let joint = r.chain.joint(column)?;
            Some((joint.limits.lower, joint.limits.upper))
        }
        Limits::Envelope(e) => (e.columns.iter())
            .find(|c| c.name == column)
            .map(|c| (c.min, c.max)),
    }
}

/// Where a roll-out's learner was: the goals it rolled out, if it learns
/// them, else its query.
pub fn point(record: &Record<TaskTrial>) -> Point {
    match record.trial.goals.is_empty() {
        true => Point::query(&record.query),
        false => Point {
            values: record.trial.goals.iter().map(|(_, v)| *v).collect(),
            goals: record.trial.goals.iter().map(|(c, _)| c.clone()).collect(),
        },
    }
}
