//! The learning algorithms a run can use, and their one spelling: the key
//! (`golden`, `fixed-gain`, `power-el`) in every file, flag and message,
//! and a description for people ([`Algorithm::name`]).

use primo_core::golden::SearchConfig;
use primo_core::power::PAPER_SAMPLER;
use primo_core::secant::{Rule, SecantConfig};
use primo_protocol::learner::{LearnerSetup, MAX_QUERY};
use primo_skill::Skill;
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::learner::wire_query;

/// The learning algorithm.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Algorithm {
    /// The paper's error learning with golden-section search on the query
    /// (one value).
    Golden,
    /// Error learning that also uses the error's magnitude (Illinois
    /// regula falsi), with the same bracket guarantee (one value).
    Illinois,
    /// Error learning on a query of any dimension, `q ← q + K ε` with the
    /// gain `K` learned from the roll-outs (Broyden; paper eq. 10).
    Secant,
    /// Secant error learning on a change of the generalized movement's
    /// goals, one per error value, instead of the query: the movement is
    /// generalized at the desired query, and its goals move where no query
    /// of the demonstrations' takes the outcome.
    SecantGoals,
    /// The paper's eq. 10 with a fixed gain `K = gain · I`.
    FixedGain,
    /// The paper's eq. 11, `q ← q + e^{−εᵀε} K ε`, `K = gain · I` fixed.
    WeightedGain,
    /// PoWER over the extended parameter set `[q̂, Δθ]`.
    Power,
    /// PoWER over `[q̂, Δθ]` whose query is learned from the error by the
    /// paper's eq. 10 (`K = gain`) instead of explored: error learning
    /// (Sec. IV) and PoWER (Sec. V) in one learner.
    PowerEl,
}

/// The error learners, in the order experiments report them.
pub const ERROR_LEARNERS: [Algorithm; 5] = [
    Algorithm::Golden,
    Algorithm::Illinois,
    Algorithm::Secant,
    Algorithm::FixedGain,
    Algorithm::WeightedGain,
];

impl Algorithm {
    /// Every learner.
    pub const ALL: [Algorithm; 8] = [
        Algorithm::Golden,
        Algorithm::Illinois,
        Algorithm::Secant,
        Algorithm::SecantGoals,
        Algorithm::FixedGain,
        Algorithm::WeightedGain,
        Algorithm::Power,
        Algorithm::PowerEl,
    ];

    /// Its one spelling, in files (as serde writes it), task files,
    /// flags and messages: `golden`, `fixed-gain`, `power-el`.
    pub fn key(self) -> &'static str {
        match self {
            Algorithm::Golden => "golden",
            Algorithm::Illinois => "illinois",
            Algorithm::Secant => "secant",
            Algorithm::SecantGoals => "secant-goals",
            Algorithm::FixedGain => "fixed-gain",
            Algorithm::WeightedGain => "weighted-gain",
            Algorithm::Power => "power",
            Algorithm::PowerEl => "power-el",
        }
    }

    /// What it is, for people.
    pub fn name(self) -> &'static str {
        match self {
            Algorithm::Golden => "golden-section error learning",
            Algorithm::Illinois => "Illinois error learning",
            Algorithm::Secant => "secant error learning",
            Algorithm::SecantGoals => "secant error learning on the goals",
            Algorithm::FixedGain => "fixed-gain error learning (eq. 10)",
            Algorithm::WeightedGain => "weighted fixed-gain error learning (eq. 11)",
            Algorithm::Power => "extended PoWER",
            Algorithm::PowerEl => "PoWER with error-learned query",
        }
    }

    /// PoWER (learns `Δθ` from rewards), not only the query.
    pub fn is_power(self) -> bool {
        matches!(self, Algorithm::Power | Algorithm::PowerEl)
    }

    /// Learns from the error (every learner but plain PoWER).
    pub fn uses_error(self) -> bool {
        self != Algorithm::Power
    }

    /// Learns the movement's goals, not its query.
    pub fn learns_goals(self) -> bool {
        self == Algorithm::SecantGoals
    }

    /// PoWER's default query exploration scale s1: the paper's 0.2, and 0
    /// when the error moves the query instead.
    pub fn default_s1(self) -> f32 {
        match self {
            Algorithm::PowerEl => 0.0,
            _ => 0.2,
        }
    }

    /// PoWER's default importance sampler length: the paper's 3, and 2
    /// when the error moves the query. The sampler averages the corrected
    /// queries of the best roll-outs, each corrected by its own error,
    /// partly caused by its own `Δθ`; the fewer, the less a new mean's query
    /// lags behind the error (on the pouring cell over 16 bottles,
    /// targets, glasses and spaces, bench/results/2026-12-06-power-el-sampler.md).
    pub fn default_sampler(self) -> usize {
        match self {
            Algorithm::PowerEl => 2,
            _ => PAPER_SAMPLER,
        }
    }

    /// PoWER's error-learning gain on the query for `gain` (0: plain PoWER).
    pub fn query_gain(self, gain: f32) -> f32 {
        match self {
            Algorithm::PowerEl => gain,
            _ => 0.0,
        }
    }

    /// Parameters it learns on `skill`: `[q̂, Δθ]` for PoWER, the query
    /// otherwise (or as many goals).
    pub fn learned_parameters(self, skill: &Skill) -> usize {
        match self {
            Algorithm::Power | Algorithm::PowerEl => skill.param_len() + skill.query_dim(),
            _ => skill.query_dim(),
        }
    }

    /// Its search core's setup, for the error learners on the query over
    /// the bounds `low`, `high` from `desired` (one value each for golden
    /// section and Illinois); `None` for PoWER. Secant-goals is set up by
    /// [`goals_setup`], on a skill's goals.
    pub fn search(
        self,
        (low, high, desired): (&[f32], &[f32], &[f32]),
        precision: f32,
        max_rollouts: u32,
        gain: f32,
    ) -> Result<Option<LearnerSetup>, Error> {
        let scalar = || SearchConfig {
            low: low.first().copied().unwrap_or(f32::NAN),
            high: high.first().copied().unwrap_or(f32::NAN),
            desired: desired.first().copied().unwrap_or(f32::NAN),
            precision,
            max_rollouts,
        };
        let secant = |rule| -> Result<LearnerSetup, Error> {
            let bounds = (low, high, desired);
            Ok(LearnerSetup::Secant(secant_config(
                bounds,
                precision,
                max_rollouts,
                gain,
                rule,
            )?))
        };
        Ok(Some(match self {
            Algorithm::Golden => LearnerSetup::Golden(scalar()),
            Algorithm::Illinois => LearnerSetup::Illinois(scalar()),
            Algorithm::Secant => secant(Rule::Broyden)?,
            Algorithm::FixedGain => secant(Rule::Fixed)?,
            Algorithm::WeightedGain => secant(Rule::Weighted)?,
            Algorithm::SecantGoals => {
                return Err(Error::Invalid(
                    "secant-goals learns the goals of a task file's demonstrations; it searches \
                     no query"
                        .into(),
                ));
            }
            Algorithm::Power | Algorithm::PowerEl => return Ok(None),
        }))
    }
}

/// The secant learner's settings over `(low, high, desired)`.
fn secant_config(
    (low, high, desired): (&[f32], &[f32], &[f32]),
    precision: f32,
    max_rollouts: u32,
    gain: f32,
    rule: Rule,
) -> Result<SecantConfig<MAX_QUERY>, Error> {
    Ok(SecantConfig {
        low: wire_query(low)?,
        high: wire_query(high)?,
        desired: wire_query(desired)?,
        precision,
        max_rollouts,
        gain,
        rule,
    })
}

/// Secant-goals' setup: the movement generalized at `query`, the learner's
/// values the changes of the goals from `first_goal` in `θ` on, from 0
/// within `(low, high)` (one per error value).
pub fn goals_setup(
    (low, high): (&[f32], &[f32]),
    (precision, max_rollouts, gain): (f32, u32, f32),
    query: &[f32],
    first_goal: usize,
) -> Result<LearnerSetup, Error> {
    let start = vec![0.0; low.len()];
    let bounds = (low, high, &start[..]);
    Ok(LearnerSetup::SecantGoals {
        config: secant_config(bounds, precision, max_rollouts, gain, Rule::Broyden)?,
        query: wire_query(query)?,
        first_goal: u16::try_from(first_goal)
            .map_err(|_| Error::Invalid(format!("goal {first_goal} of θ: θ too long")))?,
    })
}

impl std::fmt::Display for Algorithm {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.key())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn files_and_messages_spell_each_learner_alike() {
        for m in Algorithm::ALL {
            let json = serde_json::to_string(&m).unwrap();
            assert_eq!(json, format!("\"{m}\""));
            assert_eq!(serde_json::from_str::<Algorithm>(&json).unwrap(), m);
        }
    }
}
