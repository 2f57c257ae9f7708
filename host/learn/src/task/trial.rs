//! What a task's roll-out gave, scored: the evaluator's answer against the
//! task's desired query.

use serde::{Deserialize, Serialize};

use crate::Error;
use crate::rollouts::Scored;

use super::evaluator::Answer;
use super::{RewardRule, Task};

/// What a task's roll-out gave.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TaskTrial {
    /// The query achieved, as the evaluator measured it.
    pub measured: Option<Vec<f64>>,
    /// `desired − measured` (empty without a measurement).
    pub error: Vec<f64>,
    /// The reward.
    pub reward: f64,
    /// Why the limits rejected the movement, if they did.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rejected: Option<String>,
    /// Why the evaluator said the roll-out failed, if it did.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub failed: Option<String>,
}

impl Scored for TaskTrial {
    fn error(&self) -> Vec<f32> {
        self.error.iter().map(|e| *e as f32).collect()
    }

    fn reward(&self) -> f64 {
        self.reward
    }

    fn infeasible(&self) -> Option<&str> {
        self.rejected.as_deref().or(self.failed.as_deref())
    }

    fn worst_error(&self) -> Option<f64> {
        self.error.iter().map(|e| e.abs()).reduce(f64::max)
    }
}

/// The reward of an error under the task's rule.
pub fn reward(rule: RewardRule, scale: f32, error: &[f64]) -> f64 {
    let norm = error.iter().map(|e| e * e).sum::<f64>().sqrt() * f64::from(scale);
    match rule {
        RewardRule::Linear => (1.0 - norm).max(0.0),
        RewardRule::Exp => (-norm * norm).exp(),
    }
}

/// Scores an evaluator's answer for `task`. A failed roll-out scores 0
/// (error learning takes its query as a bound of the search).
pub(crate) fn score(task: &Task, rollout: u32, answer: Answer) -> Result<TaskTrial, Error> {
    if let Some(why) = answer.failed {
        return Ok(TaskTrial {
            measured: None,
            error: Vec::new(),
            reward: 0.0,
            rejected: None,
            failed: Some(why),
        });
    }
    let error: Vec<f64> = match &answer.measured {
        Some(m) => task
            .goal
            .desired
            .iter()
            .zip(m)
            .map(|(d, m)| f64::from(*d) - m)
            .collect(),
        None if !task.learner.method.uses_error() => Vec::new(),
        None => {
            return Err(Error::Instrument(format!(
                "roll-out {rollout}: the evaluator gave no `measured` query; {} needs it",
                task.learner.method
            )));
        }
    };
    let reward = match answer.reward {
        Some(r) => r,
        None => reward(task.learner.reward, task.learner.reward_scale, &error),
    };
    Ok(TaskTrial {
        measured: answer.measured,
        error,
        reward,
        rejected: None,
        failed: None,
    })
}
