use primo_robot::Rejection;

/// What goes wrong with demonstrations, DMP files and the movements a
/// skill plans. Every message names what it is about (file, line and
/// column; demonstration; query).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A file that is not what it should be: a demonstration CSV or a DMP
    /// file.
    #[error("{0}")]
    File(String),
    /// Demonstrations that do not make a skill: wrong columns, too few, a
    /// fit that fails, examples that cannot be generalized.
    #[error("{0}")]
    Demonstrations(String),
    /// A movement that cannot be computed: a query the generalization
    /// refuses, parameters a DMP refuses, an integration that fails.
    #[error("{0}")]
    Movement(String),
    /// The safety gate refused the movement.
    #[error(transparent)]
    Rejected(#[from] Rejection),
}
