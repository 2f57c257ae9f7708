//! A task file: what `primo learn` teaches, from the lab's own
//! demonstrations, query, limits and evaluator. TOML, versioned; every key
//! is documented in the book's task file reference, an unknown key is
//! refused, and every check runs before anything moves: the message names
//! the file, the line and the key.
//!
//! [`Task::load`] reads and checks the file; [`Task::build`] reads the
//! demonstrations, checks their columns (by name, across demonstrations)
//! and that they pass the limits, and fits the skill.

pub mod build;
pub mod change;
pub mod check;
pub mod evaluator;
pub mod goals;
pub mod report;
pub mod run;
mod schema;
pub mod spec;
pub mod trial;

pub use spec::{
    Built, ColumnRange, DEFAULT_TIMEOUT, Evaluate, Goal, GoalSearch, LearnerSettings, LimitsSpec,
    PourTask, RewardRule, Task, TaskDemo, VERSION, Workspace,
};
