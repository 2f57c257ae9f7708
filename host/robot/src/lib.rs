//! primo's robot model and safety gate.
//!
//! - [`urdf`]: a URDF's links and joints, each placed at its line.
//! - [`chain`]: any serial arm ([`Chain`]: its joints from a base link to
//!   a tip, with their limits) from a URDF or a DH table; forward
//!   kinematics and the geometric Jacobian on nalgebra.
//! - [`columns`]: a trajectory's columns as a chain's joints by name or
//!   its tool's pose.
//! - [`ik`]: inverse kinematics of any chain (damped least squares within
//!   the limits, a null-space pull toward a rest posture).
//! - [`description`]: the built-in KUKA LWR 4+ ([`Robot`]: DH table,
//!   flange, joint limits), or an arm of its structure read from JSON.
//! - [`pose`]: [`Pose`], rigid transforms and their rotations (matrix,
//!   rotation vector, quaternion).
//! - [`kinematics`]: an [`Arm`] (a robot holding a tool): forward
//!   kinematics, the Jacobian and inverse kinematics.
//! - [`limits`]: the joint position and velocity limits of any chain (and
//!   an acceleration bound) checked along a trajectory.
//! - [`posture`]: a chain's posture by joint name, within its limits.
//! - [`tool_path`]: a trajectory of any chain's tool poses, solved to joint
//!   positions by the inverse kinematics and checked.
//! - [`envelope`]: the limits of a task's trajectory of named columns (a
//!   robot's, or per-column limits and a workspace box); its only
//!   output is a [`envelope::Checked`] trajectory.
//! - [`safety`]: the one gate every trajectory passes before it moves a
//!   robot, simulated or real; its only output is a [`JointPath`].
//! - [`execute`]: the [`execute::Executor`] trait every robot driver
//!   implements to execute a [`JointPath`] and report what it did.
//!
//! Nothing here knows the simulator or a driver: both take their limits
//! from here.
#![deny(missing_docs)]

pub mod chain;
pub mod columns;
pub mod description;
pub mod envelope;
pub mod execute;
pub mod ik;
pub mod kinematics;
pub mod limits;
pub mod pose;
pub mod posture;
pub mod safety;
pub mod tool_path;
pub mod urdf;

pub use chain::{Chain, JointLimits, Link, Tip};
pub use description::{DescriptionError, JOINTS, Robot};
pub use ik::IkError;
pub use kinematics::Arm;
pub use limits::Violation;
pub use pose::Pose;
pub use safety::{
    CartesianLimits, Gate, JOINT_COLUMNS, JointPath, POSE_COLUMNS, Rejection, check_joints,
};
