//! What FRI streams: a checked [`JointPath`] of seven joints, the KRC's
//! LWR 4's (the built-in description's or its URDF's limits).
//!
//! ```
//! use primo_fri::path::FriPath;
//! use primo_robot::{Robot, safety::check_joints};
//! let path = check_joints(&Robot::lwr4(), vec![0.0, 1.0], vec![[0.1; 7], [0.2; 7]]).unwrap();
//! let fri = FriPath::try_from(&path).unwrap();
//! assert_eq!(fri.start(), [0.1; 7]);
//! ```

use primo_robot::limits::{min_jerk, min_jerk_duration};
use primo_robot::{JOINTS, JointPath};

/// A checked joint path for FRI: seven joints.
#[derive(Debug, Clone, PartialEq)]
pub struct FriPath {
    path: JointPath,
    rows: Vec<[f64; JOINTS]>,
    velocity: [f64; JOINTS],
}

/// A path of a robot that is no seven-joint arm.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "FRI streams the seven joints of a KUKA LWR; the path is for {robot}, which has {dof} joints"
)]
pub struct NotSeven {
    /// The path's robot.
    pub robot: String,
    /// Its joints.
    pub dof: usize,
}

impl TryFrom<&JointPath> for FriPath {
    type Error = NotSeven;

    fn try_from(path: &JointPath) -> Result<FriPath, NotSeven> {
        let chain = path.chain();
        let not_seven = || NotSeven {
            robot: chain.robot.clone(),
            dof: chain.dof(),
        };
        let velocity: [f64; JOINTS] = chain
            .joints()
            .iter()
            .map(|j| j.limits.velocity)
            .collect::<Vec<_>>()
            .try_into()
            .map_err(|_| not_seven())?;
        let rows = path
            .rows()
            .map(<[f64; JOINTS]>::try_from)
            .collect::<Result<_, _>>()
            .map_err(|_| not_seven())?;
        Ok(FriPath {
            path: path.clone(),
            rows,
            velocity,
        })
    }
}

impl FriPath {
    /// The checked path, with the robot whose limits it passed.
    pub fn path(&self) -> &JointPath {
        &self.path
    }

    /// Joint angles per sample, rad.
    pub fn rows(&self) -> &[[f64; JOINTS]] {
        &self.rows
    }

    /// The first sample's joint angles.
    pub fn start(&self) -> [f64; JOINTS] {
        self.rows.first().copied().unwrap_or_default()
    }

    /// Each joint's velocity limit, rad/s.
    pub fn velocity_limits(&self) -> &[f64; JOINTS] {
        &self.velocity
    }
}

/// Minimum-jerk setpoints every `dt` from `from` (the first) to `to` (the
/// last), with each joint's peak speed at most `speed` times its limit
/// (`limits`, rad/s). Its acceleration peaks at 5.77·Δ/T² and its jerk at
/// 60·Δ/T³ for a move Δ in T; it starts and ends at rest.
pub fn approach(
    from: [f64; JOINTS],
    to: [f64; JOINTS],
    dt: f64,
    speed: f64,
    limits: &[f64; JOINTS],
) -> impl ExactSizeIterator<Item = [f64; JOINTS]> {
    let duration = min_jerk_duration(&from, &to, speed, limits);
    let steps = (duration / dt).ceil().max(1.0) as usize;
    (0..steps + 1).map(move |k| {
        let blend = min_jerk(k as f64 / steps as f64);
        std::array::from_fn(|j| from[j] + (to[j] - from[j]) * blend)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use primo_robot::chain::{Chain, JointLimits, Link};

    #[test]
    fn a_path_of_another_arm_is_refused() {
        let limits = JointLimits {
            lower: -1.0,
            upper: 1.0,
            velocity: 1.0,
        };
        let link = Link {
            d: 0.1,
            a: 0.0,
            alpha: 0.0,
        };
        let six = Chain::from_dh("six", &[link; 6], &Default::default(), &[limits; 6]);
        let path = primo_robot::safety::check_path(&six, vec![0.0], vec![0.0; 6], None).unwrap();
        assert_eq!(
            FriPath::try_from(&path).unwrap_err().to_string(),
            "FRI streams the seven joints of a KUKA LWR; the path is for six, which has 6 joints"
        );
    }
}
