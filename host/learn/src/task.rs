//! A task file: what `primo learn` teaches, from the lab's own
//! demonstrations, query, limits and evaluator. TOML, versioned; every key
//! is documented in the README ("Teach your own skill"), an unknown key is
//! refused, and every check runs before anything moves: the message names
//! the file, the line and the key.
//!
//! [`Task::load`] reads and checks the file; [`Task::build`] reads the
//! demonstrations, checks their columns (by name, across demonstrations)
//! and that they pass the limits, and fits the skill.

use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

use primo_core::generalize::Method as Regression;
use primo_robot::Robot;
use primo_robot::envelope::{ColumnLimit, Envelope, Limits, WorkspaceBox};
use primo_skill::csv::{Demo, check_rotation_vectors, parse_demo};
use primo_skill::dmpfile::orientation_groups;
use primo_skill::skill::{MAX_EXAMPLES, same_columns};
use primo_skill::{MAX_KERNELS, MAX_QUERY, Skill};
use serde::{Deserialize, Serialize};
use toml::Spanned;

use crate::Error;
use crate::learning::{Algorithm, QUERY_DECAY};

/// The task file format's version.
pub const VERSION: u32 = 1;
/// Seconds an evaluator program may take for one roll-out, by default.
pub const DEFAULT_TIMEOUT: f64 = 60.0;

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
    /// A robot preset by name (`lwr4`).
    Robot(String),
    /// Per-column limits and an optional workspace box.
    Columns {
        /// By column name.
        columns: BTreeMap<String, ColumnRange>,
        /// The workspace.
        workspace: Option<Workspace>,
    },
}

impl LimitsSpec {
    /// The limits to check with.
    pub fn limits(&self) -> Result<Limits, Error> {
        Ok(match self {
            LimitsSpec::Robot(name) => Limits::Robot(robot_preset(name)?),
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
    /// A program talking JSON lines (README: "Teach your own skill").
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
    pub space: Option<primo_skill::Space>,
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
    /// The generalization.
    pub regression: Regression,
    /// The trajectory's time step, s (`None`: the first demonstration's
    /// median step).
    pub dt: Option<f64>,
    /// The limits (`None` for the built-in pour: its cell's gate).
    pub limits: Option<LimitsSpec>,
    /// The query to reach.
    pub goal: Goal,
    /// The learner.
    pub learner: LearnerSettings,
    /// The evaluator.
    pub evaluate: Evaluate,
}

/// A task fitted: its skill and limits, its trajectories' step.
#[derive(Debug, Clone)]
pub struct Built {
    /// Demonstrations → DMPs → generalization.
    pub skill: Skill,
    /// What every trajectory passes.
    pub limits: Limits,
    /// The trajectories' time step, s.
    pub dt: f64,
}

// The file as written. Values that later checks may refuse keep their
// place in the file (`Spanned`), so the message can name the line.

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    version: Spanned<u32>,
    #[serde(default)]
    demo: Vec<DemoKeys>,
    #[serde(default)]
    movement: Option<Spanned<MovementKeys>>,
    goal: Spanned<GoalKeys>,
    learner: Spanned<LearnerKeys>,
    evaluate: Spanned<EvaluateKeys>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DemoKeys {
    file: Spanned<String>,
    query: Spanned<Vec<f64>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct MovementKeys {
    kernels: Option<Spanned<usize>>,
    generalization: Option<Spanned<String>>,
    dt: Option<Spanned<f64>>,
    robot: Option<Spanned<String>>,
    limits: Option<Spanned<BTreeMap<String, ColumnRange>>>,
    workspace: Option<Spanned<Workspace>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GoalKeys {
    desired: Spanned<Vec<f64>>,
    low: Option<Spanned<Vec<f64>>>,
    high: Option<Spanned<Vec<f64>>>,
    precision: Option<Spanned<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LearnerKeys {
    method: Spanned<Algorithm>,
    max_rollouts: Option<Spanned<u32>>,
    gain: Option<Spanned<f64>>,
    s1: Option<Spanned<f64>>,
    s2: Option<Spanned<f64>>,
    sampler: Option<Spanned<usize>>,
    rollouts_per_update: Option<Spanned<u16>>,
    decay: Option<Spanned<f64>>,
    reward: Option<Spanned<RewardRule>>,
    reward_scale: Option<Spanned<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EvaluateKeys {
    command: Option<Spanned<Vec<String>>>,
    timeout: Option<Spanned<f64>>,
    operator: Option<Spanned<bool>>,
    builtin: Option<Spanned<String>>,
    target: Option<Spanned<f64>>,
    glass: Option<Spanned<primo_sim::cell::GlassKind>>,
    space: Option<Spanned<primo_skill::Space>>,
}

/// Messages that name a place in the task file.
struct Place<'a> {
    name: String,
    text: &'a str,
}

impl Place<'_> {
    /// `FILE:LINE: [table] key: why`.
    fn at(&self, span: Range<usize>, key: &str, why: impl std::fmt::Display) -> Error {
        Error::Invalid(format!(
            "{}:{}: {key}: {why}",
            self.name,
            self.line(span.start)
        ))
    }

    fn line(&self, offset: usize) -> usize {
        self.text
            .get(..offset)
            .map_or(1, |before| before.matches('\n').count() + 1)
    }
}

/// `values` as a query of `dim` finite values (`dim` 0: any of 1 to
/// [`MAX_QUERY`]).
fn query(p: &Place, v: &Spanned<Vec<f64>>, key: &str, dim: usize) -> Result<Vec<f32>, Error> {
    let values = v.get_ref();
    if dim == 0 && !(1..=MAX_QUERY).contains(&values.len()) {
        return Err(p.at(
            v.span(),
            key,
            format!(
                "a query has 1 to {MAX_QUERY} values, this one {}",
                values.len()
            ),
        ));
    }
    if dim != 0 && values.len() != dim {
        return Err(p.at(
            v.span(),
            key,
            format!(
                "{} values; the demonstrations' queries have {dim}",
                values.len()
            ),
        ));
    }
    values
        .iter()
        .map(|x| {
            let q = *x as f32;
            if q.is_finite() {
                Ok(q)
            } else {
                Err(p.at(v.span(), key, format!("{x} is not a finite number")))
            }
        })
        .collect()
}

/// A positive finite number.
fn positive(p: &Place, v: &Spanned<f64>, key: &str) -> Result<f64, Error> {
    let x = *v.get_ref();
    if x.is_finite() && x > 0.0 {
        Ok(x)
    } else {
        Err(p.at(v.span(), key, format!("{x}: must be a positive number")))
    }
}

impl Task {
    /// Reads and checks the task file at `path`: every key, every value,
    /// the demonstrations' files named (they are read by [`Task::build`]).
    pub fn load(path: &Path) -> Result<Task, Error> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| Error::Invalid(format!("--task {}: cannot read: {e}", path.display())))?;
        let file = std::path::absolute(path)
            .map_err(|e| Error::Invalid(format!("--task {}: {e}", path.display())))?;
        Task::parse(&file, &text)
    }

    /// Checks the task file `text`, read from `file` (absolute: the
    /// demonstrations and the evaluator are found beside it).
    pub fn parse(file: &Path, text: &str) -> Result<Task, Error> {
        let p = Place {
            name: file.display().to_string(),
            text,
        };
        let raw: File = toml::from_str(text).map_err(|e| {
            let line = e.span().map_or(1, |s| p.line(s.start));
            Error::Invalid(format!("{}:{line}: {}", p.name, e.message().trim_end()))
        })?;
        if *raw.version.get_ref() != VERSION {
            return Err(p.at(
                raw.version.span(),
                "version",
                format!(
                    "{}: this primo reads task files of version {VERSION}",
                    raw.version.get_ref()
                ),
            ));
        }
        let dir = file.parent().unwrap_or(Path::new("/")).to_path_buf();
        let evaluate = evaluate(&p, &raw.evaluate, &dir)?;
        let pour = matches!(evaluate, Evaluate::Pour(_));
        let demos = demos(&p, &raw, &dir, pour)?;
        let dim = demos.first().map_or(1, |d| d.query.len());
        let movement = raw.movement.as_ref();
        let m = movement.map(Spanned::get_ref);
        let kernels = match m.and_then(|m| m.kernels.as_ref()) {
            Some(k) if !(2..=MAX_KERNELS).contains(k.get_ref()) => {
                return Err(p.at(
                    k.span(),
                    "[movement] kernels",
                    format!("{}: must be in 2..={MAX_KERNELS}", k.get_ref()),
                ));
            }
            Some(k) => *k.get_ref(),
            None => 30,
        };
        let regression = match m.and_then(|m| m.generalization.as_ref()) {
            None => Regression::Lwr { bandwidth: None },
            Some(g) => match g.get_ref().as_str() {
                "lwr" => Regression::Lwr { bandwidth: None },
                "gpr" => Regression::Gpr {
                    length_scale: None,
                    noise: 0.0,
                },
                other => {
                    return Err(p.at(
                        g.span(),
                        "[movement] generalization",
                        format!("`{other}`: must be `lwr` or `gpr`"),
                    ));
                }
            },
        };
        let dt = m
            .and_then(|m| m.dt.as_ref())
            .map(|v| positive(&p, v, "[movement] dt"))
            .transpose()?;
        let limits = limits(&p, movement, pour)?;
        let learner = learner(&p, &raw.learner, dim, &demos, pour)?;
        let goal = goal(&p, &raw.goal, dim, learner.method)?;
        Ok(Task {
            file: file.to_path_buf(),
            demos,
            kernels,
            regression,
            dt,
            limits,
            goal,
            learner,
            evaluate,
        })
    }

    /// The query's dimension.
    pub fn query_dim(&self) -> usize {
        self.goal.desired.len()
    }

    /// Reads the demonstrations, checks that their columns match by name
    /// (each against the first) and that they pass the limits, and fits the
    /// skill. Not for the built-in pour (its cell builds its own skill).
    pub fn build(&self) -> Result<Built, Error> {
        let spec = self
            .limits
            .as_ref()
            .ok_or_else(|| Error::Invalid("the built-in pour builds its skill itself".into()))?;
        let mut limits = spec.limits()?;
        let mut demos: Vec<(String, Demo)> = Vec::new();
        for d in &self.demos {
            let name = d.file.display().to_string();
            let text = std::fs::read_to_string(&d.file)
                .map_err(|e| Error::Invalid(format!("{name}: cannot read: {e}")))?;
            let demo = parse_demo(&name, &text)?;
            check_rotation_vectors(&name, &demo)?;
            if let Some((first, reference)) = demos.first() {
                same_columns(&reference.names, &demo.names).map_err(|why| {
                    Error::Invalid(format!(
                        "{name}: {why} (the columns of {first}, the first demonstration)"
                    ))
                })?;
            } else {
                self.exempt_orientations(spec, &mut limits, &demo.names)?;
            }
            limits.covers(&demo.names).map_err(|why| {
                Error::Invalid(format!("{name}: {why} ({})", self.limits_place()))
            })?;
            let times: Vec<f64> = demo.times.iter().map(|t| f64::from(*t)).collect();
            let rows: Vec<f64> = demo.positions.iter().map(|v| f64::from(*v)).collect();
            limits.check(&demo.names, times, &rows).map_err(|why| {
                Error::Invalid(format!(
                    "{name}: the demonstration itself is beyond the task's limits: {why}"
                ))
            })?;
            demos.push((name, demo));
        }
        if let LimitsSpec::Columns { columns, .. } = spec
            && let Some((_, first)) = demos.first()
            && let Some(extra) = columns.keys().find(|c| !first.names.contains(c))
        {
            return Err(Error::Invalid(format!(
                "{}: [movement.limits] {extra}: not a column of the demonstrations ({})",
                self.file.display(),
                first.names.join(",")
            )));
        }
        let dt = match (self.dt, demos.first()) {
            (Some(dt), _) => dt,
            (None, Some((_, d))) => median_step(&d.times),
            (None, None) => return Err(Error::Invalid("no demonstrations".into())),
        };
        let examples: Vec<(&[f32], &Demo)> = self
            .demos
            .iter()
            .zip(&demos)
            .map(|(t, (_, d))| (&t.query[..], d))
            .collect();
        let skill = Skill::fit(&examples, self.kernels, self.regression)?;
        Ok(Built { skill, limits, dt })
    }

    /// Orientation columns (`…qw,…qx,…qy,…qz`, the rule of `primo dmp
    /// fit`) take no per-column limits: a unit quaternion's components say
    /// nothing of how far or fast it turns, and primo writes them
    /// unit-norm. An entry for one is refused; they pass the check.
    fn exempt_orientations(
        &self,
        spec: &LimitsSpec,
        limits: &mut Limits,
        names: &[String],
    ) -> Result<(), Error> {
        let groups = orientation_groups(names);
        let columns = groups.iter().flat_map(|(group, _)| group);
        if let LimitsSpec::Columns {
            columns: limited, ..
        } = spec
            && let Some((group, name)) = groups
                .iter()
                .find_map(|(g, _)| g.iter().find(|c| limited.contains_key(*c)).map(|c| (g, c)))
        {
            return Err(Error::Invalid(format!(
                "{}: [movement.limits] {name}: a component of the orientation {} (a unit \
                 quaternion); per-column limits do not apply to orientations: remove the entry",
                self.file.display(),
                group.join(",")
            )));
        }
        if let Limits::Envelope(e) = limits {
            e.columns.extend(columns.map(|name| ColumnLimit {
                name: name.clone(),
                min: f64::NEG_INFINITY,
                max: f64::INFINITY,
                max_speed: f64::INFINITY,
            }));
        }
        Ok(())
    }

    fn limits_place(&self) -> String {
        format!("the limits in {}", self.file.display())
    }
}

/// The median time step of a recording, s.
fn median_step(times: &[f32]) -> f64 {
    let mut steps: Vec<f64> = times
        .windows(2)
        .map(|w| f64::from(w[1]) - f64::from(w[0]))
        .collect();
    steps.sort_by(f64::total_cmp);
    steps.get(steps.len() / 2).copied().unwrap_or(0.01)
}

fn demos(p: &Place, raw: &File, dir: &Path, pour: bool) -> Result<Vec<TaskDemo>, Error> {
    if raw.demo.is_empty() && pour {
        return Ok(Vec::new());
    }
    if raw.demo.len() < 2 {
        return Err(Error::Invalid(format!(
            "{}: {} [[demo]]: a skill generalizes over at least two demonstrations, at \
             different queries",
            p.name,
            raw.demo.len()
        )));
    }
    if raw.demo.len() > MAX_EXAMPLES {
        return Err(Error::Invalid(format!(
            "{}: {} [[demo]]: at most {MAX_EXAMPLES}",
            p.name,
            raw.demo.len()
        )));
    }
    let mut out: Vec<TaskDemo> = Vec::new();
    for d in &raw.demo {
        let dim = out.first().map_or(0, |f| f.query.len());
        let q = query(p, &d.query, "[[demo]] query", dim)?;
        if pour && !q.iter().all(|v| *v > 0.0) {
            return Err(p.at(
                d.query.span(),
                "[[demo]] query",
                "the pour's query is the bottle's volume, a positive number of litres",
            ));
        }
        if let Some(same) = out.iter().find(|o| o.query == q) {
            return Err(p.at(
                d.query.span(),
                "[[demo]] query",
                format!(
                    "{q:?} is also the query of {}: the demonstrations must show different \
                     queries to generalize over",
                    same.file.display()
                ),
            ));
        }
        let file = dir.join(d.file.get_ref());
        if !file.is_file() {
            return Err(p.at(
                d.file.span(),
                "[[demo]] file",
                format!("{}: no such file", file.display()),
            ));
        }
        out.push(TaskDemo { file, query: q });
    }
    Ok(out)
}

fn limits(
    p: &Place,
    movement: Option<&Spanned<MovementKeys>>,
    pour: bool,
) -> Result<Option<LimitsSpec>, Error> {
    let m = movement.map(Spanned::get_ref);
    let robot = m.and_then(|m| m.robot.as_ref());
    let columns = m.and_then(|m| m.limits.as_ref());
    let workspace = m.and_then(|m| m.workspace.as_ref());
    if pour {
        if let Some(span) = robot
            .map(Spanned::span)
            .or(columns.map(Spanned::span))
            .or(workspace.map(Spanned::span))
        {
            return Err(p.at(
                span,
                "[movement]",
                "the built-in pour's limits are its cell's own gate: remove robot, limits and \
                 workspace",
            ));
        }
        return Ok(None);
    }
    match (robot, columns) {
        (Some(r), None) => {
            robot_preset(r.get_ref()).map_err(|e| p.at(r.span(), "[movement] robot", e))?;
            if let Some(w) = workspace {
                return Err(p.at(
                    w.span(),
                    "[movement.workspace]",
                    "a workspace box limits position columns, not a robot's joints",
                ));
            }
            Ok(Some(LimitsSpec::Robot(r.get_ref().clone())))
        }
        (None, Some(c)) => {
            for (name, r) in c.get_ref() {
                if !(r.min.is_finite() && r.max.is_finite() && r.min < r.max) {
                    return Err(p.at(
                        c.span(),
                        &format!("[movement.limits] {name}"),
                        format!(
                            "min {} and max {}: need min < max, both finite",
                            r.min, r.max
                        ),
                    ));
                }
                if !(r.max_speed.is_finite() && r.max_speed > 0.0) {
                    return Err(p.at(
                        c.span(),
                        &format!("[movement.limits] {name}"),
                        format!("max_speed {}: must be a positive number", r.max_speed),
                    ));
                }
            }
            if let Some(w) = workspace {
                let ws = w.get_ref();
                let ok = (0..3).all(|k| ws.min[k].is_finite() && ws.max[k].is_finite())
                    && (0..3).all(|k| ws.min[k] < ws.max[k])
                    && ws.max_speed.is_finite()
                    && ws.max_speed > 0.0;
                if !ok {
                    return Err(p.at(
                        w.span(),
                        "[movement.workspace]",
                        "need min < max on every axis and a positive max_speed",
                    ));
                }
                if let Some(missing) = ws.columns.iter().find(|n| !c.get_ref().contains_key(*n)) {
                    return Err(p.at(
                        w.span(),
                        "[movement.workspace] columns",
                        format!("`{missing}` has no [movement.limits] entry"),
                    ));
                }
            }
            Ok(Some(LimitsSpec::Columns {
                columns: c.get_ref().clone(),
                workspace: workspace.map(|w| w.get_ref().clone()),
            }))
        }
        (Some(r), Some(_)) => Err(p.at(
            r.span(),
            "[movement] robot",
            "give a robot preset or per-column [movement.limits], not both",
        )),
        (None, None) => Err(Error::Invalid(format!(
            "{}:{}: [movement]: no limits: give `robot = \"lwr4\"` or [movement.limits] for \
             every column (nothing leaves primo unchecked)",
            p.name,
            movement.map_or(1, |m| p.line(m.span().start))
        ))),
    }
}

fn learner(
    p: &Place,
    raw: &Spanned<LearnerKeys>,
    dim: usize,
    demos: &[TaskDemo],
    pour: bool,
) -> Result<LearnerSettings, Error> {
    let l = raw.get_ref();
    // The built-in pour is `primo pour`: PoWER with the paper's sampler,
    // roll-outs per update and decay, and the paper's reward.
    let fixed_by_the_pour = [
        ("sampler", l.sampler.as_ref().map(Spanned::span)),
        (
            "rollouts_per_update",
            l.rollouts_per_update.as_ref().map(Spanned::span),
        ),
        ("decay", l.decay.as_ref().map(Spanned::span)),
        ("reward", l.reward.as_ref().map(Spanned::span)),
        ("reward_scale", l.reward_scale.as_ref().map(Spanned::span)),
    ];
    if pour && let Some((key, Some(span))) = fixed_by_the_pour.iter().find(|(_, s)| s.is_some()) {
        return Err(p.at(
            span.clone(),
            &format!("[learner] {key}"),
            "the built-in pour runs as `primo pour`, with the paper's setting (and reward) here",
        ));
    }
    let method = *l.method.get_ref();
    if dim > 1 && matches!(method, Algorithm::Golden | Algorithm::Illinois) {
        return Err(p.at(
            l.method.span(),
            "[learner] method",
            format!(
                "{} searches a one-value query; the demonstrations' queries have {dim}: use \
                 \"secant\" (or \"power\")",
                if method == Algorithm::Golden {
                    "golden"
                } else {
                    "illinois"
                }
            ),
        ));
    }
    let power = method.is_power();
    let power_keys = [
        ("s1", l.s1.as_ref().map(Spanned::span)),
        ("s2", l.s2.as_ref().map(Spanned::span)),
        ("sampler", l.sampler.as_ref().map(Spanned::span)),
        (
            "rollouts_per_update",
            l.rollouts_per_update.as_ref().map(Spanned::span),
        ),
        ("decay", l.decay.as_ref().map(Spanned::span)),
    ];
    if !power && let Some((key, Some(span))) = power_keys.iter().find(|(_, s)| s.is_some()) {
        return Err(p.at(
            span.clone(),
            &format!("[learner] {key}"),
            "a PoWER setting; this task's method is error learning",
        ));
    }
    let max_rollouts = match &l.max_rollouts {
        Some(v) if *v.get_ref() == 0 => {
            return Err(p.at(v.span(), "[learner] max_rollouts", "must be at least 1"));
        }
        Some(v) => *v.get_ref(),
        None if power => 200,
        None => 30,
    };
    let unit = |v: &Option<Spanned<f64>>, key: &str, default: f32, open: bool| {
        v.as_ref().map_or(Ok(default), |v| {
            let x = *v.get_ref();
            let ok = x.is_finite() && x >= 0.0 && (!open || (x > 0.0 && x <= 1.0));
            if ok {
                Ok(x as f32)
            } else {
                let need = if open { "in (0, 1]" } else { "finite and >= 0" };
                Err(p.at(v.span(), key, format!("{x}: must be {need}")))
            }
        })
    };
    let sampler = match &l.sampler {
        Some(v) if !(1..=primo_learner::SAMPLER).contains(v.get_ref()) => {
            return Err(p.at(
                v.span(),
                "[learner] sampler",
                format!("{}: must be in 1..={}", v.get_ref(), primo_learner::SAMPLER),
            ));
        }
        Some(v) => *v.get_ref(),
        None => 3,
    };
    let rollouts_per_update = match &l.rollouts_per_update {
        Some(v) if *v.get_ref() == 0 => {
            return Err(p.at(
                v.span(),
                "[learner] rollouts_per_update",
                "must be at least 1",
            ));
        }
        Some(v) => *v.get_ref(),
        None => 3,
    };
    // Default reward scale: an error as large as the demonstrations' query
    // span scores 0 (linear) or e^-1 (exp).
    let span = demos
        .iter()
        .flat_map(|a| demos.iter().map(move |b| distance(&a.query, &b.query)))
        .fold(0.0f32, f32::max);
    let reward_scale = match &l.reward_scale {
        Some(v) => positive(p, v, "[learner] reward_scale")? as f32,
        None if span > 0.0 => 1.0 / span,
        None => 1.0,
    };
    let gain = match &l.gain {
        Some(v) if !method.uses_error() => {
            return Err(p.at(
                v.span(),
                "[learner] gain",
                "an error learner's setting; this task's method is PoWER (\"power-el\" learns \
                 the query from the error with a gain)",
            ));
        }
        Some(v) if !(v.get_ref().is_finite() && *v.get_ref() != 0.0) => {
            return Err(p.at(
                v.span(),
                "[learner] gain",
                format!("{}: must be a finite number other than 0", v.get_ref()),
            ));
        }
        Some(v) => *v.get_ref() as f32,
        None => 1.0,
    };
    Ok(LearnerSettings {
        method,
        max_rollouts,
        gain,
        s1: unit(&l.s1, "[learner] s1", method.default_s1(), false)?,
        s2: unit(&l.s2, "[learner] s2", 0.05, false)?,
        sampler,
        rollouts_per_update,
        decay: unit(&l.decay, "[learner] decay", QUERY_DECAY, true)?,
        reward: l
            .reward
            .as_ref()
            .map_or(RewardRule::Linear, |r| *r.get_ref()),
        reward_scale,
    })
}

/// Euclidean distance between two queries.
pub fn distance(a: &[f32], b: &[f32]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f32>()
        .sqrt()
}

fn goal(p: &Place, raw: &Spanned<GoalKeys>, dim: usize, method: Algorithm) -> Result<Goal, Error> {
    let g = raw.get_ref();
    let desired = query(p, &g.desired, "[goal] desired", dim)?;
    let error_learning = !method.is_power();
    let bound = |v: &Option<Spanned<Vec<f64>>>, key: &str| -> Result<Option<Vec<f32>>, Error> {
        v.as_ref().map(|v| query(p, v, key, dim)).transpose()
    };
    let low = bound(&g.low, "[goal] low")?;
    let high = bound(&g.high, "[goal] high")?;
    let precision = g
        .precision
        .as_ref()
        .map(|v| positive(p, v, "[goal] precision"))
        .transpose()?;
    let need = |what: &str| {
        Error::Invalid(format!(
            "{}:{}: [goal]: error learning needs `{what}`",
            p.name,
            p.line(raw.span().start)
        ))
    };
    let (low, high, precision) = match (low, high, precision) {
        (Some(l), Some(h), Some(pr)) => (l, h, pr),
        (l, h, pr) if !error_learning => (
            l.unwrap_or_default(),
            h.unwrap_or_default(),
            pr.unwrap_or(0.0),
        ),
        (None, _, _) => return Err(need("low")),
        (_, None, _) => return Err(need("high")),
        (_, _, None) => return Err(need("precision")),
    };
    let unbounded = |b: &[f32], fill: f32| {
        if b.is_empty() {
            vec![fill; dim]
        } else {
            b.to_vec()
        }
    };
    let (lo, hi) = (
        unbounded(&low, f32::NEG_INFINITY),
        unbounded(&high, f32::INFINITY),
    );
    for (i, ((l, h), d)) in lo.iter().zip(&hi).zip(&desired).enumerate() {
        if !(l < d && d < h) {
            return Err(p.at(
                g.desired.span(),
                "[goal] desired",
                format!(
                    "value {} is {d}, outside the bounds: it must lie strictly between low {l} \
                     and high {h}",
                    i + 1
                ),
            ));
        }
    }
    Ok(Goal {
        desired,
        low,
        high,
        precision,
    })
}

fn evaluate(p: &Place, raw: &Spanned<EvaluateKeys>, dir: &Path) -> Result<Evaluate, Error> {
    let e = raw.get_ref();
    let kinds = [
        e.command.is_some(),
        e.operator.is_some(),
        e.builtin.is_some(),
    ];
    if kinds.iter().filter(|k| **k).count() != 1 {
        return Err(Error::Invalid(format!(
            "{}:{}: [evaluate]: give exactly one of `command`, `operator = true` or \
             `builtin = \"pour\"`",
            p.name,
            p.line(raw.span().start)
        )));
    }
    let pour_keys = [
        ("target", e.target.as_ref().map(Spanned::span)),
        ("glass", e.glass.as_ref().map(Spanned::span)),
        ("space", e.space.as_ref().map(Spanned::span)),
    ];
    if e.builtin.is_none()
        && let Some((key, Some(span))) = pour_keys.iter().find(|(_, s)| s.is_some())
    {
        return Err(p.at(
            span.clone(),
            &format!("[evaluate] {key}"),
            "a setting of the built-in pour (builtin = \"pour\")",
        ));
    }
    if e.command.is_none()
        && let Some(t) = &e.timeout
    {
        return Err(p.at(
            t.span(),
            "[evaluate] timeout",
            "the time an evaluator `command` may take",
        ));
    }
    if let Some(c) = &e.command {
        if c.get_ref()
            .first()
            .is_none_or(|prog| prog.trim().is_empty())
        {
            return Err(p.at(
                c.span(),
                "[evaluate] command",
                "name the program: command = [\"program\", \"argument\", ...]",
            ));
        }
        let timeout = e
            .timeout
            .as_ref()
            .map(|t| positive(p, t, "[evaluate] timeout"))
            .transpose()?
            .unwrap_or(DEFAULT_TIMEOUT);
        return Ok(Evaluate::Command {
            argv: c.get_ref().clone(),
            dir: dir.to_path_buf(),
            timeout,
        });
    }
    if let Some(o) = &e.operator {
        if !o.get_ref() {
            return Err(p.at(
                o.span(),
                "[evaluate] operator",
                "`operator = false` names no evaluator",
            ));
        }
        return Ok(Evaluate::Operator);
    }
    let builtin = e
        .builtin
        .as_ref()
        .ok_or_else(|| Error::Invalid("no evaluator".into()))?;
    if builtin.get_ref() != "pour" {
        return Err(p.at(
            builtin.span(),
            "[evaluate] builtin",
            format!("`{}`: the built-in task is `pour`", builtin.get_ref()),
        ));
    }
    Ok(Evaluate::Pour(PourTask {
        target: e.target.as_ref().map_or(0.2, |t| *t.get_ref()),
        glass: e
            .glass
            .as_ref()
            .map_or(primo_sim::cell::GlassKind::Normal, |g| *g.get_ref()),
        space: e.space.as_ref().map(|s| *s.get_ref()),
    }))
}
