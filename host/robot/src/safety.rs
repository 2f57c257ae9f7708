//! The one gate every trajectory passes before it leaves primo, for the
//! simulated cell and the real robot alike: a [`JointPath`] exists only as
//! the result of [`check_joints`] or a [`Gate`]'s checks, and the robot
//! drivers (and the simulated cell's rig) take nothing else. A path carries
//! the robot whose limits it passed, so a driver keeps to the same limits.
//!
//! - Joint trajectories of any robot ([`check_path`]): every sample within
//!   its joints' position limits, every step within their velocity limits
//!   (and an acceleration bound, if given: [`Chain::check_path`]).
//! - Cartesian trajectories (tool poses: the controlled point's position
//!   and the tool's orientation as a unit quaternion): the point stays in
//!   the workspace box and moves no faster than the [`CartesianLimits`],
//!   the tool turns (its angular speed, from consecutive quaternions) no
//!   faster than they allow; then
//!   every pose is converted to joint angles by the inverse kinematics,
//!   sample by sample from a rest posture, and the joint angles pass the
//!   joint checks. A pose the inverse kinematics cannot reach is a
//!   rejection too.
//!
//! ```
//! use primo_robot::{Robot, safety::check_joints};
//! let times = vec![0.0, 0.01, 0.02];
//! let still = [0.0, 0.5, 0.0, -1.0, 0.0, 0.5, 0.0];
//! let mut jump = still;
//! jump[1] = 0.6; // 0.1 rad in 10 ms: 573 deg/s
//! let lwr4 = Robot::lwr4();
//! assert!(check_joints(&lwr4, times.clone(), vec![still; 3]).is_ok());
//! let err = check_joints(&lwr4, times, vec![still, jump, jump]).unwrap_err();
//! assert_eq!(
//!     err.to_string(),
//!     "joint a2 at sample 1 (t = 0.010 s): 10.0000 rad/s (572.96 deg/s) beyond its velocity \
//!      limit 1.9199 rad/s (110.00 deg/s)"
//! );
//! ```

use crate::chain::Chain;
use crate::ik::IkOptions;
use crate::tool_path::{ToolPathError, check_tool_path};
use crate::{Arm, IkError, JOINTS, Pose, Robot, Violation};

/// Box the controlled point (the bottle's mouth) must stay in during
/// Cartesian movements (base frame, m).
pub const WORKSPACE: [[f64; 2]; 3] = [[0.3, 1.1], [-0.5, 0.7], [0.3, 1.1]];
/// Fastest the mouth may move, m/s.
pub const MAX_MOUTH_SPEED: f64 = 1.0;
/// Fastest the bottle may turn (its angular speed), rad/s.
pub const MAX_TURN_RATE: f64 = 3.0;

/// Why a trajectory may not move a robot.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Rejection {
    /// No samples, or not one time per sample.
    #[error(
        "a trajectory needs at least one sample and one time per sample \
         ({times} times, {samples} samples)"
    )]
    Shape {
        /// Times given.
        times: usize,
        /// Samples given.
        samples: usize,
    },
    /// A joint limit.
    #[error("{0}")]
    Limit(#[from] Violation),
    /// Columns that are neither the arm's joints nor the tool's pose.
    #[error(
        "the gate checks the arm's joints ({}) or the tool's pose ({}), not ({names})",
        JOINT_COLUMNS.join(","),
        POSE_COLUMNS.join(",")
    )]
    Coordinates {
        /// The columns, comma-separated.
        names: String,
    },
    /// A non-finite time or pose.
    #[error("sample {sample}: non-finite time or pose")]
    NonFinite {
        /// Sample index.
        sample: usize,
    },
    /// Time does not increase.
    #[error("sample {sample}: time {time} s does not increase")]
    TimeOrder {
        /// Sample index.
        sample: usize,
        /// Its time, s.
        time: f64,
    },
    /// Outside the workspace box.
    #[error("sample {sample}: mouth {axis} = {value:.3} m outside the workspace [{low}, {high}] m")]
    Workspace {
        /// Sample index.
        sample: usize,
        /// `x`, `y` or `z`.
        axis: &'static str,
        /// The coordinate, m.
        value: f64,
        /// The box's lower side, m.
        low: f64,
        /// The box's upper side, m.
        high: f64,
    },
    /// Moving too fast.
    #[error("sample {sample}: mouth speed {speed:.2} m/s beyond {limit} m/s")]
    Speed {
        /// Sample index.
        sample: usize,
        /// The speed, m/s.
        speed: f64,
        /// The limit, m/s.
        limit: f64,
    },
    /// An orientation that is not a unit quaternion.
    #[error("sample {sample}: the orientation quaternion's norm is {norm:.4}, not 1")]
    NotUnit {
        /// Sample index.
        sample: usize,
        /// Its norm.
        norm: f64,
    },
    /// Turning too fast.
    #[error("sample {sample}: turning at {rate:.2} rad/s beyond {limit} rad/s")]
    Turn {
        /// Sample index.
        sample: usize,
        /// The rate, rad/s.
        rate: f64,
        /// The limit, rad/s.
        limit: f64,
    },
    /// A pose the inverse kinematics cannot reach.
    #[error("sample {sample}: bottle pose {pose:.3?}: {ik}")]
    Unreachable {
        /// Sample index.
        sample: usize,
        /// The pose `[x, y, z, qw, qx, qy, qz]`.
        pose: [f64; 7],
        /// How close the inverse kinematics came.
        ik: IkError,
    },
    /// A trajectory's columns cannot be limited (a column without
    /// limits, a robot's joints out of order).
    #[error("{0}")]
    Columns(String),
    /// A column outside its range.
    #[error("column `{column}` at sample {sample}: {value:.4} outside [{low}, {high}]")]
    Column {
        /// Sample index.
        sample: usize,
        /// The column.
        column: String,
        /// Its value.
        value: f64,
        /// The lowest allowed.
        low: f64,
        /// The highest allowed.
        high: f64,
    },
    /// A column changing too fast.
    #[error(
        "column `{column}` at sample {sample}: speed {speed:.4} per s beyond the limit of {limit} per s"
    )]
    ColumnSpeed {
        /// Sample index.
        sample: usize,
        /// The column.
        column: String,
        /// Its speed, per second.
        speed: f64,
        /// The limit, per second.
        limit: f64,
    },
    /// A workspace point moving too fast.
    #[error(
        "sample {sample}: the point ({columns}) moves at {speed:.4} per s, beyond {limit} per s"
    )]
    PointSpeed {
        /// Sample index.
        sample: usize,
        /// Its columns, comma-separated.
        columns: String,
        /// Its speed, per second.
        speed: f64,
        /// The limit, per second.
        limit: f64,
    },
    /// The joint angles of a Cartesian trajectory cross a joint limit.
    #[error("{0} (joint angles of the bottle poses, by inverse kinematics)")]
    Joints(Violation),
    /// A robot's tool trajectory it cannot follow.
    #[error("{0}")]
    ToolPath(#[from] ToolPathError),
}

/// A joint trajectory that passed the checks: at least one sample, times
/// strictly increasing, every sample and step within the joint limits of
/// [`JointPath::chain`], the robot it is for.
#[derive(Debug, Clone, PartialEq)]
pub struct JointPath {
    chain: Chain,
    times: Vec<f64>,
    positions: Vec<f64>,
}

impl JointPath {
    /// The robot whose limits the path passed.
    pub fn chain(&self) -> &Chain {
        &self.chain
    }

    /// Sample times, s.
    pub fn times(&self) -> &[f64] {
        &self.times
    }

    /// Joint positions, row-major: one per joint of the chain per sample,
    /// rad or m.
    pub fn positions(&self) -> &[f64] {
        &self.positions
    }

    /// Joint positions per sample.
    pub fn rows(&self) -> std::slice::ChunksExact<'_, f64> {
        self.positions.chunks_exact(self.chain.dof().max(1))
    }

    /// The first sample's joint positions.
    pub fn start(&self) -> &[f64] {
        self.positions.get(..self.chain.dof()).unwrap_or_default()
    }

    /// Time from the first to the last sample, s.
    pub fn duration(&self) -> f64 {
        match (self.times.first(), self.times.last()) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        }
    }

    /// The joint positions [`check_tool_path`] solved and checked.
    pub(crate) fn solved(chain: &Chain, times: Vec<f64>, positions: Vec<f64>) -> JointPath {
        JointPath {
            chain: chain.clone(),
            times,
            positions,
        }
    }
}

/// Checks a joint trajectory of `chain` (`times[i]`, row `i` of
/// `positions`, row-major in the chain's joint order) against its joints'
/// position and velocity limits and `max_acceleration` if given
/// ([`Chain::check_path`]); the rejection names the first offending sample
/// and joint.
pub fn check_path(
    chain: &Chain,
    times: Vec<f64>,
    positions: Vec<f64>,
    max_acceleration: Option<f64>,
) -> Result<JointPath, Rejection> {
    aligned(times.len(), positions.len() / chain.dof().max(1))?;
    chain.check_path(&times, &positions, max_acceleration)?;
    Ok(JointPath {
        chain: chain.clone(),
        times,
        positions,
    })
}

/// [`check_path`] for `robot`'s chain, one array of joint angles (rad) per
/// sample.
pub fn check_joints(
    robot: &Robot,
    times: Vec<f64>,
    positions: Vec<[f64; JOINTS]>,
) -> Result<JointPath, Rejection> {
    check_path(&robot.chain(), times, positions.concat(), None)
}

/// How fast and where a Cartesian movement's controlled point may go.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CartesianLimits {
    /// Box the point stays in, per axis `[low, high]`, m.
    pub workspace: [[f64; 2]; 3],
    /// Fastest it moves, m/s.
    pub max_speed: f64,
    /// Fastest the tool turns, rad/s.
    pub max_turn_rate: f64,
}

impl Default for CartesianLimits {
    /// [`WORKSPACE`], [`MAX_MOUTH_SPEED`], [`MAX_TURN_RATE`].
    fn default() -> Self {
        CartesianLimits {
            workspace: WORKSPACE,
            max_speed: MAX_MOUTH_SPEED,
            max_turn_rate: MAX_TURN_RATE,
        }
    }
}

/// The columns of a pose trajectory: the controlled point (m) and the
/// tool's orientation, a unit quaternion.
pub const POSE_COLUMNS: [&str; 7] = ["x", "y", "z", "qw", "qx", "qy", "qz"];
/// The columns of a joint trajectory: the arm's joints (rad), as its
/// controller names them.
pub const JOINT_COLUMNS: [&str; JOINTS] = ["a1", "a2", "a3", "a4", "a5", "a6", "a7"];

/// The checks of a robot holding a tool: Cartesian trajectories of the
/// tool's controlled point (`reach` metres along the tool frame's z axis,
/// e.g. a bottle's mouth) and the joint trajectories they become.
///
/// It is the pouring cell's gate, so the LWR 4's ([`Arm`], seven joints,
/// a Cartesian box and speed for the point): the paper's cell is that
/// robot. Every other robot's trajectories go through
/// [`crate::envelope::RobotLimits`]; both end in the same checks, a
/// chain's tool path ([`check_tool_path`]) and joint path ([`check_path`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Gate {
    /// The robot and its tool.
    pub arm: Arm,
    /// The controlled point's distance along the tool's z axis, m.
    pub reach: f64,
    /// The Cartesian limits.
    pub limits: CartesianLimits,
    /// The rest posture the inverse kinematics starts from and pulls
    /// toward (it chooses the elbow).
    pub rest: [f64; JOINTS],
}

impl Gate {
    /// The tool frame's pose for a controlled point at `point` and a tool
    /// orientation `q = [w, x, y, z]` (a Cartesian trajectory's
    /// coordinates).
    pub fn tool_pose(&self, point: [f64; 3], q: [f64; 4]) -> Pose {
        Pose::tool_at(point, q, self.reach)
    }

    /// The controlled point and the tool's orientation (`w ≥ 0`) of a tool
    /// pose.
    pub fn point_and_orientation(&self, pose: &Pose) -> ([f64; 3], [f64; 4]) {
        (pose.point_along_z(self.reach), pose.quaternion())
    }

    /// Checks a trajectory by its columns `names`, `rows` row-major one
    /// value per column: [`JOINT_COLUMNS`] as [`Gate::check_joints`],
    /// [`POSE_COLUMNS`] as [`Gate::check_cartesian`]; any other columns
    /// are refused.
    pub fn check_columns(
        &self,
        names: &[String],
        times: &[f64],
        rows: &[f64],
    ) -> Result<JointPath, Rejection> {
        fn rows_of<const N: usize>(rows: &[f64]) -> Vec<[f64; N]> {
            rows.chunks_exact(N)
                .map(|r| std::array::from_fn(|j| r[j]))
                .collect()
        }
        if JOINT_COLUMNS.iter().eq(names) {
            self.check_joints(times.to_vec(), rows_of(rows))
        } else if POSE_COLUMNS.iter().eq(names) {
            self.check_cartesian(times, &rows_of(rows))
        } else {
            Err(Rejection::Coordinates {
                names: names.join(","),
            })
        }
    }

    /// [`check_path`] with this gate's arm.
    pub fn check_joints(
        &self,
        times: Vec<f64>,
        positions: Vec<[f64; JOINTS]>,
    ) -> Result<JointPath, Rejection> {
        check_path(self.arm.chain(), times, positions.concat(), None)
    }

    /// Checks a Cartesian trajectory of poses `[x, y, z, qw, qx, qy, qz]`
    /// (the controlled point, m; the tool's orientation, a unit quaternion
    /// of either sign): the point's workspace and speed, the tool's turn
    /// rate, then the joint angles the inverse
    /// kinematics gives, tracked sample by sample from the rest posture,
    /// are checked by [`check_joints`]. Returns those joint angles.
    pub fn check_cartesian(
        &self,
        times: &[f64],
        poses: &[[f64; 7]],
    ) -> Result<JointPath, Rejection> {
        self.check_point(times, poses)?;
        // The tool frames of the controlled point's poses, solved and
        // checked as any chain's tool path, from and toward the rest.
        let frames: Vec<[f64; 7]> = poses
            .iter()
            .map(|p| {
                let frame = self
                    .tool_pose([p[0], p[1], p[2]], [p[3], p[4], p[5], p[6]])
                    .isometry();
                let (t, r) = (frame.translation.vector, frame.rotation);
                [t.x, t.y, t.z, r.w, r.i, r.j, r.k]
            })
            .collect();
        let joints = check_tool_path(
            self.arm.chain(),
            times,
            &frames,
            Some(&self.rest),
            None,
            &IkOptions::default(),
        )
        .map_err(|e| match e {
            ToolPathError::Unreachable { sample, ik, .. } => Rejection::Unreachable {
                sample,
                pose: poses[sample],
                ik,
            },
            ToolPathError::Joints(v) => Rejection::Joints(v),
            // The point's checks have passed: times aligned and increasing,
            // values finite, orientations unit.
            other => Rejection::Columns(other.to_string()),
        })?;
        Ok(JointPath::solved(self.arm.chain(), times.to_vec(), joints))
    }

    /// The point stays in the workspace and moves no faster than the
    /// limits; the orientation is a unit quaternion and turns no faster.
    fn check_point(&self, times: &[f64], poses: &[[f64; 7]]) -> Result<(), Rejection> {
        const AXES: [&str; 3] = ["x", "y", "z"];
        let limits = &self.limits;
        aligned(times.len(), poses.len())?;
        let mut last: Option<(f64, &[f64; 7])> = None;
        for (sample, (&t, row)) in times.iter().zip(poses).enumerate() {
            if !t.is_finite() || row.iter().any(|v| !v.is_finite()) {
                return Err(Rejection::NonFinite { sample });
            }
            let norm = row[3..].iter().map(|v| v * v).sum::<f64>().sqrt();
            if (norm - 1.0).abs() > UNIT {
                return Err(Rejection::NotUnit { sample, norm });
            }
            for ((axis, v), [low, high]) in AXES.iter().zip(row).zip(limits.workspace) {
                if *v < low || *v > high {
                    return Err(Rejection::Workspace {
                        sample,
                        axis,
                        value: *v,
                        low,
                        high,
                    });
                }
            }
            if let Some((t0, r0)) = last {
                let dt = t - t0;
                if dt <= 0.0 {
                    return Err(Rejection::TimeOrder { sample, time: t });
                }
                let speed = row[..3]
                    .iter()
                    .zip(&r0[..3])
                    .map(|(x, y)| (x - y) * (x - y))
                    .sum::<f64>()
                    .sqrt()
                    / dt;
                if speed > limits.max_speed {
                    return Err(Rejection::Speed {
                        sample,
                        speed,
                        limit: limits.max_speed,
                    });
                }
                let rate = turn(&r0[3..], &row[3..]) / dt;
                if rate > limits.max_turn_rate {
                    return Err(Rejection::Turn {
                        sample,
                        rate,
                        limit: limits.max_turn_rate,
                    });
                }
            }
            last = Some((t, row));
        }
        Ok(())
    }
}

/// How far from 1 an orientation's norm may be: a plan's f32 quaternions
/// are unit to rounding; anything further is not an orientation.
const UNIT: f64 = 1e-3;

/// The angle of the rotation from orientation `a` to `b` (quaternions
/// `[w, x, y, z]` of norm about 1, either sign), rad, in [0, π]:
/// `2·atan2(|v|, |w|)` of `a* ⊗ b`, accurate for small steps too.
fn turn(a: &[f64], b: &[f64]) -> f64 {
    let (aw, av) = (a[0], [a[1], a[2], a[3]]);
    let (bw, bv) = (b[0], [b[1], b[2], b[3]]);
    let w = aw * bw + av[0] * bv[0] + av[1] * bv[1] + av[2] * bv[2];
    // The vector part of a* ⊗ b: aw·bv − bw·av − av × bv.
    let cross = [
        av[1] * bv[2] - av[2] * bv[1],
        av[2] * bv[0] - av[0] * bv[2],
        av[0] * bv[1] - av[1] * bv[0],
    ];
    let v: f64 = (0..3)
        .map(|i| aw * bv[i] - bw * av[i] - cross[i])
        .map(|x| x * x)
        .sum::<f64>()
        .sqrt();
    2.0 * v.atan2(w.abs())
}

/// At least one sample, and one time per sample.
fn aligned(times: usize, samples: usize) -> Result<(), Rejection> {
    if times == 0 || times != samples {
        return Err(Rejection::Shape { times, samples });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The built-in pouring cell's gate: a 21 cm bottle held crosswise
    /// 16 cm from the flange, its mouth the controlled point.
    fn gate() -> Gate {
        let grasp = Pose {
            rotation: [[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]],
            position: [0.105, 0.0, 0.16],
        };
        Gate {
            arm: Arm::with_tool(Robot::lwr4(), &grasp),
            reach: 0.21,
            limits: CartesianLimits::default(),
            rest: [0.0, -0.75, 0.0, 1.7, 0.05, 0.9, 0.0],
        }
    }

    fn lwr4() -> Robot {
        Robot::lwr4()
    }

    /// A pose `[x, y, z, qw, qx, qy, qz]` of a point and a rotation vector.
    fn pose(p: [f64; 6]) -> [f64; 7] {
        let q = Pose::from_rotation_vector([0.0; 3], [p[3], p[4], p[5]]).quaternion();
        [p[0], p[1], p[2], q[0], q[1], q[2], q[3]]
    }

    /// A slow straight move of the mouth over the glass, turning about a
    /// fixed axis (the rotation vector interpolated).
    fn poses(from: [f64; 6], to: [f64; 6], n: usize) -> (Vec<f64>, Vec<[f64; 7]>) {
        let t = (0..n).map(|i| i as f64 * 0.01).collect();
        let p = (0..n)
            .map(|i| {
                let s = i as f64 / (n - 1) as f64;
                pose(std::array::from_fn(|k| from[k] + (to[k] - from[k]) * s))
            })
            .collect();
        (t, p)
    }

    #[test]
    fn joint_paths_must_be_nonempty_and_aligned() {
        assert!(check_joints(&lwr4(), vec![], vec![]).is_err());
        assert!(check_joints(&lwr4(), vec![0.0, 1.0], vec![[0.0; JOINTS]]).is_err());
        let path = check_joints(&lwr4(), vec![0.5, 1.5], vec![[0.1; JOINTS]; 2]).unwrap();
        assert_eq!(path.duration(), 1.0);
        assert_eq!(path.start(), [0.1; JOINTS]);
    }

    #[test]
    fn a_reachable_cartesian_move_comes_back_as_checked_joint_angles() {
        let cfg = gate();
        let (t, p) = poses(
            [0.65, 0.2, 0.35, 0.0, 0.0, 0.0],
            [0.72, 0.05, 0.3, 0.5, 0.0, 0.0],
            100,
        );
        let path = cfg.check_cartesian(&t, &p).unwrap();
        for (q, pose) in path.rows().zip(&p) {
            let q: [f64; JOINTS] = q.try_into().unwrap();
            let (mouth, turned) = cfg.point_and_orientation(&cfg.arm.forward(&q));
            assert!((0..3).all(|k| (mouth[k] - pose[k]).abs() < 1e-6));
            assert!(turn(&turned, &pose[3..]) < 1e-6);
        }
    }

    #[test]
    fn a_cartesian_move_within_the_mouth_limits_can_still_cross_a_joint_limit() {
        let cfg = gate();
        // Turning the bottle about the vertical by 0.58 rad at 2.9 rad/s is
        // within MAX_TURN_RATE, but the wrist (joint 5) would have to turn
        // faster than it can.
        let (t, mut p) = poses(
            [0.65, 0.2, 0.35, 0.0, 0.0, 0.0],
            [0.65, 0.2, 0.35, 0.0, 0.0, 0.58],
            101,
        );
        let t: Vec<f64> = t.iter().map(|t| 0.2 * t).collect();
        assert_eq!(cfg.check_point(&t, &p), Ok(()));
        assert_eq!(
            cfg.check_cartesian(&t, &p).unwrap_err().to_string(),
            "joint a5 at sample 1 (t = 0.002 s): -4.4263 rad/s (-253.61 deg/s) beyond its \
             velocity limit 3.5605 rad/s (204.00 deg/s) (joint angles of the bottle poses, by \
             inverse kinematics)"
        );
        // Slower, the same turn is fine.
        let slow: Vec<f64> = t.iter().map(|t| 2.0 * t).collect();
        assert!(cfg.check_cartesian(&slow, &p).is_ok());
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
        let err = cfg.check_cartesian(&slow, &p).unwrap_err().to_string();
        assert!(
            err.starts_with(
                "sample 247: bottle pose [0.700, 0.100, 0.400, 0.574, 0.000, 0.000, 0.819]: \
                 inverse kinematics did not converge"
            ),
            "{err}"
        );
    }

    #[test]
    fn the_mouth_checks_name_the_sample() {
        let cfg = gate();
        let still = [0.65, 0.2, 0.35, 0.0, 0.0, 0.0];
        let (t, mut p) = poses(still, still, 5);
        p[3][2] = 0.2;
        assert_eq!(
            cfg.check_cartesian(&t, &p).unwrap_err().to_string(),
            "sample 3: mouth z = 0.200 m outside the workspace [0.3, 1.1] m"
        );
        p[3][2] = 0.4;
        assert_eq!(
            cfg.check_cartesian(&t, &p).unwrap_err().to_string(),
            "sample 3: mouth speed 5.00 m/s beyond 1 m/s"
        );
        p[3] = pose([0.65, 0.2, 0.35, 0.1, 0.0, 0.0]);
        assert_eq!(
            cfg.check_cartesian(&t, &p).unwrap_err().to_string(),
            "sample 3: turning at 10.00 rad/s beyond 3 rad/s"
        );
        p[3] = pose(still);
        p[3][3] = 1.01;
        assert_eq!(
            cfg.check_cartesian(&t, &p).unwrap_err().to_string(),
            "sample 3: the orientation quaternion's norm is 1.0100, not 1"
        );
    }

    #[test]
    fn the_turn_rate_is_the_angular_speed_through_180_degrees_and_either_sign() {
        let cfg = gate();
        // Yaw from 178° to 182°, 1° per 10 ms (1.75 rad/s): the rotation
        // vector wraps by 2π between 180° and 181°, the quaternion does
        // not, and a recorder may flip its sign.
        let t: Vec<f64> = (0..5).map(|i| i as f64 * 0.01).collect();
        let p: Vec<[f64; 7]> = (0..5)
            .map(|i| {
                let half = (178.0 + i as f64).to_radians() / 2.0;
                let s = if i == 3 { -1.0 } else { 1.0 };
                [0.65, 0.2, 0.35, s * half.cos(), 0.0, 0.0, s * half.sin()]
            })
            .collect();
        assert_eq!(cfg.check_point(&t, &p), Ok(()));
        for pair in p.windows(2) {
            let rate = turn(&pair[0][3..], &pair[1][3..]) / 0.01;
            assert!((rate - 1f64.to_radians() / 0.01).abs() < 1e-9, "{rate}");
        }
    }
}
