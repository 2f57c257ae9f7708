//! A DMP file's run with coupling terms: steered round obstacles (spheres
//! in the space of three of its position columns,
//! [`primo_core::coupling::Obstacles`]) and pushed back from its columns'
//! limits ([`primo_core::coupling::JointLimits`]).

use primo_core::coupling::{Coupling, DEFAULT_MAX_ACCELERATION, JointLimits, Obstacles, Sphere};

use crate::dmpfile::{DmpFile, Prepared};
use crate::{Error, HOST_MAX_DOF};

/// The most obstacles one run avoids.
pub const MAX_OBSTACLES: usize = 16;

/// How long a run avoiding obstacles may go on past `τ`, in `τ`, to reach
/// its goal.
pub const OVERTIME: f32 = 2.0;

/// How near its goal a run avoiding obstacles ends, as a fraction of the
/// distance from its start (the goal itself when that is 0).
pub const ARRIVAL: f32 = 1e-3;

/// Obstacles, and the three columns (by name) that are their `x, y, z`.
#[derive(Debug, Clone, PartialEq)]
pub struct Avoidance {
    /// The spheres to keep out of.
    pub spheres: Vec<Sphere>,
    /// The position columns holding `x, y, z`.
    pub columns: [String; 3],
}

/// The push of a joint-limit term at half its margin when none is given,
/// units/s²: with it, a 1 s reach to 0.8 that overshoots to 1.09 stays
/// under a limit at 0.95 with a margin of 0.1
/// (`core/core/tests/coupling.rs`).
pub const DEFAULT_LIMIT_GAIN: f32 = 50.0;

/// Columns' limits a run is pushed back from, within a margin.
#[derive(Debug, Clone, PartialEq)]
pub struct Repulsion {
    /// Per position column, by name: its lower and upper limit (an
    /// infinite one is none). Columns not named have none.
    pub limits: Vec<(String, f32, f32)>,
    /// How near a limit the push starts, in the columns' units.
    pub margin: f32,
    /// The push at half the margin, units/s².
    pub gain: f32,
}

/// The coupling terms of a run: all optional.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Coupled {
    /// Obstacles to steer round.
    pub avoid: Option<Avoidance>,
    /// Limits to keep away from.
    pub repel: Option<Repulsion>,
}

impl Coupled {
    /// Whether it has no term.
    pub fn is_none(&self) -> bool {
        self.avoid.is_none() && self.repel.is_none()
    }
}

impl DmpFile {
    /// [`DmpFile::run_prepared`] with `coupled`'s terms, at steps of `dt`
    /// from 0: the rows (time, one value per column). A detour takes time,
    /// so the run goes on past `τ` until it is within [`ARRIVAL`] of its
    /// goal, for at most [`OVERTIME`]·`τ` more; a run the terms keep from
    /// its goal is an error that says by how much.
    pub fn run_coupled(
        &self,
        prepared: &Prepared,
        dt: f32,
        coupled: &Coupled,
    ) -> Result<Vec<(f32, Vec<f32>)>, Error> {
        let exec = &prepared.execution;
        let dof = self.dmp.dof();
        let (from, to) = (&exec.start[..dof], &exec.goal[..dof]);
        let obstacles = (coupled.avoid.as_ref())
            .map(|avoid| self.obstacles(avoid, from, to))
            .transpose()?;
        let limits = (coupled.repel.as_ref())
            .map(|repel| self.joint_limits(repel, from, to))
            .transpose()?;
        let mut terms: Vec<&dyn Coupling> = Vec::new();
        if let Some(o) = &obstacles {
            terms.push(o);
        }
        if let Some(l) = &limits {
            terms.push(l);
        }
        let movement = |e: primo_core::Error| Error::Movement(e.to_string());
        let mut run = self.dmp.start(exec).map_err(movement)?;
        let span = distance(from, to);
        let near = if span > 0.0 { ARRIVAL * span } else { ARRIVAL };
        let last = exec.tau * (1.0 + OVERTIME);
        let mut rows = vec![(0.0, prepared.columns(run.position()))];
        let mut steps = 0u32;
        loop {
            let t = steps as f32 * dt;
            if t >= exec.tau && distance(run.position(), to) <= near {
                return Ok(rows);
            }
            if t >= last {
                return Err(Error::Movement(format!(
                    "the {} keep the movement {:.3} from its goal at {:.3} s, {OVERTIME}τ past \
                     its end τ: move them or the goal",
                    match (&obstacles, &limits) {
                        (Some(_), None) => "obstacles",
                        (None, Some(_)) => "joint limits",
                        _ => "obstacles and joint limits",
                    },
                    distance(run.position(), to),
                    t
                )));
            }
            run.step_with(&self.dmp, dt, &terms).map_err(movement)?;
            steps += 1;
            rows.push((steps as f32 * dt, prepared.columns(run.position())));
        }
    }

    /// `repel`'s limits as the core's term, one pair per DMP DoF (an
    /// orientation's: none), for a run from `from` to `to`.
    fn joint_limits(
        &self,
        repel: &Repulsion,
        from: &[f32],
        to: &[f32],
    ) -> Result<JointLimits<HOST_MAX_DOF>, Error> {
        let dof = self.dmp.dof();
        let mut low = vec![f32::NEG_INFINITY; dof];
        let mut high = vec![f32::INFINITY; dof];
        for (name, lo, hi) in &repel.limits {
            let d = self.scalar_dof(name).ok_or_else(|| {
                Error::Movement(format!(
                    "joint limits: no position column `{name}` among {}",
                    self.names.join(",")
                ))
            })?;
            if let (Some(l), Some(h)) = (low.get_mut(d), high.get_mut(d)) {
                (*l, *h) = (*lo, *hi);
            }
        }
        JointLimits::new(
            &low,
            &high,
            repel.margin,
            repel.gain,
            DEFAULT_MAX_ACCELERATION.max(2.0 * repel.gain),
            from,
            to,
        )
        .map_err(|e| Error::Movement(format!("joint limits: {e}")))
    }

    /// `avoid`'s spheres as the core's term, for a run from `from` to `to`.
    fn obstacles(
        &self,
        avoid: &Avoidance,
        from: &[f32],
        to: &[f32],
    ) -> Result<Obstacles<MAX_OBSTACLES>, Error> {
        let mut axes = [0; 3];
        for (axis, name) in axes.iter_mut().zip(&avoid.columns) {
            *axis = self.scalar_dof(name).ok_or_else(|| {
                Error::Movement(format!(
                    "obstacles: no position column `{name}` among {}",
                    self.names.join(",")
                ))
            })?;
        }
        // Each sphere alone first, so a refusal names the one refused.
        for (i, s) in avoid.spheres.iter().enumerate() {
            Obstacles::<1>::new(axes, &[*s], from, to).map_err(|e| {
                let [x, y, z] = s.center;
                Error::Movement(format!(
                    "obstacle {} (centre {x},{y},{z}, radius {}): {e}",
                    i + 1,
                    s.radius
                ))
            })?;
        }
        Obstacles::new(axes, &avoid.spheres, from, to)
            .map_err(|e| Error::Movement(format!("obstacles: {e}")))
    }
}

fn distance(a: &[f32], b: &[f32]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(a, b)| (a - b) * (a - b))
        .sum::<f32>()
        .sqrt()
}
