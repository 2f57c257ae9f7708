//! A posture of a [`Chain`] given by joint name (a task file's or a
//! command line's): every joint once, each within its position limits,
//! returned in the chain's order. It is where a tool trajectory's inverse
//! kinematics starts, so the elbow it solves to is the robot's own.
//!
//! ```
//! use primo_robot::Robot;
//! let lwr = Robot::lwr4().chain();
//! let names = ["a1", "a2", "a3", "a4", "a5", "a6", "a7"];
//! let q = lwr.posture(names.iter().map(|n| (*n, 0.1))).unwrap();
//! assert_eq!(q, vec![0.1; 7]);
//! let err = lwr.posture([("a1", 0.1)]).unwrap_err();
//! assert!(err.to_string().starts_with("no position for joint `a2`"), "{err}");
//! ```

use crate::chain::Chain;
use crate::limits::amount;

/// A posture that is not one of the chain's.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PostureError {
    /// A name that is no joint of the chain.
    #[error("`{name}` names no joint of {robot} (its joints: {joints})")]
    Unknown {
        /// The name given.
        name: String,
        /// The robot's name.
        robot: String,
        /// The chain's joints, comma-separated.
        joints: String,
    },
    /// One joint given twice (by its name and an alias).
    #[error("joint `{joint}` is given twice")]
    Twice {
        /// The joint.
        joint: String,
    },
    /// A joint without a position.
    #[error("no position for joint `{joint}`: a posture gives every joint ({joints})")]
    Missing {
        /// The joint.
        joint: String,
        /// The chain's joints, comma-separated.
        joints: String,
    },
    /// A position outside the joint's limits (or not a number).
    #[error("joint `{joint}`: {value} is outside its limits {lower} to {upper}")]
    Outside {
        /// The joint.
        joint: String,
        /// The position, in the joint's units.
        value: String,
        /// Its lower limit.
        lower: String,
        /// Its upper limit.
        upper: String,
    },
}

impl Chain {
    /// The posture `named` (joint name, position in rad or m) in the
    /// chain's order; a DH table's joints also by their aliases
    /// ([`Chain::index`]).
    pub fn posture<'a>(
        &self,
        named: impl IntoIterator<Item = (&'a str, f64)>,
    ) -> Result<Vec<f64>, PostureError> {
        let joints = || self.names().join(",");
        let mut q: Vec<Option<f64>> = vec![None; self.dof()];
        for (name, value) in named {
            let slot = self
                .index(name)
                .and_then(|i| q.get_mut(i).map(|slot| (i, slot)));
            let Some((i, slot)) = slot else {
                return Err(PostureError::Unknown {
                    name: name.to_string(),
                    robot: self.robot.clone(),
                    joints: joints(),
                });
            };
            let joint = &self.joints()[i];
            if slot.replace(value).is_some() {
                return Err(PostureError::Twice {
                    joint: joint.name.clone(),
                });
            }
            let l = joint.limits;
            if !(l.lower..=l.upper).contains(&value) {
                return Err(PostureError::Outside {
                    joint: joint.name.clone(),
                    value: amount(joint.motion, value, ""),
                    lower: amount(joint.motion, l.lower, ""),
                    upper: amount(joint.motion, l.upper, ""),
                });
            }
        }
        (self.joints().iter().zip(q))
            .map(|(j, v)| {
                v.ok_or_else(|| PostureError::Missing {
                    joint: j.name.clone(),
                    joints: joints(),
                })
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use crate::Robot;

    #[test]
    fn a_posture_is_every_joint_once_within_its_limits() {
        let lwr = Robot::lwr4().chain();
        let all =
            |v: f64| (1..=7).map(move |i| (["a1", "a2", "a3", "a4", "a5", "a6", "a7"][i - 1], v));
        // Any order, aliases included.
        let mixed = [("A7", 7.0e-2), ("a1", 0.01), ("j2", 0.02), ("a3", 0.03)]
            .into_iter()
            .chain([("joint_4", 0.04), ("a5", 0.05), ("a6", 0.06)]);
        assert_eq!(
            lwr.posture(mixed).unwrap(),
            [0.01, 0.02, 0.03, 0.04, 0.05, 0.06, 0.07]
        );
        let unknown = lwr.posture(all(0.0).chain([("elbow", 0.0)])).unwrap_err();
        assert!(
            unknown.to_string().starts_with("`elbow` names no joint of"),
            "{unknown}"
        );
        let twice = lwr.posture(all(0.0).chain([("A1", 0.0)])).unwrap_err();
        assert_eq!(twice.to_string(), "joint `a1` is given twice");
        let outside = lwr.posture(all(3.0)).unwrap_err();
        assert!(
            outside
                .to_string()
                .starts_with("joint `a1`: 3.0000 rad (171.89 deg) is outside its limits"),
            "{outside}"
        );
        assert!(matches!(
            lwr.posture(all(f64::NAN)),
            Err(super::PostureError::Outside { .. })
        ));
    }
}
