//! KUKA LWR4 kinematics (standard DH, all θ offsets 0) and joint limits.
//!
//! ```
//! use primo_host::sim::arm::{Lwr4, JOINTS};
//! let arm = Lwr4::with_flange();
//! // Stretched out: the flange is straight above the base.
//! let pose = arm.forward(&[0.0; JOINTS]);
//! assert!((pose.position[2] - 1.178).abs() < 1e-12);
//! ```

/// Number of joints.
pub const JOINTS: usize = 7;

/// DH parameters `(d, a, α)` per joint, metres and radians.
const DH: [(f64, f64, f64); JOINTS] = {
    use std::f64::consts::FRAC_PI_2 as H;
    [
        (0.310, 0.0, H),
        (0.0, 0.0, -H),
        (0.400, 0.0, -H),
        (0.0, 0.0, H),
        (0.390, 0.0, H),
        (0.0, 0.0, -H),
        (0.0, 0.0, 0.0),
    ]
};

/// Distance from the last joint frame to the flange along its z axis.
pub const FLANGE: f64 = 0.078;

/// Joint position limits, ± degrees.
pub const POSITION_LIMITS_DEG: [f64; JOINTS] = [170.0, 120.0, 170.0, 120.0, 170.0, 120.0, 170.0];
/// Joint velocity limits (LWR 4+), degrees per second.
pub const VELOCITY_LIMITS_DEG: [f64; JOINTS] = [110.0, 110.0, 128.0, 128.0, 204.0, 184.0, 184.0];

/// A rigid transform: rotation (row-major 3×3) and translation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Rotation matrix, rows.
    pub rotation: [[f64; 3]; 3],
    /// Translation in metres.
    pub position: [f64; 3],
}

impl Pose {
    /// The identity transform.
    pub const IDENTITY: Pose = Pose {
        rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        position: [0.0; 3],
    };

    /// A pure translation.
    pub fn translation(x: f64, y: f64, z: f64) -> Pose {
        Pose {
            position: [x, y, z],
            ..Pose::IDENTITY
        }
    }

    /// `self · other`: `other` expressed in `self`'s parent frame.
    pub fn then(&self, other: &Pose) -> Pose {
        let mut out = Pose::IDENTITY;
        for (i, row) in self.rotation.iter().enumerate() {
            out.rotation[i] =
                std::array::from_fn(|j| (0..3).map(|k| row[k] * other.rotation[k][j]).sum());
            out.position[i] =
                self.position[i] + (0..3).map(|k| row[k] * other.position[k]).sum::<f64>();
        }
        out
    }

    /// The frame's z axis in the parent frame (third column).
    pub fn z_axis(&self) -> [f64; 3] {
        [
            self.rotation[0][2],
            self.rotation[1][2],
            self.rotation[2][2],
        ]
    }
}

/// One DH link: `Rz(θ) · Tz(d) · Tx(a) · Rx(α)`.
fn dh(theta: f64, d: f64, a: f64, alpha: f64) -> Pose {
    let (st, ct) = theta.sin_cos();
    let (sa, ca) = alpha.sin_cos();
    Pose {
        rotation: [
            [ct, -st * ca, st * sa],
            [st, ct * ca, -ct * sa],
            [0.0, sa, ca],
        ],
        position: [a * ct, a * st, d],
    }
}

/// The arm with a tool transform from the last joint frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lwr4 {
    /// Last joint frame → tool frame (flange, hand, bottle mouth, …).
    pub tool: Pose,
}

impl Lwr4 {
    /// The bare arm, tool frame at the flange.
    pub fn with_flange() -> Self {
        Lwr4 {
            tool: Pose::translation(0.0, 0.0, FLANGE),
        }
    }

    /// Base → tool frame for joint angles `q` (radians).
    pub fn forward(&self, q: &[f64; JOINTS]) -> Pose {
        let mut pose = Pose::IDENTITY;
        for (theta, (d, a, alpha)) in q.iter().zip(DH) {
            pose = pose.then(&dh(*theta, d, a, alpha));
        }
        pose.then(&self.tool)
    }
}

/// Which limit a trajectory crosses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Violation {
    /// `|q| > limit` at sample `row`.
    Position {
        /// Joint index, from 0.
        joint: usize,
        /// Sample index.
        row: usize,
        /// The angle, radians.
        value: f64,
    },
    /// `|q̇| > limit` between samples `row − 1` and `row`.
    Velocity {
        /// Joint index, from 0.
        joint: usize,
        /// Sample index.
        row: usize,
        /// The speed, radians per second.
        value: f64,
    },
    /// A non-finite value or non-increasing time at sample `row`.
    Malformed {
        /// Sample index.
        row: usize,
    },
}

impl std::fmt::Display for Violation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Violation::Position { joint, row, value } => write!(
                f,
                "joint {} at sample {row}: {:.2} deg beyond the ±{} deg position limit",
                joint + 1,
                value.to_degrees(),
                POSITION_LIMITS_DEG[joint]
            ),
            Violation::Velocity { joint, row, value } => write!(
                f,
                "joint {} at sample {row}: {:.2} deg/s beyond the {} deg/s velocity limit",
                joint + 1,
                value.to_degrees(),
                VELOCITY_LIMITS_DEG[joint]
            ),
            Violation::Malformed { row } => {
                write!(f, "sample {row}: non-finite value or time not increasing")
            }
        }
    }
}

/// Checks every sample `(t, q)` against the position limits and every
/// pair of consecutive samples against the velocity limits (finite
/// differences); the first violation is returned.
pub fn check_limits<'a>(
    samples: impl IntoIterator<Item = (f64, &'a [f64; JOINTS])>,
) -> Result<(), Violation> {
    let mut previous: Option<(f64, [f64; JOINTS])> = None;
    for (row, (t, q)) in samples.into_iter().enumerate() {
        if !t.is_finite()
            || q.iter().any(|v| !v.is_finite())
            || previous.is_some_and(|(t0, _)| t <= t0)
        {
            return Err(Violation::Malformed { row });
        }
        for (joint, (&value, limit)) in q.iter().zip(POSITION_LIMITS_DEG).enumerate() {
            if value.abs() > limit.to_radians() {
                return Err(Violation::Position { joint, row, value });
            }
        }
        if let Some((t0, q0)) = previous {
            for (joint, ((a, b), limit)) in q0.iter().zip(q).zip(VELOCITY_LIMITS_DEG).enumerate() {
                let value = (b - a) / (t - t0);
                if value.abs() > limit.to_radians() {
                    return Err(Violation::Velocity { joint, row, value });
                }
            }
        }
        previous = Some((t, *q));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9)
    }

    #[test]
    fn known_configurations() {
        let arm = Lwr4::with_flange();
        assert!(close(arm.forward(&[0.0; 7]).position, [0.0, 0.0, 1.178]));
        // Joint 2 at +90°: the arm lies along the base x axis (or −x: the DH
        // z axes fix the sign), at shoulder height.
        let p = arm
            .forward(&[0.0, FRAC_PI_2, 0.0, 0.0, 0.0, 0.0, 0.0])
            .position;
        assert!(
            (p[0].abs() - 0.868).abs() < 1e-9 && p[1].abs() < 1e-9 && (p[2] - 0.31).abs() < 1e-9,
            "{p:?}"
        );
        // Elbow (joint 4) at +90°: forearm horizontal at elbow height.
        let p = arm
            .forward(&[0.0, 0.0, 0.0, FRAC_PI_2, 0.0, 0.0, 0.0])
            .position;
        assert!(
            (p[0].abs() - 0.468).abs() < 1e-9 && (p[2] - 0.71).abs() < 1e-9,
            "{p:?}"
        );
        // Joint 1 rotates everything about the base z axis.
        let q = [0.7, 0.5, -0.3, 1.1, 0.4, -0.6, 0.2];
        let mut turned = q;
        turned[0] += 0.5;
        let (a, b) = (arm.forward(&q).position, arm.forward(&turned).position);
        let (r_a, r_b) = (a[0].hypot(a[1]), b[0].hypot(b[1]));
        assert!((r_a - r_b).abs() < 1e-12 && (a[2] - b[2]).abs() < 1e-12);
        let angle = b[1].atan2(b[0]) - a[1].atan2(a[0]);
        assert!((angle.rem_euclid(std::f64::consts::TAU) - 0.5).abs() < 1e-9);
    }

    #[test]
    fn rotation_stays_orthonormal() {
        let r = Lwr4::with_flange()
            .forward(&[0.3, -1.0, 2.0, 1.5, -2.5, 0.9, 3.0])
            .rotation;
        for i in 0..3 {
            for j in 0..3 {
                let dot: f64 = (0..3).map(|k| r[i][k] * r[j][k]).sum();
                assert!((dot - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn limits_are_checked_per_sample_and_per_step() {
        let ok = [0.0; 7];
        let mut far = [0.0; 7];
        far[1] = 121f64.to_radians();
        assert!(matches!(
            check_limits([(0.0, &far)]),
            Err(Violation::Position {
                joint: 1,
                row: 0,
                ..
            })
        ));
        // 1° in 10 ms is 100 °/s: fine for joint 1 (110), too fast for none.
        let mut step = [0.0; 7];
        step[0] = 1f64.to_radians();
        assert_eq!(check_limits([(0.0, &ok), (0.01, &step)]), Ok(()));
        // 1.2° in 10 ms is 120 °/s: beyond joint 1's 110 °/s.
        step[0] = 1.2f64.to_radians();
        let err = check_limits([(0.0, &ok), (0.01, &step)]).unwrap_err();
        assert!(matches!(
            err,
            Violation::Velocity {
                joint: 0,
                row: 1,
                ..
            }
        ));
        assert_eq!(
            err.to_string(),
            "joint 1 at sample 1: 120.00 deg/s beyond the 110 deg/s velocity limit"
        );
        assert!(matches!(
            check_limits([(0.0, &ok), (0.0, &ok)]),
            Err(Violation::Malformed { row: 1 })
        ));
        let mut nan = ok;
        nan[3] = f64::NAN;
        assert!(matches!(
            check_limits([(0.0, &nan)]),
            Err(Violation::Malformed { row: 0 })
        ));
    }
}
