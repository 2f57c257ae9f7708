//! ROS 2: a checked [`primo_robot::JointPath`] executed as a
//! `control_msgs/action/FollowJointTrajectory` goal to a
//! `joint_trajectory_controller`, the robot's state read from
//! `/joint_states`.
//!
//! - [`msgs`]: the messages, as serde structs (Jazzy's layout).
//! - [`execution`]: one goal's execution, sans I/O: the start check
//!   against the joint states, the goal, its response, feedback and
//!   result, the joint series it went through, and how it ended.
//! - [`dds`]: the DDS adapter around it: a participant, the
//!   `/joint_states` subscription and the action client.
//!
//! **Why ros2-client**: it is ROS 2 in pure Rust over RustDDS, so primo
//! builds with its own toolchain and needs no ROS installation, C
//! libraries or generated message packages at build time (`r2r` and
//! `rclrs` bind the C `rcl` and need a sourced ROS 2 to build); it has a
//! poll-style action client that suits a sans-I/O core, needs no async
//! runtime (its spinner runs on a thread of its own), and is tested
//! upstream against Humble to Lyrical. It speaks DDS (rmw_fastrtps and
//! the other DDS middlewares), without Zenoh.
//!
//! Addressing: `ros2:/CONTROLLER` names a controller; its action is
//! `/CONTROLLER/follow_joint_trajectory`, the ros2_control convention.
//!
//! ```
//! use primo_ros2::Controller;
//! let c = Controller::parse("ros2:/arm_controller")?;
//! assert_eq!(c.action(), ("/arm_controller", "follow_joint_trajectory"));
//! assert!(Controller::parse("ros2:arm").is_err());
//! # Ok::<(), primo_ros2::Ros2Error>(())
//! ```

#![deny(missing_docs)]

pub mod dds;
pub mod execution;
pub mod msgs;

use std::fmt;
use std::time::Duration;

/// A controller's `FollowJointTrajectory` error code (its result's
/// `error_code`, non-zero).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorCode {
    /// -1: the goal is malformed.
    InvalidGoal,
    /// -2: the joints are not the controller's.
    InvalidJoints,
    /// -3: the trajectory's header is older than the controller's time.
    OldHeaderTimestamp,
    /// -4: a joint left the path tolerance.
    PathToleranceViolated,
    /// -5: the end was not reached within the goal tolerance.
    GoalToleranceViolated,
    /// Any other non-zero code.
    Other(i32),
}

impl ErrorCode {
    /// The code's meaning; `None` for 0 (success).
    pub fn from_code(code: i32) -> Option<ErrorCode> {
        Some(match code {
            0 => return None,
            -1 => ErrorCode::InvalidGoal,
            -2 => ErrorCode::InvalidJoints,
            -3 => ErrorCode::OldHeaderTimestamp,
            -4 => ErrorCode::PathToleranceViolated,
            -5 => ErrorCode::GoalToleranceViolated,
            other => ErrorCode::Other(other),
        })
    }
}

impl fmt::Display for ErrorCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ErrorCode::InvalidGoal => f.write_str("the goal is invalid (INVALID_GOAL)"),
            ErrorCode::InvalidJoints => {
                f.write_str("the joints are not the controller's (INVALID_JOINTS)")
            }
            ErrorCode::OldHeaderTimestamp => {
                f.write_str("the trajectory's time stamp is too old (OLD_HEADER_TIMESTAMP)")
            }
            ErrorCode::PathToleranceViolated => {
                f.write_str("a joint left the path tolerance (PATH_TOLERANCE_VIOLATED)")
            }
            ErrorCode::GoalToleranceViolated => f.write_str(
                "the end was not reached within the goal tolerance (GOAL_TOLERANCE_VIOLATED)",
            ),
            ErrorCode::Other(code) => write!(f, "error code {code}"),
        }
    }
}

/// The controller's own words after its code, if it said any.
fn said(text: &str) -> String {
    match text.trim() {
        "" => String::new(),
        t => format!(": \"{t}\""),
    }
}

/// Everything that stops a roll-out through ROS 2, or keeps it from
/// starting.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Ros2Error {
    /// A robot address that is not `ros2:/CONTROLLER`.
    #[error(
        "robot address `{spec}`: {why}; expected ros2:/CONTROLLER, a joint trajectory controller's name (its action is /CONTROLLER/follow_joint_trajectory)"
    )]
    Address {
        /// What was given.
        spec: String,
        /// What is wrong with it.
        why: String,
    },
    /// The DDS participant, node, subscription or client could not be made.
    #[error("ROS 2 setup failed: {0}")]
    Setup(String),
    /// Sending or receiving failed.
    #[error("ROS 2 communication failed: {0}")]
    Communication(String),
    /// No action server answered.
    #[error("no FollowJointTrajectory server at {action} within {:.1} s: is the controller running, on the same ROS_DOMAIN_ID?", waited.as_secs_f64())]
    NoController {
        /// The action.
        action: String,
        /// How long primo waited.
        waited: Duration,
    },
    /// `/joint_states` said nothing.
    #[error("no joint states on /joint_states within {:.1} s: nothing sent to the robot", waited.as_secs_f64())]
    NoJointStates {
        /// How long primo waited.
        waited: Duration,
    },
    /// The joint states lack a joint of the robot's description.
    #[error(
        "the joint states lack joint `{joint}` of the robot's description (they name {named}): nothing sent to the robot"
    )]
    MissingJoint {
        /// The joint.
        joint: String,
        /// The names the states had.
        named: String,
    },
    /// The robot is not at the trajectory's start.
    #[error("the robot is not at the trajectory's start: joint `{joint}` is at {at:.4}, the start is {start:.4} ({:.4} away, more than the tolerance {tolerance}): nothing sent to the robot", (at - start).abs())]
    NotAtStart {
        /// The joint furthest off.
        joint: String,
        /// Where it is.
        at: f64,
        /// Where the trajectory starts.
        start: f64,
        /// How far it may be.
        tolerance: f64,
    },
    /// The approach to the start would cross a limit.
    #[error(
        "the approach from where the robot is to the trajectory's start would cross a limit: {why}: nothing sent to the robot"
    )]
    Approach {
        /// The limit.
        why: String,
    },
    /// The controller rejected the goal.
    #[error("the controller rejected the goal: the robot did not move")]
    Rejected,
    /// No answer to the goal.
    #[error("the controller did not answer the goal within {:.1} s", waited.as_secs_f64())]
    NoGoalResponse {
        /// How long primo waited.
        waited: Duration,
    },
    /// The goal ended (aborted, as a rule) with a non-zero error code.
    #[error("the controller stopped the trajectory: {code}{}", said(message))]
    Failed {
        /// The code.
        code: ErrorCode,
        /// The controller's `error_string`.
        message: String,
    },
    /// The controller aborted the goal without an error code.
    #[error("the controller aborted the trajectory{}", said(message))]
    Aborted {
        /// The controller's `error_string`.
        message: String,
    },
    /// The goal was canceled (by someone else; primo cancels only on an
    /// error of its own, which it reports instead).
    #[error("the trajectory was canceled{}", said(message))]
    Canceled {
        /// The controller's `error_string`.
        message: String,
    },
    /// The goal ended in a status the controller should not end in.
    #[error("the goal ended in status {status}{}", said(message))]
    Ended {
        /// The `action_msgs/GoalStatus` number.
        status: i8,
        /// The controller's `error_string`.
        message: String,
    },
    /// No result long after the trajectory's end.
    #[error("no result {:.1} s after the trajectory's end: primo canceled the goal", waited.as_secs_f64())]
    NoResult {
        /// How long after the end.
        waited: Duration,
    },
    /// `/joint_states` fell silent while the robot moved.
    #[error("/joint_states fell silent for {:.2} s while the robot moved: primo canceled the goal", silent.as_secs_f64())]
    StatesLost {
        /// How long.
        silent: Duration,
    },
    /// A joint state older than the one before.
    #[error("a joint state is stamped {:.6} s, before the previous one ({:.6} s): primo canceled the goal", stamp.seconds(), previous.seconds())]
    NonMonotonic {
        /// Its stamp.
        stamp: msgs::Stamp,
        /// The previous stamp.
        previous: msgs::Stamp,
    },
    /// Joint states that repeat one stamp.
    #[error("the joint states repeated the stamp {:.6} s for {:.2} s while the robot moved: they are stale, primo canceled the goal", stamp.seconds(), stale.as_secs_f64())]
    Stale {
        /// The stamp.
        stamp: msgs::Stamp,
        /// How long it repeated.
        stale: Duration,
    },
}

/// A `ros2:/CONTROLLER` address.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Controller {
    name: String,
}

impl Controller {
    /// Parses `ros2:/CONTROLLER` (a ROS 2 name: `/`-separated tokens of
    /// letters, digits and `_`, not starting with a digit).
    pub fn parse(spec: &str) -> Result<Controller, Ros2Error> {
        let bad = |why: &str| Ros2Error::Address {
            spec: spec.to_string(),
            why: why.to_string(),
        };
        let Some(name) = spec.strip_prefix("ros2:") else {
            return Err(bad("unknown robot driver"));
        };
        let Some(rest) = name.strip_prefix('/') else {
            return Err(bad("the controller's name must be absolute, /NAME"));
        };
        let token_ok = |t: &str| {
            t.bytes().next().is_some_and(|b| !b.is_ascii_digit())
                && t.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_')
        };
        if rest.is_empty() || !rest.split('/').all(token_ok) {
            return Err(bad(
                "not a ROS 2 name (tokens of letters, digits and _, separated by /)",
            ));
        }
        Ok(Controller {
            name: name.to_string(),
        })
    }

    /// `/CONTROLLER`.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The action's namespace and base name:
    /// `(/CONTROLLER, follow_joint_trajectory)`.
    pub fn action(&self) -> (&str, &str) {
        (&self.name, "follow_joint_trajectory")
    }
}

impl fmt::Display for Controller {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/follow_joint_trajectory", self.name)
    }
}

/// The ROS 2 domain from `ROS_DOMAIN_ID` as ROS 2's tools read it (0 when
/// unset); an error if it is not a number in 0..=232.
pub fn domain_from_env() -> Result<u16, Ros2Error> {
    match std::env::var("ROS_DOMAIN_ID") {
        Err(_) => Ok(0),
        Ok(text) if text.trim().is_empty() => Ok(0),
        Ok(text) => text
            .trim()
            .parse::<u16>()
            .ok()
            .filter(|d| *d <= 232)
            .ok_or_else(|| {
                Ros2Error::Setup(format!(
                    "ROS_DOMAIN_ID `{text}` is not a domain number in 0..=232"
                ))
            }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn addresses() {
        let name = |s: &str| Controller::parse(s).map(|c| c.to_string());
        assert_eq!(
            name("ros2:/arm_controller").as_deref(),
            Ok("/arm_controller/follow_joint_trajectory")
        );
        assert_eq!(
            name("ros2:/ns/jtc").as_deref(),
            Ok("/ns/jtc/follow_joint_trajectory")
        );
        let err = |s: &str| Controller::parse(s).unwrap_err().to_string();
        assert!(err("fri:1.2.3.4").starts_with(
            "robot address `fri:1.2.3.4`: unknown robot driver; expected ros2:/CONTROLLER"
        ));
        assert!(err("ros2:arm").contains("must be absolute"));
        assert!(err("ros2:/").contains("not a ROS 2 name"));
        assert!(err("ros2:/arm-1").contains("not a ROS 2 name"));
        assert!(err("ros2:/a//b").contains("not a ROS 2 name"));
        assert!(err("ros2:/1arm").contains("not a ROS 2 name"));
    }

    #[test]
    fn error_codes_in_words() {
        assert_eq!(ErrorCode::from_code(0), None);
        let e = Ros2Error::Failed {
            code: ErrorCode::from_code(-4).unwrap(),
            message: "joint a3 off".into(),
        };
        assert_eq!(
            e.to_string(),
            "the controller stopped the trajectory: a joint left the path tolerance \
             (PATH_TOLERANCE_VIOLATED): \"joint a3 off\""
        );
        assert_eq!(ErrorCode::from_code(-2), Some(ErrorCode::InvalidJoints));
        assert_eq!(ErrorCode::from_code(-9), Some(ErrorCode::Other(-9)));
    }
}
