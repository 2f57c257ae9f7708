//! The ROS 2 messages primo exchanges, as serde structs in the field order
//! of their `.msg` definitions (the CDR encoding is ros2-client's):
//! `sensor_msgs/JointState` and `control_msgs/action/FollowJointTrajectory`
//! in the layout of control_msgs 5.8.0 (ROS 2 Jazzy; Humble's is the
//! same).
//!
//! Rolling's control_msgs (6.x) appends `index` and `multi_dof_index` to
//! the feedback: extra bytes at its end, which the decoder ignores, so
//! either layout is read.

use ros2_client::Message;
use serde::{Deserialize, Serialize};

/// `builtin_interfaces/Time` and `Duration`: seconds and nanoseconds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default, Serialize, Deserialize)]
pub struct Stamp {
    /// Whole seconds.
    pub sec: i32,
    /// Nanoseconds, below 10⁹.
    pub nanosec: u32,
}

impl Stamp {
    /// `seconds` (≥ 0), to the nanosecond.
    pub fn from_seconds(seconds: f64) -> Stamp {
        let ns = (seconds.max(0.0) * 1e9).round() as i64;
        Stamp {
            sec: i32::try_from(ns / 1_000_000_000).unwrap_or(i32::MAX),
            nanosec: (ns % 1_000_000_000) as u32,
        }
    }

    /// In seconds.
    pub fn seconds(self) -> f64 {
        f64::from(self.sec) + f64::from(self.nanosec) * 1e-9
    }

    /// Zero: "not set" in a header, "start now" in a trajectory's.
    pub fn is_zero(self) -> bool {
        self.sec == 0 && self.nanosec == 0
    }
}

/// `std_msgs/Header`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Header {
    /// When.
    pub stamp: Stamp,
    /// The frame.
    pub frame_id: String,
}

/// `sensor_msgs/JointState`: any subset of the robot's joints, by name.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct JointState {
    /// When it was measured.
    pub header: Header,
    /// Joint names.
    pub name: Vec<String>,
    /// Positions, rad or m, by `name`.
    pub position: Vec<f64>,
    /// Velocities (may be empty).
    pub velocity: Vec<f64>,
    /// Efforts (may be empty).
    pub effort: Vec<f64>,
}
impl Message for JointState {}

/// `trajectory_msgs/JointTrajectoryPoint`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct JointTrajectoryPoint {
    /// Positions by the trajectory's `joint_names`.
    pub positions: Vec<f64>,
    /// Velocities (empty: the controller interpolates).
    pub velocities: Vec<f64>,
    /// Accelerations (may be empty).
    pub accelerations: Vec<f64>,
    /// Efforts (may be empty).
    pub effort: Vec<f64>,
    /// Since the trajectory's start.
    pub time_from_start: Stamp,
}

/// `trajectory_msgs/JointTrajectory`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct JointTrajectory {
    /// A zero stamp starts it at once.
    pub header: Header,
    /// The joints, in the order of every point's vectors.
    pub joint_names: Vec<String>,
    /// The points.
    pub points: Vec<JointTrajectoryPoint>,
}

/// `geometry_msgs/Vector3`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Vector3 {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

/// `geometry_msgs/Quaternion`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Quaternion {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w.
    pub w: f64,
}

/// `geometry_msgs/Transform`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Transform {
    /// Translation.
    pub translation: Vector3,
    /// Rotation.
    pub rotation: Quaternion,
}

/// `geometry_msgs/Twist`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Twist {
    /// Linear.
    pub linear: Vector3,
    /// Angular.
    pub angular: Vector3,
}

/// `trajectory_msgs/MultiDOFJointTrajectoryPoint` (primo sends none).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct MultiDofPoint {
    /// Transforms.
    pub transforms: Vec<Transform>,
    /// Velocities.
    pub velocities: Vec<Twist>,
    /// Accelerations.
    pub accelerations: Vec<Twist>,
    /// Since the start.
    pub time_from_start: Stamp,
}

/// `trajectory_msgs/MultiDOFJointTrajectory` (primo sends an empty one).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct MultiDofTrajectory {
    /// Header.
    pub header: Header,
    /// Joints.
    pub joint_names: Vec<String>,
    /// Points.
    pub points: Vec<MultiDofPoint>,
}

/// `control_msgs/JointTolerance` (primo leaves the controller's own).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct JointTolerance {
    /// Joint.
    pub name: String,
    /// Position.
    pub position: f64,
    /// Velocity.
    pub velocity: f64,
    /// Acceleration.
    pub acceleration: f64,
}

/// `control_msgs/JointComponentTolerance`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct JointComponentTolerance {
    /// Joint.
    pub joint_name: String,
    /// Component (X_AXIS 1 … TWIST 7).
    pub component: u16,
    /// Position.
    pub position: f64,
    /// Velocity.
    pub velocity: f64,
    /// Acceleration.
    pub acceleration: f64,
}

/// The goal of `FollowJointTrajectory`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Goal {
    /// The joint trajectory.
    pub trajectory: JointTrajectory,
    /// Empty.
    pub multi_dof_trajectory: MultiDofTrajectory,
    /// Empty: the controller's.
    pub path_tolerance: Vec<JointTolerance>,
    /// Empty.
    pub component_path_tolerance: Vec<JointComponentTolerance>,
    /// Empty: the controller's.
    pub goal_tolerance: Vec<JointTolerance>,
    /// Empty.
    pub component_goal_tolerance: Vec<JointComponentTolerance>,
    /// Zero: the controller's.
    pub goal_time_tolerance: Stamp,
}
impl Message for Goal {}

/// The result of `FollowJointTrajectory`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct FjtResult {
    /// 0 or one of [`crate::ErrorCode`]'s.
    pub error_code: i32,
    /// The controller's words.
    pub error_string: String,
}
impl Message for FjtResult {}

/// The feedback of `FollowJointTrajectory`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Feedback {
    /// When.
    pub header: Header,
    /// The joints of the points below.
    pub joint_names: Vec<String>,
    /// Where the controller wants them.
    pub desired: JointTrajectoryPoint,
    /// Where they are.
    pub actual: JointTrajectoryPoint,
    /// `desired - actual`.
    pub error: JointTrajectoryPoint,
    /// Multi-DOF joints.
    pub multi_dof_joint_names: Vec<String>,
    /// Multi-DOF desired.
    pub multi_dof_desired: MultiDofPoint,
    /// Multi-DOF actual.
    pub multi_dof_actual: MultiDofPoint,
    /// Multi-DOF error.
    pub multi_dof_error: MultiDofPoint,
}
impl Message for Feedback {}

/// How a goal ended, `action_msgs/GoalStatus`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GoalStatus {
    /// Ran to its end (the result's error code says how well).
    Succeeded,
    /// Canceled.
    Canceled,
    /// Aborted by the controller.
    Aborted,
    /// Any other status (the number).
    Other(i8),
}

#[cfg(test)]
mod tests {
    use super::*;
    use ros2_client::dds::rustdds::serialization::{
        RepresentationIdentifier, deserialize_from_cdr_with_rep_id, to_writer_with_rep_id,
    };

    /// Rolling's feedback (control_msgs 6.x): Jazzy's fields, then two
    /// more.
    #[derive(Serialize)]
    struct RollingFeedback {
        jazzy: Feedback,
        index: i32,
        multi_dof_index: i32,
    }

    #[test]
    fn feedback_of_either_layout_decodes() {
        let jazzy = Feedback {
            joint_names: vec!["a1".into(), "a2".into()],
            actual: JointTrajectoryPoint {
                positions: vec![0.5, -0.25],
                time_from_start: Stamp::from_seconds(1.5),
                ..Default::default()
            },
            ..Default::default()
        };
        let rolling = RollingFeedback {
            jazzy: jazzy.clone(),
            index: 7,
            multi_dof_index: -1,
        };
        for bytes in [to_cdr(&jazzy), to_cdr(&rolling)] {
            let (read, _): (Feedback, usize) =
                deserialize_from_cdr_with_rep_id(&bytes, RepresentationIdentifier::CDR_LE).unwrap();
            assert_eq!(read, jazzy);
        }
        assert_eq!(to_cdr(&rolling).len(), to_cdr(&jazzy).len() + 8);
    }

    fn to_cdr(value: &impl Serialize) -> Vec<u8> {
        let mut bytes = Vec::new();
        to_writer_with_rep_id(&mut bytes, value, RepresentationIdentifier::CDR_LE).unwrap();
        bytes
    }

    #[test]
    fn stamps_round_to_the_nanosecond() {
        assert_eq!(
            Stamp::from_seconds(2.000_000_000_4),
            Stamp { sec: 2, nanosec: 0 }
        );
        assert_eq!(Stamp::from_seconds(-1.0), Stamp::default());
        assert_eq!(
            Stamp {
                sec: 1,
                nanosec: 500_000_000
            }
            .seconds(),
            1.5
        );
    }
}
