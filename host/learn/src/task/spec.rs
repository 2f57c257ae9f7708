//! A task as checked: what a task file says, in the library's terms (the
//! file's own keys are the private `schema` module's; [`super::check`]
//! turns one into the other).

use std::collections::BTreeMap;
use std::path::PathBuf;

use primo_core::generalize::Method as Regression;
use primo_mtsics::path::read_text;
use primo_robot::envelope::{ColumnLimit, Envelope, Limits, RobotLimits, WorkspaceBox};
use primo_robot::posture::PostureError;
use primo_robot::urdf::{Urdf, origin};
use primo_robot::{Chain, JointLimits, Robot, Tip};
use primo_skill::Skill;
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::algorithm::Algorithm;

/// The task file format's version.
pub const VERSION: u32 = 1;
/// Seconds an evaluator program may take for one roll-out, by default.
pub const DEFAULT_TIMEOUT: f64 = 60.0;

/// The longest an evaluator may be given for one roll-out, s (a day).
pub const MAX_TIMEOUT: f64 = 86_400.0;

/// How a reward is made from the error when the evaluator gives none.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RewardRule {
    /// `max(0, 1 − c‖ε‖)`.
    Linear,
    /// `exp(−c²‖ε‖²)`.
    Exp,
}

/// A demonstration and the query it shows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TaskDemo {
    /// The CSV file, absolute.
    pub file: PathBuf,
    /// Its query.
    pub query: Vec<f32>,
}

/// Limits of one column.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColumnRange {
    /// Lowest value.
    pub min: f64,
    /// Highest value.
    pub max: f64,
    /// Fastest change, per second.
    pub max_speed: f64,
}

/// A box three position columns stay in.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Workspace {
    /// The point's columns.
    pub columns: [String; 3],
    /// Lower corner.
    pub min: [f64; 3],
    /// Upper corner.
    pub max: [f64; 3],
    /// Fastest the point moves, per second.
    pub max_speed: f64,
}

/// The limits every trajectory of the task passes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LimitsSpec {
    /// A robot's.
    Robot(#[serde(deserialize_with = "logged_robot")] RobotSpec),
    /// Per-column limits and an optional workspace box.
    Columns {
        /// By column name.
        columns: BTreeMap<String, ColumnRange>,
        /// The workspace.
        workspace: Option<Workspace>,
    },
}

/// Where a robot's description comes from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RobotModel {
    /// A preset by name (`lwr4`).
    Preset(String),
    /// A URDF file, absolute.
    Urdf(PathBuf),
}

/// A robot whose limits a task's trajectories keep to.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RobotSpec {
    /// Its description.
    pub model: RobotModel,
    /// The chain's base link (a URDF's; default its root).
    pub base: Option<String>,
    /// The chain's tip link (a URDF's; default its one leaf).
    pub tip: Option<String>,
    /// A tool frame in the tip's (the preset's: its flange's): `x, y, z`
    /// (m) then roll, pitch, yaw about the fixed axes (rad), as a URDF's
    /// `<origin>`.
    pub tool: Option<[f64; 6]>,
    /// A URDF's joints' limits by name: for joints it gives none, or a
    /// lab's own within it.
    pub limits: BTreeMap<String, ColumnRange>,
    /// Every joint's fastest acceleration, rad/s² or m/s².
    pub max_acceleration: Option<f64>,
    /// The posture a tool trajectory starts from, by joint name (rad or
    /// m): every joint, or none (logs from before it have none).
    #[serde(default)]
    pub start: BTreeMap<String, f64>,
}

/// A logged robot: before URDF models, run logs held a preset's name alone.
fn logged_robot<'de, D: serde::Deserializer<'de>>(d: D) -> Result<RobotSpec, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Logged {
        Preset(String),
        Spec(RobotSpec),
    }
    Ok(match Logged::deserialize(d)? {
        Logged::Preset(name) => RobotSpec {
            model: RobotModel::Preset(name),
            base: None,
            tip: None,
            tool: None,
            limits: BTreeMap::new(),
            max_acceleration: None,
            start: BTreeMap::new(),
        },
        Logged::Spec(spec) => spec,
    })
}

impl RobotSpec {
    /// The robot's chain: the preset's, or the URDF's read and checked
    /// (its faults name the file, the line and the element).
    pub fn chain(&self) -> Result<Chain, Error> {
        let tool = self
            .tool
            .map(|[x, y, z, roll, pitch, yaw]| origin([x, y, z], [roll, pitch, yaw]));
        match &self.model {
            RobotModel::Preset(name) => {
                let robot = robot_preset(name)?;
                Ok(match tool {
                    Some(tool) => robot.chain_with_tool(&tool),
                    None => robot.chain(),
                })
            }
            RobotModel::Urdf(file) => {
                let name = file.display().to_string();
                let text = read_text(file).map_err(|f| Error::Invalid(format!("{name}: {f}")))?;
                let urdf = Urdf::parse(&name, &text).map_err(|e| Error::Invalid(e.to_string()))?;
                let tip = Tip {
                    base: self.base.clone(),
                    tip: self.tip.clone(),
                    tool,
                    limits: self
                        .limits
                        .iter()
                        .map(|(joint, r)| {
                            let limits = JointLimits {
                                lower: r.min,
                                upper: r.max,
                                velocity: r.max_speed,
                            };
                            (joint.clone(), limits)
                        })
                        .collect(),
                };
                Chain::from_urdf(&urdf, &tip).map_err(|e| Error::Invalid(e.to_string()))
            }
        }
    }

    /// The start posture in `chain`'s order (the robot's chain), if given.
    pub fn start(&self, chain: &Chain) -> Result<Option<Vec<f64>>, PostureError> {
        if self.start.is_empty() {
            return Ok(None);
        }
        let named = self.start.iter().map(|(joint, v)| (joint.as_str(), *v));
        chain.posture(named).map(Some)
    }
}

impl LimitsSpec {
    /// The limits to check with.
    pub fn limits(&self) -> Result<Limits, Error> {
        Ok(match self {
            LimitsSpec::Robot(robot) => {
                let chain = robot.chain()?;
                Limits::Robot(RobotLimits {
                    start: (robot.start(&chain))
                        .map_err(|e| Error::Invalid(format!("the robot's start posture: {e}")))?,
                    chain,
                    max_acceleration: robot.max_acceleration,
                })
            }
            LimitsSpec::Columns { columns, workspace } => Limits::Envelope(Envelope {
                columns: columns
                    .iter()
                    .map(|(name, r)| ColumnLimit {
                        name: name.clone(),
                        min: r.min,
                        max: r.max,
                        max_speed: r.max_speed,
                    })
                    .collect(),
                workspace: workspace.as_ref().map(|w| WorkspaceBox {
                    columns: w.columns.clone(),
                    min: w.min,
                    max: w.max,
                    max_speed: w.max_speed,
                }),
            }),
        })
    }
}

fn robot_preset(name: &str) -> Result<Robot, Error> {
    match name {
        "lwr4" => Ok(Robot::lwr4()),
        other => Err(Error::Invalid(format!(
            "robot preset `{other}`: primo knows `lwr4`"
        ))),
    }
}

/// `[movement] obstacles`: spheres `[x, y, z, radius]` in three position
/// columns.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Obstacles {
    /// Each sphere's centre and radius.
    pub spheres: Vec<[f64; 4]>,
    /// The columns of `x, y, z`.
    pub columns: [String; 3],
}

impl Obstacles {
    /// As the skill takes them.
    pub fn avoidance(&self) -> primo_skill::coupled::Avoidance {
        primo_skill::coupled::Avoidance {
            spheres: self
                .spheres
                .iter()
                .map(|[x, y, z, r]| primo_core::coupling::Sphere {
                    center: [*x as f32, *y as f32, *z as f32],
                    radius: *r as f32,
                })
                .collect(),
            columns: self.columns.clone(),
        }
    }
}

/// `[movement] limit_margin` and `limit_gain`: every roll-out pushed back
/// from the task's limits within the margin.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LimitPush {
    /// How near a limit the push starts, in the column's units.
    pub margin: f64,
    /// The push at half the margin, units/s².
    pub gain: f64,
}

/// The query to reach.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Goal {
    /// The desired query: the first one tried.
    pub desired: Vec<f32>,
    /// Error learning's bounds, per value (PoWER: empty if not given).
    pub low: Vec<f32>,
    /// See `low`.
    pub high: Vec<f32>,
    /// Error learning stops once every `|ε_i| < precision`.
    pub precision: f64,
}

/// Which goals secant-goals changes, and within what (`[learner] goals`,
/// `goals_min`, `goals_max`): one per value of the error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GoalSearch {
    /// The position columns whose goals are learned, consecutive in the
    /// demonstrations' order (empty: the first ones).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub columns: Vec<String>,
    /// The lowest goal of each (empty: its column's limit).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub min: Vec<f32>,
    /// The highest goal of each (empty: its column's limit).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub max: Vec<f32>,
}

/// The learner and its settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LearnerSettings {
    /// Which.
    pub method: Algorithm,
    /// Roll-out budget.
    pub max_rollouts: u32,
    /// The error learners' first (fixed-gain: only) gain `K = gain · I`.
    pub gain: f32,
    /// PoWER's exploration of the query, a fraction of the demonstrations'
    /// spread (0: ordinary PoWER).
    pub s1: f32,
    /// PoWER's exploration of `Δθ`, a fraction of the demonstrations'
    /// spread per block.
    pub s2: f32,
    /// PoWER's importance sampler length.
    pub sampler: usize,
    /// PoWER's exploration roll-outs per update.
    pub rollouts_per_update: u16,
    /// Per-update decay of the query's exploration variance.
    pub decay: f32,
    /// The reward from the error, when the evaluator gives none.
    pub reward: RewardRule,
    /// Its scale `c`, per unit of query.
    pub reward_scale: f32,
}

/// How a roll-out is executed and measured.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Evaluate {
    /// A program talking JSON lines (docs/src/reference/evaluator.md).
    Command {
        /// The program and its arguments.
        argv: Vec<String>,
        /// Where it runs: the task file's directory.
        dir: PathBuf,
        /// Seconds it may take per roll-out.
        timeout: f64,
    },
    /// The operator at the terminal.
    Operator,
    /// The built-in pouring cell.
    Pour(PourTask),
}

/// The built-in pour's own settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PourTask {
    /// Volume to pour, l.
    pub target: f64,
    /// `normal` or `small`.
    pub glass: primo_sim::cell::GlassKind,
    /// `joint` or `cartesian` (default: as `primo pour`, Cartesian for
    /// error learning, joint for PoWER).
    pub space: Option<crate::pour::skill::Space>,
}

/// A checked task.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Task {
    /// The task file, absolute.
    pub file: PathBuf,
    /// The demonstrations (none: the built-in pour's pair).
    pub demos: Vec<TaskDemo>,
    /// Kernels per DoF.
    pub kernels: usize,
    /// How the DMPs scale their forcing terms (absent from run logs
    /// written before it existed: per DoF, as they then did).
    #[serde(default)]
    pub scaling: primo_skill::dmpfile::AmplitudeScaling,
    /// The velocity the DMPs end with: at rest, or as demonstrated (absent
    /// from run logs written before it existed: at rest).
    #[serde(default)]
    pub final_velocity: primo_core::dmp::FinalVelocity,
    /// The generalization.
    pub regression: Regression,
    /// Spheres every roll-out steers round (absent from run logs written
    /// before they existed: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub obstacles: Option<Obstacles>,
    /// The push back from the limits every roll-out gets (absent from run
    /// logs written before it existed: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limit_push: Option<LimitPush>,
    /// Via-points every roll-out passes, `(seconds, column, value)`
    /// (absent from run logs written before they existed: none).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub vias: Vec<(f64, String, f64)>,
    /// Phase stopping's gain, per squared joint unit: the robot that
    /// executes the roll-outs slows each while it lags its command (absent
    /// from run logs written before it existed: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub phase_stop: Option<f64>,
    /// The trajectory's time step, s (`None`: the first demonstration's
    /// median step).
    pub dt: Option<f64>,
    /// The limits (`None` for the built-in pour: its cell's gate).
    pub limits: Option<LimitsSpec>,
    /// The query to reach.
    pub goal: Goal,
    /// The learner.
    pub learner: LearnerSettings,
    /// The goals secant-goals learns (absent for every other learner, and
    /// from run logs written before it existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub goals: Option<GoalSearch>,
    /// The evaluator.
    pub evaluate: Evaluate,
}

impl Task {
    /// The query's dimension.
    pub fn query_dim(&self) -> usize {
        self.goal.desired.len()
    }
}

/// A task fitted: its skill and limits, its trajectories' step.
#[derive(Debug, Clone)]
pub struct Built {
    /// Demonstrations → DMPs → generalization.
    pub skill: Skill,
    /// The DMP fitted to each demonstration, in the task file's order:
    /// the examples the skill generalizes.
    pub fitted: Vec<primo_skill::dmpfile::DmpFile>,
    /// What every trajectory passes.
    pub limits: Limits,
    /// The trajectories' time step, s.
    pub dt: f64,
    /// The goals secant-goals learns, on the skill.
    pub goals: Option<super::goals::LearnedGoals>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_run_log_of_a_robot_preset_before_urdf_models_still_reads() {
        let logged: LimitsSpec = serde_json::from_str(r#"{"robot":"lwr4"}"#).unwrap();
        let LimitsSpec::Robot(robot) = &logged else {
            panic!("{logged:?}")
        };
        assert_eq!(robot.model, RobotModel::Preset("lwr4".into()));
        let again: LimitsSpec =
            serde_json::from_str(&serde_json::to_string(&logged).unwrap()).unwrap();
        assert_eq!(again, logged);
        assert_eq!(robot.chain().unwrap(), Robot::lwr4().chain());
    }
}
