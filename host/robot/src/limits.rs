//! The joint limits of a [`Robot`]: every sample within the position
//! limits, every step (finite difference) within the velocity limits.

use crate::{JOINTS, Robot};

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
        /// The limit, ± degrees.
        limit_deg: f64,
    },
    /// `|q̇| > limit` between samples `row − 1` and `row`.
    Velocity {
        /// Joint index, from 0.
        joint: usize,
        /// Sample index.
        row: usize,
        /// The speed, radians per second.
        value: f64,
        /// The limit, degrees per second.
        limit_deg: f64,
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
            Violation::Position {
                joint,
                row,
                value,
                limit_deg,
            } => write!(
                f,
                "joint {} at sample {row}: {:.2} deg beyond the ±{limit_deg} deg position limit",
                joint + 1,
                value.to_degrees(),
            ),
            Violation::Velocity {
                joint,
                row,
                value,
                limit_deg,
            } => write!(
                f,
                "joint {} at sample {row}: {:.2} deg/s beyond the {limit_deg} deg/s velocity limit",
                joint + 1,
                value.to_degrees(),
            ),
            Violation::Malformed { row } => {
                write!(f, "sample {row}: non-finite value or time not increasing")
            }
        }
    }
}

impl std::error::Error for Violation {}

impl Robot {
    /// Checks every sample `(t, q)` against the position limits and every
    /// pair of consecutive samples against the velocity limits (finite
    /// differences); the first violation is returned.
    pub fn check_limits<'a>(
        &self,
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
            for (joint, (&value, limit)) in q.iter().zip(self.position_limits_deg).enumerate() {
                if value.abs() > limit.to_radians() {
                    return Err(Violation::Position {
                        joint,
                        row,
                        value,
                        limit_deg: limit,
                    });
                }
            }
            if let Some((t0, q0)) = previous {
                for (joint, ((a, b), limit)) in
                    q0.iter().zip(q).zip(self.velocity_limits_deg).enumerate()
                {
                    let value = (b - a) / (t - t0);
                    if value.abs() > limit.to_radians() {
                        return Err(Violation::Velocity {
                            joint,
                            row,
                            value,
                            limit_deg: limit,
                        });
                    }
                }
            }
            previous = Some((t, *q));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_are_checked_per_sample_and_per_step() {
        let lwr4 = Robot::lwr4();
        let ok = [0.0; 7];
        let mut far = [0.0; 7];
        far[1] = 121f64.to_radians();
        assert!(matches!(
            lwr4.check_limits([(0.0, &far)]),
            Err(Violation::Position {
                joint: 1,
                row: 0,
                ..
            })
        ));
        // 1° in 10 ms is 100 °/s: fine for joint 1 (110), too fast for none.
        let mut step = [0.0; 7];
        step[0] = 1f64.to_radians();
        assert_eq!(lwr4.check_limits([(0.0, &ok), (0.01, &step)]), Ok(()));
        // 1.2° in 10 ms is 120 °/s: beyond joint 1's 110 °/s.
        step[0] = 1.2f64.to_radians();
        let err = lwr4.check_limits([(0.0, &ok), (0.01, &step)]).unwrap_err();
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
            lwr4.check_limits([(0.0, &ok), (0.0, &ok)]),
            Err(Violation::Malformed { row: 1 })
        ));
        let mut nan = ok;
        nan[3] = f64::NAN;
        assert!(matches!(
            lwr4.check_limits([(0.0, &nan)]),
            Err(Violation::Malformed { row: 0 })
        ));
    }
}
