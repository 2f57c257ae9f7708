//! primo's robot model and safety gate.
//!
//! - [`description`]: a robot's description ([`Robot`]: DH table, flange,
//!   joint limits), built in for the KUKA LWR 4+ or read from JSON.
//! - [`pose`]: [`Pose`], rigid transforms and their rotations (matrix,
//!   rotation vector, quaternion).
//! - [`kinematics`]: an [`Arm`] (a robot holding a tool): forward
//!   kinematics, the Jacobian and inverse kinematics.
//! - [`limits`]: the joint position and velocity limits checked along a
//!   trajectory.
//! - [`envelope`]: the limits of a task's trajectory of named columns (a
//!   robot preset, or per-column limits and a workspace box); its only
//!   output is a [`envelope::Checked`] trajectory.
//! - [`safety`]: the one gate every trajectory passes before it moves a
//!   robot, simulated or real; its only output is a [`JointPath`].
//!
//! Nothing here knows the simulator or a driver: both take their limits
//! from here.
#![deny(missing_docs)]

pub mod description;
pub mod envelope;
pub mod kinematics;
pub mod limits;
pub mod pose;
pub mod safety;

pub use description::{DescriptionError, JOINTS, Link, Robot};
pub use kinematics::{Arm, IkError};
pub use limits::Violation;
pub use pose::Pose;
pub use safety::{
    CartesianLimits, Gate, JOINT_COLUMNS, JointPath, POSE_COLUMNS, Rejection, check_joints,
};
