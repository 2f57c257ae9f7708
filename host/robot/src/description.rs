//! A robot's description: what the kinematics and the safety gate know of
//! it. The built-in [`Robot::lwr4`] is the KUKA LWR 4+; a lab's own arm of
//! the same structure (seven revolute joints, standard DH) is described in
//! JSON and read with [`Robot::from_json`], which checks every value.
//!
//! ```
//! use primo_robot::Robot;
//! let lwr4 = Robot::lwr4();
//! let json = serde_json::to_string(&lwr4).unwrap();
//! assert_eq!(Robot::from_json("robot.json", &json).unwrap(), lwr4);
//! let err = Robot::from_json("robot.json", &json.replace("110.0", "-1.0")).unwrap_err();
//! assert!(err.to_string().contains("velocity limit of joint 1"), "{err}");
//! ```

use serde::{Deserialize, Serialize};

use crate::chain::{Chain, JointLimits, Link};

/// Number of joints.
pub const JOINTS: usize = 7;

/// A seven-joint arm: its DH table, its flange and its joint limits.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Robot {
    /// DH parameters per joint, base to wrist.
    pub dh: [Link; JOINTS],
    /// Distance from the last joint frame to the flange along its z, m.
    pub flange: f64,
    /// Joint position limits, ± degrees.
    pub position_limits_deg: [f64; JOINTS],
    /// Joint velocity limits, degrees per second.
    pub velocity_limits_deg: [f64; JOINTS],
}

/// A robot description that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DescriptionError {
    /// Not a description.
    #[error("{file}: not a robot description: {why}")]
    Parse {
        /// The file.
        file: String,
        /// What the parser said.
        why: String,
    },
    /// A value out of range.
    #[error("{file}: {what} is {value}, must be {range}")]
    OutOfRange {
        /// The file.
        file: String,
        /// Which value.
        what: String,
        /// Its value.
        value: f64,
        /// What it must be.
        range: &'static str,
    },
}

impl Robot {
    /// The KUKA LWR 4+: DH table, 0.078 m flange, position limits
    /// ±170/120°, velocity limits 110–204 °/s.
    pub fn lwr4() -> Robot {
        use std::f64::consts::FRAC_PI_2 as H;
        let link = |d, alpha| Link { d, a: 0.0, alpha };
        Robot {
            dh: [
                link(0.310, H),
                link(0.0, -H),
                link(0.400, -H),
                link(0.0, H),
                link(0.390, H),
                link(0.0, -H),
                link(0.0, 0.0),
            ],
            flange: 0.078,
            position_limits_deg: [170.0, 120.0, 170.0, 120.0, 170.0, 120.0, 170.0],
            velocity_limits_deg: [110.0, 110.0, 128.0, 128.0, 204.0, 184.0, 184.0],
        }
    }

    /// The robot as a [`Chain`]: its DH table, the flange as the tip,
    /// joints `a1`…`a7` with its limits in radians.
    pub fn chain(&self) -> Chain {
        self.chain_with_tool(&nalgebra::Isometry3::identity())
    }

    /// The robot as a [`Chain`] ending at `tool`, in its flange's frame.
    pub fn chain_with_tool(&self, tool: &nalgebra::Isometry3<f64>) -> Chain {
        self.chain_to(&(nalgebra::Isometry3::translation(0.0, 0.0, self.flange) * tool))
    }

    /// The robot as a [`Chain`] ending at `tool`, in the last DH frame.
    pub fn chain_to(&self, tool: &nalgebra::Isometry3<f64>) -> Chain {
        Chain::from_dh("lwr4", &self.dh, tool, &self.joint_limits())
    }

    /// Each joint's limits in radians (± the position limit).
    pub fn joint_limits(&self) -> [JointLimits; JOINTS] {
        std::array::from_fn(|j| JointLimits {
            lower: -self.position_limits_deg[j].to_radians(),
            upper: self.position_limits_deg[j].to_radians(),
            velocity: self.velocity_limits_deg[j].to_radians(),
        })
    }

    /// Reads a JSON description (`file` names it in errors) and checks it.
    pub fn from_json(file: &str, text: &str) -> Result<Robot, DescriptionError> {
        let robot: Robot = serde_json::from_str(text).map_err(|e| DescriptionError::Parse {
            file: file.to_string(),
            why: e.to_string(),
        })?;
        robot.validate(file)?;
        Ok(robot)
    }

    /// Every length finite, every limit positive and finite (position
    /// limits at most 360°).
    pub fn validate(&self, file: &str) -> Result<(), DescriptionError> {
        let bad = |what: String, value: f64, range| DescriptionError::OutOfRange {
            file: file.to_string(),
            what,
            value,
            range,
        };
        for (j, l) in self.dh.iter().enumerate() {
            for (name, v) in [("d", l.d), ("a", l.a), ("alpha", l.alpha)] {
                if !v.is_finite() {
                    return Err(bad(format!("DH {name} of joint {}", j + 1), v, "finite"));
                }
            }
        }
        if !(self.flange.is_finite() && self.flange >= 0.0) {
            return Err(bad("the flange".into(), self.flange, "finite and >= 0"));
        }
        for j in 0..JOINTS {
            let p = self.position_limits_deg[j];
            if !(p > 0.0 && p <= 360.0) {
                return Err(bad(
                    format!("the position limit of joint {}", j + 1),
                    p,
                    "in (0, 360] degrees",
                ));
            }
            let v = self.velocity_limits_deg[j];
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(
                    format!("the velocity limit of joint {}", j + 1),
                    v,
                    "a positive number of degrees per second",
                ));
            }
        }
        Ok(())
    }
}
