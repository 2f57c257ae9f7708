//! The roll-out loop: the learner asks, the task rolls out, the learner is
//! told ([`learn_on`]); each roll-out's [`Record`] and what the run log
//! keeps of it ([`Entry`]); a resumed run's learner checked against its
//! log (`verify_replayed`). It knows no task: a roll-out is whatever
//! [`Scored`] the caller's `roll` returns.

use primo_core::golden::Status as SearchStatus;
use primo_protocol::learner::{LearnerSetup, Outcome, Reply, Request, Rollout, Setup, Status};
use primo_skill::Skill;
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::learner::{Learner, wire_query};
use crate::runlog::RunLog;

/// What a roll-out gave, as the learners see it.
pub trait Scored {
    /// The error `ε` told to the error learners, one value per query
    /// dimension; `ε_i > 0` asks for a larger `q_i`.
    fn error(&self) -> Vec<f32>;
    /// The reward, ≥ 0, told to PoWER.
    fn reward(&self) -> f64;
    /// Why the roll-out gave nothing to learn from, if so: the limits
    /// rejected its movement (it never left primo), or it failed.
    fn infeasible(&self) -> Option<&str>;
    /// The largest `|ε_i|` measured, if the roll-out measured an error:
    /// error learning has converged once it is below the precision.
    fn worst_error(&self) -> Option<f64>;
    /// Drops what a run does not keep in memory (a recorded series).
    fn lighten(&mut self) {}
}

/// One roll-out of a learning run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Record<T> {
    /// Roll-out number, from 1.
    pub rollout: u32,
    /// PoWER updates completed before this roll-out (0 for error learning).
    pub update: u32,
    /// This roll-out executed PoWER's current mean (no exploration).
    pub mean: bool,
    /// The query `q̂` rolled out.
    pub query: Vec<f32>,
    /// What happened.
    pub trial: T,
}

/// The query as people write it: `0.5`, or `[1.5, 0.3]`.
pub fn query_text(query: &[f32]) -> String {
    match query {
        [q] => q.to_string(),
        q => format!(
            "[{}]",
            q.iter().map(f32::to_string).collect::<Vec<_>>().join(", ")
        ),
    }
}

/// A roll-out as the run log keeps it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Entry<T> {
    /// The roll-out and what happened.
    #[serde(flatten)]
    pub record: Record<T>,
    /// The learner's `Δθ` (empty for the error learners).
    pub delta: Vec<f32>,
    /// The learner's state after it was told the outcome.
    pub status: Status,
    /// CRC-32C of what the learner asked (the roll-out and `Δθ`) and of its
    /// status, bit for bit: a resumed run checks its learner against it.
    pub check: u32,
}

/// The CRC of [`Entry::check`].
fn check(asked: &Rollout, delta: &[f32], status: &Status) -> Result<u32, Error> {
    let bytes = postcard::to_allocvec(&(asked, delta, status))
        .map_err(|e| Error::Learner(format!("learner state: {e}")))?;
    Ok(crc::Crc::<u32>::new(&crc::CRC_32_ISCSI).checksum(&bytes))
}

/// The most roll-outs a run may be given (its budget): a run log of this
/// many roll-outs is some tens of megabytes, and a real cell makes tens.
pub const MAX_ROLLOUTS: u32 = 100_000;

/// The roll-outs of an interrupted run to tell a learner again, and how
/// its learner's values read in the user's terms (a query, or goals by
/// column: [`Point`]) when it asks for other ones.
pub struct Replay<'a, T> {
    /// The logged roll-outs, oldest first.
    pub logged: &'a [Entry<T>],
    /// The point of what a learner asked: `(q̂, Δθ)`.
    pub point: &'a dyn Fn(&[f32], &[f32]) -> Point,
}

impl<T> Replay<'_, T> {
    /// Nothing to replay: a new run.
    pub fn none() -> Self {
        Replay {
            logged: &[],
            point: &Point::asked,
        }
    }
}

/// Runs the learner of `setup` on `skill` for at most `max_rollouts`:
/// `roll(i, q̂, Δθ)` makes roll-out `i` (on a rig, through an evaluator),
/// and `each` is called after every roll-out (with `true` for a replayed
/// one) before the next begins; returns all roll-outs. An error from
/// `roll` (an instrument failed) or `each` (the run log could not be
/// written, the output closed) ends the run. An error learner takes an
/// infeasible roll-out's query as a bound of its search
/// ([`Request::Infeasible`]); PoWER learns from its reward.
///
/// `replay` holds the roll-outs of an interrupted run of the same
/// settings: the learner is told their outcomes again instead of rolling
/// them out, and `verify_replayed` checks it asks for exactly the logged
/// roll-outs and reaches exactly the logged states, so the run goes on as
/// if it had never stopped.
pub fn learn_on<T: Scored + Clone>(
    skill: &Skill,
    setup: Setup,
    max_rollouts: u32,
    learner: &mut Learner,
    replay: Replay<'_, T>,
    mut roll: impl FnMut(u32, &[f32], &[f32]) -> Result<T, Error>,
    mut each: impl FnMut(&Entry<T>, bool) -> Result<(), Error>,
) -> Result<Vec<Entry<T>>, Error> {
    let logged = replay.logged;
    let error_learning = !matches!(setup.learner, LearnerSetup::Power { .. });
    learner.configure(skill, setup)?;
    let mut run = Vec::new();
    for i in 1..=max_rollouts {
        let asked = match learner.call(&Request::Ask)? {
            Reply::Rollout(r) => r,
            Reply::Finished(_) => break,
            other => {
                return Err(Error::Learner(format!(
                    "learner: asked for a roll-out, got {other:?}"
                )));
            }
        };
        let delta = learner.delta(asked.delta_len)?;
        let query = asked.query.to_vec();
        let before = logged.get(run.len());
        let trial = match before {
            Some(e) => e.record.trial.clone(),
            None => roll(i, &query, &delta)?,
        };
        let told = match (trial.infeasible(), error_learning) {
            (Some(_), true) => Request::Infeasible,
            _ => Request::Tell(Outcome {
                error: wire_query(&trial.error())?,
                reward: trial.reward() as f32,
            }),
        };
        learner.call(&told)?;
        let status = match learner.call(&Request::Status)? {
            Reply::Status(status) => status,
            other => {
                return Err(Error::Learner(format!(
                    "learner: asked for its status, got {other:?}"
                )));
            }
        };
        let mut entry = Entry {
            check: check(&asked, &delta, &status)?,
            record: Record {
                rollout: i,
                update: asked.update,
                mean: asked.mean,
                query,
                trial,
            },
            delta,
            status,
        };
        let last_logged = run.len() + 1 == logged.len();
        if let Some(logged) = before {
            // A run that ended by its budget may go on with a larger one:
            // its last logged roll-out left the learner out of budget,
            // where it now searches on.
            let reopened = last_logged
                && logged.status.search == SearchStatus::BudgetExhausted
                && entry.status.search == SearchStatus::Running;
            let as_logged = Status {
                search: SearchStatus::BudgetExhausted,
                ..entry.status.clone()
            };
            let check = match reopened {
                true => check(&asked, &entry.delta, &as_logged)?,
                false => entry.check,
            };
            verify_replayed(logged, &entry, check, replay.point)?;
        }
        each(&entry, before.is_some())?;
        // A series (megabytes) is not kept: the best one is replayed.
        entry.record.trial.lighten();
        run.push(entry);
    }
    if run.len() < logged.len() {
        return Err(Error::Log(format!(
            "the run log has {} roll-outs, the learner finished after {}: the log is of \
             another learner, seed or skill",
            logged.len(),
            run.len()
        )));
    }
    Ok(run)
}

/// Checks that the learner of `setup` asks for exactly the `logged`
/// roll-outs and reaches exactly their states (in this process: the
/// coprocessor's learner is the same bit for bit), as a resumed run's
/// changed settings must keep them.
pub fn check_replay<T: Scored + Clone>(
    skill: &Skill,
    setup: Setup,
    max_rollouts: u32,
    replay: Replay<'_, T>,
) -> Result<(), Error> {
    let logged = replay.logged;
    if (max_rollouts as usize) < logged.len() {
        return Err(Error::Invalid(format!(
            "a budget of {max_rollouts} roll-outs: the run has made {} already",
            logged.len()
        )));
    }
    let mut beyond = false;
    let replayed = learn_on(
        skill,
        setup,
        max_rollouts,
        &mut Learner::local(),
        replay,
        |_, _, _| {
            // Past the logged roll-outs: all of them were the same.
            beyond = true;
            Err(Error::Interrupted)
        },
        |_, _| Ok(()),
    );
    match replayed {
        Err(_) if beyond => Ok(()),
        Err(e) => Err(e),
        Ok(_) => Ok(()),
    }
}

/// [`learn_on`] for a logged run: every new roll-out is appended to the
/// `log` before `show` is told of it, and the log ended after the last;
/// a run whose log is already `ended` is only told again.
#[allow(clippy::too_many_arguments)]
pub(crate) fn learn_logged<T: Scored + Clone + Serialize>(
    skill: &Skill,
    setup: Setup,
    max_rollouts: u32,
    learner: &mut Learner,
    replay: Replay<'_, T>,
    (log, ended): (&mut RunLog, bool),
    roll: impl FnMut(u32, &[f32], &[f32]) -> Result<T, Error>,
    mut show: impl FnMut(&Entry<T>, bool) -> Result<(), Error>,
) -> Result<Vec<Entry<T>>, Error> {
    let run = learn_on(
        skill,
        setup,
        max_rollouts,
        learner,
        replay,
        roll,
        |entry, replayed| {
            if !(replayed || ended) {
                log.append(entry)?;
            }
            show(entry, replayed)
        },
    )?;
    if !ended {
        log.end()?;
    }
    Ok(run)
}

/// A replayed roll-out must be the logged one: the learner asked for the
/// same roll-out and `Δθ` and reached the same state, bit for bit (`check`:
/// the replayed one's [`Entry::check`] as the log would hold it).
fn verify_replayed<T>(
    logged: &Entry<T>,
    replayed: &Entry<T>,
    check: u32,
    point: &dyn Fn(&[f32], &[f32]) -> Point,
) -> Result<(), Error> {
    if logged.check != check || logged.record.rollout != replayed.record.rollout {
        return Err(Error::Log(format!(
            "the run log's roll-out {} is not what the learner asks for and reaches \
             as roll-out {} ({}, logged {}): the log is of another learner, seed \
             or skill",
            logged.record.rollout,
            replayed.record.rollout,
            point(&replayed.record.query, &replayed.delta),
            point(&logged.record.query, &logged.delta)
        )));
    }
    Ok(())
}

/// The best executed roll-out: the highest reward, the later of equals
/// (the more learned).
pub fn best<T: Scored>(run: &[Entry<T>]) -> Option<&Entry<T>> {
    run.iter()
        .filter(|e| e.record.trial.infeasible().is_none())
        .fold(None, |best: Option<&Entry<T>>, e| match best {
            Some(b) if b.record.trial.reward() > e.record.trial.reward() => Some(b),
            _ => Some(e),
        })
}

/// How a run ended, from its roll-outs: what every kind reports.
#[derive(Debug)]
pub struct Ending<'a, T> {
    /// The last roll-out (PoWER: the last roll-out of the mean).
    pub last: &'a Record<T>,
    /// Error learning reached the precision at this roll-out (never for
    /// PoWER, which learns from rewards).
    pub converged_at: Option<u32>,
    /// Why the learner stopped.
    pub stop: Stop,
    /// The best executed roll-out ([`best`]).
    pub best: Option<&'a Entry<T>>,
}

/// Where an error learner was, as reports name it: a query (`q = 0.5`),
/// or the goals it changes by column (`goals shoulder = -0.4`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Point {
    /// The values.
    pub values: Vec<f32>,
    /// The columns whose goals they are (empty: a query).
    pub goals: Vec<String>,
}

impl Point {
    /// The query `query`.
    pub fn query(query: &[f32]) -> Point {
        Point {
            values: query.to_vec(),
            goals: Vec::new(),
        }
    }

    /// The query of a learner that asked `(q̂, Δθ)`, whatever `Δθ`.
    pub fn asked(query: &[f32], _: &[f32]) -> Point {
        Point::query(query)
    }

    /// Its largest difference to `other`, value by value.
    fn distance(&self, other: &Point) -> f32 {
        (self.values.iter())
            .zip(&other.values)
            .fold(0.0f32, |m, (a, b)| m.max((a - b).abs()))
    }
}

impl std::fmt::Display for Point {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.goals.is_empty() {
            return write!(f, "q = {}", query_text(&self.values));
        }
        let each: Vec<String> = (self.goals.iter())
            .zip(&self.values)
            .map(|(column, v)| format!("{column} = {v}"))
            .collect();
        write!(f, "goals {}", each.join(", "))
    }
}

/// Why a run's learner stopped.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stop {
    /// Error learning reached the precision.
    Converged,
    /// PoWER made its budget's roll-outs (it has no precision to reach).
    Learned,
    /// Error learning used up its budget of roll-outs first.
    Budget {
        /// The budget.
        rollouts: u32,
    },
    /// The search's bracket shrank to nothing at `at` first: the error is
    /// discontinuous or noisy there, or the target lies where nothing can
    /// be rolled out (`beyond`: the nearest such point, if any).
    Collapsed {
        /// Where.
        at: Point,
        /// The nearest point that could not be rolled out.
        beyond: Option<Point>,
    },
    /// The secant learner showed from its best point, `at`, that the
    /// target lies outside the search bounds (or beyond `beyond`, the
    /// nearest point that could not be rolled out).
    Stalled {
        /// Where.
        at: Point,
        /// The nearest point that could not be rolled out.
        beyond: Option<Point>,
    },
    /// The first roll-out, at the desired query (and the generalized
    /// goals), could not be made.
    Infeasible {
        /// Its point.
        at: Point,
        /// Why.
        why: String,
    },
}

/// What a run's `summary.json` says of how its learning ended.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Verdict {
    /// Error learning reached the precision (`null` for PoWER, which has
    /// none).
    pub converged: Option<bool>,
    /// Why the learner stopped ([`Stop::key`]).
    pub stopped: &'static str,
    /// The same, in words.
    pub why: String,
}

impl Stop {
    /// The precision was reached.
    pub fn converged(&self) -> bool {
        *self == Stop::Converged
    }

    /// What a summary says of it.
    pub fn verdict(&self) -> Verdict {
        Verdict {
            converged: (*self != Stop::Learned).then_some(self.converged()),
            stopped: self.key(),
            why: self.to_string(),
        }
    }

    /// Its name in a summary.
    pub fn key(&self) -> &'static str {
        match self {
            Stop::Converged => "converged",
            Stop::Learned => "learned",
            Stop::Budget { .. } => "budget",
            Stop::Collapsed { .. } => "bracket_collapsed",
            Stop::Stalled { .. } => "stalled",
            Stop::Infeasible { .. } => "infeasible",
        }
    }
}

impl std::fmt::Display for Stop {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let beyond = |f: &mut std::fmt::Formatter<'_>, b: &Option<Point>| match b {
            Some(b) => write!(
                f,
                "; {b} could not be rolled out: the target may lie where nothing can be"
            ),
            None => Ok(()),
        };
        match self {
            Stop::Converged => write!(f, "reached the precision"),
            Stop::Learned => write!(f, "made every roll-out of its budget"),
            Stop::Budget { rollouts } => {
                write!(
                    f,
                    "the budget of {rollouts} roll-outs ran out before the precision"
                )
            }
            Stop::Collapsed { at, beyond: b } => {
                write!(
                    f,
                    "the search bracket shrank to nothing at {at} before the precision \
                     (the error jumps there, or is noisy)"
                )?;
                beyond(f, b)
            }
            Stop::Stalled { at, beyond: b } => {
                write!(
                    f,
                    "the search stalled at {at} before the precision: the target lies \
                     outside the search bounds"
                )?;
                beyond(f, b)
            }
            Stop::Infeasible { at, why } if at.goals.is_empty() => write!(
                f,
                "the desired query {at} could not be rolled out ({why}): change it or the \
                 limits"
            ),
            Stop::Infeasible { at, why } => write!(
                f,
                "the movement generalized to the desired query ({at}) could not be rolled \
                 out ({why}): change the query or the limits"
            ),
        }
    }
}

impl<'a, T: Scored> Ending<'a, T> {
    /// The outcome of `run`, learned with PoWER (`power`) or by error
    /// learning to `precision`; `point` names where a roll-out's learner
    /// was.
    pub fn of(
        run: &'a [Entry<T>],
        power: bool,
        precision: f64,
        point: impl Fn(&Record<T>) -> Point,
    ) -> Result<Self, Error> {
        let last = run
            .iter()
            .rev()
            .map(|e| &e.record)
            .find(|r| r.mean)
            .ok_or_else(|| Error::Learner("no roll-out was made".into()))?;
        let converged_at = match power {
            true => None,
            false => run
                .iter()
                .map(|e| &e.record)
                .find(|r| r.trial.worst_error().is_some_and(|e| e < precision))
                .map(|r| r.rollout),
        };
        Ok(Ending {
            last,
            converged_at,
            stop: stop(run, power, converged_at.is_some(), point),
            best: best(run),
        })
    }
}

/// Why the learner of `run` stopped, from its last status.
fn stop<T: Scored>(
    run: &[Entry<T>],
    power: bool,
    converged: bool,
    point: impl Fn(&Record<T>) -> Point,
) -> Stop {
    let Some(end) = run.last() else {
        return Stop::Budget { rollouts: 0 };
    };
    if power {
        return Stop::Learned;
    }
    // Where it ended: the secant learner stalls at its best roll-out (the
    // smallest error; its last may be a probe), the others at their last.
    let at = match end.status.search {
        SearchStatus::Stalled => run
            .iter()
            .filter_map(|e| Some((e.record.trial.worst_error()?, &e.record)))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map_or(&end.record, |(_, r)| r),
        _ => &end.record,
    };
    let at = point(at);
    // The infeasible point nearest the end (max-norm), if any.
    let beyond = run
        .iter()
        .filter(|e| e.record.trial.infeasible().is_some())
        .map(|e| point(&e.record))
        .min_by(|a, b| a.distance(&at).total_cmp(&b.distance(&at)));
    match end.status.search {
        SearchStatus::Converged => Stop::Converged,
        _ if converged => Stop::Converged,
        SearchStatus::BracketCollapsed => Stop::Collapsed { at, beyond },
        SearchStatus::Stalled => Stop::Stalled { at, beyond },
        SearchStatus::Infeasible => Stop::Infeasible {
            at,
            why: end.record.trial.infeasible().unwrap_or("").to_string(),
        },
        SearchStatus::Running | SearchStatus::BudgetExhausted => Stop::Budget {
            rollouts: end.status.rollouts,
        },
    }
}
