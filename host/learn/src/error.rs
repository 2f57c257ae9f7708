use std::path::PathBuf;

/// What goes wrong in the learning library. [`Error::is_input`] tells bad
/// input and refused settings (the user can fix them before anything
/// runs) from failures while running (instruments, I/O, the robot).
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A setting out of range or settings that contradict each other.
    #[error("{0}")]
    Invalid(String),
    /// Demonstrations, DMP files, and the skill made of them.
    #[error(transparent)]
    Skill(#[from] primo_skill::Error),
    /// The simulated cell refused a setting or a movement, or one of its
    /// devices failed.
    #[error(transparent)]
    Sim(#[from] primo_sim::Error),
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
    /// The scale failed.
    #[error(transparent)]
    Scale(#[from] primo_mtsics::ScaleError),
    /// An instrument or the operator failed in a roll-out.
    #[error("{0}")]
    Instrument(String),
    /// The robot stopped before a roll-out's movement was complete.
    #[error("{0}")]
    RobotStopped(String),
    /// The coprocessor's link failed.
    #[error("{0}")]
    Coprocessor(String),
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
        matches!(
            self,
            Error::Invalid(_)
                | Error::Skill(_)
                | Error::Address(_)
                | Error::Log(_)
                | Error::Sim(primo_sim::Error::Invalid(_))
        )
    }

    /// An I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> Error {
        let path = path.into();
        move |source| Error::Io { path, source }
    }
}
