//! What a resumed task run may take from its task file as it is now: the
//! `[goal]` bounds (secant-goals': `[learner] goals_min` and `goals_max`),
//! the roll-out budget and the evaluator (where and how
//! roll-outs are executed is the lab's, not the learned state). Anything
//! else changed would make the logged roll-outs another run's, and is
//! refused, named by its key. (Whether changed bounds keep the logged
//! roll-outs is for the learner to say: [`crate::rollouts::check_replay`].)

use crate::Error;

use super::{Evaluate, Task};

/// A resumed task run's changes: the task file as it is now, and a budget
/// given on the command line.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Changes {
    /// The task file, read again.
    pub task: Option<Task>,
    /// A new roll-out budget.
    pub max_rollouts: Option<u32>,
}

impl Task {
    /// Takes `changes` into this (logged) task; returns what changed, in
    /// the task file's terms, or refuses a change it may not take.
    pub fn take(&mut self, changes: Changes) -> Result<Vec<String>, Error> {
        let mut said = Vec::new();
        if let Some(now) = changes.task {
            self.check_kept(&now)?;
            let mut differ = |key: &str, was: String, is: String| {
                if was != is {
                    said.push(format!("{key} {was} -> {is}"));
                }
            };
            differ("[goal] low", list(&self.goal.low), list(&now.goal.low));
            differ("[goal] high", list(&self.goal.high), list(&now.goal.high));
            let bounds = |t: &Task, max: bool| {
                let g = t.goals.as_ref();
                list(g.map_or(&[][..], |g| if max { &g.max } else { &g.min }))
            };
            differ(
                "[learner] goals_min",
                bounds(self, false),
                bounds(&now, false),
            );
            differ(
                "[learner] goals_max",
                bounds(self, true),
                bounds(&now, true),
            );
            differ(
                "[learner] max_rollouts",
                self.learner.max_rollouts.to_string(),
                now.learner.max_rollouts.to_string(),
            );
            differ(
                "[evaluate]",
                evaluator(&self.evaluate),
                evaluator(&now.evaluate),
            );
            self.goal.low = now.goal.low;
            self.goal.high = now.goal.high;
            self.goals = now.goals;
            self.learner.max_rollouts = now.learner.max_rollouts;
            self.evaluate = now.evaluate;
            self.file = now.file;
        }
        if let Some(n) = changes.max_rollouts {
            said.extend(crate::run::budget_change(&mut self.learner.max_rollouts, n));
        }
        Ok(said)
    }

    /// Refuses `now` if it differs from this task in anything but what a
    /// resumed run may take.
    fn check_kept(&self, now: &Task) -> Result<(), Error> {
        let (a, b) = (self, now);
        let (la, lb) = (&a.learner, &b.learner);
        let kept = [
            ("[[demo]]", a.demos == b.demos),
            ("[movement] kernels", a.kernels == b.kernels),
            ("[movement] scaling", a.scaling == b.scaling),
            (
                "[movement] final_velocity",
                a.final_velocity == b.final_velocity,
            ),
            ("[movement] generalization", a.regression == b.regression),
            ("[movement] obstacles", a.obstacles == b.obstacles),
            (
                "[movement] limit_margin and limit_gain",
                a.limit_push == b.limit_push,
            ),
            ("[movement] via", a.vias == b.vias),
            ("[movement] dt", a.dt == b.dt),
            ("[movement] robot and limits", a.limits == b.limits),
            ("[goal] desired", a.goal.desired == b.goal.desired),
            ("[goal] precision", a.goal.precision == b.goal.precision),
            ("[learner] method", la.method == lb.method),
            (
                "[learner] goals",
                a.goals.as_ref().map(|g| &g.columns) == b.goals.as_ref().map(|g| &g.columns),
            ),
            ("[learner] gain", la.gain == lb.gain),
            ("[learner] s1", la.s1 == lb.s1),
            ("[learner] s2", la.s2 == lb.s2),
            ("[learner] sampler", la.sampler == lb.sampler),
            (
                "[learner] rollouts_per_update",
                la.rollouts_per_update == lb.rollouts_per_update,
            ),
            ("[learner] decay", la.decay == lb.decay),
            ("[learner] reward", la.reward == lb.reward),
            ("[learner] reward_scale", la.reward_scale == lb.reward_scale),
            (
                "[evaluate] builtin",
                matches!(a.evaluate, Evaluate::Pour(_)) == matches!(b.evaluate, Evaluate::Pour(_)),
            ),
        ];
        match kept.iter().find(|(_, same)| !same) {
            None => Ok(()),
            Some((key, _)) => Err(Error::Invalid(format!(
                "{}: {key} differs from the logged run's: a resumed run takes only changed \
                 [goal] low/high, [learner] goals_min/goals_max and max_rollouts, and \
                 [evaluate]; start a new run for the rest",
                now.file.display()
            ))),
        }
    }
}

/// A query's values as a task file writes them.
fn list(values: &[f32]) -> String {
    format!(
        "[{}]",
        values
            .iter()
            .map(f32::to_string)
            .collect::<Vec<_>>()
            .join(", ")
    )
}

/// An evaluator, as a change names it.
fn evaluator(e: &Evaluate) -> String {
    match e {
        Evaluate::Command { argv, timeout, .. } => {
            format!("command `{}` (timeout {timeout} s)", argv.join(" "))
        }
        Evaluate::Operator => "the operator".into(),
        Evaluate::Pour(_) => "the built-in pour".into(),
    }
}
