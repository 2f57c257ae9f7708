//! primo's skills: demonstrations fitted as DMPs, generalized over a task
//! query, planned, and checked by the safety gate.
//!
//! - [`coupled`]: a DMP's run with coupling terms: obstacles, joint limits.
//! - [`csv`]: demonstration and trajectory CSV files (`t,<DoF names>`).
//! - [`dmpfile`]: the versioned JSON format of a fitted DMP.
//! - [`prompfile`]: a ProMP by column name, and its JSON file.
//! - [`stamps`]: sample times taken relative to the first sample.
//! - [`shaping`]: a run's velocity at the goal and via-points, by column.
//! - [`skill`]: demonstrations → DMPs → generalization → checked plans.
#![deny(missing_docs)]

pub mod coupled;
pub mod csv;
pub mod dmpfile;
mod error;
pub mod prompfile;
mod seconds;
pub mod shaping;
pub mod skill;
pub mod stamps;

pub use error::Error;
pub use skill::{MAX_QUERY, Plan, Skill};

/// Largest DoF count the host's DMPs hold.
pub const HOST_MAX_DOF: usize = 16;
/// Largest kernel count per DoF the host's DMPs hold.
pub const MAX_KERNELS: usize = 128;
/// The DMP type the host uses for files and skills.
pub type HostDmp = primo_core::dmp::Dmp<HOST_MAX_DOF, MAX_KERNELS>;
