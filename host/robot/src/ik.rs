//! Inverse kinematics of any [`Chain`]: damped least squares within the
//! joint limits, with a null-space pull toward a rest posture that picks
//! the elbow of a redundant arm (and moves only where the limits leave
//! room).
//!
//! Each iteration solves `(J Jᵀ + λ² I) y = e` for the tool's pose error
//! `e` (position, then the rotation vector, both in the base frame), with
//! `λ² = |e|² + 10⁻¹²` (Sugihara's Levenberg–Marquardt choice: strong
//! damping far away or out of reach, Newton steps close by), and steps the
//! joints by `Jᵀ y`; a joint the step would carry past a limit stops there
//! and the others are solved again without it. The pull `rest − q`,
//! projected onto the null space of the free joints, is added with a
//! Barzilai–Borwein gain.
//!
//! **Stop rule.** Success once the tool is within `tolerance` (metres and
//! radians) of the target and the pull has settled (its step below the
//! tolerance), or after [`SETTLE_ITERATIONS`] iterations on target (near a
//! singularity the pull may never settle). Not on target after half the
//! iterations, the pull is dropped for the rest of them: it is what holds
//! the tool a fraction of a millimetre off the target when the arm is far
//! from rest near a limit (of random Panda poses seeded 0.05 rad off and
//! pulled toward mid-range, 15 % failed without this, 2 % with it).
//! Failure after `iterations`
//! without reaching the target, with the smallest errors reached. The
//! search is local: seeded with a nearby solution, as when a path is
//! solved sample by sample, it takes a handful of iterations; a far seed
//! may end in a local minimum or against a limit.
//!
//! ```
//! use primo_robot::Robot;
//! use primo_robot::ik::{IkOptions, inverse};
//! let chain = Robot::lwr4().chain();
//! let q = [0.3, 0.6, -0.2, -1.2, 0.4, 0.7, -0.5];
//! let target = chain.forward(&q);
//! let rest = [0.0, 0.5, 0.0, -1.0, 0.0, 0.5, 0.0];
//! let solved = inverse(&chain, &target, &q, &rest, &IkOptions::default()).unwrap();
//! let reached = chain.forward(&solved);
//! assert!((reached.translation.vector - target.translation.vector).norm() < 1e-9);
//! ```

use nalgebra::{Cholesky, Isometry3, Matrix6, SVector, U6, UnitQuaternion, Vector6};

use crate::chain::{Chain, Jacobian, MAX_JOINTS};

/// How [`inverse`] stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkOptions {
    /// Tool-pose tolerance, metres and radians; also the pull step,
    /// radians, below which the pull toward rest counts as settled.
    pub tolerance: f64,
    /// Iterations before giving up.
    pub iterations: usize,
}

impl Default for IkOptions {
    /// 1e-9 m and rad, 200 iterations.
    fn default() -> Self {
        IkOptions {
            tolerance: 1e-9,
            iterations: 200,
        }
    }
}

/// Iterations on target after which [`inverse`] stops refining the pull
/// toward rest.
pub const SETTLE_ITERATIONS: usize = 10;
/// Damping floor λ², added to |e|²: small, since damping also leaks the
/// null-space pull into the tool pose.
const DAMPING: f64 = 1e-12;
/// Largest task step per iteration, radians: far seeds do not jump across
/// the workspace.
const MAX_STEP: f64 = 0.5;
/// Largest pull step per iteration, radians: the self-motion is curved, and
/// a long step along its tangent would leave the target.
const MAX_PULL: f64 = 0.1;
/// Smallest pull gain: the secant estimate is noisy while the task step
/// still dominates.
const GAIN_MIN: f64 = 0.1;
/// Largest pull gain, for nearly flat stretches of the self-motion.
const GAIN_MAX: f64 = 2.0;

/// [`inverse`] found no joint positions putting the tool on the target
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

/// Joint positions of `chain` that put its tool at `target`, from `seed`
/// (clamped into the limits), pulled toward `rest` (one value per joint
/// each; see the module docs for the stop rule).
pub fn inverse(
    chain: &Chain,
    target: &Isometry3<f64>,
    seed: &[f64],
    rest: &[f64],
    options: &IkOptions,
) -> Result<Vec<f64>, IkError> {
    let n = chain.dof();
    // Every vector on the stack at the most joints a chain has; the
    // entries past `n` stay 0, their joints locked.
    let mut limits = Limits {
        n,
        lower: Joints::zeros(),
        upper: Joints::zeros(),
    };
    for (j, joint) in chain.joints().iter().enumerate().take(MAX_JOINTS) {
        limits.lower[j] = joint.limits.lower;
        limits.upper[j] = joint.limits.upper;
    }
    let value = |v: &[f64], j: usize| v.get(j).copied().unwrap_or(0.0);
    let rest = Joints::from_fn(|j, _| if j < n { value(rest, j) } else { 0.0 });
    let mut q = Joints::from_fn(|j, _| limits.clamp(j, value(seed, j)));
    let target = crate::chain::matrix(target);
    let mut jacobian = Jacobian::zeros();
    let mut best = IkError {
        position_error: f64::INFINITY,
        orientation_error: f64::INFINITY,
    };
    let mut on_target = None;
    let mut settling = 0;
    // Gain on the pull: Barzilai–Borwein, the secant estimate of the
    // inverse curvature of |q − rest|² along the self-motion, from the
    // last pull step and how much the pull changed over it.
    let mut gain = 1.0;
    let mut last_pull: Option<(Joints, Joints)> = None;
    let solution = |q: &Joints| q.iter().take(n).copied().collect::<Vec<f64>>();
    for iteration in 0..options.iterations {
        let pose = chain.jacobian_into(q.as_slice(), &mut jacobian);
        let position = target.translation.vector - pose.translation.vector;
        // The rotation vector through the quaternion: accurate near zero,
        // where an angle from the trace is not.
        let turn = target.rotation * pose.rotation.inverse();
        let orientation = UnitQuaternion::from_rotation_matrix(&turn).scaled_axis();
        let error = IkError {
            position_error: position.norm(),
            orientation_error: orientation.norm(),
        };
        if error.position_error + error.orientation_error
            < best.position_error + best.orientation_error
        {
            best = error;
        }
        let reached = error.position_error <= options.tolerance
            && error.orientation_error <= options.tolerance;
        if reached {
            on_target = Some(q);
            settling += 1;
        }
        let e = Vector6::new(
            position.x,
            position.y,
            position.z,
            orientation.x,
            orientation.y,
            orientation.z,
        );
        let Some(mut step) = step(&jacobian, &e, &q, &rest, &limits, gain) else {
            break;
        };
        // Not on target after half the budget: the pull toward rest is
        // what holds the tool off it (each pull step, tangent to a curved
        // self-motion, leaves the target by about what the task step
        // recovers), so the rest is plain damped least squares.
        if on_target.is_none() && 2 * iteration >= options.iterations {
            step.pull_step.fill(0.0);
        }
        // Near a singularity the pull can leak into the tool pose and be
        // undone by the task step, indefinitely: settle after a while.
        if reached
            && (settling >= SETTLE_ITERATIONS
                || step.pull_step.iter().all(|s| s.abs() <= options.tolerance))
        {
            return Ok(solution(&q));
        }
        if let Some((s, pull)) = &last_pull {
            let change = pull - step.pull;
            let curvature = s.dot(&change);
            if curvature > 0.0 {
                gain = (s.dot(s) / curvature).clamp(GAIN_MIN, GAIN_MAX);
            }
        }
        for j in 0..n {
            q[j] = limits.clamp(j, q[j] + step.task[j] + step.pull_step[j]);
        }
        last_pull = Some((step.pull_step, step.pull));
    }
    on_target.map(|q| solution(&q)).ok_or(best)
}

/// A value per joint, up to [`MAX_JOINTS`].
type Joints = SVector<f64, MAX_JOINTS>;

/// The joints' position limits; joints from `n` on are no joints.
struct Limits {
    n: usize,
    lower: Joints,
    upper: Joints,
}

impl Limits {
    fn clamp(&self, j: usize, x: f64) -> f64 {
        match j < self.n {
            true => x.clamp(self.lower[j], self.upper[j]),
            false => 0.0,
        }
    }

    /// Room from `x` to joint `j`'s limit in the direction of `sign`'s sign.
    fn room(&self, j: usize, x: f64, sign: f64) -> f64 {
        match sign.is_sign_positive() {
            true => self.upper[j] - x,
            false => x - self.lower[j],
        }
    }
}

/// One iteration's joint steps.
struct Step {
    /// Damped least-squares correction of the tool pose; joints it would
    /// carry past a limit stop there and the rest is re-solved without them.
    task: Joints,
    /// `rest − q` projected onto the null space of the free joints.
    pull: Joints,
    /// `pull` times the gain, shortened to fit the limits and [`MAX_PULL`].
    pull_step: Joints,
}

/// The task step `Jᵀ (J Jᵀ + λ² I)⁻¹ e` and the pull `z − Jᵀ (J Jᵀ + λ² I)⁻¹ J z`
/// toward rest, with λ² = |e|² + [`DAMPING`]. `None` if the system is not
/// solvable (non-finite input).
fn step(
    jacobian: &Jacobian,
    e: &Vector6<f64>,
    q: &Joints,
    rest: &Joints,
    limits: &Limits,
    gain: f64,
) -> Option<Step> {
    let n = limits.n;
    let damping = e.norm_squared() + DAMPING;
    let mut locked = [true; MAX_JOINTS];
    for l in locked.iter_mut().take(n) {
        *l = false;
    }
    let mut task = Joints::zeros();
    let factor = loop {
        let mut a = Matrix6::identity() * damping;
        for (column, _) in jacobian.column_iter().zip(locked).filter(|(_, l)| !l) {
            a += column * column.transpose();
        }
        let factor = Cholesky::<f64, U6>::new(a)?;
        // Locked joints move exactly to their limit; the free ones make up
        // for it.
        let y = factor.solve(&(e - jacobian * task));
        let mut settled = true;
        for (j, column) in jacobian.column_iter().enumerate().take(n) {
            if locked[j] {
                continue;
            }
            task[j] = column.dot(&y);
            let next = q[j] + task[j];
            if next < limits.lower[j] || next > limits.upper[j] {
                locked[j] = true;
                task[j] = limits.clamp(j, next) - q[j];
                settled = false;
            }
        }
        if settled {
            break factor;
        }
    };
    let largest = task.amax();
    if largest > MAX_STEP {
        task *= MAX_STEP / largest;
    }
    let z = Joints::from_fn(|j, _| if locked[j] { 0.0 } else { rest[j] - q[j] });
    let y = factor.solve(&(jacobian * z));
    let mut pull = z - jacobian.transpose() * y;
    for (p, _) in pull.iter_mut().zip(locked).filter(|(_, l)| *l) {
        *p = 0.0;
    }
    // Shorten the pull, never its direction, so it stays tool-preserving.
    let mut scale = gain;
    for j in 0..n {
        let proposed = scale * pull[j];
        if proposed.abs() > MAX_PULL {
            scale *= MAX_PULL / proposed.abs();
        }
        let room = limits.room(j, q[j] + task[j], pull[j]);
        if scale * pull[j].abs() > room {
            scale = (room / pull[j].abs()).max(0.0);
        }
    }
    Some(Step {
        task,
        pull,
        pull_step: pull * scale,
    })
}
