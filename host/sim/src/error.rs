/// What goes wrong in the simulation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A setting out of range, or a movement the simulated cell or expert
    /// cannot make: refused before anything runs.
    #[error("{0}")]
    Invalid(String),
    /// A socket or pseudo-terminal of a simulated device failed.
    #[error("{0}")]
    Io(String),
}

impl From<&'static str> for Error {
    fn from(why: &'static str) -> Self {
        Error::Invalid(why.into())
    }
}
