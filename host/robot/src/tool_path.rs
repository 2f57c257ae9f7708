//! A Cartesian trajectory of any [`Chain`]'s tool: poses `[x, y, z, qw,
//! qx, qy, qz]` (the tool frame in the base's, m and a unit quaternion of
//! either sign) solved to joint positions by [`ik::inverse`], sample by
//! sample from the previous solution (the first from a given start
//! posture, else by [`first_posture`]), each pulled toward the start or
//! the first sample's posture (the elbow the trajectory begins with), then
//! checked as a joint trajectory ([`Chain::check_path`]). The first pose
//! the solver cannot reach is refused by its sample and time.
//!
//! ```
//! use primo_robot::Robot;
//! use primo_robot::ik::IkOptions;
//! use primo_robot::tool_path::check_tool_path;
//! let chain = Robot::lwr4().chain();
//! let q = [0.1, 0.5, 0.0, -1.0, 0.0, 0.5, 0.0];
//! let p = chain.forward(&q);
//! let (t, r) = (p.translation.vector, p.rotation);
//! let pose = [t.x, t.y, t.z, r.w, r.i, r.j, r.k];
//! let joints = check_tool_path(&chain, &[0.0], &[pose], Some(&q), None, &IkOptions::default());
//! assert_eq!(joints.unwrap().len(), 7);
//! let far = [2.0, 0.0, 0.5, 1.0, 0.0, 0.0, 0.0];
//! let err = check_tool_path(&chain, &[0.0, 0.1], &[pose, far], Some(&q), None, &IkOptions::default());
//! assert!(err.unwrap_err().to_string().starts_with("sample 1 (t = 0.100 s): tool pose"));
//! ```

use std::f64::consts::FRAC_PI_2;

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};

use crate::chain::Chain;
use crate::ik::{self, IkError, IkOptions};
use crate::limits::Violation;

/// How far from 1 an orientation's norm may be: a file's quaternions are
/// unit to a few digits; anything further is not an orientation.
const UNIT: f64 = 1e-3;

/// Why a tool trajectory cannot be followed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ToolPathError {
    /// Not one time per pose, or a start posture not one position per
    /// joint.
    #[error("{what}")]
    Shape {
        /// What does not fit.
        what: String,
    },
    /// A non-finite time or pose value, or a time not after the previous.
    #[error("sample {sample}: non-finite value or time not increasing")]
    Malformed {
        /// Sample index.
        sample: usize,
    },
    /// An orientation that is not a unit quaternion.
    #[error(
        "sample {sample} (t = {time:.3} s): the orientation quaternion's norm is {norm:.4}, not 1"
    )]
    NotUnit {
        /// Sample index.
        sample: usize,
        /// Its time, s.
        time: f64,
        /// Its norm.
        norm: f64,
    },
    /// A pose the inverse kinematics cannot reach.
    #[error("sample {sample} (t = {time:.3} s): tool pose {pose:.3?}: {ik}")]
    Unreachable {
        /// Sample index.
        sample: usize,
        /// Its time, s.
        time: f64,
        /// The pose `[x, y, z, qw, qx, qy, qz]`.
        pose: [f64; 7],
        /// How close the inverse kinematics came.
        ik: IkError,
    },
    /// The joint positions of the poses cross a joint limit.
    #[error("{0} (joint positions of the tool poses, by inverse kinematics)")]
    Joints(Violation),
}

/// The posture midway between each joint's limits (for a joint unlimited
/// on a side, 0, or its limit nearer 0 if 0 is beyond it).
pub fn mid_range(chain: &Chain) -> Vec<f64> {
    chain
        .joints()
        .iter()
        .map(|j| {
            let (lower, upper) = (j.limits.lower, j.limits.upper);
            match lower.is_finite() && upper.is_finite() {
                true => (lower + upper) / 2.0,
                false => 0.0_f64.clamp(lower, upper),
            }
        })
        .collect()
}

/// Joint positions reaching `target` with no posture to start from: from
/// [`mid_range`], else from postures folded a quarter of each joint's range
/// (a mid-range posture may be singular, as the LWR 4's stretched arm is,
/// where the local solver cannot leave it); the first error if none
/// reaches it.
pub fn first_posture(
    chain: &Chain,
    target: &Isometry3<f64>,
    options: &IkOptions,
) -> Result<Vec<f64>, IkError> {
    let mid = mid_range(chain);
    // Signs per joint of each fold: alternating, then all alike.
    let folds: [fn(usize) -> f64; 4] = [
        |j| if j % 2 == 0 { 1.0 } else { -1.0 },
        |j| if j % 2 == 0 { -1.0 } else { 1.0 },
        |_| 1.0,
        |_| -1.0,
    ];
    let first = match ik::inverse(chain, target, &mid, &mid, options) {
        Ok(q) => return Ok(q),
        Err(e) => e,
    };
    for sign in folds {
        let seed: Vec<f64> = chain
            .joints()
            .iter()
            .zip(&mid)
            .enumerate()
            .map(|(j, (joint, m))| {
                let range = joint.limits.upper - joint.limits.lower;
                let quarter = if range.is_finite() {
                    range / 4.0
                } else {
                    FRAC_PI_2
                };
                m + sign(j) * quarter
            })
            .collect();
        if let Ok(q) = ik::inverse(chain, target, &seed, &seed, options) {
            return Ok(q);
        }
    }
    Err(first)
}

/// Solves `poses` (at `times`) to joint positions of `chain` from `start`
/// (default: the first pose's [`first_posture`]) and checks them against
/// the joint limits and `max_acceleration` ([`Chain::check_path`]);
/// returns them row-major, one per joint per sample.
pub fn check_tool_path(
    chain: &Chain,
    times: &[f64],
    poses: &[[f64; 7]],
    start: Option<&[f64]>,
    max_acceleration: Option<f64>,
    options: &IkOptions,
) -> Result<Vec<f64>, ToolPathError> {
    if times.len() != poses.len() {
        return Err(ToolPathError::Shape {
            what: format!("{} times for {} poses", times.len(), poses.len()),
        });
    }
    if let Some(q) = start
        && q.len() != chain.dof()
    {
        return Err(ToolPathError::Shape {
            what: format!(
                "a start posture of {} positions for {} joints",
                q.len(),
                chain.dof()
            ),
        });
    }
    // The posture the solver pulls toward: the start, or where the first
    // pose was reached (the elbow the trajectory begins with).
    let mut rest: Option<Vec<f64>> = start.map(<[f64]>::to_vec);
    let mut joints = Vec::with_capacity(poses.len() * chain.dof());
    let mut last: Option<(f64, Vec<f64>)> = None;
    for (sample, (&time, pose)) in times.iter().zip(poses).enumerate() {
        let increasing = last.as_ref().is_none_or(|(t0, _)| time > *t0);
        if !time.is_finite() || pose.iter().any(|v| !v.is_finite()) || !increasing {
            return Err(ToolPathError::Malformed { sample });
        }
        let [x, y, z, w, i, j, k] = *pose;
        let quaternion = Quaternion::new(w, i, j, k);
        let norm = quaternion.norm();
        if (norm - 1.0).abs() > UNIT {
            return Err(ToolPathError::NotUnit { sample, time, norm });
        }
        let target = Isometry3::from_parts(
            Translation3::new(x, y, z),
            UnitQuaternion::from_quaternion(quaternion),
        );
        let solved = match (&last, &rest) {
            (Some((_, q)), Some(rest)) => ik::inverse(chain, &target, q, rest, options),
            (None, Some(start)) => ik::inverse(chain, &target, start, start, options),
            (_, None) => first_posture(chain, &target, options),
        };
        let q = solved.map_err(|ik| ToolPathError::Unreachable {
            sample,
            time,
            pose: *pose,
            ik,
        })?;
        joints.extend_from_slice(&q);
        rest.get_or_insert_with(|| q.clone());
        last = Some((time, q));
    }
    chain
        .check_path(times, &joints, max_acceleration)
        .map_err(ToolPathError::Joints)?;
    Ok(joints)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Tip;
    use crate::urdf::Urdf;

    /// A planar arm of three revolute joints about z, links 0.4, 0.3 and
    /// 0.1 m along x, each ±2 rad at 2 rad/s.
    fn planar() -> Chain {
        let joint = |name: &str, parent: &str, child: &str, x: f64| {
            format!(
                r#"<joint name="{name}" type="revolute">
                  <parent link="{parent}"/> <child link="{child}"/>
                  <origin xyz="{x} 0 0"/> <axis xyz="0 0 1"/>
                  <limit lower="-2" upper="2" velocity="2"/>
                </joint>"#
            )
        };
        let text = format!(
            r#"<robot name="planar">
              <link name="base"/> <link name="l1"/> <link name="l2"/> <link name="l3"/>
              <link name="tool"/>
              {} {} {}
              <joint name="tool" type="fixed">
                <parent link="l3"/> <child link="tool"/> <origin xyz="0.1 0 0"/>
              </joint>
            </robot>"#,
            joint("j1", "base", "l1", 0.0),
            joint("j2", "l1", "l2", 0.4),
            joint("j3", "l2", "l3", 0.3),
        );
        Chain::from_urdf(&Urdf::parse("planar.urdf", &text).unwrap(), &Tip::default()).unwrap()
    }

    fn pose_of(chain: &Chain, q: &[f64]) -> [f64; 7] {
        let p = chain.forward(q);
        let (t, r) = (p.translation.vector, p.rotation);
        [t.x, t.y, t.z, r.w, r.i, r.j, r.k]
    }

    #[test]
    fn a_reachable_tool_path_comes_back_as_joint_positions() {
        let chain = planar();
        assert_eq!(mid_range(&chain), [0.0; 3]);
        let times: Vec<f64> = (0..20).map(|i| i as f64 * 0.05).collect();
        let path: Vec<[f64; 3]> = times
            .iter()
            .map(|t| [0.3 * t, 0.6 + 0.2 * t, -0.4])
            .collect();
        let poses: Vec<[f64; 7]> = path.iter().map(|q| pose_of(&chain, q)).collect();
        let joints = check_tool_path(
            &chain,
            &times,
            &poses,
            Some(&path[0]),
            None,
            &IkOptions::default(),
        )
        .unwrap();
        for (q, pose) in joints.chunks_exact(3).zip(&poses) {
            let reached = pose_of(&chain, q);
            assert!(
                (0..7).all(|k| (reached[k] - pose[k]).abs() < 1e-6),
                "{reached:?}"
            );
        }
    }

    #[test]
    fn the_first_unreachable_or_too_fast_pose_is_named() {
        let chain = planar();
        let q = [0.2, 0.5, -0.3];
        let mut poses = vec![pose_of(&chain, &q); 4];
        let times = [0.0, 0.1, 0.2, 0.3];
        // 0.9 m from the base: the arm reaches 0.8.
        poses[2][0] = 0.9;
        poses[2][1] = 0.0;
        let err =
            check_tool_path(&chain, &times, &poses, None, None, &IkOptions::default()).unwrap_err();
        assert!(
            matches!(err, ToolPathError::Unreachable { sample: 2, .. }),
            "{err}"
        );
        assert!(
            err.to_string()
                .starts_with("sample 2 (t = 0.200 s): tool pose [0.900, 0.000"),
            "{err}"
        );
        // Reachable, but the elbow turns 0.3 rad in 0.1 s: 3 rad/s.
        poses[2] = pose_of(&chain, &[0.2, 0.8, -0.3]);
        let err = check_tool_path(
            &chain,
            &times,
            &poses,
            Some(&q),
            None,
            &IkOptions::default(),
        )
        .unwrap_err();
        assert!(
            matches!(
                err,
                ToolPathError::Joints(Violation::Velocity { sample: 2, .. })
            ),
            "{err}"
        );
        poses[2][3] = 2.0;
        assert!(matches!(
            check_tool_path(&chain, &times, &poses, None, None, &IkOptions::default()),
            Err(ToolPathError::NotUnit { sample: 2, .. })
        ));
        assert!(matches!(
            check_tool_path(
                &chain,
                &times[..3],
                &poses,
                None,
                None,
                &IkOptions::default()
            ),
            Err(ToolPathError::Shape { .. })
        ));
        assert!(matches!(
            check_tool_path(
                &chain,
                &[0.0, 0.1, 0.1, 0.2],
                &poses,
                None,
                None,
                &IkOptions::default()
            ),
            Err(ToolPathError::Malformed { sample: 2 })
        ));
    }

    #[test]
    fn a_first_pose_is_found_from_the_singular_mid_range() {
        // The LWR 4's mid-range is its stretched arm, singular: the flange
        // turned over to point down is found from there (by the IK alone
        // since it drops the pull late in its iterations; before, only
        // from a folded seed).
        let chain = crate::Robot::lwr4().chain();
        let down = [0.5, 0.2, 0.6, 0.0, 1.0, 0.0, 0.0];
        let [x, y, z, w, i, j, k] = down;
        let target = Isometry3::from_parts(
            Translation3::new(x, y, z),
            UnitQuaternion::from_quaternion(Quaternion::new(w, i, j, k)),
        );
        let q = first_posture(&chain, &target, &IkOptions::default()).unwrap();
        let reached = pose_of(&chain, &q);
        assert!(
            (0..3).all(|c| (reached[c] - down[c]).abs() < 1e-6),
            "{reached:?}"
        );
        let times = [0.0, 0.1, 0.2];
        assert!(
            check_tool_path(
                &chain,
                &times,
                &[down; 3],
                None,
                None,
                &IkOptions::default()
            )
            .is_ok()
        );
    }
}
