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
    /// The goals its movement ended at by column, when the learner learns
    /// them (secant-goals; the query is the desired one throughout).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub goals: Vec<(String, f32)>,
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
            goals: Vec::new(),
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
    // Each is finite in f32, as the learners take them, yet two of opposite
    // sign near f32's largest differ by more than it holds.
    if let Some(((d, m), _)) = task
        .goal
        .desired
        .iter()
        .zip(answer.measured.iter().flatten())
        .zip(&error)
        .find(|(_, e)| !(**e as f32).is_finite())
    {
        return Err(Error::Instrument(format!(
            "roll-out {rollout}: the evaluator measured {m}, so far from the desired {d} that \
             the error is beyond what the learners compute with (about ±3.4e38)"
        )));
    }
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
        goals: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A task desiring `desired`, its demonstrations' files in a scratch
    /// directory (scoring reads none of them).
    fn task(desired: f32) -> Task {
        let dir = std::env::temp_dir().join(format!("primo-task-trial-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for name in ["a", "b"] {
            std::fs::write(dir.join(format!("{name}.csv")), "t,x\n0,0\n").unwrap();
        }
        let (low, high) = (desired * 0.5, desired * 1.1);
        let text = format!(
            "version = 1\n[[demo]]\nfile = \"a.csv\"\nquery = [{low:e}]\n[[demo]]\n\
             file = \"b.csv\"\nquery = [{high:e}]\n[goal]\ndesired = [{desired:e}]\n\
             low = [{low:e}]\nhigh = [{high:e}]\nprecision = 0.01\n\
             [movement.limits]\nx = {{ min = -1.0, max = 1.0, max_speed = 1.0 }}\n[learner]\n\
             method = \"golden\"\n[evaluate]\ncommand = [\"true\"]\n"
        );
        Task::parse(&dir.join("task.toml"), &text).unwrap()
    }

    fn measured(m: f64) -> Answer {
        Answer {
            measured: Some(vec![m]),
            ..Answer::default()
        }
    }

    /// A roll-out of any learner but secant-goals is logged as before the
    /// goals existed, and such a logged roll-out reads back.
    #[test]
    fn a_trial_without_goals_is_logged_as_before() {
        let logged = r#"{"measured":[1.0],"error":[0.5],"reward":0.5}"#;
        let trial: TaskTrial = serde_json::from_str(logged).unwrap();
        assert!(trial.goals.is_empty());
        assert_eq!(serde_json::to_string(&trial).unwrap(), logged);
        let goals = TaskTrial {
            goals: vec![("shoulder".into(), -0.5)],
            ..trial
        };
        let text = serde_json::to_string(&goals).unwrap();
        assert!(text.ends_with(r#","goals":[["shoulder",-0.5]]}"#), "{text}");
    }

    #[test]
    fn an_error_beyond_f32_is_refused_naming_both_values() {
        let t = task(3.0e38);
        let e = score(&t, 4, measured(-3.0e38)).unwrap_err().to_string();
        assert!(
            e.contains("roll-out 4: the evaluator measured -300000000"),
            "{e}"
        );
        assert!(e.contains("beyond what the learners compute with"), "{e}");
        // Large but representable errors are scored.
        let trial = score(&t, 4, measured(1.0e38)).unwrap();
        assert_eq!(trial.error(), vec![2.0e38_f32]);
        let near = score(&task(1.0), 1, measured(-3.0e38)).unwrap();
        assert!(near.error()[0].is_finite());
    }
}
