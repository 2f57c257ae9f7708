//! The command line's one error: a message and the exit status, chosen
//! here from the libraries' typed errors and nowhere else.
//!
//! | status | meaning |
//! |---|---|
//! | 0 | done |
//! | 1 | a failure while running: an instrument, the robot stopping, I/O; a trajectory failing `robot check` |
//! | 2 | bad input or a refused setting: nothing was started |
//! | 130 | interrupted (Ctrl-C); a learning run can be resumed |
//! | 141 | standard output was closed (a pipe's reader left); a learning run can be resumed |

use std::fmt;

/// A command's failure: a one-line message and the process exit status.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CliError {
    /// The message, already naming file, line and column where known; empty
    /// when nothing should be said.
    pub message: String,
    /// Exit status.
    pub status: i32,
}

/// Exit status of an interrupted command.
pub const INTERRUPTED: i32 = 130;
/// Exit status when standard output was closed.
pub const CLOSED: i32 = 141;

impl CliError {
    /// Bad input (a malformed file or argument): exit status 2.
    pub fn input(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            status: 2,
        }
    }

    /// Anything else (I/O, instruments): exit status 1.
    pub fn other(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            status: 1,
        }
    }

    /// A failed write to standard output: quiet if its reader is gone.
    pub fn stdout(e: std::io::Error) -> Self {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            Self {
                message: String::new(),
                status: CLOSED,
            }
        } else {
            Self::other(format!("stdout: {e}"))
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

/// Where the port of a scale `qemu:LOAD_CELL` comes from, if that is
/// what `scale` names.
pub fn load_cell_hint(scale: &str) -> &'static str {
    match scale.starts_with("qemu") {
        true => " (`primo robot sim-krc --load-cell` prints it)",
        false => "",
    }
}

/// The flag of a learning setting.
fn flag(setting: primo_learn::Setting) -> String {
    format!("--{}", setting.name().replace('_', "-"))
}

impl CliError {
    /// A learning library's error from `primo COMMAND`: settings named
    /// by their flags, with the advice what to do next.
    pub fn learning(command: &str, e: primo_learn::Error) -> Self {
        use primo_learn::Error;
        match e {
            Error::Occupied {
                ref log,
                finished: false,
                ..
            } => {
                let dir = log.parent().unwrap_or(log);
                Self::input(format!(
                    "{e}: continue it with `primo {command} --resume {}`, choose another --out, \
                     or give --force to start anew (the run is moved aside)",
                    dir.display()
                ))
            }
            Error::OtherKind { ref kind, ref dir } => {
                // `primo learn` continues either kind.
                let other = if kind == "pour" { "pour" } else { "learn" };
                Self::input(format!(
                    "{e}, written by `primo {other}`: continue it with `primo {other} --resume {}`",
                    dir.display()
                ))
            }
            e => e.into(),
        }
    }
}

impl From<primo_learn::Error> for CliError {
    fn from(e: primo_learn::Error) -> Self {
        use primo_learn::Error;
        match e {
            Error::Setting {
                setting,
                value,
                why,
            } => {
                let hint = match setting {
                    primo_learn::Setting::Scale => load_cell_hint(&value),
                    _ => "",
                };
                Self::input(format!("{} {value}: {why}{hint}", flag(setting)))
            }
            Error::Conflict {
                setting,
                value,
                other,
                other_value,
                why,
            } => Self::input(format!(
                "{} {value} with {} {other_value}: {why}",
                flag(setting),
                flag(other)
            )),
            Error::Address(e) => e.into(),
            Error::Open {
                setting,
                ref path,
                ref fault,
            } => Self::opening(
                format!("{} {}: {fault}", flag(setting), path.display()),
                fault,
            ),
            // The coprocessor's image, unlike the scale's, has a flag.
            e @ Error::NoFirmware {
                name: "primo-firmware",
                ..
            } => Self::other(format!("{e}, or with --firmware")),
            Error::NotADirectory { out, blocking } => Self::input(format!(
                "--out {}: {} is not a directory",
                out.display(),
                blocking.display()
            )),
            Error::Occupied { finished: true, .. } => Self::input(format!(
                "{e}: choose another --out, or give --force to start anew (the run is moved aside)"
            )),
            Error::Occupied { .. } => Self::input(format!(
                "{e}: continue it with --resume, choose another --out, or give --force to start \
                 anew (the run is moved aside)"
            )),
            Error::HoldsResult { .. } => Self::input(format!(
                "{e}: choose another --out, or give --force to replace it"
            )),
            Error::NoLog(ref log) => Self::input(format!(
                "--resume {}: no run log ({}) there",
                log.parent().unwrap_or(log).display(),
                primo_learn::runlog::FILE
            )),
            Error::Io { ref source, .. } if source.kind() == std::io::ErrorKind::BrokenPipe => {
                Self::stdout(std::io::Error::from(std::io::ErrorKind::BrokenPipe))
            }
            Error::Interrupted => Self {
                message: "interrupted".into(),
                status: INTERRUPTED,
            },
            e if e.is_input() => Self::input(e.to_string()),
            e => Self::other(e.to_string()),
        }
    }
}

impl From<primo_skill::Error> for CliError {
    fn from(e: primo_skill::Error) -> Self {
        Self::input(e.to_string())
    }
}

impl From<primo_fri::AddressError> for CliError {
    fn from(e: primo_fri::AddressError) -> Self {
        Self::input(format!("--robot `{}`: {}", e.spec, e.explained()))
    }
}

impl From<primo_fri::udp::SocketError> for CliError {
    fn from(e: primo_fri::udp::SocketError) -> Self {
        Self::other(e.to_string())
    }
}

impl From<primo_sim::Error> for CliError {
    fn from(e: primo_sim::Error) -> Self {
        match e {
            primo_sim::Error::Invalid(why) => Self::input(why),
            primo_sim::Error::Io(why) => Self::other(why),
        }
    }
}

impl From<primo_mtsics::ScaleError> for CliError {
    /// A port that would not open is bad input unless opening failed
    /// otherwise ([`CliError::opening`]); the rest happened while talking
    /// to the scale.
    fn from(e: primo_mtsics::ScaleError) -> Self {
        match &e.kind {
            primo_mtsics::ErrorKind::Open(fault) => Self::opening(e.to_string(), fault),
            _ => Self::other(e.to_string()),
        }
    }
}

impl CliError {
    /// A port or file that would not open (`message` says which and why):
    /// the one status for the one fault, whichever command met it, 2 for
    /// a bad path (missing, a directory, no serial port, not permitted).
    pub fn opening(message: String, fault: &primo_mtsics::path::Fault) -> Self {
        match fault.is_input() {
            true => Self::input(message),
            false => Self::other(message),
        }
    }
}
