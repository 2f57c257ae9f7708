use std::path::{Path, PathBuf};

use primo_mtsics::path::{Fault, Wanted, read_text};

/// What goes wrong in the learning library. [`Error::is_input`] tells bad
/// input and refused settings (the user can fix them before anything
/// runs) from failures while running (instruments, I/O, the robot).
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A setting out of range or settings that contradict each other.
    #[error("{0}")]
    Invalid(String),
    /// A run's setting that cannot be used: which, as given, and why.
    #[error("{} {value}: {why}", setting.name())]
    Setting {
        /// Which.
        setting: Setting,
        /// As given.
        value: String,
        /// Why not.
        why: String,
    },
    /// Two settings that contradict each other: which, as given, and why.
    #[error("{} {value} with {} {other_value}: {why}", setting.name(), other.name())]
    Conflict {
        /// The setting refused.
        setting: Setting,
        /// As given.
        value: String,
        /// The setting it contradicts.
        other: Setting,
        /// As given.
        other_value: String,
        /// Why.
        why: String,
    },
    /// An output directory that cannot be one: something else is in its
    /// way.
    #[error("{}: {} is not a directory", out.display(), blocking.display())]
    NotADirectory {
        /// The directory asked for.
        out: PathBuf,
        /// What is in the way (`out` or one of its parents).
        blocking: PathBuf,
    },
    /// A run is logged in the directory a new run was to be logged in.
    #[error(
        "{}: {} run ({rollouts} roll-outs) is logged here",
        log.display(),
        if *finished { "a finished" } else { "an unfinished" }
    )]
    Occupied {
        /// The log.
        log: PathBuf,
        /// Its roll-outs.
        rollouts: usize,
        /// It is complete (a new run may replace it when forced); an
        /// unfinished run is never replaced, only continued.
        finished: bool,
    },
    /// An output directory another process holds ([`crate::lock`]).
    #[error("{}", crate::lock::describe(dir, pid, command))]
    InUse {
        /// The directory.
        dir: PathBuf,
        /// The holder's pid, if it said.
        pid: Option<u32>,
        /// The holder's command line, if it said.
        command: Option<String>,
    },
    /// An experiment's earlier result in the directory it was to write.
    #[error("{}: an earlier result is here", file.display())]
    HoldsResult {
        /// The result's file found.
        file: PathBuf,
    },
    /// An existing file this user may not write: left as it is.
    #[error("{}: not writable by this user (mode {mode:o}): left as it is", path.display())]
    ReadOnly {
        /// The file.
        path: PathBuf,
        /// Its permission bits.
        mode: u32,
    },
    /// No run log where a run was to be continued: the log's path.
    #[error("{}: not found: there is no run to continue", .0.display())]
    NoLog(PathBuf),
    /// The run logged in `dir` is of another kind than the one asked for.
    #[error("the run logged in {} is a {kind} run", dir.display())]
    OtherKind {
        /// Its directory.
        dir: PathBuf,
        /// Its kind's name.
        kind: String,
    },
    /// Demonstrations, DMP files, and the skill made of them.
    #[error(transparent)]
    Skill(#[from] primo_skill::Error),
    /// A robot address that cannot be used.
    #[error(transparent)]
    Address(#[from] primo_fri::AddressError),
    /// A run log that is not what it should be (corrupt, of another run,
    /// of another version): refused, and left as it is.
    #[error("{0}")]
    Log(String),
    /// A file or directory could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The path.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The robot's FRI socket failed.
    #[error(transparent)]
    Socket(#[from] primo_fri::udp::SocketError),
    /// A port or file named by a setting would not open: why
    /// ([`primo_mtsics::path`]).
    #[error("{} {}: {fault}", setting.name(), path.display())]
    Open {
        /// The setting that named it.
        setting: Setting,
        /// As given.
        path: PathBuf,
        /// Why it would not open.
        fault: Fault,
    },
    /// The scale failed.
    #[error(transparent)]
    Scale(primo_mtsics::ScaleError),
    /// An instrument or the operator failed in a roll-out.
    #[error("{0}")]
    Instrument(String),
    /// The robot stopped before a roll-out's movement was complete.
    #[error("{0}")]
    RobotStopped(String),
    /// The coprocessor's link failed.
    #[error("{0}")]
    Coprocessor(String),
    /// A firmware image that is not built where primo looks for it.
    #[error(
        "the firmware {name} is not built (looked at {}): build it with `cd {} && cargo \
         build --release` (needs `rustup target add thumbv7em-none-eabihf`), or name it in \
         {variable}",
        looked.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", "),
        sources.display()
    )]
    NoFirmware {
        /// The image's ELF name.
        name: &'static str,
        /// The environment variable that names it.
        variable: &'static str,
        /// Where primo looked.
        looked: Vec<PathBuf>,
        /// The firmware's sources, where it is built.
        sources: PathBuf,
    },
    /// A report (summary, chart) could not be made.
    #[error("{0}")]
    Report(String),
    /// The user asked the run to stop.
    #[error("interrupted")]
    Interrupted,
    /// The learner refused a request, or answered out of turn.
    #[error("{0}")]
    Learner(String),
}

impl Error {
    /// Bad input or a refused configuration (exit status 2 on the command
    /// line), as opposed to a failure while running (status 1).
    pub fn is_input(&self) -> bool {
        if let Error::Open { fault, .. } = self {
            return fault.is_input();
        }
        matches!(
            self,
            Error::Invalid(_)
                | Error::Setting { .. }
                | Error::Conflict { .. }
                | Error::NotADirectory { .. }
                | Error::Occupied { .. }
                | Error::InUse { .. }
                | Error::HoldsResult { .. }
                | Error::NoLog(_)
                | Error::OtherKind { .. }
                | Error::Skill(_)
                | Error::Address(_)
                | Error::Log(_)
        )
    }

    /// A refused `setting` given as `value`, and why.
    pub fn setting(setting: Setting, value: impl ToString, why: impl Into<String>) -> Error {
        Error::Setting {
            setting,
            value: value.to_string(),
            why: why.into(),
        }
    }

    /// `path`, named by `setting`, would not open as `wanted` with `e`.
    pub fn open(
        setting: Setting,
        path: impl Into<PathBuf>,
        wanted: Wanted,
    ) -> impl FnOnce(std::io::Error) -> Error {
        let path = path.into();
        move |e| Error::Open {
            fault: Fault::of(&path, wanted, e),
            setting,
            path,
        }
    }

    /// The text file `path` named by `setting`, read.
    pub fn read(setting: Setting, path: &Path) -> Result<String, Error> {
        read_text(path).map_err(|fault| Error::Open {
            setting,
            path: path.to_path_buf(),
            fault,
        })
    }

    /// An I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> Error {
        let path = path.into();
        move |source| Error::Io { path, source }
    }
}

impl From<primo_mtsics::ScaleError> for Error {
    /// The real cell's scale: a port that would not open is its setting's.
    fn from(e: primo_mtsics::ScaleError) -> Self {
        match e.kind {
            primo_mtsics::ErrorKind::Open(fault) => Error::Open {
                setting: Setting::Scale,
                path: e.port.into(),
                fault,
            },
            _ => Error::Scale(e),
        }
    }
}

/// A setting of a run or an experiment, as the library names it (the
/// command line names its flag, the Python package its parameter).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Setting {
    /// The output directory.
    Out,
    /// Kernels per DoF.
    Kernels,
    /// A demonstration file and its query.
    Demo,
    /// Liquid in the bottle, l.
    Bottle,
    /// Volume to pour, l.
    Target,
    /// Error learning's query bounds.
    Search,
    /// What the glass holds, l.
    GlassHolds,
    /// Error learning's precision.
    Precision,
    /// The learner.
    Method,
    /// The roll-out budget.
    MaxRollouts,
    /// The error learners' gain.
    Gain,
    /// PoWER's importance sampler length.
    Sampler,
    /// PoWER updates per run of the power experiment.
    Updates,
    /// Seeded runs per variant of the power experiment.
    Runs,
    /// The golden experiment's bottle volumes.
    Volumes,
    /// Where the learner runs.
    Coprocessor,
    /// The real cell's scale.
    Scale,
    /// An MT-SICS scale's baud rate.
    Baud,
    /// The liquid's density, g/ml.
    Density,
    /// A task file.
    Task,
    /// The run to continue.
    Resume,
}

impl Setting {
    /// Its name.
    pub fn name(self) -> &'static str {
        match self {
            Setting::Out => "out",
            Setting::Kernels => "kernels",
            Setting::Demo => "demo",
            Setting::Bottle => "bottle",
            Setting::Target => "target",
            Setting::Search => "search",
            Setting::GlassHolds => "glass_holds",
            Setting::Precision => "precision",
            Setting::Method => "method",
            Setting::MaxRollouts => "max_rollouts",
            Setting::Gain => "gain",
            Setting::Sampler => "sampler",
            Setting::Updates => "updates",
            Setting::Runs => "runs",
            Setting::Volumes => "volumes",
            Setting::Coprocessor => "coprocessor",
            Setting::Scale => "scale",
            Setting::Baud => "baud",
            Setting::Density => "density",
            Setting::Task => "task",
            Setting::Resume => "resume",
        }
    }
}
