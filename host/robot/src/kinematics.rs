//! Kinematics of a 7-joint arm described by a [`Robot`] (standard DH, all
//! θ offsets 0): forward kinematics, the geometric Jacobian, and numerical
//! inverse kinematics (damped least squares) whose null-space pull toward a
//! rest configuration picks the elbow of this redundant arm.
//!
//! ```
//! use primo_robot::{Arm, JOINTS, Robot};
//! let arm = Arm::new(Robot::lwr4());
//! // Stretched out: the flange is straight above the base.
//! let pose = arm.forward(&[0.0; JOINTS]);
//! assert!((pose.position[2] - 1.178).abs() < 1e-12);
//! // Back from the pose to joint angles, elbow pulled toward `rest`.
//! let q = [0.3, 0.6, -0.2, -1.2, 0.4, 0.7, -0.5];
//! let rest = [0.0, 0.5, 0.0, -1.0, 0.0, 0.5, 0.0];
//! let solution = arm.inverse(&arm.forward(&q), &q, &rest).unwrap();
//! let reached = arm.forward(&solution).position;
//! assert!((0..3).all(|i| (reached[i] - arm.forward(&q).position[i]).abs() < 1e-9));
//! ```

use primo_core::linalg::{cholesky, cholesky_solve};

use crate::pose::{Pose, cross, norm, sub};
use crate::{JOINTS, Link, Robot};

/// One DH link, `Rz(θ) · Tz(d) · Tx(a) · Rx(α)`, its twist's sine and
/// cosine computed once: a control loop's forward kinematics computes only
/// the joint angles'.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Twisted {
    d: f64,
    a: f64,
    sin_alpha: f64,
    cos_alpha: f64,
}

impl Twisted {
    fn new(Link { d, a, alpha }: Link) -> Self {
        let (sin_alpha, cos_alpha) = alpha.sin_cos();
        Twisted {
            d,
            a,
            sin_alpha,
            cos_alpha,
        }
    }

    /// The link's transform at joint angle `theta`.
    fn pose(&self, theta: f64) -> Pose {
        let (st, ct) = theta.sin_cos();
        let (sa, ca) = (self.sin_alpha, self.cos_alpha);
        Pose {
            rotation: [
                [ct, -st * ca, st * sa],
                [st, ct * ca, -ct * sa],
                [0.0, sa, ca],
            ],
            position: [self.a * ct, self.a * st, self.d],
        }
    }
}

/// A robot with a tool transform from its last joint frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Arm {
    robot: Robot,
    tool: Pose,
    /// The robot's DH table, ready for forward kinematics.
    links: [Twisted; JOINTS],
}

impl Arm {
    /// The bare arm, tool frame at the flange.
    pub fn new(robot: Robot) -> Self {
        Arm::holding(robot, Pose::translation(0.0, 0.0, robot.flange))
    }

    /// The arm holding a tool: `grasp` is flange → tool frame.
    pub fn with_tool(robot: Robot, grasp: &Pose) -> Self {
        let bare = Arm::new(robot);
        Arm::holding(robot, bare.tool.then(grasp))
    }

    /// `robot` with `tool` as its last joint frame → tool frame.
    fn holding(robot: Robot, tool: Pose) -> Self {
        Arm {
            robot,
            tool,
            links: robot.dh.map(Twisted::new),
        }
    }

    /// The robot's description.
    pub fn robot(&self) -> &Robot {
        &self.robot
    }

    /// Last joint frame → tool frame (flange, hand, bottle, …).
    pub fn tool(&self) -> &Pose {
        &self.tool
    }

    /// Base → tool frame for joint angles `q` (radians).
    pub fn forward(&self, q: &[f64; JOINTS]) -> Pose {
        // The last of `frames`, without keeping the others.
        q.iter()
            .zip(&self.links)
            .fold(Pose::IDENTITY, |frame, (theta, link)| {
                frame.then(&link.pose(*theta))
            })
            .then(&self.tool)
    }

    /// The geometric Jacobian of the tool frame in the base frame at `q`:
    /// rows vx, vy, vz, ωx, ωy, ωz; column i is joint i's axis `z` crossed
    /// with the lever to the tool, then `z` itself.
    pub fn jacobian(&self, q: &[f64; JOINTS]) -> [[f64; JOINTS]; 6] {
        self.forward_and_jacobian(q).1
    }

    /// Joint angles that put the tool at `target`, by damped least squares
    /// from `seed`, plus a null-space pull toward `rest`: the arm is
    /// redundant, and `rest` chooses among the tool-preserving motions
    /// (mainly the elbow swing about the shoulder–wrist line). Joints stay
    /// within the robot's position limits; the tool pose has priority over the
    /// pull, which only moves joints where the limits leave room.
    ///
    /// Succeeds once the tool is within 1e-9 m and 1e-9 rad of `target` and
    /// the pull toward `rest` has settled (or after a few more iterations on
    /// target: near singularities the pull may never settle). Seeded with a
    /// nearby solution, as when tracking a path sample by sample, this takes
    /// a handful of iterations. The search is local: a far seed may end in a
    /// local minimum or against a limit, which is an error.
    pub fn inverse(
        &self,
        target: &Pose,
        seed: &[f64; JOINTS],
        rest: &[f64; JOINTS],
    ) -> Result<[f64; JOINTS], IkError> {
        let limits = self.robot.position_limits_deg.map(f64::to_radians);
        let mut q: [f64; JOINTS] = std::array::from_fn(|j| seed[j].clamp(-limits[j], limits[j]));
        let mut best = IkError {
            position_error: f64::INFINITY,
            orientation_error: f64::INFINITY,
        };
        let mut on_target = None;
        let mut settling = 0;
        // Gain on the pull: Barzilai–Borwein, i.e. the secant estimate of the
        // inverse curvature of |q − rest|² along the self-motion, from the
        // last pull step and how much the pull changed over it.
        let mut gain = 1.0;
        let mut last_pull: Option<([f64; JOINTS], [f64; JOINTS])> = None;
        for _ in 0..IK_ITERATIONS {
            let (pose, jacobian) = self.forward_and_jacobian(&q);
            let position = sub(target.position, pose.position);
            let mut current = pose;
            current.position = [0.0; 3];
            let orientation = target.then(&current.inverse()).rotation_vector();
            let error = IkError {
                position_error: norm(position),
                orientation_error: norm(orientation),
            };
            if error.position_error + error.orientation_error
                < best.position_error + best.orientation_error
            {
                best = error;
            }
            let reached =
                error.position_error <= IK_TOLERANCE && error.orientation_error <= IK_TOLERANCE;
            if reached {
                on_target = Some(q);
                settling += 1;
            }
            let e = [
                position[0],
                position[1],
                position[2],
                orientation[0],
                orientation[1],
                orientation[2],
            ];
            let Some(step) = ik_step(&jacobian, &e, &q, rest, &limits, gain) else {
                break;
            };
            // Near a singularity the pull can leak into the tool pose and be
            // undone by the task step, indefinitely: settle after a while.
            if reached
                && (settling >= IK_SETTLE_ITERATIONS
                    || step.pull_step.iter().all(|s| s.abs() <= IK_TOLERANCE))
            {
                return Ok(q);
            }
            if let Some((s, pull)) = last_pull {
                let change: [f64; JOINTS] = std::array::from_fn(|j| pull[j] - step.pull[j]);
                let curvature = dot_joints(&s, &change);
                if curvature > 0.0 {
                    gain = (dot_joints(&s, &s) / curvature).clamp(IK_GAIN_MIN, IK_GAIN_MAX);
                }
            }
            last_pull = Some((step.pull_step, step.pull));
            for (j, qj) in q.iter_mut().enumerate() {
                *qj = (*qj + step.task[j] + step.pull_step[j]).clamp(-limits[j], limits[j]);
            }
        }
        on_target.ok_or(best)
    }

    /// The tool pose and the Jacobian, from one pass down the chain.
    /// Base → DH frame i for i = 0 (the base itself) to [`JOINTS`].
    fn frames(&self, q: &[f64; JOINTS]) -> [Pose; JOINTS + 1] {
        let mut frames = [Pose::IDENTITY; JOINTS + 1];
        for (i, (theta, link)) in q.iter().zip(&self.links).enumerate() {
            frames[i + 1] = frames[i].then(&link.pose(*theta));
        }
        frames
    }

    fn forward_and_jacobian(&self, q: &[f64; JOINTS]) -> (Pose, [[f64; JOINTS]; 6]) {
        let frames = self.frames(q);
        let tool = frames[JOINTS].then(&self.tool);
        let mut jacobian = [[0.0; JOINTS]; 6];
        for (i, frame) in frames[..JOINTS].iter().enumerate() {
            let z = frame.z_axis();
            let linear = cross(z, sub(tool.position, frame.position));
            for (row, value) in jacobian.iter_mut().zip(linear.into_iter().chain(z)) {
                row[i] = value;
            }
        }
        (tool, jacobian)
    }
}

/// Tool-pose tolerance of [`Lwr4::inverse`], metres and radians; also the
/// pull step, radians, below which the pull toward rest counts as settled.
const IK_TOLERANCE: f64 = 1e-9;
/// Iteration cap of [`Lwr4::inverse`].
const IK_ITERATIONS: usize = 200;
/// Damping floor λ², added to |e|² (Sugihara's Levenberg–Marquardt choice:
/// strong damping far away or unreachable, Newton steps close by). Small,
/// since damping also leaks the null-space pull into the tool pose.
const IK_DAMPING: f64 = 1e-12;
/// Iterations on target after which [`Lwr4::inverse`] stops refining the
/// pull toward rest.
const IK_SETTLE_ITERATIONS: usize = 10;
/// Largest task step per iteration, radians: far seeds do not jump across
/// the workspace.
const IK_MAX_STEP: f64 = 0.5;
/// Largest pull step per iteration, radians: the self-motion is curved, and
/// a long step along its tangent would leave the target.
const IK_MAX_PULL: f64 = 0.1;
/// Smallest pull gain: the secant estimate is noisy while the task step
/// still dominates.
const IK_GAIN_MIN: f64 = 0.1;
/// Largest pull gain, for nearly flat stretches of the self-motion.
const IK_GAIN_MAX: f64 = 2.0;

/// One iteration's joint steps.
struct Step {
    /// Damped least-squares correction of the tool pose; joints it would
    /// carry past a limit stop there and the rest is re-solved without them.
    task: [f64; JOINTS],
    /// `rest − q` projected onto the null space of the free joints.
    pull: [f64; JOINTS],
    /// `pull` times the gain, shortened to fit the limits and
    /// [`IK_MAX_PULL`].
    pull_step: [f64; JOINTS],
}

/// The task step `Jᵀ (J Jᵀ + λ² I)⁻¹ e` and the pull `z − Jᵀ (J Jᵀ + λ² I)⁻¹ J z`
/// toward rest, with λ² = |e|² + [`IK_DAMPING`]. `None` if the system is not
/// solvable (non-finite input).
fn ik_step(
    jacobian: &[[f64; JOINTS]; 6],
    e: &[f64; 6],
    q: &[f64; JOINTS],
    rest: &[f64; JOINTS],
    limits: &[f64; JOINTS],
    gain: f64,
) -> Option<Step> {
    let damping = e.iter().map(|x| x * x).sum::<f64>() + IK_DAMPING;
    let mut locked = [false; JOINTS];
    let mut task = [0.0; JOINTS];
    let mut factor;
    loop {
        let mut a = [[0.0; 6]; 6];
        for (i, a_row) in a.iter_mut().enumerate() {
            a_row[i] = damping;
            for (k, a_ik) in a_row.iter_mut().enumerate() {
                *a_ik += (0..JOINTS)
                    .filter(|&j| !locked[j])
                    .map(|j| jacobian[i][j] * jacobian[k][j])
                    .sum::<f64>();
            }
        }
        factor = a;
        cholesky(&mut factor, 6, "inverse kinematics").ok()?;
        // Locked joints move exactly to their limit; the free ones make up
        // for it.
        let residual: [f64; 6] = std::array::from_fn(|i| e[i] - dot_joints(&jacobian[i], &task));
        let y = solve(&factor, &residual);
        let mut settled = true;
        for j in 0..JOINTS {
            if locked[j] {
                continue;
            }
            task[j] = (0..6).map(|i| jacobian[i][j] * y[i]).sum();
            let next = q[j] + task[j];
            if next.abs() > limits[j] {
                locked[j] = true;
                task[j] = next.clamp(-limits[j], limits[j]) - q[j];
                settled = false;
            }
        }
        if settled {
            break;
        }
    }
    let largest = task.iter().fold(0.0, |m: f64, s| m.max(s.abs()));
    if largest > IK_MAX_STEP {
        task = task.map(|s| s * IK_MAX_STEP / largest);
    }

    let z: [f64; JOINTS] = std::array::from_fn(|j| if locked[j] { 0.0 } else { rest[j] - q[j] });
    let jz: [f64; 6] = std::array::from_fn(|i| dot_joints(&jacobian[i], &z));
    let y = solve(&factor, &jz);
    let pull: [f64; JOINTS] = std::array::from_fn(|j| {
        if locked[j] {
            0.0
        } else {
            z[j] - (0..6).map(|i| jacobian[i][j] * y[i]).sum::<f64>()
        }
    });
    // Shorten the pull, never its direction, so it stays tool-preserving.
    let mut scale = gain;
    for j in 0..JOINTS {
        let proposed = scale * pull[j];
        if proposed.abs() > IK_MAX_PULL {
            scale *= IK_MAX_PULL / proposed.abs();
        }
        let room = limits[j] - (q[j] + task[j]) * pull[j].signum();
        if scale * pull[j].abs() > room {
            scale = (room / pull[j].abs()).max(0.0);
        }
    }
    let pull_step = pull.map(|p| p * scale);
    Some(Step {
        task,
        pull,
        pull_step,
    })
}

/// Solves `A x = b` with the Cholesky factor of `A` from [`cholesky`].
fn solve(factor: &[[f64; 6]; 6], b: &[f64; 6]) -> [f64; 6] {
    let mut x = *b;
    cholesky_solve(factor, 6, &mut x);
    x
}

/// [`Arm::inverse`] found no joint angles putting the tool on the target
/// (out of reach, or blocked by joint limits or a singularity); the errors
/// are the smallest it reached.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkError {
    /// Distance from the tool to the target position, metres.
    pub position_error: f64,
    /// Angle between the tool and target orientations, radians.
    pub orientation_error: f64,
}

impl std::fmt::Display for IkError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "inverse kinematics did not converge: tool still {:.3} mm and {:.3} deg \
             from the target (out of reach or blocked by joint limits?)",
            self.position_error * 1e3,
            self.orientation_error.to_degrees()
        )
    }
}

impl std::error::Error for IkError {}

fn dot_joints(a: &[f64; JOINTS], b: &[f64; JOINTS]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pose::tests::{close, distance};
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn known_configurations() {
        let arm = Arm::new(Robot::lwr4());
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
        let r = Arm::new(Robot::lwr4())
            .forward(&[0.3, -1.0, 2.0, 1.5, -2.5, 0.9, 3.0])
            .rotation;
        for i in 0..3 {
            for j in 0..3 {
                let dot: f64 = (0..3).map(|k| r[i][k] * r[j][k]).sum();
                assert!((dot - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12);
            }
        }
    }

    /// Configurations well inside the limits and away from the shoulder
    /// (q2 = 0), elbow (q4 = 0) and wrist (q6 = 0) singularities.
    const CONFIGURATIONS: [[f64; JOINTS]; 5] = [
        [0.3, 0.6, -0.2, -1.2, 0.4, 0.7, -0.5],
        [-1.1, -0.8, 0.9, 1.4, -1.3, -0.6, 2.0],
        [2.2, 1.0, -1.5, -0.7, 2.1, 1.2, -2.4],
        [0.0, -0.5, 0.4, -1.8, 0.2, 0.9, 0.0],
        [-2.5, 1.3, 2.0, 0.9, -0.6, -1.5, 1.1],
    ];

    #[test]
    fn inverse_pose_composes_to_identity() {
        let pose = Arm::new(Robot::lwr4()).forward(&CONFIGURATIONS[1]);
        for product in [pose.then(&pose.inverse()), pose.inverse().then(&pose)] {
            let (dp, dr) = distance(&product, &Pose::IDENTITY);
            assert!(dp < 1e-15 && dr < 1e-15, "{product:?}");
        }
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let arm = Arm::holding(
            Robot::lwr4(),
            Pose::from_rotation_vector([0.02, -0.01, 0.2], [0.3, 0.0, -0.2]),
        );
        let h = 1e-6;
        for q in CONFIGURATIONS {
            let jacobian = arm.jacobian(&q);
            let pose = arm.forward(&q);
            for j in 0..JOINTS {
                let (mut plus, mut minus) = (q, q);
                plus[j] += h;
                minus[j] -= h;
                let (plus, minus) = (arm.forward(&plus), arm.forward(&minus));
                // Angular velocity in the base frame: log(R(q ± h) R(q)ᵀ).
                let turn = |p: &Pose| p.then(&pose.inverse()).rotation_vector();
                let (w_plus, w_minus) = (turn(&plus), turn(&minus));
                for k in 0..3 {
                    let v = (plus.position[k] - minus.position[k]) / (2.0 * h);
                    let w = (w_plus[k] - w_minus[k]) / (2.0 * h);
                    assert!((jacobian[k][j] - v).abs() < 1e-8, "v{k} joint {j}: {q:?}");
                    assert!(
                        (jacobian[k + 3][j] - w).abs() < 1e-8,
                        "w{k} joint {j}: {q:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn inverse_kinematics_round_trips() {
        let arm = Arm::new(Robot::lwr4());
        for (n, q) in CONFIGURATIONS.into_iter().enumerate() {
            let target = arm.forward(&q);
            // ±0.2 rad on every joint, a different sign pattern each time.
            let seed: [f64; JOINTS] =
                std::array::from_fn(|j| q[j] + if (j + n) % 3 == 0 { -0.2 } else { 0.2 });
            let solution = arm.inverse(&target, &seed, &q).unwrap();
            let (dp, dr) = distance(&arm.forward(&solution), &target);
            assert!(dp < 1e-9 && dr < 1e-9, "{q:?}: {dp:e} m, {dr:e} rad");
            // Resting at q itself, the pull brings the elbow back there too.
            assert!(solution.iter().zip(q).all(|(a, b)| (a - b).abs() < 1e-6));
            assert_eq!(Robot::lwr4().check_limits([(0.0, &solution)]), Ok(()));
        }
    }

    #[test]
    fn rest_configuration_chooses_the_elbow() {
        let arm = Arm::new(Robot::lwr4());
        let q = CONFIGURATIONS[0];
        let target = arm.forward(&q);
        let (mut up, mut down) = (q, q);
        up[2] = 0.6;
        down[2] = -0.6;
        let up = arm.inverse(&target, &q, &up).unwrap();
        let down = arm.inverse(&target, &q, &down).unwrap();
        for solution in [up, down] {
            let (dp, dr) = distance(&arm.forward(&solution), &target);
            assert!(dp < 1e-9 && dr < 1e-9, "{solution:?}: {dp:e} m, {dr:e} rad");
        }
        assert!(up[2] - down[2] > 0.3, "{up:?} vs {down:?}");
    }

    #[test]
    fn pull_toward_rest_respects_the_limits() {
        let arm = Arm::new(Robot::lwr4());
        let mut q = CONFIGURATIONS[0];
        q[0] = 2.9;
        let target = arm.forward(&q);
        // Rest beyond joint 1's limit: the pull takes it to the limit and no
        // further.
        let mut rest = q;
        rest[0] = 3.5;
        let solution = arm.inverse(&target, &q, &rest).unwrap();
        let (dp, dr) = distance(&arm.forward(&solution), &target);
        assert!(dp < 1e-9 && dr < 1e-9, "{solution:?}: {dp:e} m, {dr:e} rad");
        assert!(
            (solution[0] - 170f64.to_radians()).abs() < 1e-9,
            "{solution:?}"
        );
        assert_eq!(Robot::lwr4().check_limits([(0.0, &solution)]), Ok(()));
    }

    #[test]
    fn tracks_a_path_sample_by_sample() {
        let arm = Arm::new(Robot::lwr4());
        let rest = CONFIGURATIONS[0];
        let start = arm.forward(&rest);
        let mut q = rest;
        // 10 cm in 1 mm steps, turning 0.2 rad on the way.
        for k in 1..=100 {
            let s = k as f64 / 100.0;
            let mut target = start.then(&Pose::from_rotation_vector([0.0; 3], [0.0, 0.2 * s, 0.0]));
            target.position[0] += 0.06 * s;
            target.position[2] -= 0.08 * s;
            let next = arm.inverse(&target, &q, &rest).unwrap();
            let (dp, dr) = distance(&arm.forward(&next), &target);
            assert!(dp < 1e-9 && dr < 1e-9, "sample {k}: {dp:e} m, {dr:e} rad");
            // Smooth: small target steps, small joint steps.
            assert!(
                next.iter().zip(q).all(|(a, b)| (a - b).abs() < 0.01),
                "sample {k}"
            );
            q = next;
        }
    }

    #[test]
    fn unreachable_target_is_an_error() {
        let arm = Arm::new(Robot::lwr4());
        let q = CONFIGURATIONS[0];
        let err = arm
            .inverse(&Pose::translation(3.0, 0.0, 0.0), &q, &q)
            .unwrap_err();
        assert!(err.position_error > 1.5, "{err:?}");
        assert!(
            err.to_string()
                .starts_with("inverse kinematics did not converge")
        );
    }
}
