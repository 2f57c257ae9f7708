//! A `primo learn` run of a task file: the lab's demonstrations, query,
//! limits and evaluator (a program of its own, or the operator). The
//! built-in pour task is a `primo pour` run ([`Task::pour_start`]).
//!
//! A roll-out: `θ = G(q̂) + Δθ` planned at the task's step, checked by the
//! task's limits (a rejected movement never leaves primo: reward 0 for
//! PoWER, the end of the run for error learning), written as a CSV file
//! into `trajectories/` of the output directory, handed to the evaluator,
//! scored: `ε = desired − measured`, the reward the evaluator's or made
//! from `ε` by the task's rule. Every roll-out is logged as it is made,
//! and `--resume` continues a run exactly, as for `primo pour`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use primo_core::power::PowerConfig;
use primo_protocol::learner::{LearnerSetup, Setup};
use primo_robot::envelope::Limits;
use primo_skill::Skill;
use primo_skill::csv::write_rows;
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::evaluator::{Answer, Evaluator, Operator, Program, Prompt};
use crate::learning::{
    Algorithm, Entry, Record, Scored, best, check_examples, examples_crc, learn_logged,
    power_blocks, query_text, setup, wire_query,
};
use crate::output::{check_dir, create_dir, write_file};
use crate::pour::{Failure, LearnerSpec, open_learner};
use crate::runlog::{RunEvent, RunLog};
use crate::task::{Evaluate, RewardRule, Task};

/// The log format's version of task runs.
pub const VERSION: u32 = 1;
/// Where the roll-outs' trajectories go, in the output directory.
pub const TRAJECTORIES: &str = "trajectories";

/// The first record of a task run's log.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// [`VERSION`].
    pub version: u32,
    /// The task, as checked when the run began.
    pub task: Task,
    /// Seed of exploration.
    pub seed: u64,
    /// CRC-32C of the skill's examples, bit for bit: changed demonstration
    /// files are caught on resume.
    pub examples: u32,
}

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

    fn rejected(&self) -> Option<&str> {
        self.rejected.as_deref()
    }
}

impl TaskTrial {
    /// The largest `|ε_i|`.
    pub fn worst_error(&self) -> Option<f64> {
        self.error.iter().map(|e| e.abs()).reduce(f64::max)
    }
}

/// A new run, or the continuation of one.
#[derive(Debug, Clone, PartialEq)]
pub enum Start {
    /// A new run of `task` logged in `out`.
    New {
        /// The checked task.
        task: Box<Task>,
        /// The output directory.
        out: PathBuf,
        /// Replace a finished run logged in `out`.
        force: bool,
        /// Seed of exploration.
        seed: u64,
    },
    /// Continue the run logged in `dir`.
    Resume {
        /// Its directory.
        dir: PathBuf,
    },
}

/// What kind of run a run log holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Logged {
    /// A task run.
    Task,
    /// A `primo pour` run.
    Pour,
}

/// Which kind of run `dir`'s log holds (`primo learn --resume` continues
/// both).
pub fn logged_kind(dir: &Path) -> Result<Logged, Error> {
    let file = dir.join(crate::runlog::FILE);
    let text = std::fs::read_to_string(&file).map_err(|e| {
        Error::Invalid(format!(
            "--resume {}: no run log there ({e})",
            dir.display()
        ))
    })?;
    // The header is the first record, `CRC JSON`; the log's own checks
    // come when it is opened.
    let first = text.lines().next().unwrap_or("");
    let json = first.split_once(' ').map_or("", |(_, json)| json);
    let header: serde_json::Value = serde_json::from_str(json).unwrap_or_default();
    Ok(if header.get("task").is_some() {
        Logged::Task
    } else {
        Logged::Pour
    })
}

/// What a run reports as it goes.
#[derive(Debug)]
pub enum Event<'a> {
    /// The learner and the log.
    Run(RunEvent<'a>),
    /// What is learned.
    Learning {
        /// The task.
        task: &'a Task,
        /// Parameters learned.
        parameters: usize,
    },
    /// A roll-out, made now or (`logged`) replayed from the log.
    Rollout {
        /// It.
        entry: &'a Entry<TaskTrial>,
        /// Replayed from the log.
        logged: bool,
    },
    /// The run is complete and its reports are written.
    Finished(&'a Finished),
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub struct Finished {
    /// The last roll-out (PoWER: the last roll-out of the mean).
    pub last: Record<TaskTrial>,
    /// Error learning reached the precision at this roll-out.
    pub converged_at: Option<u32>,
    /// The best roll-out.
    pub best: Option<Record<TaskTrial>>,
    /// The output directory.
    pub dir: PathBuf,
}

/// The report of a task run (`summary.json`).
#[derive(Debug, Serialize)]
struct Summary<'a> {
    task: &'a Path,
    method: Algorithm,
    query_dim: usize,
    desired: &'a [f32],
    parameters: usize,
    rollouts: usize,
    converged_at: Option<u32>,
    last: &'a Record<TaskTrial>,
    best: Option<&'a Record<TaskTrial>>,
    seconds: f64,
}

/// The learner's setup for `task` on its fitted `skill`.
pub fn task_setup(task: &Task, skill: &Skill, seed: u64) -> Result<Setup, Error> {
    let l = &task.learner;
    let g = &task.goal;
    let bounds = (&g.low[..], &g.high[..], &g.desired[..]);
    let learner = match l
        .method
        .search(bounds, g.precision as f32, l.max_rollouts, l.gain)?
    {
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

/// The reward of an error under the task's rule.
pub fn reward(rule: RewardRule, scale: f32, error: &[f64]) -> f64 {
    let norm = error.iter().map(|e| e * e).sum::<f64>().sqrt() * f64::from(scale);
    match rule {
        RewardRule::Linear => (1.0 - norm).max(0.0),
        RewardRule::Exp => (-norm * norm).exp(),
    }
}

/// Scores an evaluator's answer for `task`. A failed roll-out scores 0;
/// error learning cannot learn from it, so it ends the run (unlogged:
/// `--resume` tries it again).
fn score(task: &Task, rollout: u32, answer: Answer) -> Result<TaskTrial, Error> {
    let power = task.learner.method.is_power();
    if let Some(why) = answer.failed {
        if !power {
            return Err(Error::Instrument(format!(
                "roll-out {rollout} failed ({why}); error learning needs its measurement: fix \
                 the cause and --resume"
            )));
        }
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
                task.learner.method.name()
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

/// One roll-out of `task`: plan, check, write, evaluate, score.
struct Rollouts<'a> {
    task: &'a Task,
    skill: &'a Skill,
    limits: &'a Limits,
    dt: f64,
    dir: PathBuf,
    evaluator: Box<dyn Evaluator>,
}

impl Rollouts<'_> {
    fn roll(&mut self, rollout: u32, query: &[f32], delta: &[f32]) -> Result<TaskTrial, Error> {
        let rejected = |why: String| TaskTrial {
            measured: None,
            error: Vec::new(),
            reward: 0.0,
            rejected: Some(why),
            failed: None,
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
        let width = checked.names().len();
        write_rows(
            &mut csv,
            checked.names(),
            checked
                .times()
                .iter()
                .zip(checked.rows().chunks_exact(width))
                .map(|(t, row)| (*t as f32, row.iter().map(|v| *v as f32))),
        )
        .map_err(Error::io(&self.dir))?;
        let file = self.dir.join(format!("rollout-{rollout:04}.csv"));
        write_file(&file, &csv)?;
        let answer = self.evaluator.evaluate(rollout, &file)?;
        score(self.task, rollout, answer)
    }
}

impl Task {
    /// The `primo pour` run this task is, if it is the built-in pour:
    /// the same roll-outs as `primo pour` with the same settings and seed.
    pub fn pour_start(&self, out: PathBuf, force: bool, seed: u64) -> Option<crate::pour::Start> {
        let Evaluate::Pour(p) = &self.evaluate else {
            return None;
        };
        let method = self.learner.method;
        let bottle = f64::from(self.goal.desired.first().copied().unwrap_or(0.0));
        let defaults = crate::learning::Settings::paper(method, bottle, p.target, seed);
        let error_learning = !method.is_power();
        let skill = crate::pour::SkillSpec {
            space: p.space.unwrap_or(method.default_space()),
            glass: p.glass,
            kernels: self.kernels,
            demos: self
                .demos
                .iter()
                .map(|d| crate::pour::DemoFile {
                    file: d.file.clone(),
                    volume: d.query.first().copied().unwrap_or(0.0),
                })
                .collect(),
        };
        let settings = crate::learning::Settings {
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
            // The simulated glass, as `primo pour` has it.
            glass_holds: Some(skill.cell().glass_litres()),
            ..defaults
        };
        Some(crate::pour::Start::New {
            out,
            force,
            settings,
            skill,
            cell: crate::pour::CellSpec::Simulated,
        })
    }
}

/// `primo learn` of a task with its own evaluator: checks everything,
/// learns, logging every roll-out, and writes the reports; `prompt` asks
/// the operator (an operator task), `event` is told what happens. An error
/// from `event` (the output is gone) ends the run.
pub fn learn(
    start: Start,
    learner: &LearnerSpec,
    prompt: Box<dyn Prompt>,
    mut event: impl FnMut(Event) -> Result<(), Error>,
) -> Result<(), Failure> {
    let started = Instant::now();
    let (header, dir, logged, mut log, ended) = match start {
        Start::New {
            task,
            out,
            force,
            seed,
        } => {
            check_dir("--out", &out)?;
            RunLog::check_free(&out, force)?;
            let built = task.build()?;
            task_setup(&task, &built.skill, seed)?;
            let header = Header {
                version: VERSION,
                examples: examples_crc(&built.skill),
                task: *task,
                seed,
            };
            create_dir(&out)?;
            let log = RunLog::create(&out, &header, force)?;
            (header, out, Vec::new(), log, false)
        }
        Start::Resume { dir } => {
            let opened = RunLog::resume::<Header, Entry<TaskTrial>>(
                &dir,
                |h| h.version,
                VERSION,
                |e| event(Event::Run(e)),
            )?;
            (opened.header, dir, opened.entries, opened.log, opened.ended)
        }
    };
    let fail = |error: Error| Failure {
        error: Box::new(error),
        resumable: Some(dir.clone()),
    };
    let task = &header.task;
    let built = task.build().map_err(fail)?;
    check_examples(&built.skill, header.examples, &dir).map_err(fail)?;
    let (_qemu, mut learner, connected) = open_learner(learner).map_err(fail)?;
    if let Some(what) = connected {
        event(Event::Run(RunEvent::Learner(what))).map_err(fail)?;
    }
    event(Event::Learning {
        task,
        parameters: task.learner.method.learned_parameters(&built.skill),
    })
    .map_err(fail)?;
    let trajectories = dir.join(TRAJECTORIES);
    if !ended {
        create_dir(&trajectories).map_err(fail)?;
    }
    let dim = task.query_dim();
    let evaluator: Box<dyn Evaluator> = match &task.evaluate {
        // A complete run is only told again: nothing is evaluated.
        _ if ended => Box::new(Complete),
        Evaluate::Command { argv, dir, timeout } => {
            Box::new(Program::start(argv, dir, *timeout, dim).map_err(fail)?)
        }
        Evaluate::Operator => Box::new(Operator::new(prompt, dim)),
        Evaluate::Pour(_) => {
            return Err(fail(Error::Invalid(
                "the built-in pour runs as `primo pour` (Task::pour_start)".into(),
            )));
        }
    };
    let mut rollouts = Rollouts {
        task,
        skill: &built.skill,
        limits: &built.limits,
        dt: built.dt,
        dir: trajectories,
        evaluator,
    };
    let setup = task_setup(task, &built.skill, header.seed).map_err(fail)?;
    let run = learn_logged(
        &built.skill,
        setup,
        task.learner.max_rollouts,
        &mut learner,
        &logged,
        (&mut log, ended),
        |i, query, delta| rollouts.roll(i, query, delta),
        |entry, logged| event(Event::Rollout { entry, logged }),
    )
    .map_err(fail)?;
    let finished = report(&dir, task, &built.skill, &run, started).map_err(fail)?;
    event(Event::Finished(&finished)).map_err(fail)
}

/// The evaluator of a complete run: it is told its logged roll-outs again
/// and makes none.
struct Complete;

impl Evaluator for Complete {
    fn evaluate(&mut self, rollout: u32, _: &Path) -> Result<Answer, Error> {
        Err(Error::Log(format!(
            "the logged run is complete, yet the learner asks for roll-out {rollout}"
        )))
    }
}

/// Writes `rollouts.csv`, `summary.json` and `convergence.png`.
fn report(
    dir: &Path,
    task: &Task,
    skill: &Skill,
    run: &[Entry<TaskTrial>],
    started: Instant,
) -> Result<Finished, Error> {
    let records: Vec<&Record<TaskTrial>> = run.iter().map(|e| &e.record).collect();
    let last = records
        .iter()
        .rev()
        .find(|r| r.mean)
        .copied()
        .ok_or_else(|| Error::Learner("no roll-out was made".into()))?;
    let converged_at = match task.learner.method {
        m if m.is_power() => None,
        _ => records
            .iter()
            .find(|r| {
                r.trial
                    .worst_error()
                    .is_some_and(|e| e < task.goal.precision)
            })
            .map(|r| r.rollout),
    };
    let best = best(run).map(|e| &e.record);
    let dim = task.query_dim();
    let numbered = |name: &str| -> Vec<String> {
        (1..=dim)
            .map(|i| {
                if dim == 1 {
                    name.to_string()
                } else {
                    format!("{name}{i}")
                }
            })
            .collect()
    };
    let mut csv = ["rollout", "update", "mean"].map(String::from).to_vec();
    csv.extend(numbered("query"));
    csv.extend(numbered("measured"));
    csv.extend(numbered("error"));
    csv.extend(["reward", "rejected", "failed"].map(String::from));
    let mut text = csv.join(",") + "\n";
    let quote = |s: &Option<String>| {
        s.as_ref()
            .map_or(String::new(), |s| format!("\"{}\"", s.replace('"', "\"\"")))
    };
    for r in &records {
        let t = &r.trial;
        let mut row = vec![
            r.rollout.to_string(),
            r.update.to_string(),
            r.mean.to_string(),
        ];
        row.extend(r.query.iter().map(f32::to_string));
        let or_blank = |v: Option<&Vec<f64>>| -> Vec<String> {
            (0..dim)
                .map(|i| {
                    v.and_then(|v| v.get(i))
                        .map_or(String::new(), f64::to_string)
                })
                .collect()
        };
        row.extend(or_blank(t.measured.as_ref()));
        row.extend(or_blank((!t.error.is_empty()).then_some(&t.error)));
        row.push(t.reward.to_string());
        row.push(quote(&t.rejected));
        row.push(quote(&t.failed));
        text += &(row.join(",") + "\n");
    }
    write_file(&dir.join("rollouts.csv"), text.as_bytes())?;
    let summary = Summary {
        task: &task.file,
        method: task.learner.method,
        query_dim: dim,
        desired: &task.goal.desired,
        parameters: task.learner.method.learned_parameters(skill),
        rollouts: records.len(),
        converged_at,
        last,
        best,
        seconds: started.elapsed().as_secs_f64(),
    };
    let mut json = serde_json::to_string_pretty(&summary)
        .map_err(|e| Error::Report(format!("summary: {e}")))?;
    json.push('\n');
    write_file(&dir.join("summary.json"), json.as_bytes())?;
    crate::report::write_task_chart(dir, task, &records)?;
    Ok(Finished {
        last: last.clone(),
        converged_at,
        best: best.cloned(),
        dir: dir.to_path_buf(),
    })
}

/// A roll-out as a line of progress.
pub fn rollout_line(r: &Record<TaskTrial>) -> String {
    let t = &r.trial;
    let q = query_text(&r.query);
    if let Some(why) = &t.rejected {
        return format!(
            "roll-out {:>3}: q {q}  REJECTED ({why})  reward 0",
            r.rollout
        );
    }
    if let Some(why) = &t.failed {
        return format!("roll-out {:>3}: q {q}  FAILED ({why})  reward 0", r.rollout);
    }
    let measured = t.measured.as_ref().map_or(String::new(), |m| {
        let m: Vec<f32> = m.iter().map(|v| *v as f32).collect();
        let e: Vec<f32> = t.error.iter().map(|v| *v as f32).collect();
        format!("  measured {}  error {}", query_text(&m), query_text(&e))
    });
    format!(
        "roll-out {:>3}: q {q}{measured}  reward {:.3}{}",
        r.rollout,
        t.reward,
        if r.mean { "  (mean)" } else { "" }
    )
}
