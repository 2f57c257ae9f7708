//! One learning run, whatever its task: start or resume it, connect the
//! learner, log every roll-out as it is made, and report. A task [`Kind`]
//! (the built-in pour, a task file) says what is learned, how a roll-out is
//! made and what its reports are; everything else is this module's, so
//! every kind resumes, logs and ends the same way.
//!
//! The run log's first record is the run's [`Header`]: the format
//! [`VERSION`], the kind's name, what the kind logs of itself (its
//! settings, its seed), and a CRC of the skill's examples, so changed
//! demonstration files are caught on resume.

use std::path::{Path, PathBuf};
use std::time::Instant;

use primo_skill::Skill;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::algorithm::Algorithm;
use crate::clock::{Clock, Seconds};
use crate::coprocessor::{Image, Link, Qemu};
use crate::learner::{Learner, check_examples, examples_crc};
use crate::lock;
use crate::output::{check_dir, create_dir};
use crate::rollouts::{Entry, Point, Replay, Scored, check_replay, learn_logged};
use crate::runlog::{self, RunEvent, RunLog};
use crate::{Error, Setting};
use primo_mtsics::path::Wanted;
use primo_protocol::learner::Setup;

/// The run log's format version, one for every kind. Version 4: the
/// header names its kind. Earlier logs (a pour's version 2 and 3, a task
/// file's version 1) resume as their kind reads them ([`Kind::reads`]).
pub const VERSION: u32 = 4;

/// A kind of task a run learns.
pub trait Kind: Clone + Serialize + DeserializeOwned {
    /// Its name in the run log.
    const NAME: &'static str;
    /// What a roll-out gave.
    type Trial: Scored + Clone + Serialize + DeserializeOwned + std::fmt::Debug;
    /// The skill fitted, and what else the kind rolls out with.
    type Built;
    /// The person at the cell, for what only a person can do.
    type Person;
    /// Where a resumed run's instruments are now, if they moved.
    type Moved: Default;
    /// What the kind reports beside the run's own events.
    type Note: std::fmt::Debug;
    /// How a run of the kind ended, as it reports it.
    type Finished: std::fmt::Debug;

    /// Checks every setting, and that the learner can be where `learner`
    /// puts it, before anything is created or connected.
    fn validate(&self, learner: &LearnerSpec) -> Result<(), Error>;
    /// Checks where a resumed run's instruments moved to.
    fn check_moved(moved: &Self::Moved) -> Result<(), Error>;
    /// Whether this primo continues a log of format `version` without a
    /// kind's name (a log from before [`VERSION`] 4) holding `logged`.
    fn reads(version: u32, logged: &Self) -> bool;
    /// Applies where a resumed run's instruments moved to, and the changes
    /// a resumed run may take; returns the changes of its learned settings
    /// (in the user's terms), which the run log then keeps.
    fn resume(&mut self, moved: Self::Moved, dir: &Path) -> Result<Vec<String>, Error>;
    /// Fits the skill; `note` hears what was read differently than given.
    fn build(
        &self,
        note: &mut dyn FnMut(Self::Note) -> Result<(), Error>,
    ) -> Result<Self::Built, Error>;
    /// The skill of what [`Kind::build`] made.
    fn skill(built: &Self::Built) -> &Skill;
    /// The learner.
    fn method(&self) -> Algorithm;
    /// The learner's setup on the built skill.
    fn setup(&self, built: &Self::Built) -> Result<Setup, Error>;
    /// Where a learner that asked `(q̂, Δθ)` was, in the user's terms.
    fn point(built: &Self::Built, query: &[f32], delta: &[f32]) -> Point;
    /// The roll-out budget.
    fn max_rollouts(&self) -> u32;
    /// Opens what makes the roll-outs of a run in `dir` (not a complete
    /// one): `learner` may move onto an instrument's line.
    fn execution<'a>(
        &'a self,
        built: &'a Self::Built,
        at: Cell<'_, Self>,
    ) -> Result<Box<dyn Execute<Self::Trial> + 'a>, Error>;
    /// Writes the reports of the run's roll-outs into `dir`; `seconds`
    /// of wall-clock time.
    fn report(
        &self,
        built: &Self::Built,
        dir: &Path,
        run: &[Entry<Self::Trial>],
        seconds: Seconds,
    ) -> Result<Self::Finished, Error>;
}

/// Makes roll-outs: `roll(i, q̂, Δθ)` is roll-out `i` (from 1).
pub trait Execute<T> {
    /// Roll-out `rollout` of `θ = G(query) + Δθ`. An error means it could
    /// not be made or measured, and the run stops (unlogged: a resumed run
    /// makes it again).
    fn roll(&mut self, rollout: u32, query: &[f32], delta: &[f32]) -> Result<T, Error>;
}

/// Where [`Kind::execution`] opens a run's roll-outs.
pub struct Cell<'c, K: Kind> {
    /// The run's directory.
    pub dir: &'c Path,
    /// The learner; the kind may move it (onto its scale's line).
    pub learner: &'c mut Learner,
    /// Where the learner was asked to run.
    pub spec: &'c LearnerSpec,
    /// The person at the cell.
    pub person: K::Person,
    /// The run's events.
    pub event: &'c mut dyn FnMut(Event<'_, K>) -> Result<(), Error>,
}

/// The first record of a run log.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Header<K> {
    /// The log's format, [`VERSION`].
    pub version: u32,
    /// The kind's name ([`Kind::NAME`]); absent before version 4. (The
    /// log's records name their own kind: `run`, `rollout`, `end`.)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub task_kind: Option<String>,
    /// What the kind logs of itself.
    #[serde(flatten)]
    pub run: K,
    /// CRC-32C of the skill's examples `(q_i, θ_i)`, bit for bit.
    pub examples: u32,
}

/// The coprocessor that is the cell's scale: the learner runs on primo's
/// scale, over the scale's own line.
pub const ON_SCALE: &str = "scale";

/// Where the learner runs.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LearnerSpec {
    /// A coprocessor's serial port, `qemu`, or [`ON_SCALE`]; in this
    /// process if `None`.
    pub coprocessor: Option<String>,
    /// With `qemu`: the firmware ELF.
    pub firmware: Option<PathBuf>,
}

impl LearnerSpec {
    /// The learner runs on the cell's scale.
    pub fn on_scale(&self) -> bool {
        self.coprocessor.as_deref() == Some(ON_SCALE)
    }
}

/// A new run, or the continuation of one.
#[derive(Debug, Clone, PartialEq)]
pub enum Start<K: Kind> {
    /// A new run logged in `out`.
    New {
        /// The output directory.
        out: PathBuf,
        /// Replace a run logged in `out`, moved aside
        /// ([`runlog::set_aside`]).
        force: bool,
        /// What it learns.
        run: K,
    },
    /// Continue the run logged in `dir`.
    Resume {
        /// Its directory.
        dir: PathBuf,
        /// Where its instruments are now, if not where the log says.
        moved: K::Moved,
    },
}

impl<K: Kind> Start<K> {
    /// The run's directory.
    pub fn dir(&self) -> &Path {
        match self {
            Start::New { out, .. } => out,
            Start::Resume { dir, .. } => dir,
        }
    }

    /// Checks every setting, and that the output may be written (no other
    /// process holds its directory, [`crate::lock`]), without creating
    /// anything or touching an instrument.
    pub fn validate(&self, learner: &LearnerSpec) -> Result<(), Error> {
        match self {
            Start::New { out, force, run } => {
                run.validate(learner)?;
                check_dir(out)?;
                lock::check_free(out)?;
                RunLog::check_free(out, *force)
            }
            Start::Resume { dir, moved } => {
                K::check_moved(moved)?;
                lock::check_free(dir)?;
                check_log(dir)
            }
        }
    }
}

/// What a run reports as it goes.
#[derive(Debug)]
pub enum Event<'a, K: Kind> {
    /// The learner and the log.
    Run(RunEvent<'a>),
    /// What is learned.
    Learning {
        /// The run.
        run: &'a K,
        /// What it was built into (the skill, and what the kind learns on it).
        built: &'a K::Built,
        /// Parameters learned.
        parameters: usize,
    },
    /// The kind's own news.
    Note(K::Note),
    /// A roll-out, made now or (`logged`) replayed from the log.
    Rollout {
        /// It.
        entry: &'a Entry<K::Trial>,
        /// Replayed from the log.
        logged: bool,
        /// It could not be made or measured, and the error learner takes
        /// its query as a bound of the search.
        bounds: bool,
    },
    /// The run is complete and its reports are written.
    Finished(&'a K::Finished),
}

/// A failed run: why, and whether a run log keeps what was made (then the
/// run continues from it).
#[derive(Debug, thiserror::Error)]
#[error("{error}")]
pub struct Failure {
    /// Why.
    pub error: Box<Error>,
    /// The run's directory, once its log exists.
    pub resumable: Option<PathBuf>,
}

impl From<Error> for Failure {
    fn from(error: Error) -> Self {
        Failure {
            error: Box::new(error),
            resumable: None,
        }
    }
}

/// Sets a resumed run's roll-out budget to `now`; says the change, if any.
pub fn budget_change(budget: &mut u32, now: u32) -> Option<String> {
    let was = std::mem::replace(budget, now);
    (was != now).then(|| format!("roll-out budget {was} -> {now}"))
}

/// The log in `dir` is there and can be read and appended to: a run that
/// could not continue is refused before anything starts.
fn check_log(dir: &Path) -> Result<(), Error> {
    let log = dir.join(runlog::FILE);
    match std::fs::OpenOptions::new()
        .read(true)
        .append(true)
        .open(&log)
    {
        Ok(_) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Err(Error::NoLog(log)),
        Err(e) => Err(Error::open(Setting::Resume, &log, Wanted::File)(e)),
    }
}

/// The kind of run `dir`'s log holds: its [`Header::task_kind`], or for a log
/// from before version 4, `task` if it logged a task file, else `pour`.
pub fn logged_kind(dir: &Path) -> Result<String, Error> {
    check_log(dir)?;
    let file = dir.join(runlog::FILE);
    let bytes = std::fs::read(&file).map_err(Error::io(&file))?;
    // The header is the first record, `CRC JSON`; the log's own checks
    // come when it is opened.
    let text = String::from_utf8_lossy(&bytes);
    let first = text.lines().next().unwrap_or("");
    let json = first.split_once(' ').map_or("", |(_, json)| json);
    let header: serde_json::Value = serde_json::from_str(json).unwrap_or_default();
    Ok(match header.get("task_kind").and_then(|k| k.as_str()) {
        Some(kind) => kind.to_string(),
        None if header.get("task").is_some() => "task".into(),
        None => "pour".into(),
    })
}

/// Runs `start`: checks the settings, connects the learner of `learner`,
/// learns, logging every roll-out, and writes the reports, holding the
/// run's directory ([`crate::lock`]) from before its log is created or
/// opened to the end; `person` is
/// asked what only a person can do, `event` told what happens. An error
/// from `event` (the output is gone) ends the run.
pub fn run<K: Kind>(
    start: Start<K>,
    learner: &LearnerSpec,
    person: K::Person,
    mut event: impl FnMut(Event<K>) -> Result<(), Error>,
) -> Result<(), Failure> {
    let started = Instant::now();
    start.validate(learner)?;
    // QEMU (when asked for) lives until the run ends.
    let (_qemu, mut connected, place) = open_learner(learner)?;
    if let Some(what) = place {
        event(Event::Run(RunEvent::Learner(what)))?;
    }
    let (dir, header, logged, mut log, ended, built, changes, _held) = match start {
        Start::New { out, force, run } => {
            let built = run.build(&mut |n| event(Event::Note(n)))?;
            run.setup(&built)?;
            let header = Header {
                version: VERSION,
                task_kind: Some(K::NAME.into()),
                examples: examples_crc(K::skill(&built)),
                run,
            };
            if force && out.join(runlog::FILE).exists() {
                // Held while it is moved: no run is moved from under its
                // process.
                let _aside = lock::hold(&out)?;
                if let Some(to) = runlog::set_aside(&out)? {
                    event(Event::Run(RunEvent::SetAside { dir: &out, to: &to }))?;
                }
            }
            create_dir(&out)?;
            let held = lock::hold(&out)?;
            let log = RunLog::create(&out, &header)?;
            (
                out,
                header,
                Vec::new(),
                log,
                false,
                Some(built),
                Vec::new(),
                held,
            )
        }
        Start::Resume { dir, moved } => {
            let held = lock::hold(&dir)?;
            let kind = logged_kind(&dir)?;
            if kind != K::NAME {
                return Err(Error::OtherKind { dir, kind }.into());
            }
            let opened = RunLog::resume::<Header<K>, Entry<K::Trial>>(
                &dir,
                |h| match h.task_kind {
                    None if K::reads(h.version, &h.run) => VERSION,
                    _ => h.version,
                },
                VERSION,
                |e| event(Event::Run(e)),
            )?;
            let mut header = opened.header;
            let changes = header.run.resume(moved, &dir)?;
            // A complete run whose settings changed (a larger budget) is
            // continued where its log ends, once the changes are checked.
            let ended = opened.ended && changes.is_empty();
            let (entries, log) = (opened.entries, opened.log);
            (dir, header, entries, log, ended, None, changes, held)
        }
    };
    // Dropped before the directory is let go, on every way out.
    let clock = Clock::start(&dir, started);
    let fail = |error: Error| Failure {
        error: Box::new(error),
        resumable: Some(dir.clone()),
    };
    let run = &header.run;
    // A resumed run's settings were checked when it began; where its
    // learner runs now, not yet (a complete run only reports).
    if built.is_none() && !ended {
        run.validate(learner).map_err(fail)?;
    }
    let built = match built {
        Some(built) => built,
        None => run.build(&mut |n| event(Event::Note(n))).map_err(fail)?,
    };
    let skill = K::skill(&built);
    // How a replay names what the learner asked, should it differ.
    let point = |query: &[f32], delta: &[f32]| K::point(&built, query, delta);
    check_examples(skill, header.examples, &dir).map_err(fail)?;
    if !changes.is_empty() {
        // The changed run must ask for the logged roll-outs before its log
        // says it is the run.
        let setup = run.setup(&built).map_err(fail)?;
        let replay = Replay {
            logged: &logged,
            point: &point,
        };
        check_replay(skill, setup, run.max_rollouts(), replay).map_err(|e| {
            fail(Error::Invalid(format!(
                "{}: the changed settings do not keep the logged roll-outs: {e}",
                changes.join("; ")
            )))
        })?;
        for change in &changes {
            event(Event::Run(RunEvent::Changed(change))).map_err(fail)?;
        }
        log = log.rewrite_header(&header).map_err(fail)?;
    }
    event(Event::Learning {
        run,
        built: &built,
        parameters: run.method().learned_parameters(skill),
    })
    .map_err(fail)?;
    let mut execution: Box<dyn Execute<K::Trial>> = match ended {
        // A complete run is only told again: nothing is executed.
        true => Box::new(Complete),
        false => run
            .execution(
                &built,
                Cell {
                    dir: &dir,
                    learner: &mut connected,
                    spec: learner,
                    person,
                    event: &mut event,
                },
            )
            .map_err(fail)?,
    };
    let setup = run.setup(&built).map_err(fail)?;
    let error_learning = !run.method().is_power();
    let rollouts = learn_logged(
        skill,
        setup,
        run.max_rollouts(),
        &mut connected,
        Replay {
            logged: &logged,
            point: &point,
        },
        (&mut log, ended),
        |i, query, delta| execution.roll(i, query, delta),
        |entry, logged| {
            let bounds = error_learning && entry.record.trial.infeasible().is_some();
            event(Event::Rollout {
                entry,
                logged,
                bounds,
            })
        },
    )
    .map_err(fail)?;
    drop(execution);
    let finished = run
        .report(&built, &dir, &rollouts, clock.now())
        .map_err(fail)?;
    event(Event::Finished(&finished)).map_err(fail)
}

/// The execution of a complete run: it is told its logged roll-outs again
/// and makes none.
struct Complete;

impl<T> Execute<T> for Complete {
    fn roll(&mut self, rollout: u32, _: &[f32], _: &[f32]) -> Result<T, Error> {
        Err(Error::Log(format!(
            "the logged run is complete, yet the learner asks for roll-out {rollout}"
        )))
    }
}

/// Connects the learner of `spec`: in this process, on a coprocessor, or
/// on the firmware booted in QEMU (returned: it lives until the run ends);
/// with where it is, unless in this process. On the scale, the learner is
/// in this process until the scale's line takes it over.
pub fn open_learner(spec: &LearnerSpec) -> Result<(Option<Qemu>, Learner, Option<String>), Error> {
    Ok(match spec.coprocessor.as_deref() {
        None | Some(ON_SCALE) => (None, Learner::local(), None),
        Some("qemu") => {
            let elf = match &spec.firmware {
                Some(elf) => elf.clone(),
                None => Qemu::find(Image::Coprocessor)?,
            };
            let qemu = Qemu::start(&elf)?;
            let link = Link::open(qemu.pty(), Setting::Coprocessor)?;
            let what = format!(
                "learner: firmware {} on QEMU mps2-an386, {}",
                elf.display(),
                qemu.pty()
            );
            (Some(qemu), Learner::Remote(link), Some(what))
        }
        Some(port) => {
            let link = Link::open(port, Setting::Coprocessor)?;
            (
                None,
                Learner::Remote(link),
                Some(format!("learner: coprocessor on {port}")),
            )
        }
    })
}
