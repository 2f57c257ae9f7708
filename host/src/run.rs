//! A `primo pour` run: what it learns and where (its [`Header`]), its run
//! log, resuming it after a crash, and its reports.
//!
//! The header fixes everything that decides the run: the settings and
//! seed, the skill (demonstration files, kernels, space, glass, and a CRC
//! of the fitted examples so changed demonstration files are caught), and
//! the cell. A resumed run takes all of it from the log; only where the
//! instruments and the learner are connected (the robot's address, the
//! scale's port, the coprocessor) may change.

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::coprocessor::{Link, Qemu};
use crate::csv::parse_demo;
use crate::pour::{Entry, Learner, Method, Settings, best, built_in_skill, learn_on};
use crate::report::{PourSummary, RolloutSummary};
use crate::rig::{Instruments, InstrumentsSpec, Rig, Simulated};
use crate::runlog::RunLog;
use crate::sim::cell::{CellConfig, GlassKind};
use crate::skill::{Skill, Space, Trial};
use crate::{CliError, MAX_KERNELS};

/// The log format's version.
pub const VERSION: u32 = 1;

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
    /// The cell and the fitted skill.
    pub fn build(&self) -> Result<(CellConfig, Skill), CliError> {
        let cell = CellConfig::standard(self.glass);
        if !(2..=MAX_KERNELS).contains(&self.kernels) {
            return Err(CliError::input(format!(
                "--kernels: {} is outside 2..={MAX_KERNELS}",
                self.kernels
            )));
        }
        if self.demos.is_empty() {
            let skill = built_in_skill(&cell, self.space, self.kernels).map_err(CliError::other)?;
            return Ok((cell, skill));
        }
        let mut demos = Vec::new();
        for d in &self.demos {
            let text = std::fs::read_to_string(&d.file)
                .map_err(|e| CliError::input(format!("{}: cannot read: {e}", d.file.display())))?;
            demos.push((d.volume, parse_demo(&d.file.display().to_string(), &text)?));
        }
        let examples: Vec<_> = demos.iter().map(|(q, d)| (*q, d)).collect();
        let skill = Skill::fit(
            self.space,
            &examples,
            self.kernels,
            primo_core::generalize::Method::Lwr { bandwidth: None },
        )
        .map_err(CliError::input)?;
        Ok((cell, skill))
    }
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

/// CRC-32C of the examples of `skill`.
fn examples_crc(skill: &Skill) -> u32 {
    let crc = crc::Crc::<u32>::new(&crc::CRC_32_ISCSI);
    let mut digest = crc.digest();
    for (q, theta) in skill.examples() {
        digest.update(&q.to_le_bytes());
        for t in theta {
            digest.update(&t.to_le_bytes());
        }
    }
    digest.finalize()
}

/// Where the learner runs.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LearnerSpec {
    /// A coprocessor's serial port, or `qemu`; in this process if `None`.
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

/// `primo pour`: learns, logging every roll-out, and writes the reports.
pub fn pour(start: Start, learner: &LearnerSpec) -> Result<(), CliError> {
    let started = Instant::now();
    // QEMU (when asked for) lives until the run ends.
    let (_qemu, mut learner) = open_learner(learner)?;
    let (dir, header, logged, mut log, ended) = match start {
        Start::New {
            out,
            settings,
            skill,
            cell,
        } => {
            let (_, fitted) = skill.build()?;
            let header = Header {
                version: VERSION,
                settings,
                examples: examples_crc(&fitted),
                skill,
                cell,
            };
            create_dir(&out)?;
            let log = RunLog::create(&out, &header)?;
            (out, header, Vec::new(), log, false)
        }
        Start::Resume { dir, instruments } => {
            let opened = RunLog::open::<Header, Entry>(&dir)?;
            if let Some(note) = &opened.recovered {
                eprintln!("primo pour: {note}");
            }
            let mut header = opened.header;
            match (&mut header.cell, instruments) {
                (CellSpec::Instruments(logged), Some(now)) => *logged = now,
                (CellSpec::Simulated, Some(_)) => {
                    return Err(CliError::input(format!(
                        "the run in {} is on the simulated cell: it cannot continue on \
                         instruments",
                        dir.display()
                    )));
                }
                (_, None) => {}
            }
            if header.version != VERSION {
                return Err(CliError::input(format!(
                    "{}: run log version {}, this primo reads version {VERSION}",
                    dir.join(crate::runlog::FILE).display(),
                    header.version
                )));
            }
            println!(
                "primo pour: {} {} after roll-out {}",
                if opened.ended {
                    "the run is complete: reporting"
                } else {
                    "resuming"
                },
                dir.display(),
                opened.entries.len()
            );
            (dir, header, opened.entries, opened.log, opened.ended)
        }
    };
    let s = header.settings;
    let (cell, skill) = header.skill.build()?;
    if examples_crc(&skill) != header.examples {
        return Err(CliError::input(format!(
            "the demonstrations of the run in {} have changed since it started: its examples \
             no longer fit to the same DMPs",
            dir.display()
        )));
    }
    let parameters = learned_parameters(&s, &skill);
    println!(
        "primo pour: {} from a {} l bottle, target {} l, {:?} space, {} learned parameter(s)",
        match s.method {
            Method::Golden => "golden-section error learning",
            Method::Illinois => "Illinois error learning",
            Method::Power => "extended PoWER",
        },
        s.bottle,
        s.target,
        skill.space(),
        parameters
    );
    let simulated = Simulated {
        cell,
        bottle: s.bottle,
        target: s.target,
        seed: s.seed,
    };
    let mut rig: Box<dyn Rig> = match &header.cell {
        // A complete run is only told again: no instrument is needed.
        _ if ended => Box::new(Complete),
        CellSpec::Simulated => Box::new(simulated.clone()),
        CellSpec::Instruments(spec) => {
            let rig = Instruments::open(
                spec.clone(),
                cell,
                s.bottle,
                s.target,
                Box::new(std::io::stdin().lock()),
            )
            .map_err(CliError::other)?;
            println!(
                "cell: robot {}, scale {} (serial {}){}",
                spec.robot,
                spec.scale,
                rig.scale_serial(),
                if spec.confirm {
                    "; the operator resets the cell before every roll-out"
                } else {
                    ""
                }
            );
            Box::new(rig)
        }
    };
    let progress = Progress::new(s.max_rollouts);
    let run = learn_on(
        &skill,
        &s,
        &mut learner,
        rig.as_mut(),
        (!ended).then_some(&mut log),
        &logged,
        |e, logged| {
            progress.clear();
            let line = crate::report::rollout_line(&e.record);
            if logged {
                println!("{line}  (logged)");
            } else {
                println!("{line}");
            }
            progress.show(
                e.record.rollout,
                &format!("error {:+.1} ml", e.record.trial.error * 1e3),
            );
        },
    )
    .map_err(|e| {
        CliError::input(format!(
            "{e}\nprimo pour: the run log in {} keeps every roll-out made; continue with \
             `primo pour --resume {}`",
            dir.display(),
            dir.display()
        ))
    })?;
    progress.clear();
    report(&dir, &s, &skill, &run, &simulated, &header.cell, started)
}

/// The cell of a complete run: it is told its logged roll-outs again and
/// makes none.
struct Complete;

impl Rig for Complete {
    fn roll_out(&mut self, _: &Skill, rollout: u32, _: f32, _: &[f32]) -> Result<Trial, String> {
        Err(format!(
            "the logged run is complete, yet the learner asks for roll-out {rollout}"
        ))
    }
}

/// Parameters learned: `[q̂, Δθ]` for PoWER, the query otherwise.
fn learned_parameters(s: &Settings, skill: &Skill) -> usize {
    match s.method {
        Method::Power => skill.param_len() + 1,
        _ => 1,
    }
}

/// Writes the reports of a run and prints its verdict.
fn report(
    dir: &Path,
    s: &Settings,
    skill: &Skill,
    run: &[Entry],
    simulated: &Simulated,
    cell: &CellSpec,
    started: Instant,
) -> Result<(), CliError> {
    let records: Vec<_> = run.iter().map(|e| e.record.clone()).collect();
    let last = records
        .iter()
        .rev()
        .find(|r| r.mean)
        .ok_or_else(|| CliError::other("no roll-out was made"))?;
    let converged_at = match s.method {
        Method::Power => None,
        _ => records
            .iter()
            .find(|r| r.trial.error.abs() < s.precision)
            .map(|r| r.rollout),
    };
    let best = best(run);
    let summary = PourSummary {
        settings: s,
        space: skill.space(),
        parameters: learned_parameters(s, skill),
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
            simulated
                .replay(skill, e.record.rollout, e.record.query, &e.delta)
                .map_err(CliError::other)?
                .series
        }
        _ => None,
    };
    let series_note = match (&series, best) {
        (Some(_), Some(e)) => format!("roll-out {} (best reward)", e.record.rollout),
        (None, Some(_)) => "empty (a real cell records no series)".into(),
        (_, None) => "empty (no roll-out was executed)".into(),
    };
    crate::series::write_csv(&dir.join("series.csv"), skill.space(), series.as_ref())?;
    let verdict = match (s.method, converged_at) {
        (Method::Power, _) => "learned".to_string(),
        (_, Some(n)) => format!(
            "converged to |error| < {} ml in {n} roll-outs",
            s.precision * 1e3
        ),
        (_, None) => format!("did not reach {} ml", s.precision * 1e3),
    };
    println!(
        "primo pour: {verdict}; last: q {:.4} l, poured {:.1} ml, spilled {:.1} ml, reward {:.3}; series.csv: {series_note}; wrote {}",
        last.query,
        last.trial.poured * 1e3,
        last.trial.spilled * 1e3,
        last.trial.reward,
        dir.display()
    );
    Ok(())
}

fn open_learner(spec: &LearnerSpec) -> Result<(Option<Qemu>, Learner), CliError> {
    Ok(match spec.coprocessor.as_deref() {
        None => (None, Learner::local()),
        Some("qemu") => {
            let elf = spec.firmware.clone().unwrap_or_else(Qemu::default_firmware);
            let qemu = Qemu::start(&elf).map_err(CliError::other)?;
            let link = Link::open(qemu.pty()).map_err(CliError::other)?;
            println!(
                "learner: firmware {} on QEMU mps2-an386, {}",
                elf.display(),
                qemu.pty()
            );
            (Some(qemu), Learner::Remote(link))
        }
        Some(port) => {
            let link = Link::open(port).map_err(CliError::other)?;
            println!("learner: coprocessor on {port}");
            (None, Learner::Remote(link))
        }
    })
}

/// Creates `dir` and its parents.
pub fn create_dir(dir: &Path) -> Result<(), CliError> {
    std::fs::create_dir_all(dir)
        .map_err(|e| CliError::other(format!("{}: cannot create: {e}", dir.display())))
}

/// A progress bar on stderr, redrawn in place when stderr is a terminal.
struct Progress {
    total: u32,
    tty: bool,
}

impl Progress {
    fn new(total: u32) -> Self {
        use std::io::IsTerminal;
        Progress {
            total: total.max(1),
            tty: std::io::stderr().is_terminal(),
        }
    }

    fn show(&self, done: u32, note: &str) {
        if !self.tty {
            return;
        }
        let width = 30;
        let filled = (done.min(self.total) * width / self.total) as usize;
        eprint!(
            "\r[{}{}] {done}/{} {note}   ",
            "#".repeat(filled),
            ".".repeat(width as usize - filled),
            self.total
        );
    }

    fn clear(&self) {
        if self.tty {
            eprint!("\r{}\r", " ".repeat(70));
        }
    }
}
