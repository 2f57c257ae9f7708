//! A DMP file's run steered round obstacles: spheres in the space of three
//! of its position columns, avoided by the core's coupling term
//! ([`primo_core::coupling::Obstacles`]).

use primo_core::coupling::{Coupling, Obstacles, Sphere};

use crate::Error;
use crate::dmpfile::{DmpFile, Prepared};

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

impl DmpFile {
    /// [`DmpFile::run_prepared`] steered round `avoid`'s spheres, at steps
    /// of `dt` from 0: the rows (time, one value per column). The detour takes
    /// time, so the run goes on past `τ` until it is within [`ARRIVAL`] of
    /// its goal, for at most [`OVERTIME`]·`τ` more; a run the obstacles
    /// keep from its goal is an error that says by how much.
    pub fn run_avoiding(
        &self,
        prepared: &Prepared,
        dt: f32,
        avoid: &Avoidance,
    ) -> Result<Vec<(f32, Vec<f32>)>, Error> {
        let exec = &prepared.execution;
        let dof = self.dmp.dof();
        let mut axes = [0; 3];
        for (axis, name) in axes.iter_mut().zip(&avoid.columns) {
            *axis = self.scalar_dof(name).ok_or_else(|| {
                Error::Movement(format!(
                    "obstacles: no position column `{name}` among {}",
                    self.names.join(",")
                ))
            })?;
        }
        let (from, to) = (&exec.start[..dof], &exec.goal[..dof]);
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
        let obstacles = Obstacles::<MAX_OBSTACLES>::new(axes, &avoid.spheres, from, to)
            .map_err(|e| Error::Movement(format!("obstacles: {e}")))?;
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
                    "the obstacles keep the movement {:.3} from its goal at {:.3} s, \
                     {OVERTIME}τ past its end τ: move them or the goal",
                    distance(run.position(), to),
                    t
                )));
            }
            run.step_with(&self.dmp, dt, &[&obstacles as &dyn Coupling])
                .map_err(movement)?;
            steps += 1;
            rows.push((steps as f32 * dt, prepared.columns(run.position())));
        }
    }
}

fn distance(a: &[f32], b: &[f32]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(a, b)| (a - b) * (a - b))
        .sum::<f32>()
        .sqrt()
}
