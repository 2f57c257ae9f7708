//! The task file as written: its tables and keys, each unknown key
//! refused. Values that later checks may refuse keep their place in the
//! file (`Spanned`), so a message can name the line.

use std::collections::BTreeMap;

use serde::Deserialize;
use toml::Spanned;

use crate::algorithm::Algorithm;

use super::spec::{ColumnRange, RewardRule, Workspace};

/// A task file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct File {
    pub(super) version: Spanned<u32>,
    #[serde(default)]
    pub(super) demo: Vec<DemoKeys>,
    #[serde(default)]
    pub(super) movement: Option<Spanned<MovementKeys>>,
    pub(super) goal: Spanned<GoalKeys>,
    pub(super) learner: Spanned<LearnerKeys>,
    pub(super) evaluate: Spanned<EvaluateKeys>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct DemoKeys {
    pub(super) file: Spanned<String>,
    pub(super) query: Spanned<Vec<f64>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct MovementKeys {
    pub(super) kernels: Option<Spanned<usize>>,
    pub(super) scaling: Option<Spanned<String>>,
    pub(super) final_velocity: Option<Spanned<String>>,
    pub(super) generalization: Option<Spanned<String>>,
    pub(super) dt: Option<Spanned<f64>>,
    pub(super) robot: Option<Spanned<String>>,
    pub(super) base: Option<Spanned<String>>,
    pub(super) tip: Option<Spanned<String>>,
    pub(super) tool: Option<Spanned<ToolKeys>>,
    pub(super) max_acceleration: Option<Spanned<f64>>,
    pub(super) start: Option<Spanned<BTreeMap<String, f64>>>,
    pub(super) limits: Option<Spanned<BTreeMap<String, ColumnRange>>>,
    pub(super) workspace: Option<Spanned<Workspace>>,
    pub(super) obstacles: Option<Spanned<Vec<[f64; 4]>>>,
    pub(super) obstacle_columns: Option<Spanned<Vec<String>>>,
    pub(super) limit_margin: Option<Spanned<f64>>,
    pub(super) limit_gain: Option<Spanned<f64>>,
    pub(super) via: Option<Spanned<Vec<(f64, String, f64)>>>,
    pub(super) phase_stop: Option<Spanned<f64>>,
}

/// A tool frame, as a URDF's `<origin>`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ToolKeys {
    pub(super) xyz: [f64; 3],
    #[serde(default)]
    pub(super) rpy: [f64; 3],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct GoalKeys {
    pub(super) desired: Spanned<Vec<f64>>,
    pub(super) low: Option<Spanned<Vec<f64>>>,
    pub(super) high: Option<Spanned<Vec<f64>>>,
    pub(super) precision: Option<Spanned<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LearnerKeys {
    pub(super) method: Spanned<Algorithm>,
    pub(super) max_rollouts: Option<Spanned<u32>>,
    pub(super) gain: Option<Spanned<f64>>,
    pub(super) s1: Option<Spanned<f64>>,
    pub(super) s2: Option<Spanned<f64>>,
    pub(super) sampler: Option<Spanned<usize>>,
    pub(super) rollouts_per_update: Option<Spanned<u16>>,
    pub(super) decay: Option<Spanned<f64>>,
    pub(super) reward: Option<Spanned<RewardRule>>,
    pub(super) reward_scale: Option<Spanned<f64>>,
    pub(super) goals: Option<Spanned<Vec<String>>>,
    pub(super) goals_min: Option<Spanned<Vec<f64>>>,
    pub(super) goals_max: Option<Spanned<Vec<f64>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct EvaluateKeys {
    pub(super) command: Option<Spanned<Vec<String>>>,
    pub(super) timeout: Option<Spanned<f64>>,
    pub(super) operator: Option<Spanned<bool>>,
    pub(super) builtin: Option<Spanned<String>>,
    pub(super) target: Option<Spanned<f64>>,
    pub(super) glass: Option<Spanned<primo_sim::cell::GlassKind>>,
    pub(super) space: Option<Spanned<crate::pour::skill::Space>>,
}
