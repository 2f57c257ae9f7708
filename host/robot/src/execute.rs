//! What every robot driver offers a roll-out: execute a checked
//! [`JointPath`] and report the joint positions the robot went through.
//!
//! The trait is robot-agnostic (ROS 2's `FollowJointTrajectory`, a
//! Franka's FCI, …): a learning run executes its roll-outs through any
//! [`Executor`], records [`Executed`] in its run log and, on an
//! [`ExecutionFailed`], ends the roll-out with the run log intact.
//!
//! ```
//! use primo_robot::execute::{Executed, ExecutionFailed, Executor};
//! use primo_robot::{JointPath, Robot, safety::check_joints};
//!
//! /// A robot that is wherever it is told, at once.
//! struct Ideal;
//! impl Executor for Ideal {
//!     fn execute(&mut self, path: &JointPath) -> Result<Executed, ExecutionFailed> {
//!         Ok(Executed {
//!             times: path.times().to_vec(),
//!             positions: path.positions().to_vec(),
//!         })
//!     }
//! }
//! let path = check_joints(&Robot::lwr4(), vec![0.0, 1.0], vec![[0.1; 7], [0.2; 7]]).unwrap();
//! let done = Ideal.execute(&path).unwrap();
//! assert_eq!(done.rows(7).count(), 2);
//! ```

use std::error::Error;
use std::fmt;

use primo_core::coupling::PhaseStop;

use crate::JointPath;

/// The joint positions a robot reported while it executed a path.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Executed {
    /// When, s since the robot started executing the path.
    pub times: Vec<f64>,
    /// Joint positions, row-major, in the order of the path's chain.
    pub positions: Vec<f64>,
}

impl Executed {
    /// The positions per report, `dof` joints each.
    pub fn rows(&self, dof: usize) -> std::slice::ChunksExact<'_, f64> {
        self.positions.chunks_exact(dof.max(1))
    }
}

/// A path that was not executed to its end.
#[derive(Debug)]
pub struct ExecutionFailed {
    /// Why, a driver's typed error (its message is in the user's terms).
    pub why: Box<dyn Error + Send + Sync>,
    /// What the robot reported before it ended.
    pub executed: Executed,
}

impl fmt::Display for ExecutionFailed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.why.fmt(f)
    }
}

impl Error for ExecutionFailed {
    fn source(&self) -> Option<&(dyn Error + 'static)> {
        Some(self.why.as_ref())
    }
}

/// A robot that executes checked joint paths.
pub trait Executor {
    /// Executes `path` (it passed the limits of its chain, which names the
    /// joints) and reports what the robot did; blocks until the robot has
    /// finished or the execution failed.
    fn execute(&mut self, path: &JointPath) -> Result<Executed, ExecutionFailed>;

    /// Slows every path while the robot lags its command (phase stopping
    /// with `gain`), if this driver can: only one that streams each
    /// setpoint and reads where the robot is can wait for it. Returns
    /// whether it will; a driver that hands the whole path to the robot's
    /// controller (ROS 2) cannot.
    fn phase_stop(&mut self, gain: PhaseStop) -> bool {
        let _ = gain;
        false
    }
}
