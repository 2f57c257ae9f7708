//! The joint limits of any [`Chain`] (the built-in LWR 4's too:
//! [`crate::Robot::chain`]) along a trajectory: every sample within each
//! joint's position limits, every step (finite difference) within its
//! velocity limit and, when a bound is given, every pair of steps within
//! an acceleration bound. The first violation names the sample, its time
//! and the joint by name, in the joint's units (rad, with degrees, or m).
//!
//! ```
//! use primo_robot::Robot;
//! let chain = Robot::lwr4().chain();
//! let mut q = vec![0.0; 2 * 7];
//! q[7 + 1] = 0.1; // a2 turns 0.1 rad in 10 ms: 10 rad/s
//! let err = chain.check_path(&[0.0, 0.01], &q, None).unwrap_err();
//! assert_eq!(
//!     err.to_string(),
//!     "joint a2 at sample 1 (t = 0.010 s): 10.0000 rad/s (572.96 deg/s) beyond its velocity \
//!      limit 1.9199 rad/s (110.00 deg/s)"
//! );
//! ```

use crate::chain::{Chain, Joint, JointLimits, Motion};

/// Which limit a trajectory crosses first.
#[derive(Debug, Clone, PartialEq)]
pub enum Violation {
    /// A position below the joint's lower or above its upper limit.
    Position {
        /// The joint's name.
        joint: String,
        /// How it moves (its units: rad or m).
        motion: Motion,
        /// Sample index, from 0.
        sample: usize,
        /// Its time, s.
        time: f64,
        /// The position.
        value: f64,
        /// The lower limit.
        lower: f64,
        /// The upper limit.
        upper: f64,
    },
    /// A speed beyond the joint's velocity limit, between samples
    /// `sample − 1` and `sample`.
    Velocity {
        /// The joint's name.
        joint: String,
        /// How it moves.
        motion: Motion,
        /// Sample index.
        sample: usize,
        /// Its time, s.
        time: f64,
        /// The speed, per second.
        value: f64,
        /// The limit, per second.
        limit: f64,
    },
    /// An acceleration beyond the bound, over samples `sample − 2` to
    /// `sample`.
    Acceleration {
        /// The joint's name.
        joint: String,
        /// How it moves.
        motion: Motion,
        /// Sample index.
        sample: usize,
        /// Its time, s.
        time: f64,
        /// The acceleration, per second squared.
        value: f64,
        /// The bound, per second squared.
        limit: f64,
    },
    /// A non-finite value or time, or a time not after the previous one.
    Malformed {
        /// Sample index.
        sample: usize,
    },
    /// Not one position per joint per sample.
    Shape {
        /// Samples (times) given.
        samples: usize,
        /// Positions given.
        values: usize,
        /// The chain's joints.
        joints: usize,
    },
}

impl std::fmt::Display for Violation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let at = |joint: &str, sample: usize, time: f64| {
            format!("joint {joint} at sample {sample} (t = {time:.3} s)")
        };
        match self {
            Violation::Position {
                joint,
                motion,
                sample,
                time,
                value,
                lower,
                upper,
            } => {
                let (side, limit) = match value < lower {
                    true => ("below its lower", *lower),
                    false => ("beyond its upper", *upper),
                };
                write!(
                    f,
                    "{}: {} {side} limit {}",
                    at(joint, *sample, *time),
                    amount(*motion, *value, ""),
                    amount(*motion, limit, "")
                )
            }
            Violation::Velocity {
                joint,
                motion,
                sample,
                time,
                value,
                limit,
            } => write!(
                f,
                "{}: {} beyond its velocity limit {}",
                at(joint, *sample, *time),
                amount(*motion, *value, "/s"),
                amount(*motion, *limit, "/s")
            ),
            Violation::Acceleration {
                joint,
                motion,
                sample,
                time,
                value,
                limit,
            } => write!(
                f,
                "{}: {} beyond the acceleration bound {}",
                at(joint, *sample, *time),
                amount(*motion, *value, "/s²"),
                amount(*motion, *limit, "/s²")
            ),
            Violation::Malformed { sample } => {
                write!(
                    f,
                    "sample {sample}: non-finite value or time not increasing"
                )
            }
            Violation::Shape {
                samples,
                values,
                joints,
            } => write!(
                f,
                "{values} positions for {samples} samples of {joints} joints"
            ),
        }
    }
}

impl std::error::Error for Violation {}

/// `value` in a joint's units (`per`: "", "/s", "/s²"): rad with degrees
/// for a revolute joint (what a robot's data sheet gives), m otherwise.
pub(crate) fn amount(motion: Motion, value: f64, per: &str) -> String {
    match motion {
        Motion::Revolute => format!("{value:.4} rad{per} ({:.2} deg{per})", value.to_degrees()),
        Motion::Prismatic => format!("{value:.4} m{per}"),
    }
}

impl Chain {
    /// Checks a trajectory of this chain: `times[i]` (s) and row `i` of
    /// `positions` (row-major, one per joint in the chain's order), against
    /// every joint's position and velocity limits and, if given,
    /// `max_acceleration` (for every joint, rad/s² or m/s²); the first
    /// violation is returned.
    pub fn check_path(
        &self,
        times: &[f64],
        positions: &[f64],
        max_acceleration: Option<f64>,
    ) -> Result<(), Violation> {
        let dof = self.dof();
        if positions.len() != times.len() * dof {
            return Err(Violation::Shape {
                samples: times.len(),
                values: positions.len(),
                joints: dof,
            });
        }
        let samples = times.iter().copied().zip(positions.chunks_exact(dof));
        check(self.joints(), samples, max_acceleration)
    }

    /// Checks samples `(t, q)` as [`Chain::check_path`] does, without an
    /// acceleration bound; allocates nothing until it finds a violation:
    /// a driver checks every setpoint.
    pub fn check_samples<'a>(
        &self,
        samples: impl IntoIterator<Item = (f64, &'a [f64])>,
    ) -> Result<(), Violation> {
        check(self.joints(), samples, None)
    }
}

/// The one check: samples of `joints.len()` positions each.
fn check<'a>(
    joints: &[Joint],
    samples: impl IntoIterator<Item = (f64, &'a [f64])>,
    max_acceleration: Option<f64>,
) -> Result<(), Violation> {
    // The last two samples: a step needs one, an acceleration both.
    let mut previous: Option<(f64, &[f64])> = None;
    let mut before: Option<(f64, &[f64])> = None;
    for (sample, (time, q)) in samples.into_iter().enumerate() {
        if q.len() != joints.len() {
            return Err(Violation::Shape {
                samples: sample + 1,
                values: q.len(),
                joints: joints.len(),
            });
        }
        if !time.is_finite()
            || q.iter().any(|v| !v.is_finite())
            || previous.is_some_and(|(t0, _)| time <= t0)
        {
            return Err(Violation::Malformed { sample });
        }
        for (j, &value) in joints.iter().zip(q) {
            let JointLimits { lower, upper, .. } = j.limits;
            if value < lower || value > upper {
                return Err(Violation::Position {
                    joint: j.name.to_string(),
                    motion: j.motion,
                    sample,
                    time,
                    value,
                    lower,
                    upper,
                });
            }
        }
        if let Some((t1, q1)) = previous {
            for (k, j) in joints.iter().enumerate() {
                let value = (q[k] - q1[k]) / (time - t1);
                if value.abs() > j.limits.velocity {
                    return Err(Violation::Velocity {
                        joint: j.name.to_string(),
                        motion: j.motion,
                        sample,
                        time,
                        value,
                        limit: j.limits.velocity,
                    });
                }
                if let (Some(limit), Some((t0, q0))) = (max_acceleration, before) {
                    let earlier = (q1[k] - q0[k]) / (t1 - t0);
                    let value = (value - earlier) / ((time - t0) / 2.0);
                    if value.abs() > limit {
                        return Err(Violation::Acceleration {
                            joint: j.name.to_string(),
                            motion: j.motion,
                            sample,
                            time,
                            value,
                            limit,
                        });
                    }
                }
            }
        }
        before = previous;
        previous = Some((time, q));
    }
    Ok(())
}

/// How long a minimum-jerk move from `from` to `to` takes with each
/// joint's peak speed at most `speed` times its velocity limit
/// (`velocity[j]`), s: minimum jerk peaks at 1.875·Δ/T. The approach to a
/// trajectory's start (FRI's and ROS 2's) is planned with it and
/// [`min_jerk`].
///
/// ```
/// use primo_robot::limits::{min_jerk, min_jerk_duration};
/// let t = min_jerk_duration(&[0.0, 0.0], &[0.5, -1.0], 0.5, &[2.0, 1.0]);
/// assert_eq!(t, 1.875 * 1.0 / 0.5);
/// assert_eq!((min_jerk(0.0), min_jerk(0.5), min_jerk(1.0)), (0.0, 0.5, 1.0));
/// ```
pub fn min_jerk_duration(from: &[f64], to: &[f64], speed: f64, velocity: &[f64]) -> f64 {
    from.iter()
        .zip(to)
        .zip(velocity)
        .map(|((a, b), v)| 1.875 * (b - a).abs() / (speed * v))
        .fold(0.0, f64::max)
}

/// The minimum-jerk blend at phase `s` in [0, 1]: from 0 to 1, at rest
/// (no velocity, no acceleration) at both ends.
pub fn min_jerk(s: f64) -> f64 {
    s * s * s * (10.0 - 15.0 * s + 6.0 * s * s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Tip;
    use crate::urdf::Urdf;

    #[test]
    fn limits_are_checked_per_sample_and_per_step() {
        let lwr4 = crate::Robot::lwr4().chain();
        let ok = [0.0; 7];
        let mut far = [0.0; 7];
        far[1] = 121f64.to_radians();
        assert!(matches!(
            lwr4.check_samples([(0.0, &far[..])]),
            Err(Violation::Position { ref joint, sample: 0, .. }) if joint == "a2"
        ));
        // 1° in 10 ms is 100 °/s: fine for joint 1 (110), too fast for none.
        let mut step = [0.0; 7];
        step[0] = 1f64.to_radians();
        assert_eq!(
            lwr4.check_samples([(0.0, &ok[..]), (0.01, &step[..])]),
            Ok(())
        );
        // 1.2° in 10 ms is 120 °/s: beyond joint 1's 110 °/s.
        step[0] = 1.2f64.to_radians();
        let err = lwr4
            .check_samples([(0.0, &ok[..]), (0.01, &step[..])])
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            "joint a1 at sample 1 (t = 0.010 s): 2.0944 rad/s (120.00 deg/s) beyond its \
             velocity limit 1.9199 rad/s (110.00 deg/s)"
        );
        assert!(matches!(
            lwr4.check_samples([(0.0, &ok[..]), (0.0, &ok[..])]),
            Err(Violation::Malformed { sample: 1 })
        ));
        let mut nan = ok;
        nan[3] = f64::NAN;
        assert!(matches!(
            lwr4.check_samples([(0.0, &nan[..])]),
            Err(Violation::Malformed { sample: 0 })
        ));
        assert!(matches!(
            lwr4.check_samples([(0.0, &ok[..3])]),
            Err(Violation::Shape {
                values: 3,
                joints: 7,
                ..
            })
        ));
    }

    /// A revolute shoulder (±1 rad, 2 rad/s) and a prismatic slide
    /// (0 to 0.3 m, 0.5 m/s), then a continuous wrist (3 rad/s).
    fn slide() -> Chain {
        let text = r#"<robot name="slide">
          <link name="base"/> <link name="upper"/> <link name="carriage"/> <link name="hand"/>
          <joint name="shoulder" type="revolute">
            <parent link="base"/> <child link="upper"/> <axis xyz="0 0 1"/>
            <limit lower="-1" upper="1" velocity="2"/>
          </joint>
          <joint name="slide" type="prismatic">
            <parent link="upper"/> <child link="carriage"/> <axis xyz="1 0 0"/>
            <limit lower="0" upper="0.3" velocity="0.5"/>
          </joint>
          <joint name="wrist" type="continuous">
            <parent link="carriage"/> <child link="hand"/> <axis xyz="0 0 1"/>
            <limit velocity="3"/>
          </joint>
        </robot>"#;
        Chain::from_urdf(&Urdf::parse("slide.urdf", text).unwrap(), &Tip::default()).unwrap()
    }

    #[test]
    fn any_chain_is_checked_by_joint_name_in_its_units() {
        let chain = slide();
        let times = [0.0, 0.1, 0.2];
        let still = [0.5, 0.1, 100.0].repeat(3);
        assert_eq!(chain.check_path(&times, &still, None), Ok(()));
        let mut out = still.clone();
        out[3 + 1] = 0.31;
        assert_eq!(
            chain
                .check_path(&times, &out, None)
                .unwrap_err()
                .to_string(),
            "joint slide at sample 1 (t = 0.100 s): 0.3100 m beyond its upper limit 0.3000 m"
        );
        out[3 + 1] = 0.1;
        out[6] = -1.2;
        assert_eq!(
            chain
                .check_path(&times, &out, None)
                .unwrap_err()
                .to_string(),
            "joint shoulder at sample 2 (t = 0.200 s): -1.2000 rad (-68.75 deg) below its \
             lower limit -1.0000 rad (-57.30 deg)"
        );
        // 0.06 m in 0.1 s: 0.6 m/s.
        let mut fast = still.clone();
        fast[3 + 1] = 0.16;
        let err = chain.check_path(&times, &fast, None).unwrap_err();
        assert!(
            matches!(err, Violation::Velocity { sample: 1, .. }),
            "{err}"
        );
        assert!(
            err.to_string()
                .contains("0.6000 m/s beyond its velocity limit 0.5000 m/s")
        );
        // The continuous wrist has no position limit, only its speed.
        let mut spun = still.clone();
        spun[6 + 2] = 100.35;
        assert!(matches!(
            chain.check_path(&times, &spun, None),
            Err(Violation::Velocity { ref joint, sample: 2, .. }) if joint == "wrist"
        ));
        assert_eq!(
            chain.check_path(&times, &still[..8], None),
            Err(Violation::Shape {
                samples: 3,
                values: 8,
                joints: 3
            })
        );
    }

    #[test]
    fn accelerations_are_checked_when_bounded() {
        let chain = slide();
        let times = [0.0, 0.1, 0.2];
        // The shoulder still, then at 1 rad/s: 1 rad/s over 0.1 s, 10 rad/s².
        let q = [0.0, 0.1, 0.0, 0.0, 0.1, 0.0, 0.1, 0.1, 0.0];
        assert_eq!(chain.check_path(&times, &q, None), Ok(()));
        assert_eq!(chain.check_path(&times, &q, Some(10.5)), Ok(()));
        let err = chain.check_path(&times, &q, Some(5.0)).unwrap_err();
        assert!(
            matches!(err, Violation::Acceleration { ref joint, sample: 2, .. } if joint == "shoulder"),
            "{err}"
        );
        assert!(
            err.to_string().contains(
                "10.0000 rad/s² (572.96 deg/s²) beyond the acceleration bound 5.0000 rad/s²"
            ),
            "{err}"
        );
    }
}
