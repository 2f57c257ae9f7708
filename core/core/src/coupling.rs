//! Coupling terms: accelerations added to a running DMP each step, and the
//! phase slowed while the robot lags.
//!
//! - [`Obstacles`]: spheres (or points) in the Cartesian space of three of
//!   the DMP's DoFs, avoided by Park et al.'s dynamic potential (2008).
//! - [`JointLimits`]: a push away from each DoF's limits within a margin.
//! - [`PhaseStop`]: Ijspeert et al.'s phase stopping (2013): time runs
//!   slower while the measured position lags the command.
//!
//! The accelerations enter through [`Run::step_with`](crate::dmp::Run::step_with)
//! (or [`Run::step_coupled`](crate::dmp::Run::step_coupled) with their sum),
//! as `τ²ÿ = K(g − y) − ατẏ + f + τ²·c`. Every term is computed from the
//! run's own position and velocity (or a measured one), is finite for any
//! finite input, and is bounded in size by its `max_acceleration`.
//!
//! ```
//! use primo_core::coupling::{Coupling, Obstacles, Sphere};
//! use primo_core::dmp::{Dmp, FitOptions};
//! // A straight 0.6 m reach along x in one second.
//! let t: Vec<f32> = (0..=100).map(|i| i as f32 / 100.0).collect();
//! let y: Vec<f32> = t
//!     .iter()
//!     .flat_map(|&t| [0.6 * t * t * (3.0 - 2.0 * t), 0.0, 0.0])
//!     .collect();
//! let dmp = Dmp::<3, 20>::fit(&t, &y, 3, 20, &FitOptions::default())?;
//! let exec = dmp.execution();
//! // A ball of 5 cm radius just off the path, halfway.
//! let ball = Sphere { center: [0.3, 0.02, 0.0], radius: 0.05 };
//! let obstacles = Obstacles::<4>::new([0, 1, 2], &[ball], &exec.start, &exec.goal)?;
//! let mut run = dmp.start(&exec)?;
//! let mut closest = f32::INFINITY;
//! while run.time() < 2.0 {
//!     run.step_with(&dmp, 0.002, &[&obstacles as &dyn Coupling])?;
//!     let p = run.position();
//!     closest = closest.min(ball.distance([p[0], p[1], p[2]]));
//! }
//! assert!(closest > 0.0); // never inside the ball
//! assert!((run.position()[0] - 0.6).abs() < 1e-2); // and still at the goal
//! # Ok::<(), primo_core::Error>(())
//! ```

mod joint_limits;
mod obstacle;
mod phase_stop;

pub use joint_limits::JointLimits;
pub use obstacle::{DEFAULT_GAIN, DEFAULT_MAX_ACCELERATION, DEFAULT_POWER, Obstacles, Sphere};
pub use phase_stop::PhaseStop;

use crate::Error;

/// An acceleration added to a running DMP, from its current state.
pub trait Coupling {
    /// Adds this term's acceleration (units per s², one value per DoF) at
    /// `position` moving at `velocity` (units per s) to `acceleration`. The
    /// three slices have the DMP's DoF as their length.
    fn add_to(
        &self,
        position: &[f32],
        velocity: &[f32],
        acceleration: &mut [f32],
    ) -> Result<(), Error>;
}

/// Scales `a` down to at most `max` in Euclidean norm; a non-finite `a`
/// (an overflow near a singularity) becomes zero rather than poisoning
/// the run.
pub(crate) fn clamp_norm(a: &mut [f32], max: f32) {
    let largest = a.iter().fold(0.0f32, |m, v| m.max(libm::fabsf(*v)));
    if !largest.is_finite() || a.iter().any(|v| v.is_nan()) {
        a.iter_mut().for_each(|v| *v = 0.0);
        return;
    }
    if largest == 0.0 {
        return;
    }
    // Scaled by the largest entry first, so the sum of squares cannot
    // overflow whatever the entries.
    let norm = largest * libm::sqrtf(a.iter().map(|v| (v / largest) * (v / largest)).sum());
    if norm > max {
        let k = max / norm;
        a.iter_mut().for_each(|v| *v *= k);
    }
}
