//! What primo streams to a Franka: one joint-position setpoint a
//! millisecond, from where the robot stands to the end of a checked
//! [`JointPath`], within the description's limits and the FCI's.
//!
//! The setpoints are a minimum-jerk approach from the robot's position to
//! the path's start (the FRI path's planner, at a fraction of the
//! velocity limits), then the path through a cubic spline that starts and
//! ends at rest, sampled every millisecond. Before anything is sent, every
//! setpoint is checked by finite differences against the joint position
//! and velocity limits of the path's robot (its URDF) and the rates the
//! FCI accepts from a motion generator ([`ACCELERATION`], [`JERK`]), from
//! rest before the first setpoint to rest after the last; a path that
//! needs more is refused, not slowed down.
//!
//! ```
//! use primo_franka::plan::{Plan, fr3};
//! use primo_robot::safety::check_path;
//! let chain = fr3();
//! let start = [0.0, 0.0, 0.0, -1.57, 0.0, 1.57, 0.785];
//! let mut end = start;
//! end[0] += 0.1;
//! let path = check_path(&chain, vec![0.0, 2.0], [start, end].concat(), None).unwrap();
//! let plan = Plan::new(&path, start, 0.2).unwrap();
//! // Already at the start: the approach holds it for a cycle.
//! assert_eq!(plan.approach_len(), 2);
//! assert_eq!(plan.setpoints().len(), 2 + 2000);
//! assert_eq!(plan.setpoints().last(), Some(&end));
//! ```

use primo_fri::path::{FriPath, approach};
use primo_robot::chain::Chain;
use primo_robot::urdf::Urdf;
use primo_robot::{JOINTS, JointPath, Tip};

use crate::error::{Exceeded, FrankaError, Quantity};

/// The FCI's cycle, s.
pub const DT: f64 = 0.001;
/// The joint acceleration the FCI accepts from a motion generator, rad/s²
/// (libfranka's `kMaxJointAcceleration`, less its margin).
pub const ACCELERATION: f64 = 10.0 - 1e-3;
/// The joint jerk it accepts, rad/s³ (`kMaxJointJerk`, less its margin).
pub const JERK: f64 = 5000.0 - 1e-3;

/// The Franka Research 3's description (franka_description's, without
/// meshes): served by primo's simulated controller, and the default model
/// of a `franka:` robot.
pub const FR3_URDF: &str = include_str!("fr3.urdf");

/// The FR3's chain, link0 to link8, joints `joint1..joint7`.
pub fn fr3() -> Chain {
    // The built-in description parses: a unit test says so.
    Urdf::parse("fr3.urdf", FR3_URDF)
        .and_then(|urdf| Chain::from_urdf(&urdf, &Tip::default()))
        .unwrap_or_else(|_| Chain::from_dh("fr3", &[], &Default::default(), &[]))
}

/// The millisecond setpoints of a path, checked.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    setpoints: Vec<[f64; JOINTS]>,
    approach: usize,
}

impl Plan {
    /// Plans `path` from the robot's position `from`, approaching its start
    /// at `approach_speed` times the velocity limits, and checks it.
    pub fn new(
        path: &JointPath,
        from: [f64; JOINTS],
        approach_speed: f64,
    ) -> Result<Plan, FrankaError> {
        let seven = FriPath::try_from(path).map_err(|e| FrankaError::NotSeven {
            robot: e.robot,
            dof: e.dof,
        })?;
        let mut setpoints: Vec<[f64; JOINTS]> = approach(
            from,
            seven.start(),
            DT,
            approach_speed,
            seven.velocity_limits(),
        )
        .collect();
        let approach = setpoints.len();
        setpoints.extend(spline(path.times(), seven.rows(), DT).skip(1));
        let plan = Plan {
            setpoints,
            approach,
        };
        plan.check(path.chain())?;
        Ok(plan)
    }

    /// One joint-position setpoint a millisecond.
    pub fn setpoints(&self) -> &[[f64; JOINTS]] {
        &self.setpoints
    }

    /// How many of them approach the path's start (the first is where the
    /// robot stood).
    pub fn approach_len(&self) -> usize {
        self.approach
    }

    /// Every setpoint within the chain's joint limits and the FCI's rates,
    /// from rest to rest.
    fn check(&self, chain: &Chain) -> Result<(), FrankaError> {
        let first = self.setpoints.first().copied().unwrap_or_default();
        let last = self.setpoints.last().copied().unwrap_or_default();
        // At rest before and after: the held position three times.
        let padded: Vec<[f64; JOINTS]> = [first; 3]
            .into_iter()
            .chain(self.setpoints.iter().copied())
            .chain([last; 3])
            .collect();
        for (k, w) in padded.windows(4).enumerate() {
            if let [a, b, c, d] = w {
                let setpoint = k.min(self.setpoints.len().saturating_sub(1));
                let time = (setpoint as f64 - (self.approach as f64 - 1.0)) * DT;
                check_step(chain, [*a, *b, *c], d, setpoint, time).map_err(FrankaError::Limit)?;
            }
        }
        Ok(())
    }
}

/// The setpoint `next`, sent after `before` (the three sent last, oldest
/// first), within the chain's joint limits and the FCI's rates by finite
/// differences; `setpoint` and `time` name it in the error.
pub(crate) fn check_step(
    chain: &Chain,
    before: [[f64; JOINTS]; 3],
    next: &[f64; JOINTS],
    setpoint: usize,
    time: f64,
) -> Result<(), Exceeded> {
    let [p0, p1, p2] = before;
    for (j, joint) in chain.joints().iter().enumerate().take(JOINTS) {
        let l = joint.limits;
        let q = next[j];
        let v = [p1[j] - p0[j], p2[j] - p1[j], q - p2[j]].map(|d| d / DT);
        let a = [v[1] - v[0], v[2] - v[1]].map(|d| d / DT);
        let jerk = (a[1] - a[0]) / DT;
        let beyond = if q < l.lower || q > l.upper {
            let bound = if q < l.lower { l.lower } else { l.upper };
            Some((Quantity::Position, q, bound))
        } else if v[2].abs() > l.velocity {
            Some((Quantity::Velocity, v[2], l.velocity))
        } else if a[1].abs() > ACCELERATION {
            Some((Quantity::Acceleration, a[1], ACCELERATION))
        } else if jerk.abs() > JERK {
            Some((Quantity::Jerk, jerk, JERK))
        } else {
            None
        };
        if let Some((quantity, value, limit)) = beyond {
            return Err(Exceeded {
                setpoint,
                time,
                joint: joint.name.clone(),
                quantity,
                value,
                limit,
            });
        }
    }
    Ok(())
}

/// The samples `q` at `times` through a cubic spline of each joint that
/// starts and ends at rest (clamped, zero end velocities), every `dt` from
/// the first time, ending exactly on the last sample.
pub fn spline(times: &[f64], q: &[[f64; JOINTS]], dt: f64) -> impl Iterator<Item = [f64; JOINTS]> {
    let n = times.len().min(q.len());
    let m: Vec<[f64; JOINTS]> = second_derivatives(&times[..n], &q[..n]);
    let t0 = times.first().copied().unwrap_or(0.0);
    let duration = times.get(n.wrapping_sub(1)).copied().unwrap_or(t0) - t0;
    let steps = (duration / dt - 1e-9).ceil().max(0.0) as usize;
    let last = q.get(n.wrapping_sub(1)).copied().unwrap_or_default();
    let mut i = 0;
    let times = times.to_vec();
    let q = q.to_vec();
    (0..=steps).map(move |k| {
        if k == steps {
            return last;
        }
        let t = t0 + k as f64 * dt;
        while i + 2 < n && times[i + 1] <= t {
            i += 1;
        }
        if n < 2 {
            return last;
        }
        let (ta, tb) = (times[i], times[i + 1]);
        let h = tb - ta;
        let (a, b) = (tb - t, t - ta);
        std::array::from_fn(|j| {
            let (ma, mb) = (m[i][j], m[i + 1][j]);
            ma * a * a * a / (6.0 * h)
                + mb * b * b * b / (6.0 * h)
                + (q[i][j] / h - ma * h / 6.0) * a
                + (q[i + 1][j] / h - mb * h / 6.0) * b
        })
    })
}

/// The clamped spline's second derivatives at the knots (Thomas
/// algorithm on its tridiagonal system).
// A joint is a column of rows: indexing reads plainer than iterators.
#[allow(clippy::needless_range_loop)]
fn second_derivatives(t: &[f64], q: &[[f64; JOINTS]]) -> Vec<[f64; JOINTS]> {
    let n = t.len();
    if n < 2 {
        return vec![[0.0; JOINTS]; n];
    }
    let h: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let slope = |i: usize, j: usize| (q[i + 1][j] - q[i][j]) / h[i];
    let mut out = vec![[0.0; JOINTS]; n];
    for j in 0..JOINTS {
        // Rows: sub a, diagonal b, super c, right-hand side d.
        let mut c = vec![0.0; n];
        let mut d = vec![0.0; n];
        let row = |i: usize| -> (f64, f64, f64, f64) {
            if i == 0 {
                (0.0, 2.0 * h[0], h[0], 6.0 * slope(0, j))
            } else if i == n - 1 {
                (h[n - 2], 2.0 * h[n - 2], 0.0, -6.0 * slope(n - 2, j))
            } else {
                (
                    h[i - 1],
                    2.0 * (h[i - 1] + h[i]),
                    h[i],
                    6.0 * (slope(i, j) - slope(i - 1, j)),
                )
            }
        };
        for i in 0..n {
            let (a, b, ci, di) = row(i);
            let (cp, dp) = if i == 0 {
                (0.0, 0.0)
            } else {
                (c[i - 1], d[i - 1])
            };
            let denom = b - a * cp;
            c[i] = ci / denom;
            d[i] = (di - a * dp) / denom;
        }
        for i in (0..n).rev() {
            let next = if i + 1 < n { out[i + 1][j] } else { 0.0 };
            out[i][j] = d[i] - c[i] * next;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use primo_robot::safety::check_path;

    const HOME: [f64; JOINTS] = [0.0, 0.0, 0.0, -1.57, 0.0, 1.57, 0.785];

    fn path(rows: &[(f64, [f64; JOINTS])]) -> JointPath {
        check_path(
            &fr3(),
            rows.iter().map(|r| r.0).collect(),
            rows.iter().flat_map(|r| r.1).collect(),
            None,
        )
        .unwrap()
    }

    #[test]
    fn the_built_in_fr3_has_seven_joints_with_urdf_limits() {
        let chain = fr3();
        assert_eq!(chain.dof(), 7);
        assert_eq!(chain.names()[0], "joint1");
        assert_eq!(chain.joints()[4].limits.velocity, 5.26);
    }

    #[test]
    fn the_spline_passes_its_knots_and_rests_at_both_ends() {
        let mut mid = HOME;
        mid[0] = 0.3;
        let rows = [(0.0, HOME), (1.0, mid), (2.0, HOME)];
        let s: Vec<_> = spline(&[0.0, 1.0, 2.0], &rows.map(|r| r.1), DT).collect();
        assert_eq!(s.len(), 2001);
        assert!((s[1000][0] - 0.3).abs() < 1e-12);
        assert!((s[1][0] - s[0][0]).abs() < 1e-5, "starts at rest");
        assert_eq!(s[2000], HOME);
    }

    #[test]
    fn an_approach_leads_from_the_robot_to_the_start() {
        let mut start = HOME;
        start[3] = -1.2;
        let p = path(&[(0.0, start), (1.0, start)]);
        let plan = Plan::new(&p, HOME, 0.2).unwrap();
        assert!(plan.approach_len() > 100);
        assert_eq!(plan.setpoints()[0], HOME);
        assert_eq!(plan.setpoints()[plan.approach_len() - 1], start);
    }

    #[test]
    fn a_jump_is_refused_with_the_fci_rate_it_breaks() {
        let mut end = HOME;
        end[0] = 0.05;
        // 0.05 rad in 20 ms, from rest: far beyond 10 rad/s².
        let p = path(&[(0.0, HOME), (0.02, end)]);
        let err = Plan::new(&p, HOME, 0.2).unwrap_err().to_string();
        assert!(err.contains("joint1 acceleration"), "{err}");
        assert!(err.contains("beyond its limit 9.9990 rad/s²"), "{err}");
    }
}
