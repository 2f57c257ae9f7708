//! Checking a task file: every key and value, before anything moves; a
//! refusal names the file, the line and the key.

use std::collections::BTreeMap;
use std::ops::Range;
use std::path::Path;

use primo_core::dmp::{FinalVelocity, MAX_VIA_POINTS};
use primo_core::generalize::{Method as Regression, PROMP_RIDGE};
use primo_mtsics::path::{Wanted, check};
use primo_robot::urdf::MAX_DISTANCE;
use primo_skill::coupled::{DEFAULT_LIMIT_GAIN, MAX_OBSTACLES};
use primo_skill::dmpfile::AmplitudeScaling;
use primo_skill::skill::MAX_EXAMPLES;
use primo_skill::{MAX_KERNELS, MAX_QUERY};
use toml::Spanned;

use crate::Error;
use crate::algorithm::Algorithm;
use crate::error::Setting;
use crate::learner::QUERY_DECAY;
use crate::rollouts::MAX_ROLLOUTS;

use super::schema::{EvaluateKeys, File, GoalKeys, LearnerKeys, MovementKeys, ToolKeys};
use super::spec::{
    ColumnRange, DEFAULT_TIMEOUT, Evaluate, Goal, GoalSearch, LearnerSettings, LimitPush,
    LimitsSpec, MAX_TIMEOUT, Obstacles, PourTask, RewardRule, RobotModel, RobotSpec, Task,
    TaskDemo, VERSION,
};

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
        let text = Error::read(Setting::Task, path)?;
        let file = std::path::absolute(path)
            .map_err(|e| Error::setting(Setting::Task, path.display(), e.to_string()))?;
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
                "promp" => Regression::ProMp { ridge: PROMP_RIDGE },
                other => {
                    return Err(p.at(
                        g.span(),
                        "[movement] generalization",
                        format!("`{other}`: must be `lwr`, `gpr` or `promp`"),
                    ));
                }
            },
        };
        let scaling = match m.and_then(|m| m.scaling.as_ref()) {
            None => AmplitudeScaling::default(),
            Some(v) if pour => {
                return Err(p.at(
                    v.span(),
                    "[movement] scaling",
                    "the built-in pour scales its own DMPs: remove the key",
                ));
            }
            Some(v) => AmplitudeScaling::parse(v.get_ref()).ok_or_else(|| {
                p.at(
                    v.span(),
                    "[movement] scaling",
                    format!("`{}`: must be `per-dof`, `none` or `global`", v.get_ref()),
                )
            })?,
        };
        let final_velocity = match m.and_then(|m| m.final_velocity.as_ref()) {
            None => FinalVelocity::AtRest,
            Some(v) if pour => {
                return Err(p.at(
                    v.span(),
                    "[movement] final_velocity",
                    "the built-in pour ends its movements at rest: remove the key",
                ));
            }
            Some(v) => match v.get_ref().as_str() {
                "rest" => FinalVelocity::AtRest,
                "demonstrated" => FinalVelocity::Demonstrated,
                other => {
                    return Err(p.at(
                        v.span(),
                        "[movement] final_velocity",
                        format!("`{other}`: must be `rest` or `demonstrated`"),
                    ));
                }
            },
        };
        let dt = m
            .and_then(|m| m.dt.as_ref())
            .map(|v| positive(&p, v, "[movement] dt"))
            .transpose()?;
        let obstacles = m.map(|m| obstacles(&p, m, pour)).transpose()?.flatten();
        let limit_push = m.map(|m| limit_push(&p, m, pour)).transpose()?.flatten();
        let phase_stop = m.map(|m| phase_stop(&p, m, pour)).transpose()?.flatten();
        let vias = m
            .map(|m| vias(&p, m, pour))
            .transpose()?
            .unwrap_or_default();
        let limits = limits(&p, movement, &dir, pour)?;
        let learner = learner(&p, &raw.learner, dim, &demos, pour)?;
        let goal = goal(&p, &raw.goal, dim, learner.method)?;
        let goals = goal_search(&p, raw.learner.get_ref(), dim, learner.method)?;
        Ok(Task {
            file: file.to_path_buf(),
            demos,
            kernels,
            scaling,
            final_velocity,
            regression,
            obstacles,
            limit_push,
            vias,
            phase_stop,
            dt,
            limits,
            goal,
            learner,
            goals,
            evaluate,
        })
    }
}

/// `[movement] via`: at most [`MAX_VIA_POINTS`] `[seconds, "column",
/// value]`, the time positive and both finite (whether the column is a
/// position column, and the time within the movement, the skill checks).
fn vias(p: &Place, m: &MovementKeys, pour: bool) -> Result<Vec<(f64, String, f64)>, Error> {
    let Some(vias) = &m.via else {
        return Ok(Vec::new());
    };
    let at = |why: String| p.at(vias.span(), "[movement] via", why);
    if pour {
        return Err(at(
            "the built-in pour plans its own movements: remove the key".into(),
        ));
    }
    if vias.get_ref().len() > MAX_VIA_POINTS {
        return Err(at(format!(
            "{} via-points, at most {MAX_VIA_POINTS}",
            vias.get_ref().len()
        )));
    }
    for (i, (t, column, v)) in vias.get_ref().iter().enumerate() {
        if !(t.is_finite() && *t > 0.0 && v.is_finite()) {
            return Err(at(format!(
                "via-point {} [{t}, \"{column}\", {v}]: needs a time > 0 s and a value, both \
                 finite",
                i + 1
            )));
        }
    }
    Ok(vias.get_ref().clone())
}

/// `[movement] limit_margin` (positive) and `limit_gain` (positive,
/// default [`DEFAULT_LIMIT_GAIN`], only with a margin).
fn limit_push(p: &Place, m: &MovementKeys, pour: bool) -> Result<Option<LimitPush>, Error> {
    let Some(margin) = &m.limit_margin else {
        if let Some(g) = &m.limit_gain {
            return Err(p.at(
                g.span(),
                "[movement] limit_gain",
                "given without limit_margin",
            ));
        }
        return Ok(None);
    };
    if pour {
        return Err(p.at(
            margin.span(),
            "[movement] limit_margin",
            "the built-in pour keeps to its cell's own checks: remove the key",
        ));
    }
    Ok(Some(LimitPush {
        margin: positive(p, margin, "[movement] limit_margin")?,
        gain: (m.limit_gain.as_ref())
            .map(|g| positive(p, g, "[movement] limit_gain"))
            .transpose()?
            .unwrap_or(f64::from(DEFAULT_LIMIT_GAIN)),
    }))
}

/// `[movement] phase_stop`: a positive gain; the built-in pour's cell
/// streams as planned.
fn phase_stop(p: &Place, m: &MovementKeys, pour: bool) -> Result<Option<f64>, Error> {
    let Some(k) = &m.phase_stop else {
        return Ok(None);
    };
    if pour {
        return Err(p.at(
            k.span(),
            "[movement] phase_stop",
            "the built-in pour streams its cell's checked path as planned: remove the key",
        ));
    }
    let gain = positive(p, k, "[movement] phase_stop")?;
    if !(gain as f32).is_finite() {
        return Err(p.at(
            k.span(),
            "[movement] phase_stop",
            format!("{gain:e}: too large"),
        ));
    }
    Ok(Some(gain))
}

/// `[movement] obstacles` (spheres `[x, y, z, radius]`, at most
/// [`MAX_OBSTACLES`]) and `obstacle_columns` (three names, default `x, y,
/// z`); the built-in pour takes none.
fn obstacles(p: &Place, m: &MovementKeys, pour: bool) -> Result<Option<Obstacles>, Error> {
    let Some(spheres) = &m.obstacles else {
        if let Some(c) = &m.obstacle_columns {
            return Err(p.at(
                c.span(),
                "[movement] obstacle_columns",
                "given without obstacles",
            ));
        }
        return Ok(None);
    };
    let at = |why: String| p.at(spheres.span(), "[movement] obstacles", why);
    if pour {
        return Err(at(
            "the built-in pour has its own cell: remove the key".into()
        ));
    }
    if spheres.get_ref().len() > MAX_OBSTACLES {
        return Err(at(format!(
            "{} spheres, at most {MAX_OBSTACLES}",
            spheres.get_ref().len()
        )));
    }
    for (i, s) in spheres.get_ref().iter().enumerate() {
        let finite = s.iter().all(|v| v.is_finite() && (*v as f32).is_finite());
        if !finite || s[3] < 0.0 {
            return Err(at(format!(
                "sphere {} {s:?}: expected [x, y, z, radius], finite, radius >= 0",
                i + 1
            )));
        }
    }
    let columns = match &m.obstacle_columns {
        None => ["x", "y", "z"].map(String::from),
        Some(c) => c
            .get_ref()
            .clone()
            .try_into()
            .map_err(|names: Vec<String>| {
                p.at(
                    c.span(),
                    "[movement] obstacle_columns",
                    format!(
                        "{} names: expected three, the position columns of x, y, z",
                        names.len()
                    ),
                )
            })?,
    };
    Ok(Some(Obstacles {
        spheres: spheres.get_ref().clone(),
        columns,
    }))
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
        if let Err(fault) = check(&file, Wanted::File) {
            return Err(p.at(
                d.file.span(),
                "[[demo]] file",
                format!("{}: {fault}", file.display()),
            ));
        }
        out.push(TaskDemo { file, query: q });
    }
    Ok(out)
}

fn limits(
    p: &Place,
    movement: Option<&Spanned<MovementKeys>>,
    dir: &Path,
    pour: bool,
) -> Result<Option<LimitsSpec>, Error> {
    let m = movement.map(Spanned::get_ref);
    let robot = m.and_then(|m| m.robot.as_ref());
    let columns = m.and_then(|m| m.limits.as_ref());
    let workspace = m.and_then(|m| m.workspace.as_ref());
    let robot_keys = [
        ("base", m.and_then(|m| m.base.as_ref()).map(Spanned::span)),
        ("tip", m.and_then(|m| m.tip.as_ref()).map(Spanned::span)),
        ("tool", m.and_then(|m| m.tool.as_ref()).map(Spanned::span)),
        (
            "max_acceleration",
            m.and_then(|m| m.max_acceleration.as_ref())
                .map(Spanned::span),
        ),
        ("start", m.and_then(|m| m.start.as_ref()).map(Spanned::span)),
    ];
    let robot_key = robot_keys
        .iter()
        .find_map(|(key, span)| Some((*key, span.clone()?)));
    if pour {
        if let Some(span) = robot
            .map(Spanned::span)
            .or(columns.map(Spanned::span))
            .or(workspace.map(Spanned::span))
            .or(robot_key.as_ref().map(|(_, s)| s.clone()))
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
    if let Some(c) = columns {
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
    }
    match (robot, columns) {
        (Some(r), columns) => {
            if let Some(w) = workspace {
                return Err(p.at(
                    w.span(),
                    "[movement.workspace]",
                    "a workspace box limits position columns, not a robot's joints",
                ));
            }
            let spec = robot_spec(p, r, m, columns, dir)?;
            let chain = spec
                .chain()
                .map_err(|e| p.at(r.span(), "[movement] robot", e))?;
            if let Some(start) = m.and_then(|m| m.start.as_ref()) {
                spec.start(&chain)
                    .map_err(|e| p.at(start.span(), "[movement] start", e))?;
            }
            Ok(Some(LimitsSpec::Robot(spec)))
        }
        (None, Some(c)) => {
            if let Some((key, span)) = robot_key {
                return Err(p.at(
                    span,
                    &format!("[movement] {key}"),
                    "a robot's setting: give the robot (`robot = \"lwr4\"` or its URDF file)",
                ));
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
        (None, None) => Err(Error::Invalid(format!(
            "{}:{}: [movement]: no limits: give the robot (`robot = \"lwr4\"` or its URDF \
             file) or [movement.limits] for every column (nothing leaves primo unchecked)",
            p.name,
            movement.map_or(1, |m| p.line(m.span().start))
        ))),
    }
}

/// `[movement] robot` and its settings: the preset `lwr4`, or a URDF file
/// (beside the task file, or absolute) with its chain's base and tip and
/// `[movement.limits]` by joint; a tool frame and an acceleration bound
/// for either.
fn robot_spec(
    p: &Place,
    r: &Spanned<String>,
    m: Option<&MovementKeys>,
    columns: Option<&Spanned<BTreeMap<String, ColumnRange>>>,
    dir: &Path,
) -> Result<RobotSpec, Error> {
    let name = r.get_ref();
    let preset = name == "lwr4";
    let model = if preset {
        RobotModel::Preset(name.clone())
    } else {
        let file = dir.join(name);
        if let Err(fault) = check(&file, Wanted::File) {
            return Err(p.at(
                r.span(),
                "[movement] robot",
                format!(
                    "`{name}`: {}: {fault} (give the preset `lwr4` or the robot's URDF file)",
                    file.display()
                ),
            ));
        }
        RobotModel::Urdf(file)
    };
    let link = |v: Option<&Spanned<String>>, key: &str| -> Result<Option<String>, Error> {
        match v {
            Some(v) if preset => Err(p.at(
                v.span(),
                key,
                "the preset `lwr4` is its own chain: base and tip name a URDF's links",
            )),
            v => Ok(v.map(|v| v.get_ref().clone())),
        }
    };
    let base = link(m.and_then(|m| m.base.as_ref()), "[movement] base")?;
    let tip = link(m.and_then(|m| m.tip.as_ref()), "[movement] tip")?;
    if let Some(c) = columns.filter(|_| preset) {
        return Err(p.at(
            c.span(),
            "[movement.limits]",
            "the preset `lwr4` has its own joint limits; [movement.limits] gives a URDF's \
             joints theirs",
        ));
    }
    let tool = match m.and_then(|m| m.tool.as_ref()) {
        Some(t) => {
            let ToolKeys { xyz, rpy } = t.get_ref();
            let frame = [xyz[0], xyz[1], xyz[2], rpy[0], rpy[1], rpy[2]];
            if frame.iter().any(|v| !v.is_finite()) {
                return Err(p.at(t.span(), "[movement] tool", "xyz and rpy must be finite"));
            }
            if xyz.iter().any(|v| v.abs() > MAX_DISTANCE) {
                return Err(p.at(
                    t.span(),
                    "[movement] tool",
                    format!("xyz is farther than {MAX_DISTANCE} m from the tip (it is in m)"),
                ));
            }
            Some(frame)
        }
        None => None,
    };
    let max_acceleration = m
        .and_then(|m| m.max_acceleration.as_ref())
        .map(|v| positive(p, v, "[movement] max_acceleration"))
        .transpose()?;
    Ok(RobotSpec {
        model,
        base,
        tip,
        tool,
        limits: columns.map(|c| c.get_ref().clone()).unwrap_or_default(),
        max_acceleration,
        start: m
            .and_then(|m| m.start.as_ref())
            .map(|s| s.get_ref().clone())
            .unwrap_or_default(),
    })
}

fn learner(
    p: &Place,
    raw: &Spanned<LearnerKeys>,
    dim: usize,
    demos: &[TaskDemo],
    pour: bool,
) -> Result<LearnerSettings, Error> {
    let l = raw.get_ref();
    // The built-in pour is `primo pour`: PoWER with the paper's roll-outs
    // per update and decay, and the paper's reward.
    let fixed_by_the_pour = [
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
            "the built-in pour runs as `primo pour`, with the paper's setting (and reward) here \
             (its PoWER takes s1, s2 and sampler)",
        ));
    }
    let method = *l.method.get_ref();
    if pour && method.learns_goals() {
        return Err(p.at(
            l.method.span(),
            "[learner] method",
            "secant-goals learns the goals of the task's own demonstrations; the built-in pour \
             learns the bottle's volume: use another learner",
        ));
    }
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
        Some(v) if !(1..=MAX_ROLLOUTS).contains(v.get_ref()) => {
            return Err(p.at(
                v.span(),
                "[learner] max_rollouts",
                format!(
                    "{}: must be from 1 to {MAX_ROLLOUTS} roll-outs",
                    v.get_ref()
                ),
            ));
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
        None => method.default_sampler(),
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
    if method.learns_goals()
        && let Some(b) = g.low.as_ref().or(g.high.as_ref())
    {
        return Err(p.at(
            b.span(),
            "[goal] low, high",
            "secant-goals keeps the query at `desired` and searches the goals: bound them with \
             [learner] goals_min and goals_max",
        ));
    }
    let low = bound(&g.low, "[goal] low")?;
    let high = bound(&g.high, "[goal] high")?;
    let precision = g
        .precision
        .as_ref()
        .map(|v| positive(p, v, "[goal] precision"))
        .transpose()?;
    // The learners take it as f32: it must stay positive and finite there.
    if let (Some(v), Some(x)) = (&g.precision, precision)
        && !((x as f32).is_finite() && x as f32 > 0.0)
    {
        let why = format!("{x}: must be a positive number");
        return Err(p.at(v.span(), "[goal] precision", why));
    }
    let need = |what: &str| {
        Error::Invalid(format!(
            "{}:{}: [goal]: error learning needs `{what}`",
            p.name,
            p.line(raw.span().start)
        ))
    };
    let (low, high, precision) = match (low, high, precision) {
        (Some(l), Some(h), Some(pr)) => (l, h, pr),
        (_, _, None) if method.learns_goals() => return Err(need("precision")),
        (_, _, Some(pr)) if method.learns_goals() => (Vec::new(), Vec::new(), pr),
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

/// `[learner] goals`, `goals_min` and `goals_max`: secant-goals' only,
/// one value per value of the error (the query's `dim`); the columns and
/// their default bounds are found on the skill ([`super::goals`]).
fn goal_search(
    p: &Place,
    l: &LearnerKeys,
    dim: usize,
    method: Algorithm,
) -> Result<Option<GoalSearch>, Error> {
    let keys = [
        ("goals", l.goals.as_ref().map(Spanned::span)),
        ("goals_min", l.goals_min.as_ref().map(Spanned::span)),
        ("goals_max", l.goals_max.as_ref().map(Spanned::span)),
    ];
    if !method.learns_goals() {
        return match keys.iter().find_map(|(key, s)| Some((key, s.clone()?))) {
            Some((key, span)) => Err(p.at(
                span,
                &format!("[learner] {key}"),
                format!("a setting of secant-goals; this task's method is {method}"),
            )),
            None => Ok(None),
        };
    }
    let columns = match &l.goals {
        None => Vec::new(),
        Some(c) => {
            let names = c.get_ref();
            let at = |why: String| p.at(c.span(), "[learner] goals", why);
            if names.len() != dim {
                return Err(at(format!(
                    "{} column(s); the demonstrations' queries, and so the error, have {dim} \
                     value(s): one goal is learned per value",
                    names.len()
                )));
            }
            if let Some(twice) = (names.iter().enumerate()).find(|(i, n)| names[..*i].contains(n)) {
                return Err(at(format!("`{}` is named twice", twice.1)));
            }
            names.clone()
        }
    };
    let bound = |v: &Option<Spanned<Vec<f64>>>, key: &str| {
        (v.as_ref().map(|v| query(p, v, key, dim)))
            .transpose()
            .map(Option::unwrap_or_default)
    };
    let min = bound(&l.goals_min, "[learner] goals_min")?;
    let max = bound(&l.goals_max, "[learner] goals_max")?;
    if let (Some(span), Some((i, (lo, hi)))) = (
        l.goals_max.as_ref().map(Spanned::span),
        (min.iter().zip(&max).enumerate()).find(|(_, (lo, hi))| lo >= hi),
    ) {
        return Err(p.at(
            span,
            "[learner] goals_max",
            format!("value {} is {hi}, not above goals_min's {lo}", i + 1),
        ));
    }
    Ok(Some(GoalSearch { columns, min, max }))
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
            "for `command` evaluators, the time one may take to answer (the operator takes the \
             time needed)",
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
            .map(|t| match positive(p, t, "[evaluate] timeout")? {
                secs if secs > MAX_TIMEOUT => Err(p.at(
                    t.span(),
                    "[evaluate] timeout",
                    format!("an evaluator may take at most {MAX_TIMEOUT} s"),
                )),
                secs => Ok(secs),
            })
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

#[cfg(test)]
mod tests {
    use super::*;

    const THROW: &str = r#"version = 1

[[demo]]
file = "demos/fast.csv"
query = [1.8]

[[demo]]
file = "demos/slow.csv"
query = [1.0]

[movement.limits]
shoulder = { min = -2.5, max = 1.0, max_speed = 10.0 }

[goal]
desired = [1.5]
low = [1.0]
high = [1.9]
precision = 0.005

[learner]
method = "golden"

[evaluate]
command = ["python3", "throw.py"]
"#;

    /// A lab directory with the demonstrations' files (the checks only
    /// look that they exist; `build` reads them).
    fn lab() -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("primo-task-check-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("demos")).unwrap();
        for name in ["fast", "slow"] {
            std::fs::write(dir.join(format!("demos/{name}.csv")), "t,shoulder\n0,0\n").unwrap();
        }
        dir
    }

    fn parse(text: &str) -> Result<Task, Error> {
        Task::parse(&lab().join("throw.toml"), text)
    }

    /// The refusal's message, the lab's path as `/lab`.
    fn refused(text: &str) -> String {
        let e = parse(text).unwrap_err().to_string();
        e.replace(&lab().display().to_string(), "/lab")
    }

    /// The example task with `keys` in a `[movement]` table.
    fn with_movement(keys: &str) -> String {
        THROW.replace(
            "[movement.limits]",
            &format!("[movement]\n{keys}\n\n[movement.limits]"),
        )
    }

    #[test]
    fn the_generalization_is_lwr_gpr_or_promp() {
        let with = |value: &str| with_movement(&format!("generalization = {value}"));
        let task = parse(&with("\"promp\"")).unwrap();
        assert_eq!(task.regression, Regression::ProMp { ridge: PROMP_RIDGE });
        assert_eq!(
            refused(&with("\"knn\"")),
            "/lab/throw.toml:12: [movement] generalization: `knn`: must be `lwr`, `gpr` or \
             `promp`"
        );
    }

    #[test]
    fn via_points_are_times_columns_and_values() {
        let task = parse(&with_movement("via = [[0.2, \"shoulder\", -1.5]]")).unwrap();
        assert_eq!(task.vias, vec![(0.2, "shoulder".to_string(), -1.5)]);
        assert_eq!(
            refused(&with_movement("via = [[0, \"shoulder\", -1.5]]")),
            "/lab/throw.toml:12: [movement] via: via-point 1 [0, \"shoulder\", -1.5]: needs a \
             time > 0 s and a value, both finite"
        );
        let e = refused(&with_movement("via = [[0.2, -1.5]]"));
        assert!(e.starts_with("/lab/throw.toml:12:"), "{e}");
    }

    #[test]
    fn a_final_velocity_is_at_rest_or_demonstrated() {
        let with = |value: &str| with_movement(&format!("final_velocity = {value}"));
        assert_eq!(parse(THROW).unwrap().final_velocity, FinalVelocity::AtRest);
        let task = parse(&with("\"demonstrated\"")).unwrap();
        assert_eq!(task.final_velocity, FinalVelocity::Demonstrated);
        assert_eq!(
            refused(&with("\"fast\"")),
            "/lab/throw.toml:12: [movement] final_velocity: `fast`: must be `rest` or \
             `demonstrated`"
        );
    }

    #[test]
    fn a_phase_stop_is_a_positive_gain() {
        assert_eq!(parse(THROW).unwrap().phase_stop, None);
        let task = parse(&with_movement("phase_stop = 1e4")).unwrap();
        assert_eq!(task.phase_stop, Some(1e4));
        for (value, says) in [
            ("0", "0: must be a positive number"),
            ("1e300", "1e300: too large"),
        ] {
            assert_eq!(
                refused(&with_movement(&format!("phase_stop = {value}"))),
                format!("/lab/throw.toml:12: [movement] phase_stop: {says}")
            );
        }
    }

    #[test]
    fn a_limit_push_takes_a_positive_margin_and_gain() {
        let with = with_movement;
        assert_eq!(parse(THROW).unwrap().limit_push, None);
        let push = parse(&with("limit_margin = 0.1"))
            .unwrap()
            .limit_push
            .unwrap();
        assert_eq!((push.margin, push.gain), (0.1, 50.0));
        let push = parse(&with("limit_margin = 0.1\nlimit_gain = 20"))
            .unwrap()
            .limit_push
            .unwrap();
        assert_eq!(push.gain, 20.0);
        for (keys, says) in [
            (
                "limit_margin = -0.1",
                "/lab/throw.toml:12: [movement] limit_margin: -0.1: must be a positive number",
            ),
            (
                "limit_gain = 20",
                "/lab/throw.toml:12: [movement] limit_gain: given without limit_margin",
            ),
        ] {
            assert_eq!(refused(&with(keys)), says);
        }
    }

    #[test]
    fn obstacles_are_spheres_in_three_columns() {
        let with = with_movement;
        let task = parse(&with("obstacles = [[0.5, 0.5, 0.5, 0.1]]")).unwrap();
        let o = task.obstacles.unwrap();
        assert_eq!(o.spheres, vec![[0.5, 0.5, 0.5, 0.1]]);
        assert_eq!(o.columns, ["x", "y", "z"].map(String::from));
        let task = parse(&with(
            "obstacles = [[0.5, 0.5, 0.5, 0.1], [1, 2, 3, 0]]\nobstacle_columns = [\"a\", \"b\", \"c\"]",
        ))
        .unwrap();
        assert_eq!(
            task.obstacles.unwrap().columns,
            ["a", "b", "c"].map(String::from)
        );
        for (keys, says) in [
            (
                "obstacles = [[0.5, 0.5, 0.5, -0.1]]",
                "/lab/throw.toml:12: [movement] obstacles: sphere 1 [0.5, 0.5, 0.5, -0.1]: \
                 expected [x, y, z, radius], finite, radius >= 0",
            ),
            (
                "obstacle_columns = [\"a\", \"b\", \"c\"]",
                "/lab/throw.toml:12: [movement] obstacle_columns: given without obstacles",
            ),
            (
                "obstacles = [[0.5, 0.5, 0.5, 0.1]]\nobstacle_columns = [\"a\", \"b\"]",
                "/lab/throw.toml:13: [movement] obstacle_columns: 2 names: expected three, the \
                 position columns of x, y, z",
            ),
        ] {
            assert_eq!(refused(&with(keys)), says);
        }
    }

    /// The example task learning its goals, `keys` added to `[learner]`.
    fn goals(keys: &str) -> String {
        THROW.replace("low = [1.0]\nhigh = [1.9]\n", "").replace(
            "method = \"golden\"",
            &format!("method = \"secant-goals\"\n{keys}"),
        )
    }

    #[test]
    fn secant_goals_takes_its_columns_and_bounds_one_per_error_value() {
        let task = parse(&goals("")).unwrap();
        assert_eq!(task.learner.method, Algorithm::SecantGoals);
        assert_eq!(
            task.goals,
            Some(GoalSearch {
                columns: Vec::new(),
                min: Vec::new(),
                max: Vec::new()
            })
        );
        assert!(task.goal.low.is_empty() && task.goal.high.is_empty());
        let keys = "goals = [\"elbow\"]\ngoals_min = [0.1]\ngoals_max = [0.9]";
        let search = parse(&goals(keys)).unwrap().goals.unwrap();
        assert_eq!(
            (search.columns, search.min, search.max),
            (vec!["elbow".to_string()], vec![0.1], vec![0.9])
        );
        assert!(parse(THROW).unwrap().goals.is_none());
        for (task, says) in [
            (
                goals("goals = [\"shoulder\", \"elbow\"]"),
                "/lab/throw.toml:20: [learner] goals: 2 column(s); the demonstrations' queries, \
                 and so the error, have 1 value(s): one goal is learned per value",
            ),
            (
                goals("goals_min = [0.5, 0.5]"),
                "/lab/throw.toml:20: [learner] goals_min: 2 values; the demonstrations' queries \
                 have 1",
            ),
            (
                goals("goals_min = [0.5]\ngoals_max = [0.5]"),
                "/lab/throw.toml:21: [learner] goals_max: value 1 is 0.5, not above \
                 goals_min's 0.5",
            ),
            (
                goals("goals_max = [inf]"),
                "/lab/throw.toml:20: [learner] goals_max: inf is not a finite number",
            ),
            (
                THROW.replace("method = \"golden\"", "method = \"secant-goals\""),
                "/lab/throw.toml:16: [goal] low, high: secant-goals keeps the query at `desired` \
                 and searches the goals: bound them with [learner] goals_min and goals_max",
            ),
            (
                goals("").replace("precision = 0.005\n", ""),
                "/lab/throw.toml:14: [goal]: error learning needs `precision`",
            ),
            (
                THROW.replace(
                    "method = \"golden\"",
                    "method = \"golden\"\ngoals = [\"elbow\"]",
                ),
                "/lab/throw.toml:22: [learner] goals: a setting of secant-goals; this task's \
                 method is golden",
            ),
        ] {
            assert_eq!(refused(&task), says);
        }
        let pour = r#"version = 1

[goal]
desired = [0.5]
precision = 0.002

[learner]
method = "secant-goals"

[evaluate]
builtin = "pour"
"#;
        assert_eq!(
            refused(pour),
            "/lab/throw.toml:8: [learner] method: secant-goals learns the goals of the task's \
             own demonstrations; the built-in pour learns the bottle's volume: use another \
             learner"
        );
    }

    #[test]
    fn a_task_takes_its_defaults_and_its_places_from_the_file() {
        let task = parse(THROW).unwrap();
        assert_eq!(task.demos[0].file, lab().join("demos/fast.csv"));
        assert_eq!(task.demos[1].query, vec![1.0]);
        assert_eq!(task.kernels, 30);
        assert_eq!(task.regression, Regression::Lwr { bandwidth: None });
        assert_eq!(task.dt, None);
        assert_eq!(task.query_dim(), 1);
        assert_eq!(task.learner.method, Algorithm::Golden);
        assert_eq!(task.learner.reward, RewardRule::Linear);
        assert_eq!(task.learner.decay, QUERY_DECAY);
        let Evaluate::Command { argv, dir, timeout } = &task.evaluate else {
            panic!("{:?}", task.evaluate)
        };
        assert_eq!(argv, &["python3", "throw.py"]);
        assert_eq!(dir, &lab());
        assert_eq!(*timeout, DEFAULT_TIMEOUT);
        let Some(LimitsSpec::Columns { columns, workspace }) = &task.limits else {
            panic!("{:?}", task.limits)
        };
        assert_eq!(columns["shoulder"].max_speed, 10.0);
        assert!(workspace.is_none());
    }

    #[test]
    fn a_refusal_names_the_file_the_line_and_the_key() {
        let e = refused(&THROW.replace("version = 1", "version = 2"));
        assert!(
            e.starts_with("/lab/throw.toml:1: version: 2: this primo reads"),
            "{e}"
        );
        let e = refused(&THROW.replace("[learner]\n", "[learner]\nspeed = 1\n"));
        assert!(
            e.starts_with("/lab/throw.toml:21: unknown field `speed`"),
            "{e}"
        );
        let e = refused(&THROW.replace(
            "[movement.limits]",
            "[movement]\nkernels = 1\n\n[movement.limits]",
        ));
        assert!(
            e.starts_with("/lab/throw.toml:12: [movement] kernels: 1: must be in 2..="),
            "{e}"
        );
        let e = refused(&THROW.replace(
            "[movement.limits]",
            "[movement]\nscaling = \"both\"\n\n[movement.limits]",
        ));
        assert_eq!(
            e,
            "/lab/throw.toml:12: [movement] scaling: `both`: must be `per-dof`, `none` or `global`"
        );
        assert_eq!(parse(THROW).unwrap().scaling, AmplitudeScaling::PerDof);
        let global = THROW.replace(
            "[movement.limits]",
            "[movement]\nscaling = \"global\"\n\n[movement.limits]",
        );
        assert_eq!(parse(&global).unwrap().scaling, AmplitudeScaling::Global);
        let e = refused(&THROW.replace("desired = [1.5]", "desired = [1.5, 0.2]"));
        assert!(
            e.contains("[goal] desired: 2 values; the demonstrations' queries have 1"),
            "{e}"
        );
        let e =
            refused(&THROW.replace("command = [\"python3\", \"throw.py\"]", "command = [\"\"]"));
        assert!(e.contains("[evaluate] command: name the program"), "{e}");
    }

    #[test]
    fn a_skill_needs_two_demonstrations_except_the_built_in_pour() {
        let one = THROW.replacen(
            "[[demo]]\nfile = \"demos/fast.csv\"\nquery = [1.8]\n\n",
            "",
            1,
        );
        let e = refused(&one);
        assert!(
            e.contains("1 [[demo]]: a skill generalizes over at least two"),
            "{e}"
        );
        let pour = r#"version = 1

[goal]
desired = [0.5]
low = [0.1]
high = [1.5]
precision = 0.002

[learner]
method = "golden"

[evaluate]
builtin = "pour"
target = 0.2
"#;
        let task = parse(pour).unwrap();
        assert!(task.demos.is_empty() && task.limits.is_none());
        assert!(matches!(task.evaluate, Evaluate::Pour(PourTask { target, .. }) if target == 0.2));
    }

    /// A precision the f32 learners would see as 0 or infinite is refused
    /// here, not by the learner once the run has started.
    #[test]
    fn a_precision_beyond_f32_is_refused() {
        for precision in ["1e-300", "1e300"] {
            let e = refused(&THROW.replace("0.005", precision));
            assert!(e.contains("[goal] precision: "), "{e}");
            assert!(e.ends_with(": must be a positive number"), "{e}");
        }
    }

    #[test]
    fn an_unreadable_task_file_is_a_refused_setting() {
        let e = Task::load(Path::new("/nonexistent/task.toml")).unwrap_err();
        assert!(
            matches!(
                e,
                Error::Open {
                    setting: Setting::Task,
                    ..
                }
            ),
            "{e}"
        );
        assert!(e.is_input(), "{e}");
        assert!(e.to_string().contains("no such file or device"), "{e}");
    }
}
