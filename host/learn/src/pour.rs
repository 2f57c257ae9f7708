//! A `primo pour` run: what it learns and where (its [`Header`]), its run
//! log, resuming it after a crash, and its reports. The run reports what
//! happens as [`Event`]s; it prints nothing.
//!
//! The header fixes everything that decides the run: the settings and
//! seed, the skill (demonstration files, kernels, space, glass, and a CRC
//! of the fitted examples so changed demonstration files are caught), and
//! the cell. A resumed run takes all of it from the log; only where the
//! instruments and the learner are connected (the robot's address, the
//! scale's port, the coprocessor) may change.

use std::path::{Path, PathBuf};
use std::time::Instant;

use primo_sim::cell::{CellConfig, GlassKind};
use primo_skill::csv::parse_demo;
use primo_skill::{MAX_KERNELS, Skill, Space};
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::coprocessor::{Image, Link, Qemu};
use crate::learning::{
    Entry, Learner, Record, Settings, best, check_examples, examples_crc, learn_logged, pour_setup,
};
use crate::output::{check_dir, create_dir};
use crate::pouring::{Converted, built_in_skill, upgrade};
use crate::report::{PourSummary, RolloutSummary};
use crate::rig::{Instruments, InstrumentsSpec, Operator, Rig, Simulated, roll_out};
use crate::runlog::{RunEvent, RunLog};
use crate::trial::Measured;
use crate::weigh::ScaleSpec;

/// The log format's version. Version 3: Cartesian movements are the
/// mouth's position and the bottle's orientation as a quaternion (version
/// 2's were a rotation vector, a different skill and `Δθ`); a version 2 log
/// of a joint-space run is the same and still resumes.
pub const VERSION: u32 = 3;

/// A demonstration file and the query (bottle volume, l) it shows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DemoFile {
    /// The CSV file (absolute in a run log).
    pub file: PathBuf,
    /// Its query.
    pub volume: f32,
}

/// The skill a run learns: demonstrations fitted and generalized.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SkillSpec {
    /// Coordinates of the movement.
    pub space: Space,
    /// The glass on the scale (the simulated cell's; on a real cell, the
    /// arm's model and the workspace are the same).
    pub glass: GlassKind,
    /// Kernels per DoF.
    pub kernels: usize,
    /// The demonstrations; empty for the built-in pair.
    pub demos: Vec<DemoFile>,
}

impl SkillSpec {
    /// Checks the settings without reading a file: the kernel count, and
    /// at least two demonstrations at distinct, positive volumes.
    pub fn validate(&self) -> Result<(), Error> {
        if !(2..=MAX_KERNELS).contains(&self.kernels) {
            return Err(Error::Invalid(format!(
                "--kernels {}: must be in 2..={MAX_KERNELS}",
                self.kernels
            )));
        }
        if self.demos.len() == 1 {
            return Err(Error::Invalid(
                "--demo: one demonstration cannot be generalized; give at least two, at \
                 different volumes (or none for the built-in pair)"
                    .into(),
            ));
        }
        for (i, d) in self.demos.iter().enumerate() {
            if !(d.volume.is_finite() && d.volume > 0.0) {
                return Err(Error::Invalid(format!(
                    "--demo {}={}: the volume must be a positive number of litres",
                    d.file.display(),
                    d.volume
                )));
            }
            if let Some(same) = self.demos[..i].iter().find(|e| e.volume == d.volume) {
                return Err(Error::Invalid(format!(
                    "--demo {}={}: {} shows the same volume; the demonstrations must show \
                     different volumes to generalize over",
                    d.file.display(),
                    d.volume,
                    same.file.display()
                )));
            }
        }
        Ok(())
    }

    /// The simulated cell with this glass.
    pub fn cell(&self) -> CellConfig {
        CellConfig::standard(self.glass)
    }

    /// The cell and the fitted skill. A Cartesian demonstration in the
    /// rotation-vector columns of earlier versions is converted
    /// ([`upgrade`]) and said so in [`Built::converted`].
    pub fn build(&self) -> Result<Built, Error> {
        self.validate()?;
        let cell = self.cell();
        if self.demos.is_empty() {
            let skill = built_in_skill(&cell, self.space, self.kernels)?;
            return Ok(Built {
                cell,
                skill,
                converted: Vec::new(),
            });
        }
        let mut demos = Vec::new();
        let mut converted = Vec::new();
        for d in &self.demos {
            let text = std::fs::read_to_string(&d.file)
                .map_err(|e| Error::Invalid(format!("{}: cannot read: {e}", d.file.display())))?;
            let name = d.file.display().to_string();
            let mut demo = parse_demo(&name, &text)?;
            if self.space == Space::Cartesian
                && let Some((quaternions, wraps)) = upgrade(&demo)
            {
                demo = quaternions;
                converted.push(Converted {
                    file: d.file.clone(),
                    wraps,
                });
            }
            demos.push((name, d.volume, demo));
        }
        let skill = crate::pouring::fit(self.space, &demos, self.kernels)?;
        Ok(Built {
            cell,
            skill,
            converted,
        })
    }
}

/// A skill built: the cell, the fitted skill, and the demonstrations
/// converted from rotation vectors.
#[derive(Debug, Clone)]
pub struct Built {
    /// The cell.
    pub cell: CellConfig,
    /// The skill.
    pub skill: Skill,
    /// The demonstration files read in the earlier Cartesian columns.
    pub converted: Vec<Converted>,
}

/// Where the roll-outs happen.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CellSpec {
    /// The simulated cell in this process.
    Simulated,
    /// A real cell's instruments.
    Instruments(InstrumentsSpec),
}

/// The first record of a run log.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// [`VERSION`].
    pub version: u32,
    /// What to learn and how.
    pub settings: Settings,
    /// The skill.
    pub skill: SkillSpec,
    /// Where.
    pub cell: CellSpec,
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

/// A new run, or the continuation of one.
#[derive(Debug, Clone, PartialEq)]
pub enum Start {
    /// A new run logged in `out`.
    New {
        /// The output directory.
        out: PathBuf,
        /// Replace a finished run logged in `out`.
        force: bool,
        /// What it learns.
        settings: Settings,
        /// The skill.
        skill: SkillSpec,
        /// Where.
        cell: CellSpec,
    },
    /// Continue the run logged in `dir`.
    Resume {
        /// Its directory.
        dir: PathBuf,
        /// Where the real cell's instruments are now (a serial port's
        /// name may change between runs), if not where the log says.
        instruments: Option<InstrumentsSpec>,
    },
}

impl Start {
    /// Checks every setting, and that the output may be written, without
    /// creating anything or touching an instrument.
    pub fn validate(&self) -> Result<(), Error> {
        match self {
            Start::New {
                out,
                force,
                settings,
                skill,
                cell,
            } => {
                settings.validate()?;
                skill.validate()?;
                let capacity = skill.cell().bottle_litres();
                if settings.bottle > capacity {
                    return Err(Error::Invalid(format!(
                        "--bottle {}: the cell's bottle holds {capacity:.3} l",
                        settings.bottle
                    )));
                }
                if let CellSpec::Instruments(spec) = cell {
                    spec.validate()?;
                }
                check_dir("--out", out)?;
                RunLog::check_free(out, *force)
            }
            Start::Resume { dir, instruments } => {
                if let Some(spec) = instruments {
                    spec.validate()?;
                }
                if !dir.join(crate::runlog::FILE).is_file() {
                    return Err(Error::Invalid(format!(
                        "--resume {}: no run log ({}) there",
                        dir.display(),
                        crate::runlog::FILE
                    )));
                }
                Ok(())
            }
        }
    }
}

/// What a run reports as it goes.
#[derive(Debug)]
pub enum Event<'a> {
    /// The learner and the log.
    Run(RunEvent<'a>),
    /// What is learned.
    Learning {
        /// The settings.
        settings: &'a Settings,
        /// The movement's coordinates.
        space: Space,
        /// Parameters learned.
        parameters: usize,
    },
    /// A demonstration file in the earlier Cartesian columns was
    /// converted to the quaternion columns.
    Converted(&'a Converted),
    /// The real cell's instruments are open.
    Cell {
        /// Where they are.
        spec: &'a InstrumentsSpec,
        /// The scale's serial number.
        scale_serial: &'a str,
    },
    /// A roll-out, made now or (`logged`) replayed from the log.
    Rollout {
        /// It.
        entry: &'a Entry,
        /// Replayed from the log.
        logged: bool,
    },
    /// The run is complete and its reports are written.
    Finished(&'a Finished),
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub struct Finished {
    /// The settings.
    pub settings: Settings,
    /// The last roll-out (PoWER: the last roll-out of the mean).
    pub last: Record,
    /// Error learning reached the precision at this roll-out.
    pub converged_at: Option<u32>,
    /// The roll-out `series.csv` holds, if any.
    pub series_of: Option<u32>,
    /// Whether the cell records series (the simulated one does).
    pub simulated: bool,
    /// The output directory.
    pub dir: PathBuf,
}

/// A failed run: why, and whether a run log keeps what was made (then
/// `--resume` continues it).
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

/// `primo pour`: checks the settings, learns, logging every roll-out, and
/// writes the reports; `operator` is asked at a real cell, `event` told
/// what happens. An error from `event` (the output is gone) ends the run.
pub fn pour(
    start: Start,
    learner: &LearnerSpec,
    operator: Box<dyn Operator>,
    mut event: impl FnMut(Event) -> Result<(), Error>,
) -> Result<(), Failure> {
    let started = Instant::now();
    start.validate()?;
    let on_scale = learner.coprocessor.as_deref() == Some(ON_SCALE);
    if on_scale && let Start::New { cell, .. } = &start {
        on_primo_scale(cell)?;
    }
    // QEMU (when asked for) lives until the run ends.
    let (_qemu, mut learner, connected) = open_learner(learner)?;
    if let Some(what) = connected {
        event(Event::Run(RunEvent::Learner(what)))?;
    }
    let (dir, header, logged, mut log, ended) = match start {
        Start::New {
            out,
            force,
            settings,
            skill,
            cell,
        } => {
            let fitted = skill.build()?.skill;
            let header = Header {
                version: VERSION,
                settings,
                examples: examples_crc(&fitted),
                skill,
                cell,
            };
            create_dir(&out)?;
            let log = RunLog::create(&out, &header, force)?;
            (out, header, Vec::new(), log, false)
        }
        Start::Resume { dir, instruments } => {
            let opened = RunLog::resume::<Header, Entry>(
                &dir,
                |h| match (h.version, h.skill.space) {
                    (2, Space::Joint) => VERSION,
                    (v, _) => v,
                },
                VERSION,
                |e| event(Event::Run(e)),
            )?;
            let mut header = opened.header;
            match (&mut header.cell, instruments) {
                (CellSpec::Instruments(logged), Some(now)) => *logged = now,
                (CellSpec::Simulated, Some(_)) => {
                    return Err(Error::Invalid(format!(
                        "the run in {} is on the simulated cell: it cannot continue on \
                         instruments",
                        dir.display()
                    ))
                    .into());
                }
                (_, None) => {}
            }
            (dir, header, opened.entries, opened.log, opened.ended)
        }
    };
    let fail = |error: Error| Failure {
        error: Box::new(error),
        resumable: Some(dir.clone()),
    };
    if on_scale && !ended {
        on_primo_scale(&header.cell).map_err(fail)?;
    }
    let s = header.settings;
    let Built {
        cell,
        skill,
        converted,
    } = header.skill.build().map_err(fail)?;
    for c in &converted {
        event(Event::Converted(c)).map_err(fail)?;
    }
    check_examples(&skill, header.examples, &dir).map_err(fail)?;
    let space = header.skill.space;
    event(Event::Learning {
        settings: &s,
        space,
        parameters: s.method.learned_parameters(&skill),
    })
    .map_err(fail)?;
    let simulated = Simulated::new(cell, s.bottle, s.seed).map_err(fail)?;
    let mut rig: Box<dyn Rig> = match &header.cell {
        // A complete run is only told again: no instrument is needed.
        _ if ended => Box::new(Complete(simulated.clone())),
        CellSpec::Simulated => Box::new(simulated.clone()),
        CellSpec::Instruments(spec) => {
            let rig = Instruments::open(spec.clone(), &cell, s.bottle, operator).map_err(fail)?;
            event(Event::Cell {
                spec,
                scale_serial: &rig.scale_serial(),
            })
            .map_err(fail)?;
            if on_scale && let Some(link) = rig.scale_link() {
                let what = format!("learner: on the scale, {}", link.name());
                event(Event::Run(RunEvent::Learner(what))).map_err(fail)?;
                learner = Learner::Remote(link);
            }
            Box::new(rig)
        }
    };

    let setup = pour_setup(&skill, &s).map_err(fail)?;
    let run = learn_logged(
        &skill,
        setup,
        s.max_rollouts,
        &mut learner,
        &logged,
        (&mut log, ended),
        |i, query, delta| roll_out(rig.as_mut(), &skill, s.target, i, query, delta),
        |entry, logged| event(Event::Rollout { entry, logged }),
    )
    .map_err(fail)?;
    let finished = report(
        &dir,
        &s,
        space,
        &skill,
        &run,
        &simulated,
        &header.cell,
        started,
    )
    .map_err(fail)?;
    event(Event::Finished(&finished)).map_err(fail)
}

/// The cell of a complete run: it is told its logged roll-outs again and
/// makes none.
struct Complete(Simulated);

impl Rig for Complete {
    fn gate(&self) -> &primo_robot::Gate {
        self.0.gate()
    }

    fn dt(&self) -> f64 {
        self.0.dt()
    }

    fn execute(
        &mut self,
        rollout: u32,
        _: &primo_skill::Plan,
        _: &primo_robot::JointPath,
    ) -> Result<Measured, Error> {
        Err(Error::Log(format!(
            "the logged run is complete, yet the learner asks for roll-out {rollout}"
        )))
    }
}

/// Writes the reports of a run.
#[allow(clippy::too_many_arguments)]
fn report(
    dir: &Path,
    s: &Settings,
    space: Space,
    skill: &Skill,
    run: &[Entry],
    simulated: &Simulated,
    cell: &CellSpec,
    started: Instant,
) -> Result<Finished, Error> {
    let records: Vec<_> = run.iter().map(|e| e.record.clone()).collect();
    let last = records
        .iter()
        .rev()
        .find(|r| r.mean)
        .ok_or_else(|| Error::Learner("no roll-out was made".into()))?;
    let converged_at = match s.method {
        m if m.is_power() => None,
        _ => records
            .iter()
            .find(|r| r.trial.error.abs() < s.precision)
            .map(|r| r.rollout),
    };
    let best = best(run);
    let summary = PourSummary {
        settings: s,
        space,
        parameters: s.method.learned_parameters(skill),
        rollouts: records.len(),
        converged_at,
        last: RolloutSummary::of(last),
        best: best.map(|e| RolloutSummary::of(&e.record)),
        seconds: started.elapsed().as_secs_f64(),
    };
    crate::report::write_pour(dir, &records, &summary)?;
    // The best roll-out's time series: the simulated cell repeats it
    // exactly (the run itself keeps no series).
    let series = match (cell, best) {
        (CellSpec::Simulated, Some(e)) => {
            let mut recording = simulated.recording(1);
            crate::rig::roll_out(
                &mut recording,
                skill,
                s.target,
                e.record.rollout,
                &e.record.query,
                &e.delta,
            )?
            .series
        }
        _ => None,
    };
    crate::series::write_csv(&dir.join("series.csv"), space, series.as_ref())?;
    Ok(Finished {
        settings: *s,
        last: last.clone(),
        converged_at,
        series_of: series.as_ref().and(best.map(|e| e.record.rollout)),
        simulated: matches!(cell, CellSpec::Simulated),
        dir: dir.to_path_buf(),
    })
}

/// `--coprocessor scale` needs primo's scale on a real cell.
fn on_primo_scale(cell: &CellSpec) -> Result<(), Error> {
    let primo = match cell {
        CellSpec::Instruments(spec) => !matches!(
            ScaleSpec::parse("--scale", &spec.scale)?,
            ScaleSpec::MtSics(_)
        ),
        CellSpec::Simulated => false,
    };
    if primo {
        Ok(())
    } else {
        Err(Error::Invalid(
            "--coprocessor scale: the learner runs on primo's scale, --scale postcard:PORT or \
             qemu:LOAD_CELL (with --robot)"
                .into(),
        ))
    }
}

/// Connects the learner of `spec`: in this process, on a coprocessor, or
/// on the firmware booted in QEMU (returned: it lives until the run ends);
/// with where it is, unless in this process. On the scale, the learner is
/// in this process until the scale's line takes it over.
pub(crate) fn open_learner(
    spec: &LearnerSpec,
) -> Result<(Option<Qemu>, Learner, Option<String>), Error> {
    Ok(match spec.coprocessor.as_deref() {
        None | Some(ON_SCALE) => (None, Learner::local(), None),
        Some("qemu") => {
            let elf = match &spec.firmware {
                Some(elf) => elf.clone(),
                None => Qemu::find(Image::Coprocessor)?,
            };
            let qemu = Qemu::start(&elf)?;
            let link = Link::open(qemu.pty())?;
            let what = format!(
                "learner: firmware {} on QEMU mps2-an386, {}",
                elf.display(),
                qemu.pty()
            );
            (Some(qemu), Learner::Remote(link), Some(what))
        }
        Some(port) => {
            let link = Link::open(port)?;
            (
                None,
                Learner::Remote(link),
                Some(format!("learner: coprocessor on {port}")),
            )
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::learning::Algorithm;

    struct Nobody;

    impl Operator for Nobody {
        fn reset(&mut self, _: u32, _: f64) -> Result<(), Error> {
            Ok(())
        }

        fn warn(&mut self, _: u32, _: &str) {}
    }

    /// A version 2 log of a Cartesian run (rotation-vector movements) is
    /// refused by its version; one of a joint-space run is the same in
    /// version 3 and resumes.
    #[test]
    fn a_version_2_log_resumes_in_joint_space_only() {
        for space in [Space::Cartesian, Space::Joint] {
            let dir = std::env::temp_dir()
                .join(format!("primo-pour-v2-{space:?}-{}", std::process::id()));
            let _ = std::fs::remove_dir_all(&dir);
            std::fs::create_dir_all(&dir).unwrap();
            let mut settings = Settings::paper(Algorithm::Golden, 0.5, 0.2, 1);
            settings.max_rollouts = 1;
            let skill = SkillSpec {
                space,
                glass: GlassKind::Normal,
                kernels: 10,
                demos: Vec::new(),
            };
            let header = Header {
                version: 2,
                settings,
                examples: examples_crc(&skill.build().unwrap().skill),
                skill,
                cell: CellSpec::Simulated,
            };
            RunLog::create(&dir, &header, false).unwrap();
            let resume = Start::Resume {
                dir: dir.clone(),
                instruments: None,
            };
            let run = pour(
                resume,
                &LearnerSpec::default(),
                Box::new(Nobody),
                |_| Ok(()),
            );
            match space {
                Space::Cartesian => {
                    let e = run.unwrap_err().to_string();
                    assert!(
                        e.contains("run.log: run log version 2, this primo reads version 3"),
                        "{e}"
                    );
                }
                Space::Joint => assert!(run.is_ok(), "{:?}", run.err()),
            }
            std::fs::remove_dir_all(&dir).unwrap();
        }
    }
}
