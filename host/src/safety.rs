//! The one gate every trajectory passes before it leaves the host, for the
//! simulated cell and the real robot alike: a [`JointPath`] exists only as
//! the result of [`check_joints`] or [`check_cartesian`], and the robot
//! drivers (and [`crate::skill::Skill::roll_out`]) take nothing else.
//!
//! - Joint trajectories: every sample within the joint position limits,
//!   every step within the joint velocity limits
//!   ([`crate::sim::arm::check_limits`]).
//! - Cartesian trajectories (bottle poses: mouth position and rotation
//!   vector): the mouth stays in [`WORKSPACE`] and moves and turns no
//!   faster than [`MAX_MOUTH_SPEED`] and [`MAX_TURN_RATE`]; then every pose
//!   is converted to joint angles by the inverse kinematics, sample by
//!   sample from a rest posture, and the joint angles pass the joint checks.
//!   A pose the inverse kinematics cannot reach is a rejection too.
//!
//! ```
//! use primo_host::safety::check_joints;
//! let times = vec![0.0, 0.01, 0.02];
//! let still = [0.0, 0.5, 0.0, -1.0, 0.0, 0.5, 0.0];
//! let mut jump = still;
//! jump[1] = 0.6; // 0.1 rad in 10 ms: 573 deg/s
//! assert!(check_joints(times.clone(), vec![still; 3]).is_ok());
//! let err = check_joints(times, vec![still, jump, jump]).unwrap_err();
//! assert_eq!(err, "joint 2 at sample 1: 572.96 deg/s beyond the 110 deg/s velocity limit");
//! ```

use crate::sim::arm::{JOINTS, check_limits};
use crate::sim::cell::CellConfig;

/// Box the mouth must stay in during Cartesian movements (base frame, m).
pub const WORKSPACE: [[f64; 2]; 3] = [[0.3, 1.1], [-0.5, 0.7], [0.3, 1.1]];
/// Fastest the mouth may move, m/s.
pub const MAX_MOUTH_SPEED: f64 = 1.0;
/// Fastest the bottle's rotation vector may change, rad/s.
pub const MAX_TURN_RATE: f64 = 3.0;

/// A joint trajectory that passed the checks: at least one sample, times
/// strictly increasing, every sample and step within the joint limits.
#[derive(Debug, Clone, PartialEq)]
pub struct JointPath {
    times: Vec<f64>,
    positions: Vec<[f64; JOINTS]>,
}

impl JointPath {
    /// Sample times, s.
    pub fn times(&self) -> &[f64] {
        &self.times
    }

    /// Joint angles per sample, rad.
    pub fn positions(&self) -> &[[f64; JOINTS]] {
        &self.positions
    }

    /// The first sample's joint angles.
    pub fn start(&self) -> [f64; JOINTS] {
        self.positions.first().copied().unwrap_or_default()
    }

    /// Time from the first to the last sample, s.
    pub fn duration(&self) -> f64 {
        match (self.times.first(), self.times.last()) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        }
    }
}

/// Checks a joint trajectory (`times[i]`, `positions[i]` in rad) against
/// the joint position and velocity limits; the message names the first
/// offending sample and joint.
pub fn check_joints(times: Vec<f64>, positions: Vec<[f64; JOINTS]>) -> Result<JointPath, String> {
    aligned(times.len(), positions.len())?;
    check_limits(times.iter().copied().zip(&positions)).map_err(|v| v.to_string())?;
    Ok(JointPath { times, positions })
}

/// Checks a Cartesian trajectory of bottle poses `[x, y, z, rx, ry, rz]`
/// (mouth position, m; bottle rotation vector, rad) in `cell`: the mouth's
/// workspace and speed, then the joint angles the inverse kinematics gives,
/// tracked sample by sample from `rest` (which also chooses the elbow), are
/// checked by [`check_joints`]. Returns those joint angles.
pub fn check_cartesian(
    cell: &CellConfig,
    times: &[f64],
    poses: &[[f64; 6]],
    rest: &[f64; JOINTS],
) -> Result<JointPath, String> {
    check_mouth(times, poses)?;
    let arm = cell.arm();
    let mut q = *rest;
    let mut joints = Vec::with_capacity(poses.len());
    for (i, p) in poses.iter().enumerate() {
        let pose = cell.bottle_pose([p[0], p[1], p[2]], [p[3], p[4], p[5]]);
        q = arm
            .inverse(&pose, &q, rest)
            .map_err(|e| format!("sample {i}: bottle pose {p:.3?}: {e}"))?;
        joints.push(q);
    }
    check_joints(times.to_vec(), joints)
        .map_err(|e| format!("{e} (joint angles of the bottle poses, by inverse kinematics)"))
}

/// At least one sample, and one time per sample.
fn aligned(times: usize, samples: usize) -> Result<(), String> {
    if times == 0 || times != samples {
        return Err(format!(
            "a trajectory needs at least one sample and one time per sample \
             ({times} times, {samples} samples)"
        ));
    }
    Ok(())
}

/// The mouth stays in [`WORKSPACE`], moves no faster than
/// [`MAX_MOUTH_SPEED`] and turns no faster than [`MAX_TURN_RATE`].
fn check_mouth(times: &[f64], poses: &[[f64; 6]]) -> Result<(), String> {
    const AXES: [&str; 3] = ["x", "y", "z"];
    aligned(times.len(), poses.len())?;
    let mut last: Option<(f64, &[f64; 6])> = None;
    for (i, (&t, row)) in times.iter().zip(poses).enumerate() {
        if !t.is_finite() || row.iter().any(|v| !v.is_finite()) {
            return Err(format!("sample {i}: non-finite time or pose"));
        }
        for (axis, (v, [lo, hi])) in row.iter().zip(WORKSPACE).enumerate() {
            if *v < lo || *v > hi {
                return Err(format!(
                    "sample {i}: mouth {} = {v:.3} m outside the workspace [{lo}, {hi}] m",
                    AXES[axis]
                ));
            }
        }
        if let Some((t0, r0)) = last {
            let dt = t - t0;
            if dt <= 0.0 {
                return Err(format!("sample {i}: time {t} s does not increase"));
            }
            let dist = |a: &[f64], b: &[f64]| {
                a.iter()
                    .zip(b)
                    .map(|(x, y)| (x - y) * (x - y))
                    .sum::<f64>()
                    .sqrt()
            };
            let speed = dist(&row[..3], &r0[..3]) / dt;
            if speed > MAX_MOUTH_SPEED {
                return Err(format!(
                    "sample {i}: mouth speed {speed:.2} m/s beyond {MAX_MOUTH_SPEED} m/s"
                ));
            }
            let turn = dist(&row[3..], &r0[3..]) / dt;
            if turn > MAX_TURN_RATE {
                return Err(format!(
                    "sample {i}: turning at {turn:.2} rad/s beyond {MAX_TURN_RATE} rad/s"
                ));
            }
        }
        last = Some((t, row));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::cell::GlassKind;
    use crate::sim::expert::rest_configuration;

    fn cell() -> CellConfig {
        CellConfig::standard(GlassKind::Normal)
    }

    /// A slow straight move of the mouth over the glass, tilting a little.
    fn poses(from: [f64; 6], to: [f64; 6], n: usize) -> (Vec<f64>, Vec<[f64; 6]>) {
        let t = (0..n).map(|i| i as f64 * 0.01).collect();
        let p = (0..n)
            .map(|i| {
                let s = i as f64 / (n - 1) as f64;
                std::array::from_fn(|k| from[k] + (to[k] - from[k]) * s)
            })
            .collect();
        (t, p)
    }

    #[test]
    fn joint_paths_must_be_nonempty_and_aligned() {
        assert!(check_joints(vec![], vec![]).is_err());
        assert!(check_joints(vec![0.0, 1.0], vec![[0.0; JOINTS]]).is_err());
        let path = check_joints(vec![0.5, 1.5], vec![[0.1; JOINTS]; 2]).unwrap();
        assert_eq!(path.duration(), 1.0);
        assert_eq!(path.start(), [0.1; JOINTS]);
    }

    #[test]
    fn a_reachable_cartesian_move_comes_back_as_checked_joint_angles() {
        let cfg = cell();
        let (t, p) = poses(
            [0.65, 0.2, 0.35, 0.0, 0.0, 0.0],
            [0.72, 0.05, 0.3, 0.5, 0.0, 0.0],
            100,
        );
        let path = check_cartesian(&cfg, &t, &p, &rest_configuration(0.0)).unwrap();
        let arm = cfg.arm();
        for (q, pose) in path.positions().iter().zip(&p) {
            let (mouth, _) = cfg.mouth_and_rotation(&arm.forward(q));
            assert!((0..3).all(|k| (mouth[k] - pose[k]).abs() < 1e-6));
        }
    }

    #[test]
    fn a_cartesian_move_within_the_mouth_limits_can_still_cross_a_joint_limit() {
        let cfg = cell();
        let rest = rest_configuration(0.0);
        // Turning the bottle about the vertical by 0.58 rad at 2.9 rad/s is
        // within MAX_TURN_RATE, but the wrist (joint 5) would have to turn
        // faster than it can.
        let (t, mut p) = poses(
            [0.65, 0.2, 0.35, 0.0, 0.0, 0.0],
            [0.65, 0.2, 0.35, 0.0, 0.0, 0.58],
            101,
        );
        let t: Vec<f64> = t.iter().map(|t| 0.2 * t).collect();
        assert_eq!(check_mouth(&t, &p), Ok(()));
        assert_eq!(
            check_cartesian(&cfg, &t, &p, &rest).unwrap_err(),
            "joint 5 at sample 1: -253.61 deg/s beyond the 204 deg/s velocity limit \
             (joint angles of the bottle poses, by inverse kinematics)"
        );
        // Slower, the same turn is fine.
        let slow: Vec<f64> = t.iter().map(|t| 2.0 * t).collect();
        assert!(check_cartesian(&cfg, &slow, &p, &rest).is_ok());
        // Upside down about its own axis, the bottle cannot be held at all
        // within the joint limits: the inverse kinematics fails, and that
        // is a rejection too.
        p = poses(
            [0.7, 0.1, 0.4, 0.0, 0.0, 0.0],
            [0.7, 0.1, 0.4, 0.0, 0.0, 3.1],
            400,
        )
        .1;
        let slow: Vec<f64> = (0..400).map(|i| i as f64 * 0.01).collect();
        let err = check_cartesian(&cfg, &slow, &p, &rest).unwrap_err();
        assert!(
            err.starts_with(
                "sample 247: bottle pose [0.700, 0.100, 0.400, 0.000, 0.000, 1.919]: \
                             inverse kinematics did not converge"
            ),
            "{err}"
        );
    }

    #[test]
    fn the_mouth_checks_name_the_sample() {
        let cfg = cell();
        let rest = rest_configuration(0.0);
        let still = [0.65, 0.2, 0.35, 0.0, 0.0, 0.0];
        let (t, mut p) = poses(still, still, 5);
        p[3][2] = 0.2;
        assert_eq!(
            check_cartesian(&cfg, &t, &p, &rest).unwrap_err(),
            "sample 3: mouth z = 0.200 m outside the workspace [0.3, 1.1] m"
        );
        p[3][2] = 0.4;
        assert_eq!(
            check_cartesian(&cfg, &t, &p, &rest).unwrap_err(),
            "sample 3: mouth speed 5.00 m/s beyond 1 m/s"
        );
        p[3][2] = 0.35;
        p[3][3] = 0.1;
        assert_eq!(
            check_cartesian(&cfg, &t, &p, &rest).unwrap_err(),
            "sample 3: turning at 10.00 rad/s beyond 3 rad/s"
        );
    }
}
