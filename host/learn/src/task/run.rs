//! A task file's run as a kind of run ([`TaskRun`]): the lab's
//! demonstrations, query, limits and evaluator (a program of its own, or
//! the operator), and, if one is given, the robot that executes each
//! roll-out before the evaluator measures it ([`TaskCell`]). The built-in
//! pour task is a pour ([`Task::pour_start`]).
//!
//! With a robot, a roll-out's checked joint path goes to its
//! [`Executor`]; the joint positions it reports are written beside the
//! trajectory (`rollout-NNNN-executed.csv`), also when it fails. A roll-out
//! the robot did not complete ends the run ([`Error::RobotStopped`]) with
//! the log of the roll-outs before it; resuming the run (with the same
//! robot) makes that roll-out again.
//!
//! A roll-out: `θ = G(q̂) + Δθ` planned at the task's step, checked by the
//! task's limits (a rejected movement never leaves primo: reward 0 for
//! PoWER, a bound of the search for error learning), written as a CSV file
//! into `trajectories/` of the output directory, handed to the evaluator,
//! scored: `ε = desired − measured`, the reward the evaluator's or made
//! from `ε` by the task's rule. Every roll-out is logged as it is made, and
//! a resumed run continues exactly, as every run does ([`crate::run`]).

use std::path::{Path, PathBuf};

use primo_core::coupling::PhaseStop;
use primo_core::power::PowerConfig;
use primo_protocol::learner::{LearnerSetup, Setup};
use primo_robot::JointPath;
use primo_robot::envelope::Limits;
use primo_robot::execute::{Executed, Executor};
use primo_skill::Skill;
use primo_skill::csv::{Csv, write_rows};
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::algorithm::Algorithm;
use crate::clock::Seconds;
use crate::error::Setting;
use crate::learner::{power_blocks, setup, wire_query};
use crate::output::{create_dir, write_file};
use crate::pour::run::{CellSpec, Pour};
use crate::pour::settings::Settings;
use crate::pour::skill::{DemoFile, SkillSpec, Space};
use crate::rollouts::{Entry, MAX_ROLLOUTS, Point, Record, query_text};
use crate::run::{Cell, Execute, Kind, LearnerSpec, ON_SCALE, Start};

use super::change::Changes;
use super::evaluator::{Evaluator, Operator, Program, Prompt};
use super::goals::{LearnedGoals, point};
use super::report::{Finished, write_task};
use super::trial::{TaskTrial, score};
use super::{Built, Evaluate, Task};

/// Where the roll-outs' trajectories go, in the output directory.
pub const TRAJECTORIES: &str = "trajectories";

/// A task file's run: the task, as checked when the run began, and the
/// seed of exploration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TaskRun {
    /// The task.
    pub task: Task,
    /// Seed of exploration.
    pub seed: u64,
    /// The robot that executes the roll-outs (its address, as given), if
    /// any: a resumed run needs the same.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub robot: Option<String>,
}

/// Who and what is at a task's cell: the operator, asked when the task's
/// evaluator is the operator, and the robot that executes each roll-out,
/// if one is given (its address, as [`TaskRun::robot`] logs it, and its
/// driver).
pub struct TaskCell {
    /// The operator.
    pub prompt: Box<dyn Prompt>,
    /// The robot.
    pub robot: Option<Robot>,
}

/// A robot that executes roll-outs: its address, as given, and its driver.
pub type Robot = (String, Box<dyn Executor>);

impl Kind for TaskRun {
    const NAME: &'static str = "task";
    type Trial = TaskTrial;
    type Built = Built;
    type Person = TaskCell;
    type Moved = Changes;
    type Note = std::convert::Infallible;
    type Finished = Finished;

    fn validate(&self, learner: &LearnerSpec) -> Result<(), Error> {
        if learner.on_scale() {
            return Err(Error::setting(
                Setting::Coprocessor,
                ON_SCALE,
                "a task's own evaluator weighs nothing of primo's: the learner runs on \
                 primo's scale only in the built-in pour on a real cell",
            ));
        }
        if self.task.phase_stop.is_some() && self.robot.is_none() {
            return Err(Error::Invalid(
                "[movement] phase_stop: slows the robot that executes the roll-outs while it \
                 lags its command, and no robot executes them"
                    .into(),
            ));
        }
        let budget = self.task.learner.max_rollouts;
        if !(1..=MAX_ROLLOUTS).contains(&budget) {
            return Err(Error::setting(
                Setting::MaxRollouts,
                budget,
                format!("must be from 1 to {MAX_ROLLOUTS} roll-outs"),
            ));
        }
        Ok(())
    }

    fn check_moved(changes: &Changes) -> Result<(), Error> {
        match changes.max_rollouts {
            Some(0) => Err(Error::Invalid("a budget of 0 roll-outs makes none".into())),
            _ => Ok(()),
        }
    }

    /// Version 1 logs are the same.
    fn reads(version: u32, _: &Self) -> bool {
        version == 1
    }

    fn resume(&mut self, changes: Changes, _: &Path) -> Result<Vec<String>, Error> {
        self.task.take(changes)
    }

    fn build(&self, _: &mut dyn FnMut(Self::Note) -> Result<(), Error>) -> Result<Built, Error> {
        self.task.build()
    }

    fn skill(built: &Built) -> &Skill {
        &built.skill
    }

    fn method(&self) -> Algorithm {
        self.task.learner.method
    }

    fn setup(&self, built: &Built) -> Result<Setup, Error> {
        task_setup(&self.task, built, self.seed)
    }

    fn point(built: &Built, query: &[f32], delta: &[f32]) -> Point {
        match &built.goals {
            Some(goals) => goals.point(delta),
            None => Point::query(query),
        }
    }

    fn max_rollouts(&self) -> u32 {
        self.task.learner.max_rollouts
    }

    fn execution<'a>(
        &'a self,
        built: &'a Built,
        at: Cell<'_, Self>,
    ) -> Result<Box<dyn Execute<TaskTrial> + 'a>, Error> {
        // Absolute: the evaluator runs in the task file's directory.
        let trajectories =
            std::path::absolute(at.dir.join(TRAJECTORIES)).map_err(Error::io(at.dir))?;
        create_dir(&trajectories)?;
        let dim = self.task.query_dim();
        let TaskCell { prompt, robot } = at.person;
        let mut robot = match (robot, &self.robot) {
            (None, None) => None,
            (Some((given, robot)), Some(logged)) if &given == logged => Some(robot),
            (Some((given, _)), logged) => {
                return Err(Error::Invalid(match logged {
                    Some(logged) => format!(
                        "this run's roll-outs were executed by the robot {logged}, not {given}"
                    ),
                    None => format!(
                        "this run's roll-outs were not executed by a robot; {given} cannot join                          it (start a new run)"
                    ),
                }));
            }
            (None, Some(logged)) => {
                return Err(Error::Invalid(format!(
                    "this run's roll-outs are executed by the robot {logged}: give it again to                      resume"
                )));
            }
        };
        if let (Some(gain), Some(executor)) = (self.task.phase_stop, robot.as_mut()) {
            phase_stop(executor, self.robot.as_deref().unwrap_or_default(), gain)?;
        }
        if robot.is_some() && !matches!(built.limits, Limits::Robot(_)) {
            return Err(Error::Invalid(
                "a robot executes joint paths: the task's [movement] needs its robot (`robot =                  \"lwr4\"` or its URDF file), whose limits every roll-out passes"
                    .into(),
            ));
        }
        let evaluator: Box<dyn Evaluator> = match &self.task.evaluate {
            Evaluate::Command { argv, dir, timeout } => {
                Box::new(Program::start(argv, dir, *timeout, dim)?)
            }
            Evaluate::Operator => Box::new(Operator::new(
                prompt,
                dim,
                self.task.learner.method.uses_error(),
            )),
            Evaluate::Pour(_) => {
                return Err(Error::Invalid(
                    "the built-in pour runs as a pour (Task::pour_start)".into(),
                ));
            }
        };
        Ok(Box::new(Rollouts {
            task: &self.task,
            skill: &built.skill,
            goals: built.goals.as_ref(),
            limits: &built.limits,
            dt: built.dt,
            dir: trajectories,
            evaluator,
            robot,
        }))
    }

    fn report(
        &self,
        built: &Built,
        dir: &Path,
        run: &[Entry<TaskTrial>],
        seconds: Seconds,
    ) -> Result<Finished, Error> {
        write_task(dir, &self.task, &built.skill, run, seconds)
    }
}

/// The learner's setup for `task` on what it `built`.
pub fn task_setup(task: &Task, built: &Built, seed: u64) -> Result<Setup, Error> {
    let (l, g, skill) = (&task.learner, &task.goal, &built.skill);
    let bounds = (&g.low[..], &g.high[..], &g.desired[..]);
    let searched = match &built.goals {
        Some(goals) => Some(goals.setup(task)?),
        None => (l.method).search(bounds, g.precision as f32, l.max_rollouts, l.gain)?,
    };
    let learner = match searched {
        Some(learner) => learner,
        None => {
            let blocks = power_blocks(skill, l.s1, l.s2, l.decay)?;
            let config = PowerConfig {
                rollouts_per_update: l.rollouts_per_update,
                sampler: l.sampler,
                query_gain: l.method.query_gain(l.gain),
                ..PowerConfig::paper(&blocks).map_err(|e| Error::Invalid(format!("PoWER: {e}")))?
            };
            LearnerSetup::Power {
                config,
                query: wire_query(&g.desired)?,
            }
        }
    };
    setup(skill, learner, seed)
}

/// `[movement] phase_stop` for the robot `name` that executes the
/// roll-outs: refused when its driver cannot wait for it.
fn phase_stop(robot: &mut Box<dyn Executor>, name: &str, gain: f64) -> Result<(), Error> {
    let gain = PhaseStop::new(gain as f32)
        .map_err(|e| Error::Invalid(format!("[movement] phase_stop {gain}: {e}")))?;
    if robot.phase_stop(gain) {
        return Ok(());
    }
    Err(Error::Invalid(format!(
        "[movement] phase_stop: the robot {name} executes each whole trajectory on its own \
         controller, which cannot wait for it; phase stopping needs a driver that streams \
         every setpoint (a Franka)"
    )))
}

/// One roll-out of `task`: plan, check, write, evaluate, score.
struct Rollouts<'a> {
    task: &'a Task,
    skill: &'a Skill,
    goals: Option<&'a LearnedGoals>,
    limits: &'a Limits,
    dt: f64,
    dir: PathBuf,
    evaluator: Box<dyn Evaluator>,
    robot: Option<Box<dyn Executor>>,
}

impl Rollouts<'_> {
    /// Executes roll-out `rollout`'s `path` on the robot, if there is one,
    /// and writes what it reported beside the trajectory.
    fn execute(&mut self, rollout: u32, path: Option<&JointPath>) -> Result<(), Error> {
        let Some(robot) = &mut self.robot else {
            return Ok(());
        };
        let Some(path) = path else {
            return Err(Error::Invalid(format!(
                "roll-out {rollout}: a robot executes joint paths, and this one has none"
            )));
        };
        let done = robot.execute(path);
        let executed = match &done {
            Ok(executed) => executed,
            Err(failed) => &failed.executed,
        };
        let file = self.dir.join(format!("rollout-{rollout:04}-executed.csv"));
        write_file(&file, &executed_csv(path, executed))?;
        done.map(|_| ()).map_err(|failed| {
            Error::RobotStopped(format!(
                "roll-out {rollout}: the robot did not complete it: {failed}"
            ))
        })
    }
}

/// The joint positions a robot reported executing `path`: `t` and the
/// path's joints, a row a report.
pub fn executed_csv(path: &JointPath, executed: &Executed) -> Vec<u8> {
    let mut csv = Csv::new();
    csv.text("t");
    for name in path.chain().names() {
        csv.text(name);
    }
    csv.end_row();
    for (t, q) in executed.times.iter().zip(executed.rows(path.chain().dof())) {
        csv.seconds(*t);
        for v in q {
            csv.display(v);
        }
        csv.end_row();
    }
    csv.into_bytes()
}

impl Execute<TaskTrial> for Rollouts<'_> {
    fn roll(&mut self, rollout: u32, query: &[f32], delta: &[f32]) -> Result<TaskTrial, Error> {
        let goals = (self.goals)
            .map(|g| g.rolled_out(delta))
            .unwrap_or_default();
        let rejected = |why: String| TaskTrial {
            measured: None,
            error: Vec::new(),
            reward: 0.0,
            rejected: Some(why),
            failed: None,
            goals: goals.clone(),
        };
        let plan = match self.skill.plan(query, delta, self.dt) {
            Ok(plan) => plan,
            Err(why) => return Ok(rejected(why.to_string())),
        };
        let checked = match self.limits.check(self.skill.names(), plan.t, &plan.rows) {
            Ok(c) => c,
            Err(why) => return Ok(rejected(why.to_string())),
        };
        let mut csv = Vec::new();
        let (names, rows) = checked.table();
        write_rows(
            &mut csv,
            &names,
            checked
                .times()
                .iter()
                .zip(rows.chunks_exact(names.len()))
                .map(|(t, row)| (*t as f32, row.iter().map(|v| *v as f32))),
        )
        .map_err(Error::io(&self.dir))?;
        let file = self.dir.join(format!("rollout-{rollout:04}.csv"));
        write_file(&file, &csv)?;
        self.execute(rollout, checked.path())?;
        let answer = self.evaluator.evaluate(rollout, &file)?;
        Ok(TaskTrial {
            goals,
            ..score(self.task, rollout, answer)?
        })
    }
}

impl Task {
    /// The `primo pour` run this task is, if it is the built-in pour:
    /// the same roll-outs as `primo pour` with the same settings and seed.
    pub fn pour_start(&self, out: PathBuf, force: bool, seed: u64) -> Option<Start<Pour>> {
        let Evaluate::Pour(p) = &self.evaluate else {
            return None;
        };
        let method = self.learner.method;
        let bottle = f64::from(self.goal.desired.first().copied().unwrap_or(0.0));
        let defaults = Settings::paper(method, bottle, p.target, seed);
        let error_learning = !method.is_power();
        let skill = SkillSpec {
            space: p.space.unwrap_or(Space::default_for(method)),
            glass: p.glass,
            kernels: self.kernels,
            demos: self
                .demos
                .iter()
                .map(|d| DemoFile {
                    file: d.file.clone(),
                    volume: d.query.first().copied().unwrap_or(0.0),
                })
                .collect(),
        };
        let settings = Settings {
            max_rollouts: self.learner.max_rollouts,
            gain: self.learner.gain,
            precision: if error_learning {
                self.goal.precision
            } else {
                defaults.precision
            },
            search: if error_learning {
                [
                    self.goal.low.first().copied().unwrap_or(0.0),
                    self.goal.high.first().copied().unwrap_or(0.0),
                ]
            } else {
                defaults.search
            },
            s1: self.learner.s1,
            s2: self.learner.s2,
            sampler: self.learner.sampler,
            // The simulated glass, as `primo pour` has it.
            glass_holds: Some(skill.cell().glass_litres()),
            ..defaults
        };
        Some(Start::New {
            out,
            force,
            run: Pour {
                settings,
                skill,
                cell: CellSpec::Simulated,
            },
        })
    }
}

/// A roll-out as a line of progress.
pub fn rollout_line(r: &Record<TaskTrial>) -> String {
    let t = &r.trial;
    // Learning goals, the query is the desired one: the goals are news.
    let q = match t.goals.is_empty() {
        true => format!("q {}", query_text(&r.query)),
        false => point(r).to_string(),
    };
    if let Some(why) = &t.rejected {
        return format!("roll-out {:>3}: {q}  REJECTED ({why})  reward 0", r.rollout);
    }
    if let Some(why) = &t.failed {
        return format!("roll-out {:>3}: {q}  FAILED ({why})  reward 0", r.rollout);
    }
    let measured = t.measured.as_ref().map_or(String::new(), |m| {
        let m: Vec<f32> = m.iter().map(|v| *v as f32).collect();
        let e: Vec<f32> = t.error.iter().map(|v| *v as f32).collect();
        format!("  measured {}  error {}", query_text(&m), query_text(&e))
    });
    format!(
        "roll-out {:>3}: {q}{measured}  reward {:.3}{}",
        r.rollout,
        t.reward,
        if r.mean { "  (mean)" } else { "" }
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use primo_robot::execute::ExecutionFailed;

    /// A driver that hands each trajectory to its controller whole.
    struct Whole;
    impl Executor for Whole {
        fn execute(&mut self, _: &JointPath) -> Result<Executed, ExecutionFailed> {
            Ok(Executed::default())
        }
    }

    #[test]
    fn phase_stopping_is_refused_by_a_driver_that_cannot_wait() {
        let mut robot: Box<dyn Executor> = Box::new(Whole);
        let err = phase_stop(&mut robot, "ros2:/arm_controller", 1e4).unwrap_err();
        assert_eq!(
            err.to_string(),
            "[movement] phase_stop: the robot ros2:/arm_controller executes each whole \
             trajectory on its own controller, which cannot wait for it; phase stopping needs a \
             driver that streams every setpoint (a Franka)"
        );
    }
}
