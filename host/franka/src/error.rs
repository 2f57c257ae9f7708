//! The one error of a Franka run, and the limit a setpoint breaks.

use std::time::Duration;

use crate::wire::{Flags, MoveStatus, StopMoveStatus, WireError};

/// Why a Franka run failed, in the operator's terms.
#[derive(Debug, thiserror::Error)]
pub enum FrankaError {
    /// The trajectory is for an arm without seven joints.
    #[error("a Franka arm has seven joints; the trajectory is for {robot}, which has {dof}")]
    NotSeven {
        /// The trajectory's robot.
        robot: String,
        /// Its joints.
        dof: usize,
    },
    /// A setpoint beyond the robot's limits: nothing was sent.
    #[error("trajectory refused before the motion: {0}")]
    Limit(Exceeded),
    /// Phase stopping could not slow or resume the motion within the
    /// limits: the motion was stopped there.
    #[error(
        "phase stopping could not keep the motion within the limits: {0}; the motion was stopped"
    )]
    Retimed(Exceeded),
    /// Phase stopping waited so long for a lagging arm that the motion
    /// reached [`crate::session::MAX_STRETCH`] times its plan: stopped.
    #[error(
        "phase stopping waited for the arm until the motion had taken {stretch} times its planned \
         {planned:.1} s: the motion was stopped (is the arm held or blocked?)"
    )]
    Held {
        /// The planned motion, s.
        planned: f64,
        /// How many times that it ran.
        stretch: usize,
    },
    /// The robot cannot be reached or the network failed.
    #[error("network: {0}")]
    Io(#[from] std::io::Error),
    /// The robot speaks another protocol version.
    #[error("the robot speaks FCI protocol version {robot}, primo version {ours}")]
    Version {
        /// The robot's.
        robot: u16,
        /// primo's.
        ours: u16,
    },
    /// A message that is not the protocol's.
    #[error("malformed message from the robot: {0}")]
    Wire(#[from] WireError),
    /// A response primo did not ask for, or a status the protocol lacks.
    #[error("unexpected answer from the robot: {0}")]
    Unexpected(String),
    /// The robot did not serve its model.
    #[error("the robot did not serve its model (status {0})")]
    Model(u8),
    /// The robot is in error before the motion.
    #[error("the robot is in error ({errors}) or not ready (mode {mode}); clear it first")]
    NotReady {
        /// Its errors.
        errors: Flags,
        /// Its robot mode.
        mode: u8,
    },
    /// The robot refused the motion.
    #[error("the robot refused the motion: {0}")]
    Refused(MoveStatus),
    /// The robot stopped the motion: a reflex, the emergency stop, an
    /// abort.
    #[error("the robot stopped the motion ({}): reflex {reflex}; errors {errors}", status.map_or_else(|| "a reflex".to_string(), |s| s.to_string()))]
    Aborted {
        /// Its answer to the motion, if it gave one.
        status: Option<MoveStatus>,
        /// What triggered the reflex.
        reflex: Flags,
        /// The errors present.
        errors: Flags,
    },
    /// The robot refused or failed to stop.
    #[error("stopping the motion: {0}")]
    Stop(StopMoveStatus),
    /// A state older than the newest already seen.
    #[error("the robot's state {got} came after state {last}: its states must count up")]
    Stale {
        /// Its `message_id`.
        got: u64,
        /// The newest seen.
        last: u64,
    },
    /// The state stream fell silent.
    #[error("no state from the robot for {0:?}")]
    Silent(Duration),
    /// A response did not come.
    #[error("no answer from the robot to {what} within {after:?}")]
    NoAnswer {
        /// The request.
        what: &'static str,
        /// The wait.
        after: Duration,
    },
    /// The robot closed the command connection.
    #[error("the robot closed the command connection")]
    Closed,
    /// The operator interrupted the run; the robot stopped.
    #[error("interrupted; the motion was stopped")]
    Interrupted,
    /// A loop thread failed.
    #[error("the control loop's thread failed")]
    Thread,
}

/// Which limit a setpoint breaks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// The joint's position range.
    Position,
    /// Its velocity limit.
    Velocity,
    /// The FCI's acceleration limit.
    Acceleration,
    /// The FCI's jerk limit.
    Jerk,
}

/// A setpoint beyond a limit.
#[derive(Debug, Clone, PartialEq)]
pub struct Exceeded {
    /// The setpoint's index, from the first of the approach.
    pub setpoint: usize,
    /// Its time from the path's start, s (negative in the approach).
    pub time: f64,
    /// The joint's name.
    pub joint: String,
    /// What it breaks.
    pub quantity: Quantity,
    /// The value, rad, rad/s, rad/s² or rad/s³.
    pub value: f64,
    /// The limit (the nearer bound of a position range).
    pub limit: f64,
}

impl std::fmt::Display for Exceeded {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (what, unit) = match self.quantity {
            Quantity::Position => ("position", "rad"),
            Quantity::Velocity => ("velocity", "rad/s"),
            Quantity::Acceleration => ("acceleration", "rad/s²"),
            Quantity::Jerk => ("jerk", "rad/s³"),
        };
        write!(
            f,
            "{} {what} {:.4} {unit} at t = {:.3} s (setpoint {}) is beyond its limit {:.4} {unit}",
            self.joint, self.value, self.time, self.setpoint, self.limit
        )
    }
}
